"""Lower checked network pieces to LLVM IR text for the native backend.

One table maps a mnemonic to its lowering (:data:`LOWER`), as
:mod:`plcrt.isa.registry` maps it to its Python emitter; each lowering
mirrors the semantics of that emitter byte for byte (the differential tests
run every program on both backends and compare the memory image after every
scan).  A piece with anything outside the table (an instruction, an operand
area, a stack depth) is not lowered: :class:`NotLowered` says why, and the
piece runs as Python.

What the generated IR may contain: only integers computed here from resolved
operands (offsets, masks, constants) and names built from counters.  No text
from the program ever reaches it.

Memory is the PLC's own image: every segment function takes one argument, a
pointer to a table of buffer addresses (:data:`SLOTS`), and reads and writes
the bytes in program order, as the Python code does.  Boxes (moves, math)
run only with power flow: their stores are written as ``select`` between the
new and the old byte, which keeps each piece one basic block (cheap to
compile, and the same bytes as a conditional store).

This module is the table and its lowerings; the function under construction
is :mod:`.fn`'s and the reading and writing of operands :mod:`.values`'.
It is pure Python (no llvmlite): :mod:`.jit` compiles its output.
"""

from __future__ import annotations

import struct
from typing import Any, Callable

from ...gen.exprs import VALUE_WIDTH, const_expr
from ...gen.operands import Addr, Const
from ...memory.hardware import MAX_CV, resolution_ms
from .fn import PART_LINES, SLOT, SLOTS, Fn, NotLowered
from .values import WIDE, copy, get_bit, native_area, put_bit, rbit, rd, set_sm1, wbit, wr, zn_bits


# -- the table -------------------------------------------------------------------

Lowering = Callable[..., None]
LOWER: dict[str, Lowering] = {}


def lowers(*mnemonics: str) -> Callable[[Lowering], Lowering]:
    def deco(fn: Lowering) -> Lowering:
        for m in mnemonics:
            LOWER[m] = fn
        return fn
    return deco


def _contact(how: str, inverted: bool) -> Lowering:
    def lower(f: Fn, op: Any) -> None:
        v = rbit(f, op)
        if inverted:
            v = f.op(f"xor i1 {v}, true")
        f.combine(how, v)
    return lower


for _m, _how, _inv in (("LD", "push", False), ("LDN", "push", True), ("A", "and", False),
                       ("AN", "and", True), ("O", "or", False), ("ON", "or", True)):
    LOWER[_m] = _contact(_how, _inv)


@lowers("NOT")
def _not(f: Fn) -> None:
    f.stack[-1] = f.op(f"xor i1 {f.top}, true")


def _fold(op: str) -> Lowering:
    def lower(f: Fn) -> None:
        below = f.level(1)
        top = f.stack.pop()
        f.stack[-1] = f.op(f"{op} i1 {below}, {top}")
    return lower


LOWER["ALD"] = _fold("and")
LOWER["OLD"] = _fold("or")


@lowers("LPS")
def _lps(f: Fn) -> None:
    f.push(f.top)


@lowers("LRD")
def _lrd(f: Fn) -> None:
    f.stack[-1] = f.level(1)


@lowers("LPP")
def _lpp(f: Fn) -> None:
    f.level(1)
    f.stack.pop()


@lowers("LDS")
def _lds(f: Fn, n: Any) -> None:
    if not isinstance(n, Const) or not isinstance(n.value, int):
        raise NotLowered("the level is not a constant")
    f.push(f.level(int(n.value)))


@lowers("NOP")
def _nop(f: Fn, *_ops: Any) -> None:
    pass


@lowers("=")
def _assign(f: Fn, op: Any) -> None:
    wbit(f, op, f.top)


def _range(value: int) -> Lowering:
    """S/R of n consecutive bits where the top is 1 (as isa.bitlogic._range)."""
    def lower(f: Fn, op: Any, n: Any) -> None:
        if not isinstance(n, Const) or not isinstance(n.value, int):
            raise NotLowered("the bit count is not a constant")
        area = native_area(op)
        if area == "T" and not value:
            _reset_timers(f, op.offset, int(n.value))
            return
        if area in ("T", "C"):
            raise NotLowered("S/R of counters runs in their bank")
        top = f.top
        start = op.offset * 8 + op.bit
        end = start + int(n.value)
        bit = start
        while bit < end:
            byte, b = divmod(bit, 8)
            span = min(8 - b, end - bit)
            mask = ((1 << span) - 1) << b
            old = f.load8(area, byte)
            new = f.op(f"or i8 {old}, {mask}" if value else f"and i8 {old}, {~mask & 0xFF}")
            f.store8(area, byte, f.select(top, "i8", new, old))
            bit += span
    return lower


