"""The debugger's command interpreter: one PLC, a stream of command lines in,
plain text out.

:class:`Session` reads commands (``scan``, ``run``, ``break``, ``watch``,
``set``, ``force``, ``show``, ``axes``, ... see :data:`COMMANDS`) from any
iterable of lines or from a ``readline``-like function, and writes every
answer to a text stream.  It makes no assumption about a terminal: the
``plcrt debug`` command (:mod:`plcrt.debug.cli`) decides about prompts,
echo, colours and Ctrl-C, and tests drive a session with a list of strings
and compare the transcript.

Breakpoints stop *inside* a scan.  An instrumented program calls
``CoverageMap.on_break`` synchronously at the start of a network that has a
breakpoint, before the network executes; the handler here reads further
commands from the same input ("paused" mode) and returns to the PLC's code
when told to ``continue``, ``next`` or ``finish``.  While paused the scan in
progress sits on the Python stack below the handler, so nothing that would
start another scan (``scan``, ``run``, ``pulse``) can be allowed, and
simulated time does not move.

This module is not a second engine and holds no PLC semantics: scans are
:meth:`plcrt.Plc.scan`, durations and conditions are the test harness's
(:mod:`plcrt.testing.harness`), values are read and written through the
PLC's own address access, and pictures of networks come from
:mod:`plcrt.view` when it is available.
"""

from __future__ import annotations

import re
import signal
import sys
import threading
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, TextIO

from ..engine.coverage import NetworkRef
from ..engine.runtime import Plc
from ..errors import PlcConfigError, PlcError, PlcRuntimeError
from ..lang import ir
from ..testing.harness import Harness, PlcTimeout, condition, reader, seconds

#: prompt of the top level; while paused the prompt names the network
PROMPT = "(plcrt) "

#: ``run until`` gives up after this much simulated time unless told otherwise
DEFAULT_UNTIL_TIMEOUT = "10s"

#: a function returning the next command line (without or with its newline)
#: after showing ``prompt``, or None at the end of the input
ReadLine = Callable[[str], "str | None"]


class CommandError(Exception):
    """A command that cannot be carried out as written: printed as
    ``error: <message>`` and the session goes on."""


