"""Instruction family: integer math with SMB1 status flags.

``+I IN1, OUT`` means OUT := OUT + IN1 (STL math is destructive; likewise
``-I``: OUT - IN1, ``/I``: OUT / IN1).  Flags (System Manual, SMB1): SM1.0
result zero, SM1.1 overflow, SM1.2 negative, SM1.3 divide by zero.  On
overflow or division by zero the output is not changed and ENO is 0
(System Manual, "Math instructions": "the output is not altered").
INC/DEC wrap around and set SM1.1 on the wrap; INCB/DECB are unsigned.
Division truncates toward zero; DIV keeps the remainder (sign of the
dividend) in the high word.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.operands import Addr
from .registry import Role, insn

F = "math"

W_RANGE = (-32768, 32767)
D_RANGE = (-2**31, 2**31 - 1)


def _binop(g: Gen, a, out, kind: str, expr_fmt: str, rng: tuple[int, int]) -> None:
    with g.box():
        r = g.tmp("r")
        g.line(f"{r} = " + expr_fmt.format(a=g.rd(a, kind), o=g.rd(out, kind)))
        g.store_checked(out, kind, r, *rng)


def _quotient(g: Gen, n: str, d: str) -> str:
    """Source of the quotient truncated toward zero (as the CPU divides)."""
    return f"abs({n}) // abs({d}) * (-1 if ({n} < 0) != ({d} < 0) else 1)"


def _div(g: Gen, a, out, kind: str, rng: tuple[int, int]) -> None:
    with g.box():
        d, n, r = g.tmp("d"), g.tmp("n"), g.tmp("r")
        g.line(f"{d} = {g.rd(a, kind)}")
        with g.divisor_guard(d):
            g.line(f"{n} = {g.rd(out, kind)}")
            g.line(f"{r} = {_quotient(g, n, d)}")
            g.store_checked(out, kind, r, None, rng[1])


def _reg(mn: str, role_in: Role, role_out: Role, kind: str, fmt: str,
         rng: tuple[int, int], summary: str) -> None:
    def emit(g: Gen, a, out) -> None:
        _binop(g, a, out, kind, fmt, rng)
    insn(mn, role_in, role_out, family=F, summary=summary, may_fail=True)(emit)


_reg("+I", Role.W_R, Role.W_W, "W", "{o} + {a}", W_RANGE, "OUT := OUT + IN1 (INT)")
_reg("-I", Role.W_R, Role.W_W, "W", "{o} - {a}", W_RANGE, "OUT := OUT - IN1 (INT)")
_reg("*I", Role.W_R, Role.W_W, "W", "{o} * {a}", W_RANGE, "OUT := OUT * IN1 (INT)")
_reg("+D", Role.D_R, Role.D_W, "D", "{o} + {a}", D_RANGE, "OUT := OUT + IN1 (DINT)")
_reg("-D", Role.D_R, Role.D_W, "D", "{o} - {a}", D_RANGE, "OUT := OUT - IN1 (DINT)")
_reg("*D", Role.D_R, Role.D_W, "D", "{o} * {a}", D_RANGE, "OUT := OUT * IN1 (DINT)")


@insn("/I", Role.W_R, Role.W_W, family=F, summary="OUT := OUT / IN1 (INT)", may_fail=True)
def _divi(g: Gen, a, out) -> None:
    _div(g, a, out, "W", W_RANGE)


@insn("/D", Role.D_R, Role.D_W, family=F, summary="OUT := OUT / IN1 (DINT)", may_fail=True)
def _divd(g: Gen, a, out) -> None:
    _div(g, a, out, "D", D_RANGE)


def _low_word(g: Gen, out) -> str:
    """Expression reading the low word (INT) of a double-word operand: the
    second input of MUL/DIV (big-endian, so bytes 2..3 of the double word)."""
    if isinstance(out, Addr):
        if out.area == "AC":
            return g.rd(Addr("AC", out.offset, 2, 0, out.text), "W")
        return g.rd(Addr(out.area, out.offset + 2, 2, 0, out.text), "W")
    # *VDn / *ACn / *LDn: read the whole double word and take its low half.
    return f"(({g.rd(out, 'DU')} & 65535 ^ 32768) - 32768)"


@insn("MUL", Role.W_R, Role.D_W, family=F, summary="OUT := IN1 * low word of OUT (32-bit result)")
def _mul(g: Gen, a, out) -> None:
    with g.box():
        r = g.tmp("r")
        g.line(f"{r} = {g.rd(a, 'W')} * {_low_word(g, out)}")
        g.wr(out, "D", r)
        g.flags_zn(r)


@insn("DIV", Role.W_R, Role.D_W, family=F, may_fail=True,
      summary="low word of OUT / IN1: quotient low word, remainder high word")
def _divw(g: Gen, a, out) -> None:
    with g.box():
        d, n, q, m = g.tmp("d"), g.tmp("n"), g.tmp("q"), g.tmp("m")
        g.line(f"{d} = {g.rd(a, 'W')}")
        with g.divisor_guard(d):
            g.line(f"{n} = {_low_word(g, out)}")
            g.line(f"{q} = {_quotient(g, n, d)}")
            g.line(f"{m} = {n} - {q} * {d}")
            with g.block(f"if {q} <= 32767:"):
                g.wr(out, "DU", f"(({m} & 65535) << 16) | ({q} & 65535)")
                g.flags_zn(q)
                g.eno("1")
            with g.block("else:"):
                g.flag_overflow()
                g.line("eno = 0")


def _incdec(mn: str, role: Role, kind: str, delta: int, lo: int, hi: int) -> None:
    span = hi - lo + 1

    def emit(g: Gen, out) -> None:
        with g.box():
            r = g.tmp("r")
            g.line(f"{r} = {g.rd(out, kind)} + ({delta})")
            sm = g.use("SM")
            with g.block(f"if {lo} <= {r} <= {hi}:"):
                g.flags_zn(r) if lo < 0 else \
                    g.line(f"{sm}[1] = {sm}[1] & 248 | ({r} == 0)")
                g.eno("1")
            with g.block("else:"):
                g.line(f"{r} = ({r} - {lo}) % {span} + {lo}")
                g.line(f"{sm}[1] = {sm}[1] & 248 | 2 | ({r} == 0) | ({r} < 0) << 2")
                g.line("eno = 0")
            g.wr(out, kind, r)

    what = "+ 1" if delta > 0 else "- 1"
    insn(mn, role, family=F, summary=f"OUT := OUT {what} ({kind})", may_fail=True)(emit)


_incdec("INCB", Role.B_W, "B", 1, 0, 255)
_incdec("DECB", Role.B_W, "B", -1, 0, 255)
_incdec("INCW", Role.W_W, "W", 1, *W_RANGE)
_incdec("DECW", Role.W_W, "W", -1, *W_RANGE)
_incdec("INCD", Role.D_W, "D", 1, *D_RANGE)
_incdec("DECD", Role.D_W, "D", -1, *D_RANGE)
