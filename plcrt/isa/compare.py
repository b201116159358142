"""Instruction family: compares LD/A/O x B/W/D/R x = <> < <= > >=.

S7-200 System Manual, "Compare instructions": bytes compare unsigned, words
(INT) and double words (DINT) signed, reals as IEEE single.  The result is
pushed (LD...), ANDed (A...) or ORed (O...) into the top of the stack;
compares run regardless of power flow.  The family is generated from three
small tables.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..errors import PlcRuntimeError, SourceLoc
from ..gen.emit import Gen
from ..gen.operands import Const
from .registry import Role, insn

F = "compare"

RELATIONS = {"=": "==", "<>": "!=", "<": "<", "<=": "<=", ">": ">", ">=": ">="}
WIDTHS = {"B": (Role.B_R, "B"), "W": (Role.W_R, "W"), "D": (Role.D_R, "D"),
          "R": (Role.R_R, "R")}
COMBINE = {"LD": "push", "A": "&=", "O": "|="}


def _make(prefix: str, width: str, rel: str) -> None:
    role, kind = WIDTHS[width]
    pyop = RELATIONS[rel]
    how = COMBINE[prefix]

    def emit(g: Gen, a, b) -> None:
        if kind == "R":
            expr = _real_operands(g, a, b, pyop)
        else:
            expr = f"({g.rd(a, kind)} {pyop} {g.rd(b, kind)})"
        if how == "push":
            g.push(f"1 if {expr} else 0")
        else:
            g.line(f"{g.top} {how} (1 if {expr} else 0)")

    summary = {"push": "push", "&=": "AND", "|=": "OR"}[how]
    insn(f"{prefix}{width}{rel}", role, role, family=F,
         summary=f"{summary} IN1 {rel} IN2 ({width})")(emit)


def _illegal_real(insn_id: int, locs: Sequence[SourceLoc]) -> None:
    """Raise the fatal error of a REAL compare that reads a NaN."""
    raise PlcRuntimeError("compare of an illegal REAL value (NaN); the CPU goes to STOP",
                          locs[insn_id])


def _real_operands(g: Gen, a: Any, b: Any, pyop: str) -> str:
    """Read both REAL operands once and check them; returns the comparison.

    An illegal real is a fatal error on the S7-200 (System Manual, "Compare
    instructions"; only the S7-200 SMART makes it non-fatal with result 0).
    Python's IEEE rules would instead make ``<>`` true and every other
    relation false, matching neither CPU.  Constants are finite by
    construction, so only memory operands are checked.
    """
    names = []
    checks = []
    for op in (a, b):
        if isinstance(op, Const):
            names.append(g.rd(op, "R"))
            continue
        v = g.tmp("r")
        g.line(f"{v} = {g.rd(op, 'R')}")
        names.append(v)
        checks.append(f"{v} != {v}")
    if checks:
        bad = g.bind(_illegal_real, "badreal")
        with g.block(f"if {' or '.join(checks)}:"):
            g.line(f"{bad}({g.insn_id}, {g.use('_LOCS')})")
    return f"({names[0]} {pyop} {names[1]})"


for _p in COMBINE:
    for _w in WIDTHS:
        for _r in RELATIONS:
            _make(_p, _w, _r)