@dataclass(frozen=True)
class Command:
    """One entry of the command table."""

    name: str
    handler: Callable[[Session, list[str]], None]
    usage: str
    summary: str
    details: str = ""
    aliases: tuple[str, ...] = ()
    #: would start scans: refused while paused inside a scan
    runs_scans: bool = False
    #: only makes sense while paused (continue, next, finish)
    paused_only: bool = False


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
    """

    def __init__(self, plc: Plc, out: TextIO | None = None, *, echo: bool = False,
                 color: bool = False, handle_interrupt: bool = False) -> None:
        if plc.coverage is None:
            raise PlcConfigError("the debugger needs a program loaded with instrument=True "
                                 "(breakpoints use the network probes)")
        self.plc = plc
        self.out: TextIO = out if out is not None else sys.stdout
        self.echo = echo
        self.color = color
        self.handle_interrupt = handle_interrupt
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
        self._apply_breaks()

    # ------------------------------------------------------------------
    # Driving the session
    # ------------------------------------------------------------------
    @property
    def exit_status(self) -> int:
        """0 every command succeeded, 1 some command reported an error,
        2 the PLC faulted (the CLI's exit codes)."""
        if self.faulted:
            return 2
        return 1 if self.errors else 0

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
        axes = len(plc.axes())
        extra = f", {axes} axes" if axes else ""
        return (f"plcrt debug: {files} ({nets} network(s), scan {_ms(plc.scan_us)} ms{extra}); "
                f"type 'help' for the commands")

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
        self.out.write(text + "\n")

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

    def _time(self) -> str:
        us = self.plc.now_us
        # three decimals (ms) suffice unless the scan time has a fraction of a ms
        return f"{us / 1e6:.3f}" if self.plc.scan_us % 1000 == 0 else f"{us / 1e6:.6f}"

    def _mode(self) -> str:
        plc = self.plc
        if plc.mode == "RUN":
            return "RUN"
        return "STOP (fault)" if plc.fault is not None else "STOP"

    def _status_line(self) -> str:
        return f"t={self._time()} s  scan {self.plc.scans}  {self._mode()}"

    def _new_diagnostics(self) -> None:
        """Warnings raised while running (library blocks check parameters
        only when they execute)."""
        diags = self.plc.diagnostics
        for d in diags[self._diag_seen:]:
            self._print(str(d))
        self._diag_seen = len(diags)

    def _value(self, spec: str) -> tuple[str, bool]:
        """(formatted value, forced?) of an address spec."""
        return _fmt(reader(self.plc, spec)()), self._is_forced(spec)

    def _watch_table(self) -> list[str]:
        rows = [(w.spec, _fmt(w.read()), self._is_forced(w.spec)) for w in self._watches]
        aw = max(len("address"), *(len(r[0]) for r in rows))
        vw = max(len("value"), *(len(r[1]) for r in rows))
        lines = [f"{'address':<{aw}}  {'value':>{vw}}"]
        for spec, value, forced in rows:
            lines.append(f"{spec:<{aw}}  {value:>{vw}}" + ("  forced" if forced else ""))
        return lines

    def _report(self) -> None:
        """After a scan command: the status line and the watch table."""
        self._print(self._status_line())
        if self._watches:
            for line in self._watch_table():
                self._print(line)

    # -- forced markers ---------------------------------------------------
    def _location(self, spec: str) -> tuple[bytearray, int, int, int]:
        text, _, kind = spec.partition(":")
        a = self.plc._addr(text)
        if kind.strip().upper() == "BIT" and a.area in ("T", "C"):
            from ..compiler.operands import Addr
            a = Addr(a.area, a.offset, 0, 0, a.text)
        return self.plc._locate(a)

    def _is_forced(self, spec: str) -> bool:
        """Whether any forced address overlaps ``spec`` (forcing Q0.0 marks
        QB0 too: part of what it shows cannot change)."""
        if not self.plc.forces:
            return False
        buf, off, width, bit = self._location(spec)
        for key in self.plc.forces:
            fbuf, foff, fwidth, fbit = self._location(key)
            if fbuf is not buf:
                continue
            if width == 0 and fwidth == 0:
                if off == foff and bit == fbit:
                    return True
            elif off < foff + max(fwidth, 1) and foff < off + max(width, 1):
                return True
        return False

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
        self._print(f"{what} {self._label(net)} (t={self._time()} s, scan {self.plc.scans + 1})")
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
        start = plc.scans
        try:
            with self._interruptible():
                yield
        except PlcRuntimeError as e:
            self._new_diagnostics()
            self._fault(e)
        finally:
            reason, self._abort = self._abort, None
            self._stepping = False
            self._apply_breaks()
        self._new_diagnostics()
        if reason == "finish":
            self._print(f"scan {plc.scans} finished; the rest of the command is skipped")
        elif reason == "interrupt":
            self._print(f"interrupted after {plc.scans - start} scan(s)")
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

    def _scan(self, n: int) -> int:
        """Up to ``n`` scans, one at a time so that ``finish`` and Ctrl-C can
        end the run between two of them; returns how many ran."""
        plc = self.plc
        done = 0
        for _ in range(n):
            if plc.mode != "RUN" or self._abort is not None:
                break
            plc.scan(1)
            done += 1
        return done

    # ------------------------------------------------------------------
    # Showing networks
    # ------------------------------------------------------------------
    def _load_view(self) -> Any:
        """The ladder renderer, or False when :mod:`plcrt.view` is not
        there (or broken): the debugger then shows STL."""
        if self._view is None:
            try:
                # the package exports PlcStatus wherever the view keeps it
                from ..view import PlcStatus
                from ..view.render import ladder_text, render_network
                self._view = (ladder_text, render_network, PlcStatus)
            except Exception:  # noqa: BLE001 - any import problem means: no ladder view
                self._view = False
        return self._view

    def _show(self, net: NetworkRef) -> None:
        pou, network = self._nets[(net.block, net.number)]
        self._show_network(pou, network)

    def _block_heading(self, pou: ir.Pou) -> str:
        name = f" ({pou.name})" if pou.name and pou.name != pou.ident else ""
        return f"{pou.ident}{name}" + (f"  {pou.title}" if pou.title else "")

    def _show_network(self, pou: ir.Pou, network: ir.Network) -> None:
        """One network in ladder with the values of this moment (in the
        middle of a scan while paused), or its STL without the view."""
        view = self._load_view()
        if view:
            ladder_text, render_network, plc_status = view
            try:
                status = plc_status(self.plc)
                program = self.plc.program   # names the pins of CALL boxes
                if self.color:
                    from rich.console import Console
                    console = Console(file=self.out, force_terminal=True, highlight=False,
                                      soft_wrap=True)
                    console.print(render_network(pou, network, status=status, styled=True,
                                                 program=program))
                else:
                    text = ladder_text(pou, network, status=status, program=program)
                    self._print(text.rstrip("\n"))
                return
            except Exception as e:  # noqa: BLE001 - a drawing problem must not end the session
                self._print(f"(the ladder view failed: {type(e).__name__}: {e}; showing STL)")
        self._print(f"Network {network.number}" + (f"  {network.title}" if network.title
                                                   else ""))
        for insn in network.insns:
            ops = ", ".join(o.text for o in insn.operands)
            self._print(f"{insn.mnemonic:<7}{ops}".rstrip())

    # ------------------------------------------------------------------
    # Commands (handlers of the table at the end of the module)
    # ------------------------------------------------------------------
    def _cmd_scan(self, args: list[str]) -> None:
        n = _count(args, "scan", default=1)
        with self._scanning():
            self._scan(n)

    def _cmd_run(self, args: list[str]) -> None:
        if not args:
            raise CommandError("run needs a duration (run 1.5s, run 200ms, run 2) or "
                               "'until COND [timeout DURATION]'")
        if args[0].lower() == "until":
            self._run_until(args[1:])
            return
        if len(args) > 1:
            raise CommandError(f"run takes one duration, got '{' '.join(args)}'")
        us = round(_seconds(args[0]) * 1e6)
        n = -(-us // self.plc.scan_us)   # as Plc.run: whole scans covering the time
        with self._scanning():
            self._scan(n)

    def _run_until(self, args: list[str]) -> None:
        timeout = DEFAULT_UNTIL_TIMEOUT
        low = [a.lower() for a in args]
        if "timeout" in low:
            i = len(low) - 1 - low[::-1].index("timeout")
            if i != len(args) - 2:
                raise CommandError("write 'run until COND timeout DURATION'")
            timeout = args[-1]
            args = args[:i]
        _seconds(timeout)
        text = " ".join(args)
        if not text:
            raise CommandError("run until needs a condition: Q0.0, not M0.1, VW100 >= 5")
        try:
            pred, what = condition(self.harness, text)
        except PlcError as e:
            raise CommandError(e.message) from None

        # The harness names a callable condition by its __name__ in its
        # messages; the wrapper also ends the run on finish or Ctrl-C.
        def until() -> bool:
            return self._abort is not None or pred()

        until.__name__ = what
        with self._scanning():
            try:
                took = self.harness.run_until(until, timeout=timeout)
            except PlcTimeout as e:
                self._error(str(e))
            else:
                if self._abort is None:
                    self._print(f"{what!r} is true after {took:g} s")

    def _cmd_pulse(self, args: list[str]) -> None:
        if not 1 <= len(args) <= 2:
            raise CommandError("write 'pulse ADDR [SCANS]'")
        addr = args[0]
        n = _count(args[1:], "pulse", default=1)
        if n < 1:
            raise CommandError("a pulse lasts at least one scan")
        if self._location(addr)[2] != 0:
            raise CommandError(f"pulse is for bits; use 'set' for {addr}")
        old = self.plc.read(addr)
        self.plc.write(addr, 1)
        self._print(f"{addr} = 1 for {n} scan(s), then {old}")
        try:
            with self._scanning():
                self._scan(n)
        finally:
            self.plc.write(addr, old)

    def _cmd_break(self, args: list[str]) -> None:
        if not args:
            raise CommandError("write 'break NET' (OB1/3, SBR0/1 or 3); 'breaks' lists them")
        for text in args:
            net = self._network(text)
            known = net.index in self._breaks
            self.add_breakpoint(text)
            self._print(f"breakpoint before {self._label(net)}" + (" (already set)" if known
                                                                  else ""))

    def _cmd_delete(self, args: list[str]) -> None:
        if not args:
            raise CommandError("write 'delete NET' or 'delete all'")
        if [a.lower() for a in args] == ["all"]:
            n = len(self._breaks)
            self._breaks.clear()
            self._apply_breaks()
            self._print(f"deleted {n} breakpoint(s)")
            return
        for text in args:
            net = self._network(text)
            if net.index not in self._breaks:
                raise CommandError(f"no breakpoint at {net.name}")
            self._breaks.discard(net.index)
            self._apply_breaks()
            self._print(f"deleted the breakpoint before {net.name}")

    def _cmd_breaks(self, args: list[str]) -> None:
        _no_args(args, "breaks")
        if not self._breaks:
            self._print("no breakpoints")
            return
        for k in sorted(self._breaks):
            self._print(f"breakpoint before {self._label(self.coverage.networks[k])}")

    def _cmd_watch(self, args: list[str]) -> None:
        for spec in args:
            self.add_watch(spec)
        if not self._watches:
            self._print("no addresses watched (add some with 'watch ADDR')")
            return
        for line in self._watch_table():
            self._print(line)

    def _cmd_unwatch(self, args: list[str]) -> None:
        if not args:
            raise CommandError("write 'unwatch ADDR...' or 'unwatch all'")
        if [a.lower() for a in args] == ["all"]:
            self._watches.clear()
            self._print("watch table cleared")
            return
        for spec in args:
            match = [w for w in self._watches if w.spec == spec.strip()]
            if not match:
                raise CommandError(f"{spec} is not watched")
            self._watches.remove(match[0])
        self._print("watching " + (", ".join(w.spec for w in self._watches) or "nothing"))

    def _cmd_print(self, args: list[str]) -> None:
        if not args:
            raise CommandError("write 'print ADDR...' (VW100, Q0.0, VD4:REAL, T37)")
        for spec in args:
            value, forced = self._value(spec)
            self._print(f"{spec} = {value}" + ("  (forced)" if forced else ""))

    def _cmd_set(self, args: list[str]) -> None:
        pairs = _pairs(" ".join(args))
        if not pairs:
            raise CommandError("write 'set ADDR=VALUE...' (VALUE: 12, -3, 16#FF, 2#1010, 1.5)")
        for spec, value_text in pairs:
            addr, value = self._target(spec, value_text)
            self.plc.write(addr, value)
            self._print(f"{spec} = {self._written(addr, value)}")

    def _cmd_force(self, args: list[str]) -> None:
        usage = "write 'force ADDR VALUE' (VALUE: 12, -3, 16#FF, 2#1010, 1.5)"
        if len(args) == 2 and "=" not in args[0]:
            pairs = [(args[0], args[1])]
        else:   # also accept the ADDR=VALUE of 'set'
            try:
                pairs = _pairs(" ".join(args))
            except CommandError:
                raise CommandError(usage) from None
        if len(pairs) != 1:
            raise CommandError(usage)
        spec, value_text = pairs[0]
        addr, value = self._target(spec, value_text)
        self.plc.force(addr, value)
        self._print(f"forced {spec} = {self._written(addr, value)}")

    def _cmd_unforce(self, args: list[str]) -> None:
        if not args:
            raise CommandError("write 'unforce ADDR' or 'unforce all'")
        if [a.lower() for a in args] == ["all"]:
            n = len(self.plc.forces)
            self.plc.unforce()
            self._print(f"released {n} force(s); the values stay until the program "
                        f"changes them")
            return
        for addr in args:
            key = next((k for k in self.plc.forces if k.upper() == addr.strip().upper()), addr)
            self.plc.unforce(key)
            if self._location(key)[0] is self.plc.mem.areas["I"]:
                # the input image is read from the terminals at every scan start
                self._print(f"released {key} (from the next scan on it reads its input "
                            f"terminal again)")
            else:
                value, _ = self._value(key)
                self._print(f"released {key} (it keeps {value} until the program changes it)")

    def _cmd_forces(self, args: list[str]) -> None:
        _no_args(args, "forces")
        if not self.plc.forces:
            self._print("no forces")
            return
        for key, value in self.plc.forces.items():
            self._print(f"{key} = {_fmt(value)}")

    def _cmd_show(self, args: list[str]) -> None:
        if args:
            wanted = [self._nets[(n.block, n.number)] for n in map(self._network, args)]
        else:
            wanted = [(p, n) for p in self.plc.program.pous for n in p.networks]
        # Network numbers restart in every block: each block gets a heading.
        block = None
        for i, (pou, network) in enumerate(wanted):
            if i:
                self._print()
            if pou.ident != block:
                block = pou.ident
                self._print(self._block_heading(pou))
            self._show_network(pou, network)

    def _cmd_axes(self, args: list[str]) -> None:
        _no_args(args, "axes")
        axes = self.plc.axes()
        if not axes:
            self._print("no axes (load a --plant)")
            return
        head = ("slot", "axis", "position", "mechanical", "speed Hz", "status")
        rows = []
        for a in axes:
            status = str(a["status"])
            # SevOn masking and the STF input explain an axis that does not move
            notes = [n for n, on in (("SevOn", a.get("masked")), ("STF", a.get("stf"))) if on]
            if notes:
                status += f" ({', '.join(notes)})"
            rows.append((str(a["slot"]), str(a["axis"]), str(a["position"]),
                         str(a["mechanical"]), str(a["speed"]), status))
        widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(head)]

        def line(cells: tuple[str, ...]) -> str:
            return "  ".join(c.ljust(w) if i == len(head) - 1 else c.rjust(w)
                             for i, (c, w) in enumerate(zip(cells, widths))).rstrip()

        self._print(line(head))
        for r in rows:
            self._print(line(r))

    def _cmd_status(self, args: list[str]) -> None:
        _no_args(args, "status")
        plc = self.plc
        rows = [("time", f"{self._time()} s"),
                ("scans", f"{plc.scans} done"),
                ("mode", self._mode()),
                ("scan time", f"{_ms(plc.scan_us)} ms")]
        if self._paused is not None:
            rows.append(("paused", f"in scan {plc.scans + 1}, before {self._label(self._paused)}"))
        names = [self.coverage.networks[k].name for k in sorted(self._breaks)]
        rows.append(("breakpoints", f"{len(names)}" + (f" ({', '.join(names)})" if names else "")))
        forces = [f"{k}={_fmt(v)}" for k, v in plc.forces.items()]
        rows.append(("forces", f"{len(forces)}" + (f" ({', '.join(forces)})" if forces else "")))
        if plc.fault is not None:
            rows.append(("fault", plc.fault.message))
        w = max(len(k) for k, _ in rows)
        for k, v in rows:
            self._print(f"{k:<{w}}  {v}")

    def _cmd_continue(self, args: list[str]) -> None:
        _no_args(args, "continue")
        self._resume = "continue"

    def _cmd_next(self, args: list[str]) -> None:
        _no_args(args, "next")
        self._resume = "next"

    def _cmd_finish(self, args: list[str]) -> None:
        _no_args(args, "finish")
        self._resume = "finish"

    def _cmd_help(self, args: list[str]) -> None:
        if args:
            cmd = lookup(args[0])
            if cmd is None:
                raise CommandError(f"unknown command '{args[0]}' (type 'help' for the list)")
            aliases = f"  (short: {', '.join(cmd.aliases)})" if cmd.aliases else ""
            self._print(f"{cmd.usage}{aliases}")
            self._print(f"  {cmd.summary}")
            for line in cmd.details.strip().splitlines():
                self._print(f"  {line}" if line else "")
            return
        w = max(len(c.usage) for c in COMMANDS.values())
        for cmd in COMMANDS.values():
            short = f" [{', '.join(cmd.aliases)}]" if cmd.aliases else ""
            self._print(f"  {cmd.usage:<{w}}  {cmd.summary}{short}")
        self._print("NET: OB1/3, SBR0/1 or 3 (OB1).  ADDR: I0.0, VW100, VD4:REAL, T37, "
                    "symbols.  'help CMD' says more.")

    def _cmd_quit(self, args: list[str]) -> None:
        _no_args(args, "quit")
        if self._paused is not None:
            # The scan in progress cannot be abandoned half-way (the memory
            # image would be half of one scan): it runs to its end first.
            self._resume = "quit"
        else:
            self._quit = True

    # -- helpers of the commands -------------------------------------------
    def _written(self, addr: str, value: int | float) -> str:
        """The value now at ``addr``, read back the way it was written (a
        real as a real), so the answer shows any truncation."""
        return _fmt(self.plc.read(addr, "REAL" if isinstance(value, float) and
                                  self._location(addr)[2] == 4 else None))

    def _target(self, spec: str, value_text: str) -> tuple[str, int | float]:
        """Address and value of ``set``/``force``; ``VD4:REAL=2`` stores a REAL."""
        from ..cli import parse_value
        addr, _, kind = spec.partition(":")
        kind = kind.strip().upper()
        if kind not in ("", "REAL"):
            raise CommandError(f"{spec}: only ':REAL' can follow an address here")
        try:
            value = parse_value(value_text)
        except PlcConfigError as e:
            raise CommandError(f"{spec}: {e.message}") from None
        if kind == "REAL":
            self.plc.read(addr, "REAL")    # a double word, or the engine's message
            value = float(value)
        elif isinstance(value, float) and not value.is_integer():
            self.plc.read(addr)            # a bad address is reported as such first
            if self._location(addr)[2] != 4:
                raise CommandError(f"{spec}: a real value needs a double word (VD, MD, ...)")
        return addr, value


# ---------------------------------------------------------------------------
# Small parsers and formatters
# ---------------------------------------------------------------------------

def strip_comment(line: str) -> str:
    """The command part of a line: a ``#`` that starts a word begins a
    comment (``16#FF`` is a value, not a comment)."""
    m = re.search(r"(^|\s)#", line)
    text = line[:m.start()] if m else line
    return text.strip()


def _pairs(text: str) -> list[tuple[str, str]]:
    """``A=1 B = 2`` -> [("A", "1"), ("B", "2")]; anything left over is an error."""
    pairs = re.findall(r"([^\s=]+)\s*=\s*([^\s=]+)", text)
    if re.sub(r"([^\s=]+)\s*=\s*([^\s=]+)", "", text).strip():
        raise CommandError(f"cannot read '{text}': write ADDR=VALUE ...")
    return pairs


def _count(args: list[str], cmd: str, default: int) -> int:
    if not args:
        return default
    if len(args) > 1 or not re.fullmatch(r"\d+", args[0]):
        raise CommandError(f"{cmd} takes a number of scans, got '{' '.join(args)}'")
    return int(args[0])


def _no_args(args: list[str], cmd: str) -> None:
    if args:
        raise CommandError(f"{cmd} takes no argument, got '{' '.join(args)}'")


def _seconds(text: str) -> float:
    try:
        return seconds(text)
    except PlcConfigError as e:
        raise CommandError(e.message) from None


def _fmt(value: int | float) -> str:
    # REALs are single precision: seven significant digits say all there is
    return f"{value:.7g}" if isinstance(value, float) else str(value)


def _ms(us: int) -> str:
    return f"{us / 1000:g}"


# ---------------------------------------------------------------------------
# The command table
# ---------------------------------------------------------------------------

_TABLE = (
    Command("scan", Session._cmd_scan, "scan [N]", "run N scans (default 1)",
            "Then prints the status line and the watch table.", aliases=("s",),
            runs_scans=True),
    Command("run", Session._cmd_run, "run DURATION | run until COND [timeout D]",
            "run for simulated time, or until a condition holds",
            "DURATION: 1.5s, 200ms, 2 (seconds), 2min.  COND: Q0.0, not M0.1, VW100 >= 5,\n"
            "VD4:REAL > 1.5 (== != < <= > >=), checked after every scan.  'run until'\n"
            f"gives up after {DEFAULT_UNTIL_TIMEOUT} of simulated time unless a timeout "
            "is given.", aliases=("r",), runs_scans=True),
    Command("pulse", Session._cmd_pulse, "pulse ADDR [SCANS]",
            "push a bit for one scan (or SCANS scans), then put the old value back",
            runs_scans=True),
    Command("break", Session._cmd_break, "break NET",
            "stop before network NET executes (inside the scan)",
            "NET: OB1/3, SBR0/1, a block's name and a number (SCALE/2), or a number\n"
            "of OB1.  When a scan reaches the network the debugger pauses in the\n"
            "middle of the scan: networks before it have run in this scan, the ones\n"
            "after it still show the last scan's results.  Then 'continue', 'next'\n"
            "or 'finish'.", aliases=("b",)),
    Command("delete", Session._cmd_delete, "delete NET|all", "remove breakpoints"),
    Command("breaks", Session._cmd_breaks, "breaks", "list the breakpoints"),
    Command("watch", Session._cmd_watch, "watch [ADDR...]",
            "add addresses to the watch table (alone: print it)",
            "The table (address, value, 'forced' marker) is printed after every\n"
            "scan, run and pulse, and at every stop.  VD4:REAL reads a float,\n"
            "T37:BIT the timer bit (T37 alone is its current value).", aliases=("w",)),
    Command("unwatch", Session._cmd_unwatch, "unwatch ADDR...|all",
            "remove addresses from the watch table"),
    Command("print", Session._cmd_print, "print ADDR...", "print values now",
            "Bits as 0/1, bytes unsigned, words and double words signed,\n"
            "T37/C5 their current value, VD4:REAL a float.", aliases=("p",)),
    Command("set", Session._cmd_set, "set ADDR=VALUE...", "write values now",
            "VALUE: 12, -3, 16#FF, 2#1010, 1.5 (a real needs a double word;\n"
            "VD4:REAL=2 stores 2.0).  An input keeps its value over the next scans,\n"
            "like a switch left on; the program may overwrite anything else."),
    Command("force", Session._cmd_force, "force ADDR VALUE",
            "force a value until 'unforce'",
            "As on the CPU the value is written at the start of every scan and again\n"
            "after the program ran, so the outputs and the next scan see it.  While\n"
            "paused it takes effect at once."),
    Command("unforce", Session._cmd_unforce, "unforce ADDR|all",
            "release forces (the value stays until the program changes it)"),
    Command("forces", Session._cmd_forces, "forces", "list the forced addresses"),
    Command("show", Session._cmd_show, "show [NET]",
            "draw a network (no NET: all of them) with live values"),
    Command("axes", Session._cmd_axes, "axes",
            "the EM253 axes: position, mechanical position, speed, status"),
    Command("status", Session._cmd_status, "status",
            "time, scans, mode, scan time, breakpoints, forces"),
    Command("continue", Session._cmd_continue, "continue",
            "paused: resume the scan and the run", aliases=("c",), paused_only=True),
    Command("next", Session._cmd_next, "next",
            "paused: resume and stop before the next network that executes",
            "In any block: a CALL leads into the subroutine's first network, the\n"
            "end of OB1 to network 1 of the next scan (if the command runs one).",
            aliases=("n",), paused_only=True),
    Command("finish", Session._cmd_finish, "finish",
            "paused: finish this scan and end the command there", paused_only=True),
    Command("help", Session._cmd_help, "help [CMD]", "list the commands, or explain one",
            aliases=("h", "?")),
    Command("quit", Session._cmd_quit, "quit",
            "end the session (paused: the scan in progress finishes first)",
            aliases=("q", "exit")),
)

#: command name -> command, in the order ``help`` lists them
COMMANDS: dict[str, Command] = {c.name: c for c in _TABLE}
_ALIASES: dict[str, Command] = {a: c for c in _TABLE for a in c.aliases}


def lookup(name: str) -> Command | None:
    """The command called ``name`` or one of its short forms."""
    key = name.lower()
    return COMMANDS.get(key) or _ALIASES.get(key)


__all__ = ["COMMANDS", "PROMPT", "Command", "CommandError", "Session", "lookup",
           "strip_comment"]