LOWER["S"] = _range(1)
LOWER["R"] = _range(0)


def _reset_timers(f: Fn, first: int, count: int) -> None:
    """``R Tn, k`` where the top is 1 (TimerBank.reset of each): stopped,
    previous IN cleared, value and bit 0.  Only 100 ms timers: the 1 and
    10 ms ones are also struck off the engine's list of running timers."""
    if any(resolution_ms(n) != 100 for n in range(first, first + count)):
        raise NotLowered("R of 1 ms or 10 ms timers runs in their bank")
    top = f.top
    for n in range(first, first + count):
        for slot in ("T_RUN", "T_PREV"):
            old = f.load8(slot, n)
            f.store8(slot, n, f.select(top, "i8", "0", old))
        wr(f, Addr("T", n, 0, 0), "W", "0", top)
        old = f.load8("TB", n >> 3)
        new = f.op(f"and i8 {old}, {~(1 << (n & 7)) & 0xFF}")
        f.store8("TB", n >> 3, f.select(top, "i8", new, old))


def _edge(rising: bool) -> Lowering:
    """EU/ED (isa.bitlogic._edge): the edge memory byte keeps the last top
    (2 before the first execution, which never reports an edge)."""
    def lower(f: Fn) -> None:
        if f.site < 0:
            raise NotLowered("the edge has no memory byte")
        top = f.top
        prev = f.load8("EDGES", f.site)
        f.store8("EDGES", f.site, f.op(f"zext i1 {top} to i8"))
        if rising:
            f.stack[-1] = f.op(f"and i1 {top}, {f.op(f'icmp eq i8 {prev}, 0')}")
        else:
            low = f.op(f"xor i1 {top}, true")
            f.stack[-1] = f.op(f"and i1 {low}, {f.op(f'icmp eq i8 {prev}, 1')}")
    return lower


LOWER["EU"] = _edge(True)
LOWER["ED"] = _edge(False)

# compares (isa.compare): bytes unsigned, words and double words signed
_REL = {"=": "eq", "<>": "ne"}
_SIGNED = {"<": "slt", "<=": "sle", ">": "sgt", ">=": "sge"}
_UNSIGNED = {"<": "ult", "<=": "ule", ">": "ugt", ">=": "uge"}


def _compare(prefix: str, width: str, rel: str) -> Lowering:
    kind = width
    cond = _REL.get(rel) or (_UNSIGNED if width == "B" else _SIGNED)[rel]
    how = {"LD": "push", "A": "and", "O": "or"}[prefix]

    def lower(f: Fn, a: Any, b: Any) -> None:
        x, y = rd(f, a, kind), rd(f, b, kind)
        f.combine(how, f.op(f"icmp {cond} {WIDE[kind]} {x}, {y}"))
    return lower


for _p in ("LD", "A", "O"):
    for _w in ("B", "W", "D"):
        for _r in ("=", "<>", "<", "<=", ">", ">="):
            LOWER[f"{_p}{_w}{_r}"] = _compare(_p, _w, _r)


def _move(kind: str) -> Lowering:
    width = VALUE_WIDTH[kind[0]]

    def lower(f: Fn, src: Any, dst: Any) -> None:
        if not copy(f, src, dst, width, f.top):
            wr(f, dst, kind, rd(f, src, kind), f.top)
    return lower


LOWER["MOVB"] = _move("B")
LOWER["MOVW"] = _move("WU")
LOWER["MOVD"] = _move("DU")


@lowers("MOVR")
def _movr(f: Fn, src: Any, dst: Any) -> None:
    """MOVR copies the bit pattern; a constant is stored as IEEE single
    (isa.move._movr through Gen.wr: struct ">f" of the rounded value)."""
    if isinstance(src, Const):
        bits = int.from_bytes(struct.pack(">f", float(const_expr(src, "R"))), "big")
        value = str(bits)
    else:
        value = rd(f, src, "DU")
    wr(f, dst, "DU", value, f.top)

W_RANGE = (-32768, 32767)
D_RANGE = (-2**31, 2**31 - 1)


