"""The ``plcrt`` command line: ``check``, ``run`` and ``dump``, and the
options and steps the commands that run a program share.

``show``, ``debug`` and ``trace`` are defined beside what they present
(:mod:`plcrt.view.cli`, :mod:`plcrt.debug.cli`, :mod:`plcrt.trace.cli`) and
registered here; they declare ``--scan-ms``, ``--seconds``/``--scans`` and
``--set`` and load the program with the public helpers of this module
(:func:`add_run_length_args`, :func:`add_set_args`, :func:`load_for_run`,
...), so the options read and behave the same in every command.

This module is the presentation layer only.  It turns command-line
arguments into calls of the public API (:func:`plcrt.load`, :class:`plcrt.Plc`)
and turns results and :class:`~plcrt.errors.PlcError` diagnostics into text,
a table or JSON.  It holds no PLC semantics: what an instruction does, how an
address is spelled and what a diagnostic says are decided by the core.

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
import json
import math
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple, NoReturn, TextIO

from . import __version__
from .engine.values import BACKENDS, json_number, parse_number, split_format
from .errors import Diagnostic, PlcConfigError, PlcError, PlcRuntimeError, capped
from .safetext import printable

from .cli_tables import (DRIVE_COLUMNS, axis_rows, counters_in_use, drive_rows, ports_in_use,
                         print_devices, pulse_outputs, table_lines)

if TYPE_CHECKING:
    from .engine.runtime import Plc

EXIT_OK = 0
EXIT_ERROR = 1
EXIT_FAULT = 2
EXIT_WALL = 3   #: the run reached --max-wall

PROG = "plcrt"



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


def add_program_args(p: argparse.ArgumentParser, *, data: bool = True, cpu: bool = True,
                     plant: bool = True) -> None:
    """The program, symbol table, encoding, data, CPU and plant options
    commands share."""
    p.add_argument("programs", nargs="+", metavar="PROGRAM",
                   help="STL export (.awl); several files are merged into one program")
    p.add_argument("--symbols", metavar="F", help="symbol table (.sdf CSV or Micro/WIN tab list)")
    p.add_argument("--encoding", metavar="NAME",
                   help="text encoding of the program and table files, e.g. cp1252, gbk, "
                        "cp1251, cp932, utf-8 (default: detected)")
    if data:
        p.add_argument("--data", metavar="F", help="data block (V memory initial values)")
    if cpu:
        p.add_argument("--cpu", metavar="NAME", help="CPU model, e.g. CPU224 (default CPU226)")
    if plant:
        p.add_argument("--plant", metavar="F",
                       help="plant file (TOML): EM253 modules and the machine around "
                            "their axes")
    p.add_argument("--auto-symbols", action="store_true",
                   help="give each symbol that no symbol table defines a free M (bits) or V "
                        "address, reported as warnings (for exports published without "
                        "their symbol table)")
    p.add_argument("--backend", choices=BACKENDS, default=None,
                   help="code generator: python (default; or $PLCRT_BACKEND) or native "
                        "(machine code through llvmlite for the pieces it covers: "
                        "the 'native' extra, docs/native.md)")
    p.add_argument("--max-file-mb", type=float, default=None, metavar="MB",
                   help="refuse program, symbol and data files larger than this "
                        "(default 16 MB, far above any S7-200 program)")
    p.add_argument("--entry", metavar="BLOCK",
                   help="run this block as the main program each scan instead of OB1: "
                        "SBR0 or a subroutine's name (a subroutine-only export; "
                        "docs/decisions.md says what its parameters are)")


#: Subcommands defined beside the feature they present; each module has
#: ``register(sub)`` adding its parser with ``func`` set.
_COMMAND_MODULES = ("plcrt.view.cli", "plcrt.debug.cli", "plcrt.trace.cli",
                    "plcrt.devices.cia402.cli", "plcrt.web.cli")


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


# ---------------------------------------------------------------------------
# Commands
# ---------------------------------------------------------------------------

def load_from_args(args: argparse.Namespace, scan_ms: float = 10.0, *,
                   instrument: bool = False, library: bool = False) -> Plc:
    """Load the program named on the command line (raises PlcError);
    ``instrument`` compiles the network probes breakpoints use, ``library``
    accepts a program without OB1 (for ``check`` and ``dump``)."""
    data = getattr(args, "data", None)
    plant = getattr(args, "plant", None)
    # perf: the engine (the compiler, lark) is imported when a command runs
    # a program, never for --help or a usage error
    from .loader import load

    pace = "realtime" if getattr(args, "realtime", False) else "simulated"
    # Path objects make load() read files, never take the argument as text.
    return load([Path(p) for p in args.programs],
                symbols=Path(args.symbols) if args.symbols else None,
                data=Path(data) if data else None,
                scan_ms=scan_ms, cpu=getattr(args, "cpu", None), pace=pace,
                plant=Path(plant) if plant else None, instrument=instrument, library=library,
                encoding=getattr(args, "encoding", None),
                max_file_mb=getattr(args, "max_file_mb", None),
                auto_symbols=getattr(args, "auto_symbols", False),
                clock=getattr(args, "clock", None),
                backend=getattr(args, "backend", None), entry=getattr(args, "entry", None))


def cmd_check(args: argparse.Namespace) -> int:
    """``plcrt check``: diagnostics on stderr, a summary line, status 1 on errors.

    A subroutine library (blocks, no OB1) passes with a note saying it
    cannot run on its own; a file without any block is an error."""
    name = ", ".join(args.programs)
    try:
        plc = load_from_args(args, library=True)
    except PlcError as e:
        diags = e.diagnostics
        print_diagnostics(diags)
        print(f"{name}: {_count(diags)}", file=sys.stderr)
        return EXIT_ERROR
    diags = plc.diagnostics
    print_diagnostics(diags)
    prog = plc.program
    print(f"{name}: {_count(diags)} ({len(prog.pous)} block(s), "
          f"{prog.network_count()} network(s), {prog.instruction_count()} instruction(s))",
          file=sys.stderr)
    return EXIT_OK


def cmd_run(args: argparse.Namespace) -> int:
    """``plcrt run``: load, apply --set, run, print --watch values (and the
    axes of a --plant).  A long run on a terminal shows a progress bar on
    stderr; ``--quiet`` prints nothing but errors (and the --json object)."""
    from .trace.progress import WallTimeExceeded, run_with_progress

    program = args.programs[0]
    quiet = getattr(args, "quiet", False)

    def report(diags: Sequence[Diagnostic]) -> None:
        print_diagnostics([d for d in diags if d.severity == "error"] if quiet else diags)

    try:
        check_run_length(args)
        writes = parse_sets(args.set)
        watches = [_parse_watch(item) for item in args.watch]
        plc = load_for_run(args, writes, report=report)
        for spec, addr, kind in watches:
            plc.read(addr, kind)  # reject a bad address before running
    except PlcError as e:
        print_diagnostics(e.diagnostics)
        if args.json:
            _emit_json(args, None, {}, str(e))
        return EXIT_ERROR

    fault: PlcError | None = None
    stopped: PlcError | None = None
    loaded = len(plc.diagnostics)
    try:
        # same scans and results as plc.run(); only the bar differs
        run_with_progress(plc, seconds=args.seconds, scans=args.scans, quiet=quiet,
                          max_wall=args.max_wall, progress=args.progress)
    except PlcRuntimeError as e:
        fault = e
    except WallTimeExceeded as e:
        stopped = e
    # Warnings raised while running (library blocks such as the EM253's
    # report bad parameters only when they execute) go to stderr as well.
    report(plc.diagnostics[loaded:])
    values = {spec: plc.read(addr, kind) for spec, addr, kind in watches}
    if args.json:
        _emit_json(args, plc, values, str(fault or stopped) if fault or stopped else None)
    elif not quiet:
        _print_values(program, plc, values)
        if args.plant:
            print_devices(plc)
    if fault is not None:
        print_diagnostics(fault.diagnostics)
        return EXIT_FAULT
    if stopped is not None:
        print_diagnostics(stopped.diagnostics)
        return EXIT_WALL
    return EXIT_OK


def cmd_dump(args: argparse.Namespace) -> int:
    """``plcrt dump``: the generated module with STL lines as comments
    (of a subroutine library too)."""
    try:
        plc = load_from_args(args, library=True)
    except PlcError as e:
        print_diagnostics(e.diagnostics)
        return EXIT_ERROR
    print_diagnostics(plc.diagnostics)
    from .dump import render_dump
    sys.stdout.write(render_dump(plc))
    return EXIT_OK


# ---------------------------------------------------------------------------
# What the commands that run a program share (run, trace, show, debug)
# ---------------------------------------------------------------------------

#: help of ``--set`` (``show`` says when it applies first)
SET_HELP = ("write before the first scan (inputs keep their value); "
            "VALUE: 12, -3, 16#FF, 2#1010, 1.5, NaN, Infinity")

def add_scan_ms_arg(p: argparse.ArgumentParser) -> None:
    """``--scan-ms MS``, the simulated scan time (``args.scan_ms``, default 10),
    and ``--clock DATETIME``, the real-time clock's start (``args.clock``)."""
    p.add_argument("--scan-ms", type=float, default=10.0, metavar="MS",
                   help="simulated scan time in ms (default 10)")
    p.add_argument("--clock", metavar="DATETIME",
                   help="the real-time clock at power-up, e.g. 2026-12-02T08:00:00, or 'now' "
                        "for the host's clock (default: the plant file's, else 2024-01-01 "
                        "00:00:00)")


