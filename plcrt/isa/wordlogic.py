"""Instruction family: word logic, shifts, rotates and the bit shift register.

Mnemonics: ANDx ORx XORx INVx, SLx SRx RLx RRx (x = B, W, D) and SHRB.
S7-200 System Manual, "Logical operations" and "Shift and rotate
instructions".  STL forms are destructive: ``ANDW IN1, OUT`` computes
OUT := OUT AND IN1, ``INVW OUT`` inverts OUT in place and ``SLW OUT, N``
shifts OUT in place by the byte count N.

Status flags (SMB1):

* logic operations set SM1.0 (result zero) and leave every other bit alone;
* shifts and rotates set SM1.0 from the result and SM1.1 to the last bit
  shifted (or rotated) out; when no shift happens (N = 0, or a rotate count
  that is a multiple of the width) OUT and SM1.1 are left unchanged and only
  SM1.0 is refreshed from OUT;
* SHRB copies the bit shifted out to SM1.1 and touches nothing else.

Everything except SHRB is generated inline (one box, a few integer
operations); SHRB calls a small bound helper.  This module does not cover
the conversion or the table instructions (:mod:`plcrt.isa.convert`,
FILL in :mod:`plcrt.isa.move`).
"""

from __future__ import annotations

from ..gen.emit import BUFFER_NAME, Gen
from ..gen.operands import Addr, Const, area_size
from ..safetext import excerpt
from .registry import Role, Span, insn

F = "wordlogic"

#: width letter -> (input role, in/out role, unsigned read kind, bits)
WIDTHS: dict[str, tuple[Role, Role, str, int]] = {
    "B": (Role.B_R, Role.B_W, "B", 8),
    "W": (Role.W_R, Role.W_W, "WU", 16),
    "D": (Role.D_R, Role.D_W, "DU", 32),
}

#: logic mnemonic stem -> Python operator (bit patterns, all unsigned)
LOGIC: dict[str, tuple[str, str]] = {
    "AND": ("&", "AND"),
    "OR": ("|", "OR"),
    "XOR": ("^", "XOR"),
}

# Shift and rotate templates over the unsigned value {v}, the effective count
# {n}, {wn} = width - n and {n1} = n - 1 (numbers when N is a constant,
# expressions otherwise).  ``out`` is the last bit that left the value.
#   SL by n: bit (width - n) leaves last;     SR by n: bit (n - 1) leaves last.
#   RL by n: the last bit out of the MSB re-enters as result bit 0;
#   RR by n: the last bit out of the LSB re-enters as the result's MSB.
SHIFTS: dict[str, dict[str, str | bool]] = {
    "SL": {"rotate": False, "result": "{v} << {n} & {mask}",
           "out": "{v} >> {wn} & 1", "what": "shift left, zero fill"},
    "SR": {"rotate": False, "result": "{v} >> {n}",
           "out": "{v} >> {n1} & 1", "what": "shift right, zero fill"},
    "RL": {"rotate": True, "result": "({v} << {n} | {v} >> {wn}) & {mask}",
           "out": "{r} & 1", "what": "rotate left"},
    "RR": {"rotate": True, "result": "({v} >> {n} | {v} << {wn}) & {mask}",
           "out": "{r} >> {msb}", "what": "rotate right"},
}

SHRB_MAX = 64  #: longest shift register (System Manual, SHRB: N = -64..64)


# -- AND / OR / XOR / INV ---------------------------------------------------

def _zero_flag(g: Gen, value: str) -> None:
    """SM1.0 := value == 0; the logic family affects SM1.0 only."""
    sm = g.use("SM")
    g.line(f"{sm}[1] = {sm}[1] & 254 | ({value} == 0)")


def _make_logic(stem: str, width: str) -> None:
    op, name = LOGIC[stem]
    role_in, role_out, kind, _bits = WIDTHS[width]

    def emit(g: Gen, a, out) -> None:
        with g.box():
            r = g.tmp("r")
            g.line(f"{r} = {g.rd(out, kind)} {op} {g.rd(a, kind)}")
            g.wr(out, kind, r)
            _zero_flag(g, r)

    insn(f"{stem}{width}", role_in, role_out, family=F,
         summary=f"OUT := OUT {name} IN1 ({width}); SM1.0 zero")(emit)