def _binop(kind: str, op: str, rng: tuple[int, int]) -> Lowering:
    """``OUT := OUT op IN1`` with the SMB1 flags; on overflow SM1.1 and the
    output unchanged (isa.math_int._binop / Gen.store_checked)."""
    ty = WIDE[kind]

    def lower(f: Fn, a: Any, out: Any) -> None:
        top = f.top
        r = f.op(f"{op} {ty} {rd(f, out, kind)}, {rd(f, a, kind)}")
        lo = f.op(f"icmp sge {ty} {r}, {rng[0]}")
        hi = f.op(f"icmp sle {ty} {r}, {rng[1]}")
        ok = f.op(f"and i1 {lo}, {hi}")
        wr(f, out, kind, r, f.op(f"and i1 {top}, {ok}"))
        bits = f.select(ok, "i8", zn_bits(f, ty, r), "2")
        set_sm1(f, top, 248, bits)
    return lower


LOWER["+I"] = _binop("W", "add", W_RANGE)
LOWER["-I"] = _binop("W", "sub", W_RANGE)
LOWER["*I"] = _binop("W", "mul", W_RANGE)
LOWER["+D"] = _binop("D", "add", D_RANGE)
LOWER["-D"] = _binop("D", "sub", D_RANGE)
LOWER["*D"] = _binop("D", "mul", D_RANGE)


def _incdec(kind: str, delta: int, lo: int, hi: int) -> Lowering:
    """INC/DEC wrap around; SM1.1 on the wrap (isa.math_int._incdec)."""
    ty = WIDE[kind]
    width_bits = 8 * VALUE_WIDTH[kind[0]]
    signed = lo < 0

    def lower(f: Fn, out: Any) -> None:
        top = f.top
        r = f.op(f"add {ty} {rd(f, out, kind)}, {delta}")
        a = f.op(f"icmp sge {ty} {r}, {lo}")
        b = f.op(f"icmp sle {ty} {r}, {hi}")
        ok = f.op(f"and i1 {a}, {b}")
        # the wrapped value: the low bits, read back as the kind's range
        low = f.op(f"trunc {ty} {r} to i{width_bits}")
        ext = "sext" if signed else "zext"
        wrapped = f.op(f"{ext} i{width_bits} {low} to {ty}")
        zn = zn_bits(f, ty, wrapped, signed)
        bits = f.select(ok, "i8", zn, f.op(f"or i8 {zn}, 2"))
        set_sm1(f, top, 248, bits)
        wr(f, out, kind, wrapped, top)
    return lower


LOWER["INCB"] = _incdec("B", 1, 0, 255)
LOWER["DECB"] = _incdec("B", -1, 0, 255)
LOWER["INCW"] = _incdec("W", 1, *W_RANGE)
LOWER["DECW"] = _incdec("W", -1, *W_RANGE)
LOWER["INCD"] = _incdec("D", 1, *D_RANGE)
LOWER["DECD"] = _incdec("D", -1, *D_RANGE)


# word logic (isa.wordlogic): unsigned bit patterns, SM1.0 only
_UKIND = {"B": ("B", 8), "W": ("WU", 16), "D": ("DU", 32)}


def _logic(op: str, width: str) -> Lowering:
    kind, _bits = _UKIND[width]
    ty = WIDE[kind]

    def lower(f: Fn, a: Any, out: Any) -> None:
        top = f.top
        r = f.op(f"{op} {ty} {rd(f, out, kind)}, {rd(f, a, kind)}")
        wr(f, out, kind, r, top)
        set_sm1(f, top, 254, zn_bits(f, ty, r, signed=False))
    return lower


def _inv(width: str) -> Lowering:
    kind, bits = _UKIND[width]
    ty = WIDE[kind]

    def lower(f: Fn, out: Any) -> None:
        top = f.top
        r = f.op(f"xor {ty} {rd(f, out, kind)}, {(1 << bits) - 1}")
        wr(f, out, kind, r, top)
        set_sm1(f, top, 254, zn_bits(f, ty, r, signed=False))
    return lower


