"""The ``plcrt show`` subcommand: networks drawn as ladder (LAD), with live
status after a run (``--status``).

Registered by :mod:`plcrt.cli` through :func:`register`.  Only argument
handling and printing live here; the drawing is :mod:`plcrt.view.render`.
rich and the renderer are imported when the command runs, so building the
parser for other commands stays cheap.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Any

#: as the debugger's ``break``: OB1/3, SBR0 / 1, SCALE/2 or 3 (of OB1)
_NET_RE = re.compile(r"(?:([^/\s]+)\s*/\s*)?(\d+)")


def register(sub: Any) -> None:
    """Add ``show`` to the subparsers of the ``plcrt`` command."""
    from ..term.options import (add_long_run_args, add_program_args, add_run_length_args,
                                add_scan_ms_arg, add_set_args)

    p = sub.add_parser(
        "show", help="draw networks as ladder (LAD), optionally with live status",
        description="Draw a program's networks as ladder diagrams (LAD) in the terminal, "
                    "as Micro/WIN shows them; networks without a LAD form are shown as STL. "
                    "With --status the program runs first and the drawing shows power flow "
                    "and values at the end of the last scan.")
    add_program_args(p)
    p.add_argument("--network", action="append", default=[], metavar="ID",
                   help="only this network: OB1/3, SBR0/1 or a number (of OB1); repeatable")
    p.add_argument("--stl", action="store_true", help="show the STL text instead of LAD")
    p.add_argument("--status", action="store_true",
                   help="run the program, then draw with power flow and values")
    add_scan_ms_arg(p)
    add_run_length_args(p, required=False,
                        seconds_help="with --status: simulated seconds to run",
                        scans_help="with --status: number of scans to run (default 1)")
    add_long_run_args(p)
    add_set_args(p, help="with --status: write before the first scan (inputs keep their value)")
    p.set_defaults(func=cmd_show)


def cmd_show(args: argparse.Namespace) -> int:
    """``plcrt show``: 0 ok, 1 an input or option error, 2 a PLC fault while
    running for --status (the drawing then shows the state at the fault)."""
    from ..term.options import check_run_length, load_for_run, parse_sets
    from ..term.report import EXIT_ERROR, EXIT_FAULT, EXIT_OK, EXIT_WALL, print_diagnostics
    from ..errors import PlcConfigError, PlcError, PlcRuntimeError, PlcSyntaxError

    fault: PlcError | None = None
    broken: PlcError | None = None
    symbols: Any = None
    try:
        _check_options(args, PlcConfigError)
        check_run_length(args)
        if args.status:
            writes = parse_sets(args.set)
            plc = load_for_run(args, writes)
            program, symbols = plc.program, plc.symbols
        else:
            try:
                program, symbols = _parse(args)
            except PlcSyntaxError as e:
                # draw every block that parsed; the errors are listed first
                if e.partial is None or not e.partial.pous or args.network:
                    raise
                program, broken = e.partial, e
                print_diagnostics(e.diagnostics)
        if not program.pous:
            raise PlcConfigError(f"nothing to show: {', '.join(args.programs)} holds no block "
                                 f"(an empty file, or only comments)")
        selected = _select(program, args.network, PlcConfigError)
    except PlcError as e:
        print_diagnostics(e.diagnostics)
        return EXIT_ERROR

    status = None
    stopped: PlcError | None = None
    if args.status:
        from ..term.progress import WallTimeExceeded, run_with_progress
        from .status import PlcStatus
        loaded = len(plc.diagnostics)
        watch = dict(max_wall=args.max_wall, progress=args.progress)
        try:
            # a long run shows a progress bar on a terminal (stderr only)
            if args.seconds is not None:
                run_with_progress(plc, seconds=args.seconds, **watch)
            else:
                run_with_progress(plc, scans=1 if args.scans is None else args.scans, **watch)
        except PlcRuntimeError as e:
            fault = e
        except WallTimeExceeded as e:
            stopped = e   # the drawing shows the state reached
        print_diagnostics(plc.diagnostics[loaded:])
        status = PlcStatus(plc)

    from rich.console import Console

    from .render import render_program

    # soft_wrap: a wide rung stays one line per row when piped, instead of
    # being folded at 80 columns; highlight off: no guessed colours.
    console = Console(highlight=False, soft_wrap=True)
    if status is not None:
        console.print(f"status after {plc.scans} scan(s), {plc.time:g} s simulated, "
                      f"mode {plc.mode}", markup=False)
    texts = render_program(program, status=status, networks=selected,
                           styled=console.is_terminal, stl=args.stl, names=_names(symbols))
    for i, text in enumerate(texts):
        console.print(text)
        if i + 1 < len(texts):
            console.print()  # a blank line between networks, as Micro/WIN spaces them
    if fault is not None:
        print_diagnostics(fault.diagnostics)
        return EXIT_FAULT
    if broken is not None:
        return EXIT_ERROR
    if stopped is not None:
        print_diagnostics(stopped.diagnostics)
        return EXIT_WALL
    return EXIT_OK


def _parse(args: argparse.Namespace) -> tuple[Any, Any]:
    """(program, symbol table or None) of the command line, parsed only."""
    from ..project import frontend  # noqa: F401  registers the .mwp/.smart reader
    from ..lang.limits import file_limit
    from ..lang.sources import read_program

    program, symbols, _ = read_program(
        [Path(p) for p in args.programs], Path(args.symbols) if args.symbols else None,
        encoding=args.encoding, max_bytes=file_limit(args.max_file_mb))
    return program, symbols


def _names(symbols: Any) -> Any:
    """Operand text -> the text drawn, as the browser panel names operands:
    ``Start_PB:I0.0`` for an address or a symbol of the table; None
    without a table."""
    if symbols is None or not getattr(symbols, "entries", None):
        return None
    from .names import symbol_names
    names = symbol_names(symbols)
    return lambda text: names(text)[0]


def _check_options(args: argparse.Namespace, error: type) -> None:
    """The run options without --status are a mistake, not ignored."""
    if not args.status:
        given = [name for name, on in (("--set", args.set),
                                       ("--seconds", args.seconds is not None),
                                       ("--scans", args.scans is not None),
                                       ("--max-wall", args.max_wall is not None),
                                       ("--progress", args.progress)) if on]
        if given:
            raise error(f"{', '.join(given)} only make(s) sense with --status")


def _select(program: Any, specs: list[str], error: type) -> list[tuple[str, int]] | None:
    """``--network`` values as (block id, number) pairs; None = all."""
    if not specs:
        return None
    out = []
    for spec in specs:
        m = _NET_RE.fullmatch(spec.strip())
        if m is None:
            raise error(f"--network {spec}: use BLOCK/N (OB1/3, SBR0/1) or a number")
        block, number = (m.group(1) or "OB1").strip(), int(m.group(2))
        pou = next((p for p in program.pous
                    if block.upper() in (p.ident.upper(), p.name.upper())), None)
        if pou is None:
            names = ", ".join(p.ident for p in program.pous) or "none"
            raise error(f"--network {spec}: no block {block} (blocks: {names})")
        numbers = [n.number for n in pou.networks]
        if number not in numbers:
            have = f"{min(numbers)}..{max(numbers)}" if numbers else "none"
            raise error(f"--network {spec}: {pou.ident} has no network {number} "
                        f"(networks {have})")
        out.append((pou.ident, number))
    return out


__all__ = ["cmd_show", "register"]
