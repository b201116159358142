"""The state of a debugging session and the operations its commands act on.

:class:`SessionState` holds one instrumented PLC and what the user set up
around it (watches, breakpoints, the trace of the trace commands, where a
paused scan waits) and the operations every command relies on: running
scans (faults, Ctrl-C, ``--max-wall``, the report after a scan command),
finding networks, writing the probe table breakpoints read, and the output
helpers.  :class:`CommandError` is what a command raises for a mistake.

This module is not the command interpreter: reading input, dispatching a
line to its command and the paused mode inside a scan are
:class:`plcrt.debug.session.Session`, a :class:`SessionState`.  Nor is it
the command set (:mod:`plcrt.debug.commands`,
:mod:`plcrt.debug.trace_commands`): the commands receive a
:class:`SessionState`, so they and the interpreter import this module and
not each other.  It holds no PLC semantics: scans are
:meth:`plcrt.Plc.scan`, values are read through the harness's readers.
"""

from __future__ import annotations

import re
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TextIO

from ..engine.access import force_covers
from ..engine.coverage import NetworkRef
from ..engine.runtime import Plc
from ..errors import PlcConfigError, PlcRuntimeError
from ..lang import ir
from ..safetext import printable
from ..testing.harness import Harness, reader
from .panels import draw_network, fmt, load_view, sim_time, status_line, watch_table

if TYPE_CHECKING:
    from ..trace.recorder import Trace


class CommandError(Exception):
    """A command that cannot be carried out as written: printed as
    ``error: <message>`` and the session goes on."""


@dataclass
class _Watch:
    spec: str                       #: as the user wrote it, e.g. "VD4:REAL"
    read: Callable[[], int | float]


