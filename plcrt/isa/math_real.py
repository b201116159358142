"""Instruction family: REAL math (+R -R *R /R SQRT SIN COS TAN LN EXP).

IEEE-754 single precision, as on the S7-200: operands are read as 32-bit
floats, the result is computed in double precision and rounded once to
single (exact for + - * / and SQRT).  Flags: SM1.0 zero, SM1.1 overflow or
illegal value (result not representable, NaN input, SQRT/LN of a negative
number: output unchanged, ENO 0), SM1.2 negative, SM1.3 divide by zero for
/R.  Angles are radians.
"""

from __future__ import annotations

import math

from ..gen.emit import Gen
from ..gen.recipe import Call
from ..gen.rt import to_f32
from .registry import Role, insn

F = "real"


def _real_result(x: float) -> float | None:
    """Round to single precision; ``None`` for overflow / NaN."""
    return to_f32(x)


def _add(a: float, o: float) -> float | None:
    return _real_result(o + a)


def _sub(a: float, o: float) -> float | None:
    return _real_result(o - a)


def _mul(a: float, o: float) -> float | None:
    return _real_result(o * a)


def _div(a: float, o: float) -> float | None:
    return _real_result(o / a)


def _unary(fn):
    """``fn`` rounded to single precision, None for a domain error or an
    overflow (bound as a recipe: each PLC makes its own, as a closure does
    not pickle)."""
    def f(x: float) -> float | None:
        try:
            return _real_result(fn(x))
        except (ValueError, OverflowError):
            return None
    return f


UNARY = {
    "SQRT": (Call(_unary, (math.sqrt,)), "OUT := square root of IN"),
    "SIN": (Call(_unary, (math.sin,)), "OUT := sine of IN (radians)"),
    "COS": (Call(_unary, (math.cos,)), "OUT := cosine of IN (radians)"),
    "TAN": (Call(_unary, (math.tan,)), "OUT := tangent of IN (radians)"),
    "LN": (Call(_unary, (math.log,)), "OUT := natural logarithm of IN"),
    "EXP": (Call(_unary, (math.exp,)), "OUT := e to the power IN"),
}
BINARY = {"+R": (_add, "OUT := OUT + IN1"), "-R": (_sub, "OUT := OUT - IN1"),
          "*R": (_mul, "OUT := OUT * IN1"), "/R": (_div, "OUT := OUT / IN1")}


def _finish(g: Gen, out, r: str) -> None:
    with g.block(f"if {r} is None:"):
        g.flag_overflow()
        g.line("eno = 0")
    with g.block("else:"):
        g.wr(out, "R", r)
        g.flags_zn(r)
        g.eno("1")


def _make_binary(mn: str, fn, summary: str) -> None:
    def emit(g: Gen, a, out) -> None:
        f = g.bind(fn, "real")
        with g.box():
            r = g.tmp("r")
            if mn == "/R":
                d = g.tmp("d")
                g.line(f"{d} = {g.rd(a, 'R')}")
                with g.divisor_guard(d):
                    g.line(f"{r} = {f}({d}, {g.rd(out, 'R')})")
                    _finish(g, out, r)
                return
            g.line(f"{r} = {f}({g.rd(a, 'R')}, {g.rd(out, 'R')})")
            _finish(g, out, r)
    insn(mn, Role.R_R, Role.R_W, family=F, summary=summary, may_fail=True)(emit)


def _make_unary(mn: str, fn, summary: str) -> None:
    def emit(g: Gen, a, out) -> None:
        f = g.bind(fn, mn.lower())
        with g.box():
            r = g.tmp("r")
            g.line(f"{r} = {f}({g.rd(a, 'R')})")
            _finish(g, out, r)
    insn(mn, Role.R_R, Role.R_W, family=F, summary=summary, may_fail=True)(emit)


for _mn, (_fn, _s) in BINARY.items():
    _make_binary(_mn, _fn, _s)
for _mn, (_fn, _s) in UNARY.items():
    _make_unary(_mn, _fn, _s)
