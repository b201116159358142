"""The ``plcrt`` command line: the entry point, the parser and the dispatch
to the command a user names.

``check``, ``run`` and ``dump`` are :mod:`plcrt.cli_commands`; ``show``,
``debug``, ``trace``, ``serve`` and ``eds`` are defined beside what they
present (:mod:`plcrt.view.cli`, :mod:`plcrt.debug.cli`,
:mod:`plcrt.trace.cli`, :mod:`plcrt.web.cli`,
:mod:`plcrt.devices.cia402.cli`) and registered here.  Every command
declares the shared options and loads the program with the helpers of
:mod:`plcrt.term.options`, so the options read and behave the same in every
command; they are re-exported here for existing callers.

This module is the top of the presentation layer: it may import the
packages that implement its subcommands, and none of them imports it.  It
holds no PLC semantics and formats no result: it turns the command line
into a call of a command function and any error it did not handle into
:class:`~plcrt.errors.PlcError` diagnostics (:mod:`plcrt.term.report`).

Exit status: 0 success, 1 a problem with the input (missing file, syntax or
compile error, bad option or address, internal error), 2 a run-time fault of
the PLC program (the CPU went to STOP), 3 a run stopped by ``--max-wall``.
No path prints a Python traceback; an unexpected exception is reported as an
internal error, and the traceback is shown only when the environment
variable ``PLCRT_TRACEBACK`` is set.

``rich`` is imported lazily and only for the tables on a terminal.

``--plant F`` attaches simulated modules (an EM253 and the machine around
its axes, see :mod:`plcrt.devices.plant`); ``run`` then reports the state
of every configured axis after the watch values, or under ``"axes"`` in the
JSON object.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from typing import Any, NoReturn

from . import __version__
from .cli_commands import add_machine_args, cmd_check, cmd_dump, cmd_run
from .errors import PlcError, PlcRuntimeError
from .term.options import (SET_HELP, SetItem, add_long_run_args, add_program_args,
                           add_run_length_args, add_scan_ms_arg, add_set_args, apply_sets,
                           check_run_length, load_for_run, load_from_args, parse_sets,
                           parse_value)
from .term.report import (EXIT_ERROR, EXIT_FAULT, EXIT_OK, EXIT_WALL, PROG,
                          print_diagnostics)
from .term.tables import (DRIVE_COLUMNS, axis_rows, counters_in_use, drive_rows, ports_in_use,
                          pulse_outputs, table_lines)


class _UsageError(Exception):
    """A bad command line, reported like argparse does but with exit status 1."""


class _Parser(argparse.ArgumentParser):
    """argparse, except that a usage error returns instead of exiting with 2
    (status 2 is reserved for PLC run-time faults)."""

    def error(self, message: str) -> NoReturn:
        self.print_usage(sys.stderr)
        raise _UsageError(message)


# ---------------------------------------------------------------------------
# Entry point
# ---------------------------------------------------------------------------

def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (never raises)."""
    _tolerate_narrow_output()
    try:
        return _main(sys.argv[1:] if argv is None else argv)
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader of our output went away (`plcrt dump x | head`): stop
        # quietly, and keep Python from complaining again at shutdown.
        _silence_stdout()
        return EXIT_ERROR
    except Exception as exc:  # noqa: BLE001 - the one place that must not leak a traceback
        _internal_error(exc)
        return EXIT_ERROR


def _main(argv: list[str]) -> int:
    parser = _build_parser()
    try:
        args = parser.parse_args(argv)
    except _UsageError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return EXIT_ERROR
    except SystemExit as e:  # --help, --version
        return e.code if isinstance(e.code, int) else EXIT_OK
    try:
        return int(args.func(args))
    except PlcError as e:
        # Errors a command does not handle itself: report them all.
        print_diagnostics(e.diagnostics)
        return EXIT_FAULT if isinstance(e, PlcRuntimeError) else EXIT_ERROR


#: Subcommands defined beside the feature they present; each module has
#: ``register(sub)`` adding its parser with ``func`` set.
_COMMAND_MODULES = ("plcrt.view.cli", "plcrt.debug.cli", "plcrt.trace.cli",
                    "plcrt.devices.cia402.cli", "plcrt.web.cli", "plcrt.project.cli")


def _build_parser() -> _Parser:
    parser = _Parser(
        prog=PROG,
        description="Run Siemens S7-200 (STEP 7-Micro/WIN) STL programs in Python.",
        epilog="Exit status: 0 ok, 1 error in the input or options, "
               "2 run-time fault of the PLC program, 3 run stopped by --max-wall.")
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    common = add_program_args

    p = sub.add_parser("check", help="parse and compile; list every error and warning",
                       description="Parse and compile a program and list every error and "
                                   "warning GNU-style (file:line:col: ...) on stderr.")
    common(p)
    p.set_defaults(func=cmd_check)

    p = sub.add_parser("run", help="run a program for a simulated time or number of scans",
                       description="Run a program in simulated time and print watched values.")
    common(p)
    add_scan_ms_arg(p)
    add_run_length_args(p)
    add_long_run_args(p)
    add_set_args(p)
    p.add_argument("--watch", action="append", default=[], metavar="ADDR",
                   help="print this address at the end; ADDR:REAL reads a float")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--realtime", action="store_true",
                   help="keep wall-clock pace (sleep between scans); results are unchanged")
    p.add_argument("--quiet", action="store_true",
                   help="print only errors: no summary, value table, axes, warnings or "
                        "progress bar (--json still prints its object)")
    p.add_argument("--verbose", action="store_true",
                   help="also say on stderr which backend ran the program")
    add_machine_args(p)
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("dump", help="print the generated Python with the STL lines",
                       description="Print the Python the program compiles to, network by "
                                   "network, each instruction's code under its STL line.")
    common(p)
    p.set_defaults(func=cmd_dump)
    for name in _COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as e:
            if e.name is None or not name.startswith(e.name):
                raise
            continue
        module.register(sub)
    return parser


def _internal_error(exc: BaseException) -> None:
    print(f"{PROG}: internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
    if os.environ.get("PLCRT_TRACEBACK"):
        import traceback
        traceback.print_exception(exc, file=sys.stderr)
    else:
        print(f"{PROG}: this is a bug in plcrt; please report it together with the "
              f"program and the command (set PLCRT_TRACEBACK=1 to see the traceback)",
              file=sys.stderr)


def _tolerate_narrow_output() -> None:
    """On an output that cannot encode everything (``PYTHONIOENCODING=ascii``,
    a legacy code page) write what it cannot encode as escapes (the ladder's
    box drawing, program text in any script) instead of failing."""
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None and stream.errors == "strict":
                stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError, OSError):
            pass   # not a text stream we can reconfigure: leave it


def _silence_stdout() -> None:
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


def __getattr__(name: str) -> Any:
    # perf: render_dump needs the engine; imported on first use (PEP 562)
    if name == "render_dump":
        from .dump import render_dump
        return render_dump
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["DRIVE_COLUMNS", "EXIT_ERROR", "EXIT_FAULT", "EXIT_OK", "EXIT_WALL", "PROG",
           "SET_HELP", "SetItem", "add_long_run_args", "add_program_args",
           "add_run_length_args", "add_scan_ms_arg", "add_set_args", "apply_sets", "axis_rows",
           "check_run_length", "cmd_check", "cmd_dump", "cmd_run", "counters_in_use",
           "drive_rows", "load_for_run", "load_from_args", "main", "parse_sets", "parse_value",
           "ports_in_use", "print_diagnostics", "pulse_outputs", "render_dump", "table_lines"]
