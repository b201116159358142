"""Operands shown with their symbols: ``Start_PB:I0.0`` for an address or a
symbol of the symbol table, the symbol's comment as a tooltip.

``plcrt show`` and the browser panel (:mod:`plcrt.web`) name operands
the same way through :func:`symbol_names`.  This module reads a symbol
table; it does not parse or resolve operands (that is :mod:`plcrt.lang`'s
and the compiler's business) and draws nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def symbol_names(table: Any) -> Callable[[str], tuple[str, str]]:
    """operand text -> (text shown, tooltip): ``name:address`` and the
    symbol's comment when a symbol is involved."""
    by_name: dict[str, Any] = dict(getattr(table, "entries", {}) or {})
    by_addr: dict[str, Any] = {}
    for s in by_name.values():
        by_addr.setdefault(s.address.replace(" ", "").upper(), s)

    def names(text: str) -> tuple[str, str]:
        s = by_name.get(text)
        if s is not None:
            return f"{s.name}:{s.address}", f"{s.name} = {s.address}" + \
                (f": {s.comment}" if s.comment else "")
        s = by_addr.get(text.replace(" ", "").upper())
        if s is not None:
            return f"{s.name}:{text}", f"{s.name} = {s.address}" + \
                (f": {s.comment}" if s.comment else "")
        return text, ""

    return names


__all__ = ["symbol_names"]
