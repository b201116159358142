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

This module is the interpreter: the input loop, dispatching a line to its
command and the paused mode the breakpoint probes enter.  The state a
session keeps and the operations the commands use (running scans with
their faults, Ctrl-C and the report, networks, watches, output helpers) are
:class:`plcrt.debug.state.SessionState`, which :class:`Session` extends.
It is not the command set: each command's handler and the table ``help``
lists are :mod:`plcrt.debug.commands` (re-exported here) and, for traces,
:mod:`plcrt.debug.trace_commands`; they act on a
:class:`~plcrt.debug.state.SessionState` and never import this module.
The tables and network drawings are formatted by :mod:`plcrt.debug.panels`.
Nor is it a second engine: it holds no PLC semantics.  Scans are
:meth:`plcrt.Plc.scan`, durations and conditions are the test harness's
(:mod:`plcrt.testing.harness`), values are read and written through the
PLC's own address access, and pictures of networks come from
:mod:`plcrt.view` when it is available.
"""

from __future__ import annotations

import signal
import time
from collections.abc import Callable, Iterable, Iterator
from typing import TextIO

from ..engine.coverage import NetworkRef
from ..engine.runtime import Plc
from ..errors import PlcError, PlcRuntimeError
from ..safetext import printable
from .base import Command
from .commands import COMMANDS, lookup, strip_comment
from .panels import ms, sim_time
from .state import CommandError, SessionState

#: prompt of the top level; while paused the prompt names the network
PROMPT = "(plcrt) "

#: a function returning the next command line (without or with its newline)
#: after showing ``prompt``, or None at the end of the input
ReadLine = Callable[[str], "str | None"]


class Session(SessionState):
    """A debugging session over one instrumented :class:`~plcrt.Plc`: the
    command interpreter and the paused mode over a :class:`SessionState`.

    Args: those of :class:`SessionState`.
    """

    def __init__(self, plc: Plc, out: TextIO | None = None, *, echo: bool = False,
                 color: bool = False, handle_interrupt: bool = False,
                 max_wall: float | None = None) -> None:
        super().__init__(plc, out, echo=echo, color=color, handle_interrupt=handle_interrupt,
                         max_wall=max_wall)
        self.coverage.on_break = self._on_break
        self._readline: ReadLine = lambda prompt: None

    # ------------------------------------------------------------------
    # Driving the session
    # ------------------------------------------------------------------
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

    # ------------------------------------------------------------------
    # The paused mode
    # ------------------------------------------------------------------
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
        # the stop display (the network drawn with its values) is part of
        # the pause, not of the run --max-wall limits
        paused_at = time.monotonic()
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


__all__ = ["COMMANDS", "PROMPT", "Command", "CommandError", "Session", "lookup",
           "strip_comment"]
