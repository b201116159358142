"""Instruction family: bit logic and the logic stack.

S7-200 System Manual, "Bit logic instructions" and "Logic stack":
contacts push (LD*) or combine into the top of the stack (A*, O*); ALD/OLD
combine the two top levels; LPS/LRD/LPP/LDS copy levels; outputs read the
top without changing the stack.  Immediate contacts read the physical input
(PI) without touching the image; immediate outputs write image and terminal.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.operands import Addr, Const, area_size
from ..safetext import excerpt
from .registry import Role, Span, insn

F = "bitlogic"


def _phys(g: Gen, op: Addr) -> str:
    """Expression reading a physical input terminal (immediate contacts)."""
    pi = g.use("PI")
    return f"({pi}[{op.offset}] >> {op.bit} & 1)" if op.bit else f"({pi}[{op.offset}] & 1)"


# Contacts, from one table: (mnemonic, role, combine, inverted).  combine
# is "push" for loads, "&" for A..., "|" for O...; the immediate forms (I
# suffix) read the physical input terminal instead of the image.
CONTACTS = [
    ("LD", "push", False), ("LDN", "push", True), ("A", "&", False), ("AN", "&", True),
    ("O", "|", False), ("ON", "|", True),
]
_HOW = {"push": "push", "&": "top := top AND", "|": "top := top OR"}


def _make_contact(mnemonic: str, how: str, inverted: bool, immediate: bool) -> None:
    def emit(g: Gen, op: Addr) -> None:
        expr = _phys(g, op) if immediate else g.rbit(op)
        if inverted:
            expr = f"({expr} ^ 1)"
        if how == "push":
            g.push(expr)
        else:
            g.combine(how, expr)

    what = ("NOT " if inverted else "") + ("the physical input" if immediate else "the bit")
    insn(mnemonic, Role.IBIT if immediate else Role.BIT_R, family=F,
         summary=f"{_HOW[how]} {what}")(emit)


for _mn, _how, _inv in CONTACTS:
    _make_contact(_mn, _how, _inv, False)
    # LDI LDNI AI ANI OI ONI: the N comes before the I
    _make_contact(_mn + "I", _how, _inv, True)


@insn("NOT", family=F, summary="invert the top of the stack")
def _not(g: Gen) -> None:
    g.line(f"{g.top} ^= 1")


def _edge(g: Gen, rising: bool) -> None:
    # Each EU/ED has its own memory byte; 2 = "not executed yet", so the first
    # execution after entering RUN never reports an edge (manual: the CPU
    # saves the initial state in a memory bit).
    edges = g.unit.hooks.setdefault("edges", bytearray())
    idx = len(edges)
    edges.append(2)
    em = g.bind(edges, "EM")
    top = g.top
    prev = g.tmp("p")
    g.line(f"{prev} = {em}[{idx}]")
    g.line(f"{em}[{idx}] = {top}")
    want = (1, 0) if rising else (0, 1)
    g.line(f"{top} = 1 if ({top} == {want[0]} and {prev} == {want[1]}) else 0")


@insn("EU", family=F, summary="1 for one execution on a rising edge of the top")
def _eu(g: Gen) -> None:
    _edge(g, True)


@insn("ED", family=F, summary="1 for one execution on a falling edge of the top")
def _ed(g: Gen) -> None:
    _edge(g, False)


@insn("ALD", family="stack", summary="AND the two top levels, pop one")
def _ald(g: Gen) -> None:
    _fold(g, "&")


def _fold(g: Gen, op: str) -> None:
    """ALD/OLD: combine the top into the level below and pop it."""
    if g.depth < 2:
        g.level(1)  # raises the stack error
    expr, g.pending = g.pending, None
    below = f"s{g.depth - 1}"
    g.line(f"{below} {op}= {expr if expr is not None else f's{g.depth}'}")
    g.pop()


@insn("OLD", family="stack", summary="OR the two top levels, pop one")
def _old(g: Gen) -> None:
    _fold(g, "|")


@insn("LPS", family="stack", summary="duplicate the top (push)")
def _lps(g: Gen) -> None:
    g.push(g.top)


@insn("LRD", family="stack", summary="copy the second level to the top")
def _lrd(g: Gen) -> None:
    g.line(f"{g.top} = {g.level(1)}")


@insn("LPP", family="stack", summary="pop the top")
def _lpp(g: Gen) -> None:
    g.level(1)
    g.pop()


@insn("LDS", Role.N, family="stack", summary="push a copy of stack level n")
def _lds(g: Gen, n: Const) -> None:
    level = int(n.value)
    if level > 8:
        g.fail("LDS takes a level 1..8")
    g.push(g.level(level))


@insn("AENO", family="stack", summary="AND the previous box's ENO into the top")
def _aeno(g: Gen) -> None:
    if g.eno_valid:
        # eno is assigned only when the box ran, i.e. when the top was 1
        with g.block(f"if {g.top}:"):
            g.line(f"{g.top} = eno")


@insn("=", Role.BIT_W, family=F, summary="write the top to the bit")
def _assign(g: Gen, op: Addr) -> None:
    g.wbit(op, g.top)


@insn("=I", Role.QBIT, family=F, summary="write the top to the output and its terminal now")
def _assign_i(g: Gen, op: Addr) -> None:
    top = g.top
    g.wbit(op, top)
    g.wbit(Addr("PQ", op.offset, 0, op.bit), top)


#: S, R, SI, RI: N bits (1..255) from the first operand
_N_BITS = (Span(0, 1, 255, by=1),)


def _range(g: Gen, op: Addr, n: Const, value: int, phys: bool = False) -> None:
    """S/R over ``n`` consecutive bits starting at ``op`` (T/C: n timers)."""
    count = int(n.value)
    with g.box():
        if op.area in ("T", "C"):
            if value:
                g.fail("S cannot set timers or counters; use R to reset them")
            last = op.offset + count - 1
            limit = 256
            if last >= limit:
                g.fail(f"the range runs past {op.area}{limit - 1}")
            if op.area == "T":
                bank = g.cpu("timers.reset", "Treset")
                g.line(f"for _n in range({op.offset}, {last + 1}): {bank}(_n)")
            else:
                bank = g.cpu("counters.reset", "Creset")
                g.line(f"for _n in range({op.offset}, {last + 1}): {bank}(_n)")
            return
        start = op.offset * 8 + op.bit
        end = start + count
        size = area_size(g.unit.model, op.area) if op.area != "PQ" else g.unit.model.q_bytes
        if (end + 7) // 8 > size:
            g.fail(f"{count} bits from {excerpt(op.text)} run past the end of the {op.area} area")
        areas = [op.area] + (["PQ"] if phys else [])
        for area in areas:
            buf = g.use(area)
            bit = start
            while bit < end:
                byte, b = divmod(bit, 8)
                span = min(8 - b, end - bit)
                mask = ((1 << span) - 1) << b
                if value:
                    g.line(f"{buf}[{byte}] |= {mask}")
                else:
                    g.line(f"{buf}[{byte}] &= {~mask & 0xFF}")
                bit += span


@insn("S", Role.BIT_TC, Role.N, family=F, summary="set n bits", spans=_N_BITS)
def _s(g: Gen, op: Addr, n: Const) -> None:
    _range(g, op, n, 1)


@insn("R", Role.BIT_TC, Role.N, family=F, summary="reset n bits (timers/counters: reset them)",
      spans=_N_BITS)
def _r(g: Gen, op: Addr, n: Const) -> None:
    _range(g, op, n, 0)


@insn("SI", Role.QBIT, Role.N, family=F, summary="set n outputs and their terminals now",
      spans=_N_BITS)
def _si(g: Gen, op: Addr, n: Const) -> None:
    _range(g, op, n, 1, phys=True)


@insn("RI", Role.QBIT, Role.N, family=F, summary="reset n outputs and their terminals now",
      spans=_N_BITS)
def _ri(g: Gen, op: Addr, n: Const) -> None:
    _range(g, op, n, 0, phys=True)


# NOP N takes N = 0..255 (System Manual, "No Operation"); Role.N starts at
# 1, the label role is the registry's 0..255 constant.
@insn("NOP", Role.LABEL, family=F, summary="no operation")
def _nop(g: Gen, n: Const) -> None:
    pass
