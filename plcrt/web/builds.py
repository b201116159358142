"""The panel's breakpoints, and the two builds of the program they need.

Breakpoints stop inside a scan, as the debugger's do: the program is
loaded with network probes (``instrument=True``) and
``CoverageMap.on_break`` is called before a network with a breakpoint.
Probes cost scan time, so
the session scans in the build it was loaded in (its *home* build) and
moves to a build with probes, between two scans and in exactly the same
state (:meth:`plcrt.Plc.recompiled`), while a breakpoint is set.  The
power-up state (for the reset) is kept for each build.

What it is: the set of breakpoints, which build is which, the move from
one to the other and the lookup of ``OB1/3`` in the program.  What it is
not: what follows the PLC to the other build (the watch table, the trend,
a run until a condition: the session moves them, :mod:`plcrt.web.session`)
or the pause itself.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from ..engine.coverage import NetworkRef
from ..engine.runtime import Plc
from ..errors import PlcConfigError

_NETWORK = re.compile(r"(?:([^/\s]+)\s*/\s*)?(\d+)")


class Builds:
    """Breakpoints, and the builds with and without probes.

    Args:
        plc: the PLC as loaded (its build and backend are the home ones).
        breakpoints: whether breakpoints may be set; a PLC loaded with
            probes may always have them.
        blocks: block names and ids (upper case) -> block id.
        on_break: called by the program's code before a network with a
            breakpoint (set on every build with probes).
    """

    def __init__(self, plc: Plc, *, breakpoints: bool, blocks: dict[str, str],
                 on_break: Callable[[NetworkRef], None]) -> None:
        #: breakpoints may be set (in the build with probes)
        self.breakable = breakpoints or plc.coverage is not None
        #: the build scans run in when no breakpoint is set: with or without
        #: probes, and its backend
        self.home = (plc.coverage is not None, plc.backend["name"])
        #: the state at power-up in each build (with probes: True), for reset
        self._power_ups: dict[bool, Plc] = {self.home[0]: plc.snapshot()}
        #: the networks with a breakpoint (their coverage index)
        self.breaks: set[int] = set()
        self._blocks = blocks
        self._on_break = on_break
        if plc.coverage is not None:
            plc.coverage.on_break = on_break

    def check(self) -> None:
        """Refuse a breakpoint when they are off."""
        if not self.breakable:
            raise PlcConfigError("breakpoints are off (plcrt serve --no-breakpoints)")

    def find(self, plc: Plc, text: str) -> NetworkRef:
        """The network ``text`` names (``OB1/3``, ``SBR0/1`` or ``3`` in
        OB1) in ``plc``, a build with probes."""
        cov = plc.coverage
        assert cov is not None
        m = _NETWORK.fullmatch(text.strip())
        if m is None:
            raise PlcConfigError(f"'{text}' is not a network: write OB1/3, SBR0/1 or 3")
        block = self._blocks.get((m.group(1) or "OB1").upper())
        if block is None:
            raise PlcConfigError(f"no block '{m.group(1)}' in the program")
        net = cov.find(block, int(m.group(2)))
        if net is None:
            raise PlcConfigError(f"no network {block}/{m.group(2)} with code to stop in")
        return net

    def moved(self, old: Plc, probes: bool) -> Plc | None:
        """``old`` in the build with (or without) probes, in exactly its
        state, with its observers; None when ``old`` is that build."""
        if (old.coverage is not None) == probes:
            return None
        new = old.recompiled(instrument=probes, backend=self.backend(probes))
        new.observers[:] = old.observers
        if new.coverage is not None:
            new.coverage.on_break = self._on_break
        return new

    def power_up(self, plc: Plc) -> Plc:
        """The power-up state in the build ``plc`` is."""
        probes = plc.coverage is not None
        snap = self._power_ups.get(probes)
        if snap is None:
            home = self._power_ups[self.home[0]]
            snap = self._power_ups[probes] = home.recompiled(instrument=probes,
                                                             backend=self.backend(probes))
        return snap

    def backend(self, probes: bool) -> str:
        """The backend of the build with (or without) probes: the loaded
        one's (both backends compile probes)."""
        return self.home[1]

    def apply(self, plc: Plc, suspended: bool = False) -> None:
        """Write the breakpoints into ``plc``'s probes (none while
        ``suspended``: a reset is pending at the end of the paused scan)."""
        cov = plc.coverage
        if cov is None:
            return
        cov.on_break = self._on_break
        bp = cov.breakpoints
        bp[:] = bytes(len(bp))
        if not suspended:
            for k in self.breaks:
                bp[k] = 1

    def names(self, plc: Plc) -> list[str]:
        """The networks with a breakpoint, by name, for a frame."""
        cov = plc.coverage
        return sorted(cov.networks[k].name for k in self.breaks) if cov else []