def add_run_length_args(p: argparse.ArgumentParser, *, required: bool = True,
                        seconds_help: str = "simulated seconds to run",
                        scans_help: str = "number of scans to run") -> None:
    """``--seconds S`` or ``--scans N`` (one of them; both None when neither
    is given and not ``required``).  :func:`check_run_length` checks them."""
    length = p.add_mutually_exclusive_group(required=required)
    length.add_argument("--seconds", type=float, metavar="S", help=seconds_help)
    length.add_argument("--scans", type=int, metavar="N", help=scans_help)


def add_long_run_args(p: argparse.ArgumentParser) -> None:
    """``--max-wall SECONDS`` (stop a run after that much wall-clock time,
    exit status 3) and ``--progress`` (progress lines on stderr when it is
    not a terminal; a terminal gets the bar)."""
    p.add_argument("--max-wall", type=float, metavar="SECONDS",
                   help="stop the run after this many wall-clock seconds (exit status 3), "
                        "reporting the simulated time reached")
    p.add_argument("--progress", action="store_true",
                   help="show progress on stderr: a line every few seconds when stderr is "
                        "not a terminal (CI logs), the bar on a terminal")


def add_set_args(p: argparse.ArgumentParser, *, help: str = SET_HELP) -> None:
    """``--set ADDR=VALUE``, repeatable (``args.set``, a list of strings for
    :func:`parse_sets`)."""
    p.add_argument("--set", action="append", default=[], metavar="ADDR=VALUE", help=help)


