"""Which contacts and rung outcomes are constant, for coverage probes.

What it is: a small abstract logic stack that the code generator steps
through the instructions of a piece while it places coverage probes
(:mod:`plcrt.engine.coverage`).  Each level is 1, 0 or unknown.  A contact
on a bit that is constant while the program runs (:data:`CONSTANT_BITS`)
pushes or combines a known value; ``ALD``/``OLD``/``LPS``/``LRD``/``LPP``/
``NOT`` combine known values; anything else makes the level unknown.  A
contact on a constant bit can never be seen both open and closed, and an
output whose power input is known can never be seen both with and without
power: neither is a coverage goal, so no probe is placed for it.

What it is not: an optimiser (the code is the same with or without it), or
a proof about values the program computes.  Whatever it does not know it
treats as unknown, so a goal is only dropped when it is constant for sure;
when its stack depth disagrees with the code generator's (an instruction it
does not model) it forgets everything.
"""

from __future__ import annotations

from typing import Any

from ..gen.operands import Addr
from ..isa.shape import shape

#: (area, byte, bit) -> its value in every scan of RUN mode.  S7-200 System
#: Manual, "Special memory bits" (SMB0): SM0.0 is always on.  SM0.1 (first
#: scan), SM0.2, SM0.3 (one scan each), SM0.4 / SM0.5 (clocks), SM0.6 (scan
#: clock) change, and SM0.7 is the mode switch position on the S7-200 (RUN
#: is also entered from TERM by software) and "RTC lost" on the SMART: none
#: of them is constant.
CONSTANT_BITS: dict[tuple[str, int, int], int] = {("SM", 0, 0): 1}

Level = int | None      #: 1, 0, or unknown


def contact_value(mnemonic: str, ops: list[Any] | tuple[Any, ...]) -> Level:
    """The value a contact puts on the stack when it reads a constant bit
    (negated for ``LDN``/``AN``/``ON``), else None."""
    shp = shape(mnemonic)
    if shp.kind != "contact" or shp.compare or not ops or not isinstance(ops[0], Addr):
        return None
    op = ops[0]
    if op.width != 0:
        return None
    value = CONSTANT_BITS.get((op.area, op.offset, op.bit))
    if value is None:
        return None
    return 1 - value if shp.negated else value


def _and(a: Level, b: Level) -> Level:
    if a == 0 or b == 0:
        return 0
    return 1 if a == 1 and b == 1 else None


def _or(a: Level, b: Level) -> Level:
    if a == 1 or b == 1:
        return 1
    return 0 if a == 0 and b == 0 else None


class ConstantPower:
    """The abstract logic stack of one piece of code (see the module doc)."""

    def __init__(self, depth: int) -> None:
        self.stack: list[Level] = [None] * depth

    def level(self, n: int) -> Level:
        """Stack level *n* from the top (0 = top), None when unknown."""
        return self.stack[-1 - n] if 0 <= n < len(self.stack) else None

    def step(self, mnemonic: str, ops: list[Any] | tuple[Any, ...], depth_after: int) -> None:
        """Follow one emitted instruction; *depth_after* is the code
        generator's stack depth after it."""
        shp = shape(mnemonic)
        st = self.stack
        try:
            if shp.kind == "contact":
                v = contact_value(mnemonic, ops)
                if shp.op == "load":
                    st.append(v)
                else:
                    st[-1] = (_and if shp.op == "and" else _or)(st[-1], v)
            elif shp.kind == "modifier":
                st[-1] = None if mnemonic != "NOT" or st[-1] is None else 1 - st[-1]
            elif shp.kind == "stack":
                self._stack_op(shp.op)
            elif shp.kind == "box" and shp.inputs > 1:
                del st[len(st) - shp.inputs + 1:]   # counters: the extra inputs are popped
            elif shp.kind not in ("coil", "box"):
                st.clear()
        except IndexError:
            st.clear()
        if len(st) != depth_after:      # not modelled: forget everything
            self.stack = [None] * depth_after

    def _stack_op(self, op: str) -> None:
        st = self.stack
        if op in ("and", "or"):
            b, a = st.pop(), st.pop()
            st.append((_and if op == "and" else _or)(a, b))
        elif op == "push":
            st.append(st[-1])
        elif op == "read":
            st[-1] = st[-2]
        elif op == "pop":
            st.pop()
        elif op == "eno":
            st[-1] = _and(st[-1], None)
        else:                           # LDS n: a copy of a deeper level
            st.append(None)


__all__ = ["CONSTANT_BITS", "ConstantPower", "contact_value"]
