"""Instruction family: compares LD/A/O x B/W/D/R x = <> < <= > >=.

S7-200 System Manual, "Compare instructions": bytes compare unsigned, words
(INT) and double words (DINT) signed, reals as IEEE single.  The result is
pushed (LD...), ANDed (A...) or ORed (O...) into the top of the stack;
compares run regardless of power flow.  The family is generated from three
small tables.
"""

from __future__ import annotations

from ..compiler.emit import Gen
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
        expr = f"({g.rd(a, kind)} {pyop} {g.rd(b, kind)})"
        if how == "push":
            g.push(f"1 if {expr} else 0")
        else:
            g.line(f"{g.top} {how} (1 if {expr} else 0)")

    summary = {"push": "push", "&=": "AND", "|=": "OR"}[how]
    insn(f"{prefix}{width}{rel}", role, role, family=F,
         summary=f"{summary} IN1 {rel} IN2 ({width})")(emit)


for _p in COMBINE:
    for _w in WIDTHS:
        for _r in RELATIONS:
            _make(_p, _w, _r)