def _shift(stem: str, width: str) -> Lowering:
    """SL/SR/RL/RR by a constant count (isa.wordlogic): the result and SM1.0,
    SM1.1 the last bit out; a count that shifts nothing refreshes SM1.0 only."""
    kind, bits = _UKIND[width]
    ty = WIDE[kind]
    mask = (1 << bits) - 1
    rotate = stem in ("RL", "RR")

    def lower(f: Fn, out: Any, count: Any) -> None:
        if not isinstance(count, Const) or not isinstance(count.value, int):
            raise NotLowered("a shift by a count held in memory is not lowered")
        k = int(count.value) & 0xFF
        k = k % bits if rotate else min(k, bits)
        top = f.top
        v = rd(f, out, kind)
        if k == 0:
            set_sm1(f, top, 254, zn_bits(f, ty, v, signed=False))
            return
        if stem == "SL":
            r = f.op(f"and {ty} {f.op(f'shl {ty} {v}, {k}')}, {mask}") if k < bits else "0"
            last = f.op(f"and {ty} {f.op(f'lshr {ty} {v}, {bits - k}')}, 1")
        elif stem == "SR":
            r = f.op(f"lshr {ty} {v}, {k}") if k < bits else "0"
            last = f.op(f"and {ty} {f.op(f'lshr {ty} {v}, {k - 1}')}, 1")
        else:
            a, b = (k, bits - k) if stem == "RL" else (bits - k, k)
            hi = f.op(f"shl {ty} {v}, {a}")
            lo = f.op(f"lshr {ty} {v}, {b}")
            r = f.op(f"and {ty} {f.op(f'or {ty} {hi}, {lo}')}, {mask}")
            last = f.op(f"and {ty} {r}, 1") if stem == "RL" else \
                f.op(f"lshr {ty} {r}, {bits - 1}")
        wr(f, out, kind, r, top)
        out8 = f.op(f"trunc {ty} {last} to i8")
        bits8 = f.op(f"or i8 {zn_bits(f, ty, r, signed=False)}, {f.op(f'shl i8 {out8}, 1')}")
        set_sm1(f, top, 252, bits8)
    return lower


for _w in ("B", "W", "D"):
    LOWER[f"AND{_w}"] = _logic("and", _w)
    LOWER[f"OR{_w}"] = _logic("or", _w)
    LOWER[f"XOR{_w}"] = _logic("xor", _w)
    LOWER[f"INV{_w}"] = _inv(_w)
    for _stem in ("SL", "SR", "RL", "RR"):
        LOWER[f"{_stem}{_w}"] = _shift(_stem, _w)


def _narrow(kin: str, kout: str, lo: int, hi: int) -> Lowering:
    """ITB/DTI (isa.convert): in range, OUT and SM1.1 cleared; else SM1.1
    set and OUT unchanged."""
    ty = WIDE[kin]

    def lower(f: Fn, a: Any, out: Any) -> None:
        top = f.top
        v = rd(f, a, kin)
        ok = f.op(f"and i1 {f.op(f'icmp sge {ty} {v}, {lo}')}, "
                  f"{f.op(f'icmp sle {ty} {v}, {hi}')}")
        val = v if WIDE[kout] == ty else f.op(f"trunc {ty} {v} to {WIDE[kout]}")
        wr(f, out, kout, val, f.op(f"and i1 {top}, {ok}"))
        set_sm1(f, top, 253, f.select(ok, "i8", "0", "2"))
    return lower


def _widen(kin: str, kout: str) -> Lowering:
    """BTI/ITD (isa.convert): never fail, no flags."""
    def lower(f: Fn, a: Any, out: Any) -> None:
        v = rd(f, a, kin)
        if WIDE[kin] != WIDE[kout]:
            v = f.op(f"sext {WIDE[kin]} {v} to {WIDE[kout]}")
        wr(f, out, kout, v, f.top)
    return lower


LOWER["ITB"] = _narrow("W", "B", 0, 255)
LOWER["DTI"] = _narrow("D", "W", -32768, 32767)
LOWER["BTI"] = _widen("B", "W")
LOWER["ITD"] = _widen("W", "D")


def _timer_state(f: Fn, t: Any, pt: Any) -> tuple[int, str, str, str, str, str]:
    """What every 100 ms timer box starts from: its number, IN, PT (the
    preset is stored, as the bank does), running, CV and CV advanced by the
    scan's 100 ms ticks (capped at 32767)."""
    if not isinstance(t, Addr) or t.area != "T" or resolution_ms(t.offset) != 100:
        raise NotLowered("only 100 ms timers run natively")
    n = t.offset
    en = f.top
    p = rd(f, pt, "W")
    f.stmt(f"store i16 {f.op(f'trunc i32 {p} to i16')}, "
           f"ptr {f.at('T_PRE', 2 * n)}, align 1")
    run = f.op(f"icmp ne i8 {f.load8('T_RUN', n)}, 0")
    cv = rd(f, t, "W")
    d100 = f.op(f"load i32, ptr {f.base('T_D100')}, align 4")
    adv = f.op(f"add i32 {cv}, {d100}")
    capped = f.op(f"select i1 {f.op(f'icmp sgt i32 {adv}, {MAX_CV}')}, i32 {MAX_CV}, i32 {adv}")
    return n, en, p, run, cv, capped


