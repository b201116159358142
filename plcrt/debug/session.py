"""The debugger's session: one PLC, a stream of command lines in, plain
text out.

:class:`Session` reads commands (``scan``, ``run``, ``break``, ``watch``,
``set``, ``force``, ``show``, ``axes``, ... see
:data:`~plcrt.debug.commands.COMMANDS`) from any iterable of lines or from
a ``readline``-like function, and writes every answer to a text stream.
It makes no assumption about a terminal: the ``plcrt debug`` command
(:mod:`plcrt.debug.cli`) decides about prompts, echo, colours and Ctrl-C,
and tests drive a session with a list of strings and compare the
transcript.

Breakpoints stop *inside* a scan.  An instrumented program calls
``CoverageMap.on_break`` synchronously at the start of a network that has a
breakpoint, before the network executes; the handler here reads further
commands from the same input ("paused" mode) and returns to the PLC's code
when told to ``continue``, ``next`` or ``finish``.  While paused the scan in
progress sits on the Python stack below the handler, so nothing that would
start another scan (``scan``, ``run``, ``pulse``) can be allowed, and
simulated time does not move.

This module is the machinery every command relies on: the input loop, the
paused mode and the breakpoint probes, running scans (faults, Ctrl-C, the
report after a scan command) and the output helpers.  It is not the command
set: each command's handler and the table ``help`` lists are
:mod:`plcrt.debug.commands` (re-exported here) and, for traces,
:mod:`plcrt.debug.trace_commands`, and the tables and network
drawings are formatted by :mod:`plcrt.debug.panels`.  Nor is it a second
engine: it holds no PLC semantics.  Scans are :meth:`plcrt.Plc.scan`,
durations and conditions are the test harness's
(:mod:`plcrt.testing.harness`), values are read and written through the
PLC's own address access, and pictures of networks come from
:mod:`plcrt.view` when it is available.
"""

from __future__ import annotations

import re
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TextIO

from ..engine.access import force_covers
from ..engine.coverage import NetworkRef
from ..engine.runtime import Plc
from ..errors import PlcConfigError, PlcError, PlcRuntimeError
from ..lang import ir
from ..safetext import printable
from ..testing.harness import Harness, reader
from .commands import COMMANDS, Command, CommandError, lookup, strip_comment
from .panels import draw_network, fmt, load_view, ms, sim_time, status_line, watch_table

if TYPE_CHECKING:
    from ..trace.recorder import Trace

#: prompt of the top level; while paused the prompt names the network
PROMPT = "(plcrt) "

#: a function returning the next command line (without or with its newline)
#: after showing ``prompt``, or None at the end of the input
ReadLine = Callable[[str], "str | None"]


@dataclass
class _Watch:
    spec: str                       #: as the user wrote it, e.g. "VD4:REAL"
    read: Callable[[], int | float]


