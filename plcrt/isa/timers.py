"""Instruction family: timers TON, TONR, TOF.

The boxes take IN from the top of the stack and PT (INT) as operand; the
semantics and the 1/10/100 ms resolution rules live in
:mod:`plcrt.engine.timers`.  Compile-time checks follow the manual: a timer
number belongs to TONR or to TON/TOF by its number, and one timer number
cannot be used by two different timer boxes.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.operands import Addr
from ..memory.hardware import resolution_ms, timer_kind_ok
from .registry import Role, insn

F = "timer"


def _timer(g: Gen, kind: str, t: Addr, pt) -> None:
    n = t.offset
    if not timer_kind_ok(kind, n):
        which = "TONR (T0-T31, T64-T95)" if kind != "TONR" else "TON/TOF (T32-T63, T96-T255)"
        g.fail(f"T{n} is a {which} timer number; it cannot be used by {kind}")
    uses = g.unit.timer_use.setdefault(n, [])
    other = [k for k, _ in uses if k != kind]
    if other:
        g.fail(f"T{n} is already used by a {other[0]} box; TON and TOF cannot share a number")
    if any(k == kind for k, _ in uses) and resolution_ms(n) == 100:
        g.warn(f"T{n} ({kind}) is executed from more than one place; a 100 ms timer "
               f"gains time when its box runs more than once per scan", "timer-twice")
    uses.append((kind, g.loc))
    fn = g.cpu(f"timers.{kind.lower()}", kind.lower())
    g.line(f"{fn}({n}, {g.top}, {g.rd(pt, 'W')})")


@insn("TON", Role.TIMER, Role.W_R, family=F, summary="on-delay timer")
def _ton(g: Gen, t: Addr, pt) -> None:
    _timer(g, "TON", t, pt)


@insn("TONR", Role.TIMER, Role.W_R, family=F, summary="retentive on-delay timer")
def _tonr(g: Gen, t: Addr, pt) -> None:
    _timer(g, "TONR", t, pt)


@insn("TOF", Role.TIMER, Role.W_R, family=F, summary="off-delay timer")
def _tof(g: Gen, t: Addr, pt) -> None:
    _timer(g, "TOF", t, pt)