def _timer_store(f: Fn, t: Any, n: int, run: str, cv: str, bit: str) -> None:
    f.store8("T_RUN", n, f.op(f"zext i1 {run} to i8"))
    wr(f, t, "W", cv, None)
    put_bit(f, "TB", n >> 3, n & 7, bit)


@lowers("TON")
def _ton(f: Fn, t: Any, pt: Any) -> None:
    """TON of a 100 ms timer (engine.timers.TimerBank.ton, its full path).

    IN = 0: stopped, value and bit cleared.  IN = 1: a stopped timer starts
    from its value; a running one adds the 100 ms ticks of this scan
    (capped at 32767).  The bit is CV >= PT.  The 1 ms and 10 ms timers
    are advanced by the engine at the scan start: they stay in Python.
    """
    n, en, p, run, cv, capped = _timer_state(f, t, pt)
    on = f.select(run, "i32", capped, cv)
    cvn = f.select(en, "i32", on, "0")
    bit = f.op(f"and i1 {en}, {f.op(f'icmp sge i32 {cvn}, {p}')}")
    _timer_store(f, t, n, en, cvn, bit)


@lowers("TONR")
def _tonr(f: Fn, t: Any, pt: Any) -> None:
    """TONR of a 100 ms timer (TimerBank.tonr): IN = 0 stops it and keeps
    value and bit; IN = 1 starts it from its value or adds the ticks."""
    n, en, p, run, cv, capped = _timer_state(f, t, pt)
    on = f.select(run, "i32", capped, cv)
    cvn = f.select(en, "i32", on, cv)
    old_bit = get_bit(f, "TB", n >> 3, n & 7)
    reached = f.op(f"icmp sge i32 {on}, {p}")
    bit = f.select(en, "i1", reached, old_bit)
    _timer_store(f, t, n, en, cvn, bit)


@lowers("TOF")
def _tof(f: Fn, t: Any, pt: Any) -> None:
    """TOF of a 100 ms timer (TimerBank.tof): IN = 1 stops it, value 0, bit
    1; the falling edge of IN starts it (value 0, bit 1); a running one adds
    the ticks and, at PT, switches the bit off and stops."""
    n, en, p, run, cv, capped = _timer_state(f, t, pt)
    prev = f.op(f"icmp ne i8 {f.load8('T_PREV', n)}, 0")
    f.store8("T_PREV", n, f.op(f"zext i1 {en} to i8"))
    old_bit = get_bit(f, "TB", n >> 3, n & 7)
    done = f.op(f"icmp sge i32 {capped}, {p}")
    not_en = f.op(f"xor i1 {en}, true")
    not_prev = f.op(f"xor i1 {prev}, true")
    timing = f.op(f"and i1 {not_en}, {f.op(f'and i1 {not_prev}, {run}')}")
    starting = f.op(f"or i1 {en}, {prev}")   # IN on, or its falling edge: value 0, bit 1
    # running on: the ticks added; the bit stays on until PT
    cv_t = f.select(timing, "i32", capped, cv)
    cvn = f.select(starting, "i32", "0", cv_t)
    going = f.op(f"xor i1 {done}, true")
    bit_t = f.select(timing, "i1", going, old_bit)
    bit = f.select(starting, "i1", "true", bit_t)
    # running: stopped by IN, started by the falling edge, stopped at PT
    run_t = f.select(timing, "i1", going, run)
    run_e = f.select(prev, "i1", "true", run_t)
    run_n = f.select(en, "i1", "false", run_e)
    _timer_store(f, t, n, run_n, cvn, bit)


def lower_piece(f: Fn, insns: list[tuple[str, list[Any], int]]) -> None:
    """Lower one piece's resolved instructions into ``f`` (raises NotLowered)."""
    for mnemonic, ops, site in insns:
        fn = LOWER.get(mnemonic)
        if fn is None:
            raise NotLowered(f"{mnemonic} is not lowered")
        f.site = site
        fn(f, *ops)
    f.stack.clear()


__all__ = ["LOWER", "PART_LINES", "SLOT", "SLOTS", "Fn", "Lowering", "NotLowered", "lower_piece",
           "lowers"]