def check_run_length(args: argparse.Namespace) -> None:
    """Reject a negative ``--scans``, a negative or infinite ``--seconds``
    and a run longer than plcrt counts (:func:`plcrt.trace.progress.check_run_span`).

    Raises:
        PlcConfigError: naming the option.
    """
    if args.scans is not None and args.scans < 0:
        raise PlcConfigError(f"--scans must not be negative, got {args.scans}")
    if args.seconds is not None and not (math.isfinite(args.seconds) and args.seconds >= 0):
        raise PlcConfigError(f"--seconds must be a non-negative number, got {args.seconds}")
    from .trace.progress import check_max_wall, check_run_span
    check_run_span(args.seconds, args.scans, max(1, round(getattr(args, "scan_ms", 10.0) * 1000)))
    check_max_wall(getattr(args, "max_wall", None))


class SetItem(NamedTuple):
    """One ``--set ADDR=VALUE``, parsed."""

    addr: str
    value: int | float
    #: the argument as given, for messages
    item: str


def parse_sets(items: Sequence[str]) -> list[SetItem]:
    """Parse ``--set`` arguments (before loading, so a typo is reported
    without waiting for the program).

    Raises:
        PlcConfigError: for an item that is not ADDR=VALUE or a bad value.
    """
    out = []
    for item in items:
        addr, sep, value = item.partition("=")
        if not sep or not addr.strip() or not value.strip():
            raise PlcConfigError(f"--set needs ADDR=VALUE, got '{_shorten(item)}'")
        try:
            number = parse_value(value)
        except PlcConfigError as e:
            raise PlcConfigError(f"--set {_shorten(item)}: {e.message}") from None
        out.append(SetItem(addr.strip(), number, item))
    return out