class SessionState:
    """The state of a debugging session over one instrumented :class:`~plcrt.Plc`,
    and the operations its commands use.

    Args:
        plc: a PLC loaded with ``instrument=True`` (breakpoints need the
            probes).
        out: where every answer goes (errors too, so a transcript keeps
            them in order).
        echo: print each command after the prompt before its output, for
            transcripts of scripts and pipes where nobody typed it.
        color: the ladder view may use colours (a terminal).
        handle_interrupt: Ctrl-C during a run stops it between two scans
            instead of killing the program (interactive sessions; needs
            the main thread).
        max_wall: each command that runs scans stops between two scans
            after this many wall-clock seconds (time paused at a
            breakpoint does not count); None: no limit.
    """

    def __init__(self, plc: Plc, out: TextIO | None = None, *, echo: bool = False,
                 color: bool = False, handle_interrupt: bool = False,
                 max_wall: float | None = None) -> None:
        if plc.coverage is None:
            raise PlcConfigError("the debugger needs a program loaded with instrument=True "
                                 "(breakpoints use the network probes)")
        self.plc = plc
        self.out: TextIO = out if out is not None else sys.stdout
        self.echo = echo
        self.color = color
        self.handle_interrupt = handle_interrupt
        self.max_wall = max_wall
        self._deadline: float | None = None     # wall-clock end of the running command
        #: a command was stopped by ``max_wall`` at least once in this session
        self.walled = False
        self.harness = Harness(plc)
        self.coverage = plc.coverage
        #: commands that printed ``error: ...`` so far
        self.errors = 0
        #: the PLC faulted at least once in this session
        self.faulted = False
        self._watches: list[_Watch] = []
        self._breaks: set[int] = set()          # network indices with a user breakpoint
        self._paused: NetworkRef | None = None  # where the scan in progress waits
        self._resume: str | None = None         # what ended the pause: continue/next/...
        self._abort: str | None = None          # why the current run stops early
        self._stepping = False                  # `next`: break on every network once
        self._breaks_live = True                # False after end of input or quit
        self._quit = False
        self._sigint_ours = False
        self._diag_seen = len(plc.diagnostics)
        # Networks by block and number, and block names users may type
        # (OB1, SBR0, and the symbolic names such as MAIN or SCALE).
        self._nets: dict[tuple[str, int], tuple[ir.Pou, ir.Network]] = {
            (p.ident, n.number): (p, n) for p in plc.program.pous for n in p.networks}
        self._blocks: dict[str, str] = {}
        for p in plc.program.pous:
            self._blocks.setdefault(p.name.upper(), p.ident)
            self._blocks[p.ident.upper()] = p.ident
        self._view: Any = None   # (ladder_text, render_network, PlcStatus), False: no view
        #: the trace of the trace commands (plcrt.debug.trace_commands), or None
        self._trace: Trace | None = None
        self._apply_breaks()

    # ------------------------------------------------------------------
    # What the session reports
    # ------------------------------------------------------------------
    @property
    def exit_status(self) -> int:
        """0 every command succeeded, 1 some command reported an error,
        2 the PLC faulted, 3 a command was stopped by ``max_wall`` (the
        CLI's exit codes)."""
        if self.faulted:
            return 2
        return 1 if self.errors else 3 if self.walled else 0

    @property
    def paused(self) -> NetworkRef | None:
        """The network the current scan waits before, or None."""
        return self._paused

    # -- the same operations for the CLI's --break / --watch options --------
    def add_breakpoint(self, text: str) -> NetworkRef:
        """Set a breakpoint before network ``text`` (``OB1/3``, ``SBR0/1``, ``3``)."""
        net = self._network(text)
        self._breaks.add(net.index)
        self._apply_breaks()
        return net

    def add_watch(self, spec: str) -> None:
        """Add an address to the watch table (``VD4:REAL``, ``T37:BIT``, symbols)."""
        spec = spec.strip()
        if any(w.spec == spec for w in self._watches):
            return
        self._watches.append(_Watch(spec, reader(self.plc, spec)))

    # ------------------------------------------------------------------
    # Output helpers
    # ------------------------------------------------------------------
    def _print(self, text: str = "") -> None:
        # Titles, operands and echoed commands come from untrusted files:
        # control characters are written as escapes, never raw.
        self.out.write("\n".join(printable(line) for line in text.split("\n")) + "\n")

    def _error(self, message: str) -> None:
        self.errors += 1
        self._print(f"error: {message}")

    def _fault(self, err: PlcRuntimeError) -> None:
        self.faulted = True
        for d in err.diagnostics:
            self._print(str(d))
        self._print("the CPU went to STOP: further scans do nothing (the session goes on "
                    "for inspection)")

    def _new_diagnostics(self) -> None:
        """Warnings raised while running (library blocks check parameters
        only when they execute)."""
        diags = self.plc.diagnostics
        for d in diags[self._diag_seen:]:
            self._print(str(d))
        self._diag_seen = len(diags)

    def _watch_table(self) -> list[str]:
        return watch_table([(w.spec, fmt(w.read()), self._is_forced(w.spec))
                            for w in self._watches])

    def _report(self) -> None:
        """After a scan command: the status line and the watch table."""
        self._print(status_line(self.plc))
        if self._watches:
            for line in self._watch_table():
                self._print(line)

    # -- forced markers ---------------------------------------------------
    def _location(self, spec: str) -> tuple[bytearray, int, int, int]:
        return self.plc.locate(spec)[:4]

    def _is_forced(self, spec: str) -> bool:
        """Whether any forced address overlaps ``spec`` (see force_covers)."""
        return force_covers(self.plc, spec)

    # ------------------------------------------------------------------
    # Networks and breakpoints
    # ------------------------------------------------------------------
    def _network(self, text: str) -> NetworkRef:
        """``OB1/3``, ``SBR0/1``, ``SCALE/2`` (a block's name) or ``3`` (OB1)."""
        m = re.fullmatch(r"(?:([^/\s]+)\s*/\s*)?(\d+)", text.strip())
        if m is None:
            raise CommandError(f"'{text}' is not a network: write OB1/3, SBR0/1 or 3 "
                               f"(a network of OB1)")
        block_text, number = m.group(1) or "OB1", int(m.group(2))
        block = self._blocks.get(block_text.upper())
        if block is None:
            known = ", ".join(p.ident for p in self.plc.program.pous)
            raise CommandError(f"no block '{block_text}' in the program (blocks: {known})")
        net = self.coverage.find(block, number)
        if net is None:
            numbers = [n for (b, n) in self._nets if b == block]
            if (block, number) in self._nets:
                raise CommandError(f"{block}/{number} has no code to stop in")
            span = f"{min(numbers)}..{max(numbers)}" if numbers else "none"
            raise CommandError(f"no network {block}/{number} (networks of {block}: {span})")
        return net

    def _label(self, net: NetworkRef) -> str:
        return f'{net.name} "{net.title}"' if net.title else net.name

    def _apply_breaks(self) -> None:
        """Write the probe table the generated code reads, in place (the
        bytearray is bound into the program's functions)."""
        bp = self.coverage.breakpoints
        if not self._breaks_live or self._abort is not None:
            # finish / quit / end of input: the rest of the scan runs through
            bp[:] = bytes(len(bp))
        elif self._stepping:
            bp[:] = b"\x01" * len(bp)
        else:
            bp[:] = bytes(len(bp))
            for k in self._breaks:
                bp[k] = 1

    # ------------------------------------------------------------------
    # Running scans
    # ------------------------------------------------------------------
    @contextmanager
    def _scanning(self) -> Iterator[None]:
        """Around every command that runs scans: STOP-mode note, Ctrl-C,
        run-time faults, the end of stepping and the report."""
        plc = self.plc
        if plc.mode != "RUN":
            why = "after a fault" if plc.fault is not None else "(a STOP instruction ran)"
            self._print(f"note: the CPU is in STOP mode {why}: scans do nothing")
        self._abort = None
        start, wall_start = plc.scans, time.monotonic()
        if self.max_wall is not None:
            self._deadline = wall_start + self.max_wall
        try:
            with self._interruptible():
                yield
        except PlcRuntimeError as e:
            self._new_diagnostics()
            self._fault(e)
        finally:
            reason, self._abort, self._deadline = self._abort, None, None
            self._stepping = False
            self._apply_breaks()
        self._new_diagnostics()
        if reason == "finish":
            self._print(f"scan {plc.scans} finished; the rest of the command is skipped")
        elif reason == "interrupt":
            self._print(f"interrupted after {plc.scans - start} scan(s)")
        elif reason == "wall":
            self.walled = True
            self._print(f"stopped by --max-wall after {self.max_wall:g} s of wall-clock time, "
                        f"at t={sim_time(plc)} s ({plc.scans - start} scan(s) run); the rest "
                        f"of the command is skipped")
        self._report()

    @contextmanager
    def _interruptible(self) -> Iterator[None]:
        if not self.handle_interrupt or threading.current_thread() is not threading.main_thread():
            yield
            return

        def on_sigint(signum: int, frame: Any) -> None:
            # Stop between two scans: raising here could cut a scan in half.
            if self._abort is None:
                self._abort = "interrupt"

        old = signal.signal(signal.SIGINT, on_sigint)
        self._sigint_ours = True
        try:
            yield
        finally:
            self._sigint_ours = False
            signal.signal(signal.SIGINT, old)

    def _scan(self, n: int) -> None:
        """Up to ``n`` scans, one at a time so that ``finish`` and Ctrl-C can
        end the run between two of them."""
        plc = self.plc
        for _ in range(n):
            if plc.mode != "RUN" or self._abort is not None or self._past_wall():
                break
            plc.scan(1)

    def _past_wall(self) -> bool:
        """The running command reached ``max_wall`` (it then ends as by Ctrl-C)."""
        if self._deadline is not None and time.monotonic() >= self._deadline:
            self._abort = self._abort or "wall"
            return True
        return False

    # ------------------------------------------------------------------
    # Showing networks
    # ------------------------------------------------------------------
    def _load_view(self) -> Any:
        """The ladder renderer (see :func:`~plcrt.debug.panels.load_view`),
        imported at the first drawing; False: no view, networks show as STL."""
        if self._view is None:
            self._view = load_view()
        return self._view

    def _show(self, net: NetworkRef) -> None:
        pou, network = self._nets[(net.block, net.number)]
        self._show_network(pou, network)

    def _show_network(self, pou: ir.Pou, network: ir.Network) -> None:
        """One network in ladder with the values of this moment (in the
        middle of a scan while paused), or its STL without the view."""
        draw_network(self.out, self.plc, pou, network, view=self._load_view(),
                     color=self.color)

__all__ = ["CommandError", "SessionState"]
