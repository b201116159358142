"""Instruction family: counters CTU, CTD, CTUD (semantics in
:mod:`plcrt.engine.counters`).

Stack use: the inputs are the top levels of the logic stack (R/LD on top).
After the box the extra input levels are popped, leaving the first input
(CU or CD) on top; Micro/WIN never emits logic after a counter box in the
same network (docs/decisions.md).
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.operands import Addr
from .registry import Role, insn

F = "counter"


def _use(g: Gen, kind: str, c: Addr) -> str:
    uses = g.unit.counter_use.setdefault(c.offset, [])
    if uses:
        g.warn(f"C{c.offset} is also used by a {uses[0][0]} box; both share one current "
               f"value and edge memory", "counter-twice")
    uses.append((kind, g.loc))
    return g.cpu(f"counters.{kind.lower()}", kind.lower())


@insn("CTU", Role.COUNTER, Role.W_R, family=F, summary="count up (CU second level, R top)")
def _ctu(g: Gen, c: Addr, pv) -> None:
    fn = _use(g, "CTU", c)
    g.line(f"{fn}({c.offset}, {g.level(1)}, {g.top}, {g.rd(pv, 'W')})")
    g.pop()


@insn("CTD", Role.COUNTER, Role.W_R, family=F, summary="count down (CD second level, LD top)")
def _ctd(g: Gen, c: Addr, pv) -> None:
    fn = _use(g, "CTD", c)
    g.line(f"{fn}({c.offset}, {g.level(1)}, {g.top}, {g.rd(pv, 'W')})")
    g.pop()


@insn("CTUD", Role.COUNTER, Role.W_R, family=F,
      summary="count up/down (CU third, CD second, R top)")
def _ctud(g: Gen, c: Addr, pv) -> None:
    fn = _use(g, "CTUD", c)
    g.line(f"{fn}({c.offset}, {g.level(2)}, {g.level(1)}, {g.top}, {g.rd(pv, 'W')})")
    g.pop(2)
