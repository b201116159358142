"""Live status for the ladder view: values from a running PLC and the
power flow through LAD elements.

:class:`PlcStatus` reads values from a :class:`~plcrt.engine.runtime.Plc`
between scans, as Micro/WIN's program status shows values gathered between
scans.  :func:`contact_state`, :func:`modifier_power` and :func:`eno_power`
evaluate the elements of a :mod:`plcrt.view.ladder` rung with them in
three-valued logic: True, False, or None when a snapshot cannot tell.

This module reads memory only; it never writes and never runs a scan.
"""

from __future__ import annotations

import re
from typing import Any, Protocol, Union

from ..compiler.operands import parse_constant
from ..errors import PlcError
from .ladder import Box, Contact

Power = Union[bool, None]  #: three-valued power flow: True, False, None = unknown


class Status(Protocol):
    """Where status values come from.  ``kind`` is ``"BIT"`` for a bit
    context (``T37`` as a contact is the timer bit), ``"REAL"`` for a real,
    else None; the result is None when the value cannot be shown."""

    def value(self, pou_ident: str, operand_text: str,
              kind: str | None = None) -> int | float | None: ...


_LOCAL_RE = re.compile(r"L(\d+\.\d|[BWD]\d+)$", re.I)


class PlcStatus:
    """Status read from a :class:`~plcrt.engine.runtime.Plc` with
    ``plc.read`` (between scans, like Micro/WIN's program status)."""

    def __init__(self, plc: Any) -> None:
        self.plc = plc

    def value(self, pou_ident: str, operand_text: str,
              kind: str | None = None) -> int | float | None:
        text = operand_text.strip()
        # Locals (#x, Lx.y) belong to one call of a block and are gone after
        # it; pointers and indirect operands are not one address.
        if not text or text[0] in "#*&\"'" or _LOCAL_RE.match(text):
            return None
        if parse_constant(text) is not None:
            return None
        try:
            if kind == "BIT":
                try:
                    return self.plc.read(text, "BIT")   # T37 / C5 as a bit
                except PlcError:
                    return self.plc.read(text)
            return self.plc.read(text, kind)
        except PlcError:
            return None


def operand_value(status: Status | None, pou: str, text: str,
                  kind: str | None = None) -> int | float | None:
    """A constant's value, or the status value of an address."""
    c = parse_constant(text)
    if c is not None:
        return c.value if isinstance(c.value, (int, float)) else None
    if status is None:
        return None
    return status.value(pou, text, kind)


def _signed(v: int, bits: int) -> int:
    v &= (1 << bits) - 1
    return v - (1 << bits) if v >> (bits - 1) else v


_RELATION = {"=": lambda a, b: a == b, "<>": lambda a, b: a != b,
             "<": lambda a, b: a < b, "<=": lambda a, b: a <= b,
             ">": lambda a, b: a > b, ">=": lambda a, b: a >= b}


def contact_state(c: Contact, pou: str, status: Status | None) -> Power:
    """Whether a contact passes power (closed), or None if unknown.  For a
    modifier see :func:`modifier_power`."""
    if status is None:
        return None
    shp = c.shape
    if shp.compare:
        t, rel = shp.compare[0], shp.compare[1:]
        kind = "REAL" if t == "R" else None
        a = operand_value(status, pou, c.above, kind)
        b = operand_value(status, pou, c.below, kind)
        if a is None or b is None:
            return None
        if t != "R":  # compare as the CPU does: bytes unsigned, W/D signed
            bits = {"B": 8, "W": 16, "D": 32}[t]
            a, b = (int(x) & 0xFF if t == "B" else _signed(int(x), bits) for x in (a, b))
        return _RELATION[rel](a, b)
    v = status.value(pou, c.above, "BIT")
    if v is None:
        return None
    return bool(v) != shp.negated


def modifier_power(c: Contact, p_in: Power) -> Power:
    """Power after NOT / P / N.  An edge cannot be seen in a snapshot between
    scans, so P and N are unknown unless no power reaches them."""
    if c.shape.lad == "NOT":
        return None if p_in is None else not p_in
    return False if p_in is False else None


def and3(a: Power, b: Power) -> Power:
    if a is False or b is False:
        return False
    if a is None or b is None:
        return None
    return True


def or3(items: list[Power]) -> Power:
    if any(x is True for x in items):
        return True
    if any(x is None for x in items):
        return None
    return False


def eno_power(box: Box, en: Power) -> Power:
    """ENO: EN, except that a box that can fail (ENO 0 on an error) is
    unknown when it runs, since the error is not kept after the scan."""
    if en is not True:
        return en
    from ..isa.registry import lookup
    spec = lookup(box.insn.mnemonic)
    return None if spec is None or spec.may_fail else True


__all__ = ["PlcStatus", "Power", "Status", "and3", "contact_state", "eno_power",
           "modifier_power", "operand_value", "or3"]