def _make_inv(width: str) -> None:
    _role_in, role_out, kind, bits = WIDTHS[width]
    mask = (1 << bits) - 1

    def emit(g: Gen, out) -> None:
        with g.box():
            r = g.tmp("r")
            g.line(f"{r} = {g.rd(out, kind)} ^ {mask}")
            g.wr(out, kind, r)
            _zero_flag(g, r)

    insn(f"INV{width}", role_out, family=F,
         summary=f"OUT := NOT OUT ({width}); SM1.0 zero")(emit)


# -- shifts and rotates ----------------------------------------------------

def _shift_body(g: Gen, out, kind: str, bits: int, tpl: dict, n: str, wn: str,
                n1: str) -> None:
    """Shift/rotate OUT by a non-zero effective count and set SM1.0/SM1.1."""
    v, r = g.tmp("v"), g.tmp("r")
    fields = {"v": v, "r": r, "n": n, "wn": wn, "n1": n1,
              "mask": (1 << bits) - 1, "msb": bits - 1}
    g.line(f"{v} = {g.rd(out, kind)}")
    g.line(f"{r} = " + str(tpl["result"]).format(**fields))
    g.wr(out, kind, r)
    sm = g.use("SM")
    g.line(f"{sm}[1] = {sm}[1] & 252 | ({r} == 0) | ("
           + str(tpl["out"]).format(**fields) + ") << 1")


def _make_shift(stem: str, width: str) -> None:
    tpl = SHIFTS[stem]
    _role_in, role_out, kind, bits = WIDTHS[width]
    rotate = bool(tpl["rotate"])

    def emit(g: Gen, out, count) -> None:
        with g.box():
            if isinstance(count, Const):
                k = int(count.value) & 0xFF
                # Shifts: a count >= width shifts the maximum number of times;
                # rotates: the count is taken modulo the width (System Manual,
                # "Shift and rotate instructions").
                k = k % bits if rotate else min(k, bits)
                if k == 0:
                    # No shift/rotate: OUT and SM1.1 unchanged.  The manual
                    # updates SM1.1 only for a shift count above 0 and only
                    # when a rotate is actually performed.
                    _zero_flag(g, g.rd(out, kind))
                    return
                _shift_body(g, out, kind, bits, tpl, str(k), str(bits - k), str(k - 1))
                return
            n = g.tmp("n")
            g.line(f"{n} = {g.rd(count, 'B')}")
            if rotate:
                g.line(f"{n} %= {bits}")
            else:
                with g.block(f"if {n} > {bits}:"):
                    g.line(f"{n} = {bits}")
            with g.block(f"if {n}:"):
                _shift_body(g, out, kind, bits, tpl, n, f"({bits} - {n})", f"({n} - 1)")
            with g.block("else:"):
                _zero_flag(g, g.rd(out, kind))

    insn(f"{stem}{width}", role_out, Role.B_R, family=F,
         summary=f"OUT := OUT {tpl['what']} by N ({width}); SM1.1 last bit out")(emit)


for _w in WIDTHS:
    for _stem in LOGIC:
        _make_logic(_stem, _w)
    _make_inv(_w)
    for _stem in SHIFTS:
        _make_shift(_stem, _w)


# -- SHRB -------------------------------------------------------------------
#
# The register is the run of |N| consecutive bits that starts at S_BIT and
# climbs through bit 7 into the next byte (System Manual, SHRB: MSB.b =
# byte of S_BIT + (|N| - 1 + bit of S_BIT) / 8, remainder of the division).
# Bit numbering inside a byte is LSB-first, so the covering bytes read as a
# little-endian integer hold the register as one contiguous bit field.

def _shrb_up(buf: bytearray, b0: int, b1: int, sh: int, mask: int, top: int,
             data: int) -> int:
    """Shift plus: DATA enters at S_BIT, the MSB leaves; returns the bit out."""
    x = int.from_bytes(buf[b0:b1], "little")
    reg = x >> sh & mask
    buf[b0:b1] = (x & ~(mask << sh) | ((reg << 1 | data) & mask) << sh
                  ).to_bytes(b1 - b0, "little")
    return reg >> top


def _shrb_down(buf: bytearray, b0: int, b1: int, sh: int, mask: int, top: int,
               data: int) -> int:
    """Shift minus: DATA enters at the MSB, S_BIT leaves; returns the bit out."""
    x = int.from_bytes(buf[b0:b1], "little")
    reg = x >> sh & mask
    buf[b0:b1] = (x & ~(mask << sh) | (reg >> 1 | data << top) << sh
                  ).to_bytes(b1 - b0, "little")
    return reg & 1


