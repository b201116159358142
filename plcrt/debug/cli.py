"""``plcrt debug PROGRAM...``: the debugger on a terminal, a script or a pipe.

This module only connects a :class:`~plcrt.debug.session.Session` to the
outside world: it loads the program with instrumentation, applies
``--break`` and ``--watch``, and chooses how commands arrive:

* stdin is a terminal (and no ``--script``): a ``(plcrt)`` prompt with
  readline editing, history and Tab completion
  (:mod:`plcrt.debug.complete`) when Python has readline, colours in the
  ladder view, Ctrl-C stops a run between two scans;
* ``--script FILE`` or a pipe: no prompt, each command is echoed as
  ``(plcrt) <command>`` before its output so the transcript reads well,
  plain text only.

Exit status: 0 every command succeeded, 1 a command reported an error (or
the program or options are bad), 2 the PLC faulted, 3 a command was stopped
by ``--max-wall``.  What the commands do is the session's business, not this
module's.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

from ..errors import PlcError
from ..safetext import printable
from ..term.options import add_program_args, add_scan_ms_arg, load_for_run
from ..term.progress import check_max_wall
from ..term.report import EXIT_ERROR, PROG, print_diagnostics

#: readline history of interactive sessions (kept between sessions)
HISTORY_FILE = "~/.plcrt_debug_history"


def register(sub: Any) -> None:
    """Add the ``debug`` subcommand to the ``plcrt`` parser."""
    p = sub.add_parser(
        "debug", help="interactive debugger: breakpoints inside a scan, watch, force",
        description="Debug a program in simulated time: stop before a network inside a "
                    "scan, step network by network, watch, set and force addresses, draw "
                    "networks with live values, look at EM253 axes.  Commands come from "
                    "the terminal, from --script FILE or from a pipe (type 'help' for "
                    "the list; docs/debugger.md describes them).",
        epilog="Exit status: 0 ok, 1 a command or the input had an error, "
               "2 run-time fault of the PLC program, 3 a command stopped by --max-wall.")
    add_program_args(p)
    add_scan_ms_arg(p)
    p.add_argument("--script", metavar="FILE",
                   help="read the commands from FILE instead of stdin")
    p.add_argument("--break", dest="breaks", action="append", default=[], metavar="NET",
                   help="breakpoint before network NET (OB1/3, SBR0/1, or 3 for OB1/3)")
    p.add_argument("--watch", action="append", default=[], metavar="ADDR",
                   help="watch this address from the start; ADDR:REAL reads a float")
    p.add_argument("--max-wall", type=float, metavar="SECONDS",
                   help="stop each command that runs scans (scan, run, pulse) after this "
                        "many wall-clock seconds, between two scans (exit status 3); "
                        "time paused at a breakpoint does not count")
    p.set_defaults(func=cmd_debug)


def cmd_debug(args: argparse.Namespace) -> int:
    """Load, set up, run the session; returns the exit status."""
    from .session import CommandError, Session

    try:
        check_max_wall(args.max_wall)
    except PlcError as e:
        print(printable(f"{PROG}: error: {e.message}"), file=sys.stderr)
        return EXIT_ERROR
    script: list[str] | None = None
    if args.script is not None:
        from ..lang.limits import file_limit, read_capped
        try:
            # a regular file of at most the file size limit (not /dev/zero)
            raw = read_capped(args.script, file_limit(getattr(args, "max_file_mb", None)))
            script = raw.decode("utf-8").splitlines()
        except (PlcError, UnicodeDecodeError) as e:
            reason = e.message.removeprefix("cannot read file: ") if isinstance(e, PlcError) \
                else str(e)
            print(printable(f"{PROG}: error: cannot read the script {args.script}: {reason}"),
                  file=sys.stderr)
            return EXIT_ERROR
    try:
        # instrument=True compiles the network probes breakpoints use
        plc = load_for_run(args, instrument=True)
    except PlcError as e:
        print_diagnostics(e.diagnostics)
        return EXIT_ERROR

    interactive = script is None and _isatty(sys.stdin)
    if script is None:
        _tolerate_bad_bytes(sys.stdin)
    session = Session(plc, sys.stdout, echo=not interactive,
                      color=interactive and _isatty(sys.stdout),
                      handle_interrupt=interactive, max_wall=args.max_wall)
    for option, values, apply in (("--break", args.breaks, session.add_breakpoint),
                                  ("--watch", args.watch, session.add_watch)):
        for value in values:
            try:
                apply(value)
            except CommandError as e:
                print(printable(f"{PROG}: error: {option} {value}: {e}"), file=sys.stderr)
                return EXIT_ERROR
            except PlcError as e:
                print(printable(f"{PROG}: error: {option} {value}: {e.message}"),
                      file=sys.stderr)
                return EXIT_ERROR

    if script is not None:
        return session.run(script)
    if not interactive:
        return session.run(sys.stdin)
    print(session.banner())
    with _history(session):
        return session.run(readline=_ask)


def _ask(prompt: str) -> str | None:
    """One line from the terminal; None at Ctrl-D."""
    try:
        return input(prompt)
    except EOFError:
        print()
        return None
    except KeyboardInterrupt:
        # Ctrl-C at the prompt drops the line being typed, as in a shell.
        print("^C")
        return ""


def _tolerate_bad_bytes(stream: Any) -> None:
    """Bytes of stdin that are not valid in its encoding become U+FFFD, so
    that such a line fails as a command (``error: ...``) instead of ending
    the session at the first read; the commands before it have run."""
    try:
        stream.reconfigure(errors="replace")
    except (AttributeError, ValueError, OSError):
        pass   # not a text file (a test's StringIO), or already read from


def _isatty(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


class _history:
    """readline editing, Tab completion and a history kept between sessions,
    when Python has readline; nothing otherwise (the session works without
    it)."""

    def __init__(self, session: Any) -> None:
        self._session = session

    def __enter__(self) -> None:
        try:
            import readline
        except ImportError:
            self._readline: Any = None
            return
        self._readline = readline
        install_completion(readline, self._session)
        self._path = os.path.expanduser(HISTORY_FILE)
        try:
            readline.read_history_file(self._path)
        except OSError:
            pass  # no history yet
        readline.set_history_length(1000)

    def __exit__(self, *exc: object) -> None:
        if self._readline is None:
            return
        try:
            self._readline.write_history_file(self._path)
        except OSError:
            pass  # a read-only home: the history is lost, the session was not


def install_completion(readline: Any, session: Any) -> None:
    """Tab completes commands, networks, addresses and symbols of the
    session (:func:`plcrt.debug.complete.complete`)."""
    from .complete import ReadlineCompleter
    readline.set_completer(ReadlineCompleter(session, readline))
    readline.set_completer_delims(ReadlineCompleter.DELIMITERS)
    # macOS Pythons may link libedit, which takes its own binding syntax
    if "libedit" in (getattr(readline, "__doc__", "") or ""):
        readline.parse_and_bind("bind ^I rl_complete")
    else:
        readline.parse_and_bind("tab: complete")


__all__ = ["cmd_debug", "install_completion", "register"]
