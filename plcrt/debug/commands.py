"""The debugger's commands: the table ``help`` lists and one handler per
command.

Each :class:`Command` names its handler, a function taking the
:class:`~plcrt.debug.state.SessionState` and the words after the command
name.  A handler raises :class:`CommandError` for a command that cannot be
carried out as written; the session prints it as ``error: ...`` and goes
on.  Commands that run scans do so inside the session's ``_scanning()``, so
a fault, Ctrl-C and ``finish`` end them the same way.

This module is not the session: reading input, the paused mode and the
breakpoint probes live in :mod:`plcrt.debug.session`; the handlers use the
state and operations of :mod:`plcrt.debug.state` (one package, so they reach
its underscored members) and never import the interpreter.  The tables and the drawing are
:mod:`plcrt.debug.panels`; the trace commands (``trace``, ``trend``,
``csv``, ``plot``) are :mod:`plcrt.debug.trace_commands`, entered into the
same table.  Nothing here holds PLC semantics: values are
read and written through the PLC's own address access, durations and
conditions are the test harness's.
"""

from __future__ import annotations

import re

from ..engine.values import parse_number
from ..errors import PlcConfigError, PlcError
from ..testing.harness import PlcTimeout, condition, reader, seconds
from .base import Command
from .panels import axes_table, block_heading, drives_table, fmt, key_values, mode, ms, sim_time
from .state import CommandError, SessionState
from .trace_commands import TRACE_COMMANDS, trace_summary

#: ``run until`` gives up after this much simulated time unless told otherwise
DEFAULT_UNTIL_TIMEOUT = "10s"

#: the most scans one command runs (scan, run, run until's timeout, pulse):
#: a few minutes of wall-clock time at the debugger's scan-by-scan pace;
#: plcrt run takes longer runs (with --max-wall)
MAX_COMMAND_SCANS = 10_000_000


# ---------------------------------------------------------------------------
# The handlers
# ---------------------------------------------------------------------------

def _cmd_scan(s: SessionState, args: list[str]) -> None:
    n = _count(args, "scan", default=1)
    with s._scanning():
        s._scan(n)