def _shrb_layout(start: int, n: int) -> tuple[int, int, int, int, int]:
    """(first byte, end byte, bit shift, mask, MSB index) of a register."""
    length = abs(n)
    b0, b1 = start >> 3, (start + length + 7) >> 3
    return b0, b1, start - (b0 << 3), (1 << length) - 1, length - 1


def _signed_byte(v: int) -> int:
    v &= 0xFF
    return v - 256 if v & 0x80 else v


def _shrb_var(buf: bytearray, start: int, size: int, count: int, data: int) -> int:
    """SHRB with a count read at run time; -1 (no shift) for a bad count
    (error 0092) or a register past the end of the area (error 0091)."""
    n = _signed_byte(count)
    if n == 0 or not -SHRB_MAX <= n <= SHRB_MAX or (start + abs(n) + 7) >> 3 > size:
        return -1
    fn = _shrb_up if n > 0 else _shrb_down
    return fn(buf, *_shrb_layout(start, n), data)


def _shrb_inline(g: Gen, buf: str, byte: int, sh: int, mask: int, top: int,
                 up: bool, data: str) -> None:
    """SHRB of a register that lies inside one byte, as inline statements."""
    field = mask << sh
    x, d = g.tmp("x"), g.tmp("d")
    sm = g.use("SM")
    g.line(f"{d} = {data}")
    g.line(f"{x} = {buf}[{byte}]")
    if up:
        new = f"((({x} & {field}) << 1 | {d} << {sh}) & {field})"
        out = f"{x} >> {sh + top} & 1"
    else:
        new = f"(({x} & {field}) >> 1 & {field} | {d} << {sh + top})"
        out = f"{x} >> {sh} & 1"
    g.line(f"{buf}[{byte}] = {x} & {~field & 0xFF} | {new}")
    g.line(f"{sm}[1] = {sm}[1] & 253 | ({out}) << 1")


@insn("SHRB", Role.BIT_R, Role.BIT_W, Role.B_R, family=F, may_fail=True,
      summary="shift DATA into the bit register S_BIT..S_BIT+|N|-1; SM1.1 bit out",
      spans=(Span(1, 1, SHRB_MAX, by=2),))
def _shrb(g: Gen, data: Addr, sbit: Addr, count) -> None:
    start = sbit.offset * 8 + sbit.bit
    size = area_size(g.unit.model, sbit.area)
    buf = g.use(BUFFER_NAME[sbit.area])
    sm = g.use("SM")
    if isinstance(count, Const):
        # The count is a signed byte: 16#C0 and -64 are the same length.
        n = _signed_byte(int(count.value))
        if n == 0 or not -SHRB_MAX <= n <= SHRB_MAX:
            g.fail(f"SHRB length N must be -{SHRB_MAX}..-1 or 1..{SHRB_MAX}, got {n}")
        layout = _shrb_layout(start, n)
        if layout[1] > size:
            g.fail(f"the {abs(n)}-bit shift register from {excerpt(sbit.text)} runs past "
                   f"the end of the {sbit.area} area")
        b0, b1, sh, mask, top = layout
        if b1 - b0 == 1:
            # perf: a register inside one byte is shifted inline.
            with g.box():
                _shrb_inline(g, buf, b0, sh, mask, top, n > 0, g.rbit(data))
                g.eno("1")
            return
        fn = g.bind(_shrb_up if n > 0 else _shrb_down, "shrb")
        args = ", ".join(str(x) for x in layout)
        with g.box():
            # DATA is read before the shift (it may lie inside the register).
            g.line(f"{sm}[1] = {sm}[1] & 253 | {fn}({buf}, {args}, {g.rbit(data)}) << 1")
            g.eno("1")
        return
    fn = g.bind(_shrb_var, "shrb")
    with g.box():
        o = g.tmp("o")
        g.line(f"{o} = {fn}({buf}, {start}, {size}, {g.rd(count, 'B')}, {g.rbit(data)})")
        with g.block(f"if {o} < 0:"):
            g.line("eno = 0")
        with g.block("else:"):
            g.line(f"{sm}[1] = {sm}[1] & 253 | {o} << 1")
            g.eno("1")