class Session:
    """A debugging session over one instrumented :class:`~plcrt.Plc`.

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
        self.coverage.on_break = self._on_break
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
        self._readline: ReadLine = lambda prompt: None
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
    # Driving the session
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

    def run(self, lines: Iterable[str] | None = None, *,
            readline: ReadLine | None = None) -> int:
        """Read and execute commands until ``quit`` or the end of the input;
        returns :attr:`exit_status`.

        Give either ``lines`` (any iterable of strings: a list, a file) or
        ``readline``, a function taking the prompt and returning the next
        line or None at the end (``input()`` wrapped by the CLI).
        """
        if (lines is None) == (readline is None):
            raise ValueError("give either lines or readline")
        if readline is None:
            assert lines is not None
            it: Iterator[str] = iter(lines)
            readline = lambda prompt: next(it, None)
        self._readline = readline
        while not self._quit:
            line = self._read(PROMPT)
            if line is None:
                break
            self.execute(line)
        return self.exit_status

    def execute(self, line: str) -> None:
        """Execute one command line (comments and blank lines do nothing).

        Never raises for a user mistake or a PLC fault: both are printed.
        """
        text = strip_comment(line)
        if not text:
            return
        if self.echo:
            self._print(self._prompt() + text)
        name, *args = text.split()
        cmd = lookup(name)
        if cmd is None:
            self._error(f"unknown command '{name}' (type 'help' for the list)")
            return
        if self._paused is not None and cmd.runs_scans:
            self._error(f"'{cmd.name}' would run scans, but scan {self.plc.scans + 1} is "
                        f"paused before {self._paused.name}; use 'continue', 'next' or "
                        f"'finish' first")
            return
        if self._paused is None and cmd.paused_only:
            self._error(f"'{cmd.name}' only works while a scan is paused at a breakpoint")
            return
        try:
            cmd.handler(self, args)
        except CommandError as e:
            self._error(str(e))
        except PlcRuntimeError as e:   # from a command that scanned outside _scanning
            self._fault(e)
        except PlcError as e:
            self._error(e.message)
        except Exception as e:  # noqa: BLE001 - the session must go on, without a traceback
            self._error(f"internal error: {type(e).__name__}: {e} (this is a plcrt bug; "
                        f"please report it with the program and the commands)")

    def banner(self) -> str:
        """One line about the program, for interactive sessions."""
        plc = self.plc
        files = ", ".join(sorted({p.loc.file for p in plc.program.pous})) or plc.program.file
        nets = plc.program.network_count()
        axes, drives = len(plc.axes()), len(plc.drives())
        extra = (f", {axes} axes" if axes else "") + (f", {drives} drive(s)" if drives else "")
        return printable(f"plcrt debug: {files} ({nets} network(s), scan {ms(plc.scan_us)} ms"
                         f"{extra}); type 'help' for the commands")

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

    def _prompt(self) -> str:
        # The paused prompt names the network, so a transcript shows which
        # commands ran in the middle of a scan.
        if self._paused is not None:
            return f"(plcrt {self._paused.name}) "
        return PROMPT

    def _read(self, prompt: str) -> str | None:
        """The next line of input, or None at its end."""
        if not self._sigint_ours:
            return self._readline(prompt)
        # Paused inside a run that catches Ctrl-C: give the keyboard its
        # usual meaning back while the user types (the CLI's reader turns
        # KeyboardInterrupt into an empty line).
        old = signal.signal(signal.SIGINT, signal.default_int_handler)
        try:
            return self._readline(prompt)
        finally:
            signal.signal(signal.SIGINT, old)

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

    def _on_break(self, net: NetworkRef) -> None:
        """Called by the PLC's code before a network with its probe set.

        It runs inside the scan, so it must never raise: an exception would
        unwind through the generated code and fault the PLC.
        """
        try:
            self._pause(net)
        except Exception as e:  # noqa: BLE001 - see above
            self._paused = None
            self._error(f"internal error while paused: {type(e).__name__}: {e}; "
                        f"the scan goes on")

    def _pause(self, net: NetworkRef) -> None:
        if not self._breaks_live or self._abort is not None:
            return
        stepped = self._stepping
        if stepped:
            self._stepping = False
            self._apply_breaks()
        elif net.index not in self._breaks:
            return
        self._paused = net
        what = "stopped before" if stepped else "break at"
        # scan N is the one in progress: plc.scans counts the finished ones
        irq = getattr(self.plc, "interrupts", None)
        if irq is not None and irq.running:
            # an interrupt routine runs at its own time inside the scan interval
            self._print(f"{what} {self._label(net)} (t={self.plc._irq_t / 1e6:.3f} s, "
                        f"an interrupt in scan {self.plc.scans + 1})")
        else:
            self._print(f"{what} {self._label(net)} (t={sim_time(self.plc)} s, "
                        f"scan {self.plc.scans + 1})")
        self._new_diagnostics()
        self._show(net)
        if self._watches:
            for row in self._watch_table():
                self._print(row)
        self._resume = None
        paused_at = time.monotonic()
        while self._resume is None:
            line = self._read(self._prompt())
            if line is None:
                self._print("end of input while paused: the command runs to its end "
                            "without stopping, then the session ends")
                self._resume = "eof"
                break
            self.execute(line)
        action, self._resume, self._paused = self._resume, None, None
        if self._deadline is not None:   # the time spent paused is not the run's
            self._deadline += time.monotonic() - paused_at
        if action == "next":
            # Every network's probe on, until the first one fires (above).
            self._stepping = True
        elif action == "finish":
            self._abort = "finish"
        elif action == "quit":
            # the scan in progress completes, the rest of the command does not
            self._abort = "quit"
            self._breaks_live = False
            self._quit = True
        elif action == "eof":
            # nobody is left to answer at the next stop: run through them
            self._breaks_live = False
            self._quit = True
        self._apply_breaks()

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


__all__ = ["COMMANDS", "PROMPT", "Command", "CommandError", "Session", "lookup",
           "strip_comment"]
