"""The options the ``plcrt`` commands that read or run a program share, and
loading that program from the parsed command line.

``check``, ``run``, ``dump``, ``show``, ``trace``, ``debug`` and ``serve``
declare their options with these helpers (:func:`add_program_args`,
:func:`add_scan_ms_arg`, :func:`add_run_length_args`,
:func:`add_long_run_args`, :func:`add_set_args`), check them with
:func:`check_run_length` and :func:`parse_sets`, and load with
:func:`load_from_args` or :func:`load_for_run`, so the options read and
behave the same in every command.

This module turns arguments into calls of the public API
(:func:`plcrt.load`, :meth:`plcrt.Plc.write`); how a number or an address
is read is decided by :mod:`plcrt.engine.values` and the engine.  It builds
no parser and prints nothing but the load-time diagnostics it is told to
(:func:`plcrt.term.report.print_diagnostics` by default).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

from ..engine.values import BACKENDS, parse_number
from ..errors import Diagnostic, PlcConfigError, PlcError
from ..safetext import printable
from .progress import check_max_wall, check_run_span
from .report import print_diagnostics

if TYPE_CHECKING:
    from ..engine.runtime import Plc


def add_program_args(p: argparse.ArgumentParser, *, data: bool = True, cpu: bool = True,
                     plant: bool = True) -> None:
    """The program, symbol table, encoding, data, CPU and plant options
    commands share."""
    p.add_argument("programs", nargs="+", metavar="PROGRAM",
                   help="STL export (.awl), or a project (.mwp, .smart); several "
                        ".awl files are merged into one program")
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
                   help="code generator: auto (default, or $PLCRT_BACKEND: native where "
                        "llvmlite works, else python), native (machine code through "
                        "llvmlite for the pieces it covers, docs/native.md) or python")
    p.add_argument("--max-file-mb", type=float, default=None, metavar="MB",
                   help="refuse program, symbol and data files larger than this "
                        "(default 16 MB, far above any S7-200 program)")
    p.add_argument("--entry", metavar="BLOCK",
                   help="run this block as the main program each scan instead of OB1: "
                        "SBR0 or a subroutine's name (a subroutine-only export; "
                        "docs/decisions.md says what its parameters are)")


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
    and a run longer than plcrt counts (:func:`plcrt.term.progress.check_run_span`).

    Raises:
        PlcConfigError: naming the option.
    """
    if args.scans is not None and args.scans < 0:
        raise PlcConfigError(f"--scans must not be negative, got {args.scans}")
    if args.seconds is not None and not (math.isfinite(args.seconds) and args.seconds >= 0):
        raise PlcConfigError(f"--seconds must be a non-negative number, got {args.seconds}")
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



def load_from_args(args: argparse.Namespace, scan_ms: float = 10.0, *,
                   instrument: bool = False, library: bool = False) -> Plc:
    """Load the program named on the command line (raises PlcError);
    ``instrument`` compiles the network probes breakpoints use, ``library``
    accepts a program without OB1 (for ``check`` and ``dump``)."""
    data = getattr(args, "data", None)
    plant = getattr(args, "plant", None)
    # perf: the engine (the compiler, lark) is imported when a command runs
    # a program, never for --help or a usage error
    from ..loader import load

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


__all__ = ["SET_HELP", "SetItem", "add_long_run_args", "add_program_args", "add_run_length_args",
           "add_scan_ms_arg", "add_set_args", "apply_sets", "check_run_length", "load_for_run",
           "load_from_args", "parse_sets", "parse_value"]