def _shorten(text: str, limit: int = 60) -> str:
    """An argument as a message quotes it: one line, at most ``limit`` characters."""
    text = printable(text)
    return text if len(text) <= limit else f"{text[:limit - 3]}..."


def apply_sets(plc: Plc, sets: Sequence[SetItem]) -> None:
    """Write parsed ``--set`` values in order, checked as :meth:`Plc.write`
    checks every value (a real only into a double word, a byte 0..255,
    nothing into SMB0).

    Raises:
        PlcConfigError: a bad address, or a value that does not fit.
    """
    for addr, value, item in sets:
        try:
            plc.write(addr, value)
        except PlcError as e:
            raise PlcConfigError(f"--set {_shorten(item)}: {e.message}") from None


def load_for_run(args: argparse.Namespace, sets: Sequence[SetItem] = (), *,
                 report: Callable[[Sequence[Diagnostic]], None] | None = None,
                 instrument: bool = False) -> Plc:
    """Load the program of a command that runs it (``--scan-ms`` and the
    program options), report the load-time warnings (``report``, default
    :func:`print_diagnostics`) and write the ``--set`` values.

    Raises:
        PlcError: the program does not load (a program without OB1 is a
            compile error), or a write fails.
    """
    plc = load_from_args(args, args.scan_ms, instrument=instrument)
    (report or print_diagnostics)(plc.diagnostics)  # warnings
    apply_sets(plc, sets)
    return plc


def parse_value(text: str) -> int | float:
    """Parse a --set value: decimal, ``16#hex``, ``2#binary``, a real or
    ``NaN``/``Infinity``/``-Infinity``
    (:func:`plcrt.engine.values.parse_number`).

    Raises:
        PlcConfigError: for anything else, or a real beyond the REAL range.
    """
    return parse_number(text)


# ---------------------------------------------------------------------------
# run: --watch and the output
# ---------------------------------------------------------------------------

def _parse_watch(item: str) -> tuple[str, str, str | None]:
    """(key for the output, address, read format) of one --watch argument."""
    spec = item.strip()
    if not spec:
        raise PlcConfigError("--watch needs an address")
    try:
        addr, fmt = split_format(spec)
    except PlcError as e:
        raise PlcConfigError(f"--watch {e.message}") from None
    return spec, addr, fmt or None


