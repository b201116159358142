"""The diagnostics a page lists: what ``plcrt run`` prints on stderr.

:class:`DiagnosticLog` collects the PLC's warnings at load, its warnings
while running (library blocks check their parameters only when they
execute) and a fault, each once, and turns them into the ``diagnostics``
message of the panel's protocol: the text as the CLI prints it, and the
network (``OB1/5``) a click in the page shows.

It reads :attr:`plcrt.Plc.diagnostics` and :attr:`plcrt.Plc.fault`; it
neither runs the PLC nor sends anything (the session broadcasts).
"""

from __future__ import annotations

from collections.abc import Mapping, Set
from typing import Any

from ..engine.runtime import Plc
from ..errors import Diagnostic, capped
from ..safetext import printable

#: diagnostics a log keeps (beyond them it only counts); pages get the first
#: :data:`plcrt.errors.MAX_LISTED` of them, errors first
KEEP = 1000


class DiagnosticLog:
    """The diagnostics of one session, in the order they came.

    Args:
        blocks: block names and ids in upper case -> the block's id (``OB1``).
        networks: the (block id, network number) pairs the page draws.
    """

    def __init__(self, blocks: Mapping[str, str], networks: Set[tuple[str, int]]) -> None:
        self._blocks, self._networks = blocks, networks
        self._all: list[Diagnostic] = []
        self._seen: set[Diagnostic] = set()
        self._dropped = 0
        self._mark: tuple[int, int, int] | None = None
        #: the ``items`` and ``more`` of the message; replaced whole, so
        #: another thread (the server's ``hello``) may read it at any time
        self.shown: dict[str, Any] = {"items": [], "more": None}

    def sync(self, plc: Plc) -> bool:
        """Take the PLC's new diagnostics; True when the list grew.  A
        warning that comes again (after a power-up reset, in the other
        build of the program) is listed once."""
        mark = (id(plc.diagnostics), len(plc.diagnostics), id(plc.fault))
        if mark == self._mark:      # perf: once per frame, nearly always this
            return False
        self._mark = mark
        fault = plc.fault.diagnostics if plc.fault is not None else []
        new = [d for d in [*plc.diagnostics, *fault] if d not in self._seen]
        for d in new:
            if len(self._all) < KEEP:
                self._seen.add(d)
                self._all.append(d)
            else:
                self._dropped += 1
        if not new:
            return False
        kept, more = capped(self._all)
        if self._dropped:
            more = f"{more + '; ' if more else ''}{self._dropped} more not kept"
        self.shown = {"items": [self._item(d) for d in kept], "more": more}
        return True

    def message(self) -> dict[str, Any]:
        """The ``diagnostics`` message: the whole list (it replaces the page's)."""
        return {"type": "diagnostics", **self.shown}

    def _item(self, d: Diagnostic) -> dict[str, Any]:
        loc = d.loc
        block = network = None
        if loc is not None and loc.block is not None:
            block = self._blocks.get(loc.block.upper())
            if block is not None and (block, loc.network) in self._networks:
                network = f"{block}/{loc.network}"
        return {"severity": d.severity, "message": printable(d.message),
                "where": printable(str(loc)) if loc is not None else "",
                "block": block, "network": network, "text": str(d)}


__all__ = ["DiagnosticLog", "KEEP"]
