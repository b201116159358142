"""The ``plcrt check``, ``run`` and ``dump`` commands and the output of ``run``.

Each ``cmd_*`` function takes the parsed arguments (:mod:`plcrt.cli` builds
the parser and calls it) and returns the exit status
(:mod:`plcrt.term.report`).  ``run`` prints its ``--watch`` values as an
aligned table (a rich table on a terminal), or one strict JSON object with
``--json``, then the tables of :mod:`plcrt.term.tables` for a ``--plant``.

The other commands (``show``, ``debug``, ``trace``, ``serve``, ``eds``) are
defined beside what they present.  This module holds no PLC semantics and
no option parsing of its own beyond ``--watch``: the shared options are
:mod:`plcrt.term.options`.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from .engine.values import json_number, split_format
from .errors import Diagnostic, PlcConfigError, PlcError, PlcRuntimeError
from .safetext import printable
from .term.options import check_run_length, load_for_run, load_from_args, parse_sets
from .term.progress import WallTimeExceeded, run_with_progress
from .term.report import (EXIT_ERROR, EXIT_FAULT, EXIT_OK, EXIT_WALL, count_text,
                          print_diagnostics)
from .term.tables import counters_in_use, ports_in_use, print_devices, pulse_outputs

if TYPE_CHECKING:
    from .engine.runtime import Plc


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
        print(f"{name}: {count_text(diags)}", file=sys.stderr)
        return EXIT_ERROR
    diags = plc.diagnostics
    print_diagnostics(diags)
    prog = plc.program
    print(f"{name}: {count_text(diags)} ({len(prog.pous)} block(s), "
          f"{prog.network_count()} network(s), {prog.instruction_count()} instruction(s))",
          file=sys.stderr)
    system = getattr(prog, "system", None)    # a project's system block (docs/retentive.md)
    for line in system.lines() if system is not None else ():
        if line.startswith("CPU: "):
            line += f" (runs as {plc.model.name}; --cpu chooses)"
        print(printable(f"{name}: system block: {line}"), file=sys.stderr)
    for note in getattr(prog, "project_notes", ()):     # names read from the file: escaped
        print(printable(f"{name}: note: {note}"), file=sys.stderr)
    return EXIT_OK


def cmd_run(args: argparse.Namespace) -> int:
    """``plcrt run``: load, apply --set, run, print --watch values (and the
    axes of a --plant).  A long run on a terminal shows a progress bar on
    stderr; ``--quiet`` prints nothing but errors (and the --json object)."""
    program = args.programs[0]
    quiet = getattr(args, "quiet", False)

    def report(diags: Sequence[Diagnostic]) -> None:
        print_diagnostics([d for d in diags if d.severity == "error"] if quiet else diags)

    try:
        check_run_length(args)
        writes = parse_sets(args.set)
        watches = [_parse_watch(item) for item in args.watch]
        plc = load_for_run(args, writes, report=report)
        apply_machine_args(plc, args)
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
    if getattr(args, "verbose", False):
        print(backend_line(plc), file=sys.stderr)
    if args.json:
        _emit_json(args, plc, values, str(fault or stopped) if fault or stopped else None)
    elif not quiet:
        _print_values(program, plc, values)
        if args.plant or plc.program.project_plant:      # a project's wizards: a plant
            print_devices(plc)
            _print_machines(plc)
    if fault is not None:
        print_diagnostics(fault.diagnostics)
        return EXIT_FAULT
    if stopped is not None:
        print_diagnostics(stopped.diagnostics)
        return EXIT_WALL
    return EXIT_OK


def add_machine_args(p: argparse.ArgumentParser) -> None:
    """``--press``, ``--hold`` and ``--fault`` of ``plcrt run``: a person's
    actions on the plant's machines from the start (docs/machines.md)."""
    p.add_argument("--press", action="append", default=[], metavar="MACHINE.BUTTON",
                   help="press a machine's button at the start for 0.3 s (conveyor.start)")
    p.add_argument("--hold", action="append", default=[], metavar="MACHINE.BUTTON",
                   help="hold a button, key switch or obstacle from the start (garage.key)")
    p.add_argument("--fault", action="append", default=[], metavar="MACHINE.FAULT",
                   help="switch a machine's fault on from the start (conveyor.jam, "
                        "tank.stuck_on:high)")


def apply_machine_args(plc: Plc, args: argparse.Namespace) -> None:
    """Apply ``--fault``, ``--hold`` and ``--press`` (in that order).

    Raises:
        PlcError: a malformed item, an unknown machine, button or fault.
    """
    for opt in ("fault", "hold", "press"):
        for item in getattr(args, opt, None) or ():
            name, dot, what = str(item).partition(".")
            if not dot or not name or not what:
                raise PlcConfigError(f"--{opt} {printable(str(item))[:60]!r}: write "
                                     f"MACHINE.{'FAULT' if opt == 'fault' else 'BUTTON'}")
            getattr(plc.machine(name), opt)(what)


def _print_machines(plc: Plc) -> None:
    """One line per machine: what its terminals show on, its faults and notes."""
    from .term.tables import table_lines
    rows = []
    for m in plc.machines():
        s = m.state()
        wiring = m.wiring()
        on_in = [f"{k}={v}" if wiring[k].startswith("AIW") else k
                 for k, v in s["inputs"].items() if v or wiring[k].startswith("AIW")]
        on_out = [k for k, v in s["outputs"].items() if v]
        rows.append([s["name"], s["kind"], " ".join(on_in) or "-", " ".join(on_out) or "-",
                     " ".join(s["faults"]) or "-", str(len(m.notes()))])
    if rows:
        for line in table_lines(["machine", "kind", "inputs on", "outputs on", "faults",
                                 "notes"], rows, {0, 1, 2, 3, 4}):
            print(line)


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
        info = plc.backend
        obj["backend"] = info["name"]
        if info.get("tiered"):       # backend="auto": the scans run in Python first
            obj["python_scans"] = info["python_scans"]
        # the CPU's own state the program sets: real-time clock and DLED
        obj["clock"] = plc.clock.now(plc.now_us).isoformat()
        obj["dled"] = plc.station.led
    if plc is not None and getattr(args, "plant", None):
        obj["axes"] = [a.to_dict() for a in plc.axes()]
        drives = plc.drives()
        if drives:
            obj["drives"] = [d.to_dict() | {"flags": d.flags} for d in drives]
        machines = plc.machines()
        if machines:
            obj["machines"] = [m.state() for m in machines]
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


def backend_line(plc: Plc) -> str:
    """One line saying which code generator ran the program (``--verbose``)."""
    info = plc.backend
    if info["name"] != "native":
        return "backend: python" + (" (native not ready yet)" if info.get("tiered") else "")
    after = ""
    if info.get("tiered"):       # backend="auto": Python first, or native at once
        after = (f", after {info['python_scans']} scans in Python" if info["python_scans"]
                 else ", from the first scan")
    return (f"backend: native ({info['pieces']} pieces as machine code, "
            f"{len(info['python'])} in Python{after})")


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


__all__ = ["cmd_check", "cmd_dump", "cmd_run"]