def _emit_json(args: argparse.Namespace, plc: Plc | None, values: dict[str, int | float],
               error: str | None) -> None:
    """One strict JSON object (RFC 8259 has no NaN or Infinity: a
    non-finite REAL is written as the string "NaN", "Infinity" or
    "-Infinity", see :data:`plcrt.engine.values.NONFINITE`)."""
    obj: dict[str, Any] = {
        "program": args.programs[0],
        "scans": plc.scans if plc else 0,
        "time_s": plc.time if plc else 0.0,
        "mode": plc.mode if plc else None,
        "values": {k: json_number(v) for k, v in values.items()},
    }
    if plc is not None:
        # the CPU's own state the program sets: real-time clock and DLED
        obj["clock"] = plc.clock.now(plc.now_us).isoformat()
        obj["dled"] = plc.station.led
    if plc is not None and getattr(args, "plant", None):
        obj["axes"] = [a.to_dict() for a in plc.axes()]
        drives = plc.drives()
        if drives:
            obj["drives"] = [d.to_dict() | {"flags": d.flags} for d in drives]
    if plc is not None:
        for key, items in (("pulse_outputs", pulse_outputs(plc)),
                           ("counters", counters_in_use(plc)), ("ports", ports_in_use(plc))):
            if items:
                obj[key] = items
    if len(args.programs) > 1:
        obj["files"] = list(args.programs)
    if error is not None:
        obj["error"] = error
    sys.stdout.write(json.dumps(obj, ensure_ascii=False, allow_nan=False) + "\n")


def _fmt(value: int | float) -> str:
    # REALs are single precision: seven significant digits say all there is;
    # NaN and the infinities are spelled as in JSON (and as --set takes them).
    if isinstance(value, float):
        return f"{value:.7g}" if math.isfinite(value) else str(json_number(value))
    return str(value)


def _print_values(program: str, plc: Plc, values: dict[str, int | float]) -> None:
    summary = f"{program}: {plc.scans} scan(s), {plc.time:g} s simulated, mode {plc.mode}"
    if values and sys.stdout.isatty() and _print_rich_table(summary, values):
        return
    print(printable(summary))
    if values:
        keys = {k: printable(k) for k in values}
        width = max(len("address"), *(len(k) for k in keys.values()))
        print(f"{'address':<{width}}  value")
        for key, value in values.items():
            print(f"{keys[key]:<{width}}  {_fmt(value)}")


def _print_rich_table(summary: str, values: dict[str, int | float]) -> bool:
    try:
        from rich.console import Console
        from rich.table import Table
        from rich.text import Text
    except ImportError:  # rich is a dependency, but the plain form is fine too
        return False
    console = Console()
    # The summary stays one line above the table: as a table title it would
    # wrap to the (narrow) table width.  Text objects, never markup strings:
    # a symbol name such as "[bold]x[/]" or ":smile:" is shown as written.
    console.print(Text(printable(summary)), highlight=False)
    table = Table()
    table.add_column("address")
    table.add_column("value", justify="right")
    for key, value in values.items():
        table.add_row(Text(printable(key)), Text(_fmt(value)))
    console.print(table)
    return True


# ---------------------------------------------------------------------------
# Reporting
# ---------------------------------------------------------------------------

def print_diagnostics(diags: Sequence[Diagnostic], stream: TextIO | None = None) -> None:
    """GNU-style lines, in source order (stable for equal positions); at
    most :data:`~plcrt.errors.MAX_LISTED` of them (errors first), then one
    line counting the rest."""
    stream = stream or sys.stderr
    kept, more = capped(diags, ordered=True)
    for d in kept:
        print(str(d) if d.loc is not None else f"{PROG}: {d}", file=stream)
    if more is not None:
        print(f"{PROG}: {more}", file=stream)


def _count(diags: Sequence[Diagnostic]) -> str:
    errors = sum(d.severity == "error" for d in diags)
    warnings = sum(d.severity == "warning" for d in diags)
    return (f"{errors} error{'s' if errors != 1 else ''}, "
            f"{warnings} warning{'s' if warnings != 1 else ''}")


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


__all__ = ["DRIVE_COLUMNS", "EXIT_WALL", "axis_rows", "counters_in_use", "drive_rows",
           "ports_in_use", "pulse_outputs", "table_lines", "SET_HELP", "SetItem", "add_long_run_args", "add_program_args",
           "add_run_length_args",
           "add_scan_ms_arg", "add_set_args", "apply_sets", "check_run_length",
           "load_for_run", "load_from_args", "main", "parse_sets", "parse_value",
           "print_diagnostics", "render_dump"]