def _cmd_run(s: SessionState, args: list[str]) -> None:
    if not args:
        raise CommandError("run needs a duration (run 1.5s, run 200ms, run 2) or "
                           "'until COND [timeout DURATION]'")
    if args[0].lower() == "until":
        _run_until(s, args[1:])
        return
    if len(args) > 1:
        raise CommandError(f"run takes one duration, got '{' '.join(args)}'")
    us = round(_seconds(args[0]) * 1e6)
    n = _bounded(-(-us // s.plc.scan_us), "run", s)   # as Plc.run: whole scans covering it
    with s._scanning():
        s._scan(n)


def _run_until(s: SessionState, args: list[str]) -> None:
    timeout = DEFAULT_UNTIL_TIMEOUT
    low = [a.lower() for a in args]
    if "timeout" in low:
        i = len(low) - 1 - low[::-1].index("timeout")
        if i != len(args) - 2:
            raise CommandError("write 'run until COND timeout DURATION'")
        timeout = args[-1]
        args = args[:i]
    _bounded(-(-round(_seconds(timeout) * 1e6) // s.plc.scan_us), "run until's timeout", s)
    text = " ".join(args)
    if not text:
        raise CommandError("run until needs a condition: Q0.0, not M0.1, VW100 >= 5")
    try:
        pred, what = condition(s.harness, text)
    except PlcError as e:
        raise CommandError(e.message) from None

    # The harness names a callable condition by its __name__ in its
    # messages; the wrapper also ends the run on finish or Ctrl-C.
    def until() -> bool:
        return s._abort is not None or s._past_wall() or pred()

    until.__name__ = what
    with s._scanning():
        try:
            took = s.harness.run_until(until, timeout=timeout)
        except PlcTimeout as e:
            s._error(str(e))
        else:
            if s._abort is None:
                s._print(f"{what!r} is true after {took:g} s")


def _cmd_pulse(s: SessionState, args: list[str]) -> None:
    if not 1 <= len(args) <= 2:
        raise CommandError("write 'pulse ADDR [SCANS]'")
    addr = args[0]
    n = _count(args[1:], "pulse", default=1)
    if n < 1:
        raise CommandError("a pulse lasts at least one scan")
    if s._location(addr)[2] != 0:
        raise CommandError(f"pulse is for bits; use 'set' for {addr}")
    old = s.plc.read(addr)
    s.plc.write(addr, 1)
    s._print(f"{addr} = 1 for {n} scan(s), then {old}")
    try:
        with s._scanning():
            s._scan(n)
    finally:
        s.plc.write(addr, old)


def _cmd_break(s: SessionState, args: list[str]) -> None:
    if not args:
        raise CommandError("write 'break NET' (OB1/3, SBR0/1 or 3); 'breaks' lists them")
    for text in args:
        net = s._network(text)
        known = net.index in s._breaks
        s.add_breakpoint(text)
        s._print(f"breakpoint before {s._label(net)}" + (" (already set)" if known
                                                          else ""))


def _cmd_delete(s: SessionState, args: list[str]) -> None:
    if not args:
        raise CommandError("write 'delete NET' or 'delete all'")
    if [a.lower() for a in args] == ["all"]:
        n = len(s._breaks)
        s._breaks.clear()
        s._apply_breaks()
        s._print(f"deleted {n} breakpoint(s)")
        return
    for text in args:
        net = s._network(text)
        if net.index not in s._breaks:
            raise CommandError(f"no breakpoint at {net.name}")
        s._breaks.discard(net.index)
        s._apply_breaks()
        s._print(f"deleted the breakpoint before {net.name}")


def _cmd_clear(s: SessionState, args: list[str]) -> None:
    if args:
        # gdb's `clear LOCATION`: the breakpoints at these networks go
        _cmd_delete(s, args)
        return
    if s.color:
        # A terminal: home the cursor and erase the screen (ECMA-48 CUP, ED 2),
        # as the shell's `clear` and Ctrl-L do.  A script or pipe has no
        # screen, and its transcript keeps everything.
        s.out.write("\x1b[H\x1b[2J")
        s.out.flush()


def _cmd_breaks(s: SessionState, args: list[str]) -> None:
    _no_args(args, "breaks")
    if not s._breaks:
        s._print("no breakpoints")
        return
    for k in sorted(s._breaks):
        s._print(f"breakpoint before {s._label(s.coverage.networks[k])}")


def _cmd_watch(s: SessionState, args: list[str]) -> None:
    for spec in args:
        s.add_watch(spec)
    if not s._watches:
        s._print("no addresses watched (add some with 'watch ADDR')")
        return
    for line in s._watch_table():
        s._print(line)


def _cmd_unwatch(s: SessionState, args: list[str]) -> None:
    if not args:
        raise CommandError("write 'unwatch ADDR...' or 'unwatch all'")
    if [a.lower() for a in args] == ["all"]:
        s._watches.clear()
        s._print("watch table cleared")
        return
    for spec in args:
        match = [w for w in s._watches if w.spec == spec.strip()]
        if not match:
            raise CommandError(f"{spec} is not watched")
        s._watches.remove(match[0])
    s._print("watching " + (", ".join(w.spec for w in s._watches) or "nothing"))


def _cmd_print(s: SessionState, args: list[str]) -> None:
    if not args:
        raise CommandError("write 'print ADDR...' (VW100, Q0.0, VD4:REAL, T37)")
    for spec in args:
        value, forced = _value(s, spec)
        s._print(f"{spec} = {value}" + ("  (forced)" if forced else ""))


def _cmd_set(s: SessionState, args: list[str]) -> None:
    pairs = _pairs(" ".join(args))
    if not pairs:
        raise CommandError("write 'set ADDR=VALUE...' (VALUE: 12, -3, 16#FF, 2#1010, 1.5)")
    for spec, value_text in pairs:
        addr, value = _target(s, spec, value_text)
        s.plc.write(addr, value)
        s._print(f"{spec} = {_written(s, addr, value)}")


def _cmd_force(s: SessionState, args: list[str]) -> None:
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
    addr, value = _target(s, spec, value_text)
    s.plc.force(addr, value)
    s._print(f"forced {spec} = {_written(s, addr, value)}")


def _cmd_unforce(s: SessionState, args: list[str]) -> None:
    if not args:
        raise CommandError("write 'unforce ADDR' or 'unforce all'")
    if [a.lower() for a in args] == ["all"]:
        n = len(s.plc.forces)
        s.plc.unforce()
        s._print(f"released {n} force(s); the values stay until the program "
                 f"changes them")
        return
    for addr in args:
        # a force belongs to its location: 'unforce Start' releases 'force I0.0 1'
        key = s.plc.unforce(addr) or addr
        if s._location(key)[0] is s.plc.mem.areas["I"]:
            # the input image is read from the terminals at every scan start
            s._print(f"released {key} (from the next scan on it reads its input "
                     f"terminal again)")
        else:
            value, _ = _value(s, key)
            s._print(f"released {key} (it keeps {value} until the program changes it)")


def _cmd_forces(s: SessionState, args: list[str]) -> None:
    _no_args(args, "forces")
    if not s.plc.forces:
        s._print("no forces")
        return
    for key, value in s.plc.forces.items():
        s._print(f"{key} = {fmt(value)}")


def _cmd_show(s: SessionState, args: list[str]) -> None:
    if args:
        wanted = [s._nets[(n.block, n.number)] for n in map(s._network, args)]
    else:
        wanted = [(p, n) for p in s.plc.program.pous for n in p.networks]
    # Network numbers restart in every block: each block gets a heading.
    block = None
    for i, (pou, network) in enumerate(wanted):
        if i:
            s._print()
        if pou.ident != block:
            block = pou.ident
            s._print(block_heading(pou))
        s._show_network(pou, network)


def _cmd_axes(s: SessionState, args: list[str]) -> None:
    _no_args(args, "axes")
    axes = s.plc.axes()
    if not axes:
        s._print("no axes (load a --plant)")
        return
    for line in axes_table(axes):
        s._print(line)


def _cmd_drives(s: SessionState, args: list[str]) -> None:
    _no_args(args, "drives")
    drives = s.plc.drives()
    if not drives:
        s._print("no drives (load a --plant with a FIELDBUS module)")
        return
    for line in drives_table(drives):
        s._print(line)


def _cmd_status(s: SessionState, args: list[str]) -> None:
    _no_args(args, "status")
    plc = s.plc
    rows = [("time", f"{sim_time(plc)} s"),
            ("scans", f"{plc.scans} done"),
            ("mode", mode(plc)),
            ("scan time", f"{ms(plc.scan_us)} ms"),
            ("clock", plc.clock.now(plc.now_us).isoformat(sep=" "))]
    if plc.station.led:
        rows.append(("DLED", "on"))
    if s._paused is not None:
        rows.append(("paused", f"in scan {plc.scans + 1}, before {s._label(s._paused)}"))
    names = [s.coverage.networks[k].name for k in sorted(s._breaks)]
    rows.append(("breakpoints", f"{len(names)}" + (f" ({', '.join(names)})" if names else "")))
    forces = [f"{k}={fmt(v)}" for k, v in plc.forces.items()]
    rows.append(("forces", f"{len(forces)}" + (f" ({', '.join(forces)})" if forces else "")))
    if s._trace is not None:
        rows.append(("trace", trace_summary(s._trace)))
    if plc.fault is not None:
        rows.append(("fault", plc.fault.message))
    for line in key_values(rows):
        s._print(line)


def _cmd_continue(s: SessionState, args: list[str]) -> None:
    _no_args(args, "continue")
    s._resume = "continue"


def _cmd_next(s: SessionState, args: list[str]) -> None:
    _no_args(args, "next")
    s._resume = "next"


def _cmd_finish(s: SessionState, args: list[str]) -> None:
    _no_args(args, "finish")
    s._resume = "finish"


def _cmd_help(s: SessionState, args: list[str]) -> None:
    if args:
        cmd = lookup(args[0])
        if cmd is None:
            raise CommandError(f"unknown command '{args[0]}' (type 'help' for the list)")
        aliases = f"  (short: {', '.join(cmd.aliases)})" if cmd.aliases else ""
        s._print(f"{cmd.usage}{aliases}")
        s._print(f"  {cmd.summary}")
        for line in cmd.details.strip().splitlines():
            s._print(f"  {line}" if line else "")
        return
    w = max(len(c.usage) for c in COMMANDS.values())
    for cmd in COMMANDS.values():
        short = f" [{', '.join(cmd.aliases)}]" if cmd.aliases else ""
        s._print(f"  {cmd.usage:<{w}}  {cmd.summary}{short}")
    s._print("NET: OB1/3, SBR0/1 or 3 (OB1).  ADDR: I0.0, VW100, VD4:REAL, T37, "
             "symbols.  'help CMD' says more.")


def _cmd_quit(s: SessionState, args: list[str]) -> None:
    _no_args(args, "quit")
    if s._paused is not None:
        # The scan in progress cannot be abandoned half-way (the memory
        # image would be half of one scan): it runs to its end first.
        s._resume = "quit"
    else:
        s._quit = True


def _written(s: SessionState, addr: str, value: int | float) -> str:
    """The value now at ``addr``, read back the way it was written (a
    real as a real), so the answer shows any truncation."""
    return fmt(s.plc.read(addr, "REAL" if isinstance(value, float) and
                          s._location(addr)[2] == 4 else None))


def _target(s: SessionState, spec: str, value_text: str) -> tuple[str, int | float]:
    """Address and value of ``set``/``force``; ``VD4:REAL=2`` stores a REAL."""
    addr, _, kind = spec.partition(":")
    kind = kind.strip().upper()
    if kind not in ("", "REAL"):
        raise CommandError(f"{spec}: only ':REAL' can follow an address here")
    try:
        value = parse_number(value_text)
    except PlcConfigError as e:
        raise CommandError(f"{spec}: {e.message}") from None
    if kind == "REAL":
        s.plc.read(addr, "REAL")    # a double word, or the engine's message
        value = float(value)
    elif isinstance(value, float) and not value.is_integer():
        s.plc.read(addr)            # a bad address is reported as such first
        if s._location(addr)[2] != 4:
            raise CommandError(f"{spec}: a real value needs a double word (VD, MD, ...)")
    return addr, value


def _value(s: SessionState, spec: str) -> tuple[str, bool]:
    """(formatted value, forced?) of an address spec."""
    return fmt(reader(s.plc, spec)()), s._is_forced(spec)


# ---------------------------------------------------------------------------
# Small parsers
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
    # at most 20 digits: int() of a longer string is refused before any check
    if len(args) > 1 or not re.fullmatch(r"\d{1,20}", args[0]):
        raise CommandError(f"{cmd} takes a number of scans (at most {MAX_COMMAND_SCANS}), "
                           f"got '{' '.join(args)[:40]}'")
    return _bounded(int(args[0]), cmd)


def _bounded(n: int, what: str, s: SessionState | None = None) -> int:
    """``n`` scans, refused above :data:`MAX_COMMAND_SCANS`."""
    if n > MAX_COMMAND_SCANS:
        span = f" ({n:.3g} scans of {ms(s.plc.scan_us)} ms)" if s is not None else ""
        raise CommandError(f"{what} would run {n} scans{span}: a command runs at most "
                           f"{MAX_COMMAND_SCANS}; use several commands, or plcrt run "
                           f"(with --max-wall) for long runs")
    return n


def _no_args(args: list[str], cmd: str) -> None:
    if args:
        raise CommandError(f"{cmd} takes no argument, got '{' '.join(args)}'")


def _seconds(text: str) -> float:
    try:
        return seconds(text)
    except PlcConfigError as e:
        raise CommandError(e.message) from None


# ---------------------------------------------------------------------------
# The command table
# ---------------------------------------------------------------------------

_TABLE = (
    Command("scan", _cmd_scan, "scan [N]", "run N scans (default 1)",
            "Then prints the status line and the watch table.", aliases=("s",),
            runs_scans=True),
    Command("run", _cmd_run, "run DURATION | run until COND [timeout D]",
            "run for simulated time, or until a condition holds",
            "DURATION: 1.5s, 200ms, 2 (seconds), 2min.  COND: Q0.0, not M0.1, VW100 >= 5,\n"
            "VD4:REAL > 1.5 (== != < <= > >=), checked after every scan.  'run until'\n"
            f"gives up after {DEFAULT_UNTIL_TIMEOUT} of simulated time unless a timeout "
            "is given.", aliases=("r",), runs_scans=True),
    Command("pulse", _cmd_pulse, "pulse ADDR [SCANS]",
            "push a bit for one scan (or SCANS scans), then put the old value back",
            runs_scans=True),
    Command("break", _cmd_break, "break NET",
            "stop before network NET executes (inside the scan)",
            "NET: OB1/3, SBR0/1, a block's name and a number (SCALE/2), or a number\n"
            "of OB1.  When a scan reaches the network the debugger pauses in the\n"
            "middle of the scan: networks before it have run in this scan, the ones\n"
            "after it still show the last scan's results.  Then 'continue', 'next'\n"
            "or 'finish'.", aliases=("b",)),
    Command("delete", _cmd_delete, "delete NET|all", "remove breakpoints"),
    Command("breaks", _cmd_breaks, "breaks", "list the breakpoints"),
    Command("clear", _cmd_clear, "clear [NET...]",
            "clear the screen; with NET, remove the breakpoints there",
            "Alone it clears the terminal's screen (as Ctrl-L) and changes nothing\n"
            "else; in a script or pipe it does nothing.  'clear NET' is gdb's\n"
            "'clear LOCATION', the same as 'delete NET'.  What else can be cleared:\n"
            "'delete all' (breakpoints), 'unwatch all', 'unforce all', 'trace clear'."),
    Command("watch", _cmd_watch, "watch [ADDR...]",
            "add addresses to the watch table (alone: print it)",
            "The table (address, value, 'forced' marker) is printed after every\n"
            "scan, run and pulse, and at every stop.  VD4:REAL reads a float,\n"
            "T37:BIT the timer bit (T37 alone is its current value).", aliases=("w",)),
    Command("unwatch", _cmd_unwatch, "unwatch ADDR...|all",
            "remove addresses from the watch table"),
    Command("print", _cmd_print, "print ADDR...", "print values now",
            "Bits as 0/1, bytes unsigned, words and double words signed,\n"
            "T37/C5 their current value, VD4:REAL a float.", aliases=("p",)),
    Command("set", _cmd_set, "set ADDR=VALUE...", "write values now",
            "VALUE: 12, -3, 16#FF, 2#1010, 1.5 (a real needs a double word;\n"
            "VD4:REAL=2 stores 2.0).  An input keeps its value over the next scans,\n"
            "like a switch left on; the program may overwrite anything else."),
    Command("force", _cmd_force, "force ADDR VALUE",
            "force a value until 'unforce'",
            "As on the CPU the value is written at the start of every scan and again\n"
            "after the program ran, so the outputs and the next scan see it.  While\n"
            "paused it takes effect at once."),
    Command("unforce", _cmd_unforce, "unforce ADDR|all",
            "release forces (the value stays until the program changes it)"),
    Command("forces", _cmd_forces, "forces", "list the forced addresses"),
    Command("show", _cmd_show, "show [NET]",
            "draw a network (no NET: all of them) with live values"),
    Command("axes", _cmd_axes, "axes",
            "the EM253 axes: position, mechanical position, speed, status"),
    Command("drives", _cmd_drives, "drives",
            "the bus drives: mode, position, velocity, statusword and its meaning"),
    Command("status", _cmd_status, "status",
            "time, scans, mode, scan time, real-time clock, DLED, breakpoints, forces"),
    Command("continue", _cmd_continue, "continue",
            "paused: resume the scan and the run", aliases=("c",), paused_only=True),
    Command("next", _cmd_next, "next",
            "paused: resume and stop before the next network that executes",
            "In any block: a CALL leads into the subroutine's first network, the\n"
            "end of OB1 to network 1 of the next scan (if the command runs one).",
            aliases=("n",), paused_only=True),
    Command("finish", _cmd_finish, "finish",
            "paused: finish this scan and end the command there", paused_only=True),
    *TRACE_COMMANDS,
    Command("help", _cmd_help, "help [CMD]", "list the commands, or explain one",
            aliases=("h", "?")),
    Command("quit", _cmd_quit, "quit",
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


__all__ = ["COMMANDS", "DEFAULT_UNTIL_TIMEOUT", "Command", "CommandError", "lookup",
           "strip_comment"]
