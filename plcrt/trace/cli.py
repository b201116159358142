"""The ``plcrt trace`` command: run a program and record signals per scan.

::

    plcrt trace PROGRAM... [--symbols F] [--data F] [--cpu NAME] [--plant F]
        --signal SIG [--signal SIG]... [--scan-ms MS] (--seconds S | --scans N)
        [--set ADDR=VALUE]... [--every N] [--csv F] [--plot F.png|F.svg] [--quiet]

The run shows a progress bar on a terminal when it is long (``--progress``:
plain progress lines off a terminal; ``--max-wall S`` stops it after S
wall-clock seconds with exit status 3, keeping the samples); then the CSV
and the plot are written and the trend view (:func:`plcrt.trace.trend`) is
printed on stdout.  With ``--quiet`` nothing but errors is printed.  After
a run-time fault the samples recorded up to the fault are still written,
and the exit status is 2.

Presentation only: recording, formatting and plotting live in the other
modules of :mod:`plcrt.trace`; options shared with ``plcrt run`` are parsed
by the helpers of :mod:`plcrt.term.options`, the run is paced by
:mod:`plcrt.term.progress`.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import Any

from ..errors import Diagnostic, PlcConfigError, PlcError, PlcRuntimeError
from ..safetext import printable

#: exit status after Ctrl-C, as ``plcrt`` uses elsewhere (128 + SIGINT)
EXIT_INTERRUPTED = 130


def register(sub: Any) -> None:
    """Add the ``trace`` subcommand to the ``plcrt`` parser."""
    from ..term.options import (add_long_run_args, add_program_args, add_run_length_args,
                                add_scan_ms_arg, add_set_args)

    p = sub.add_parser(
        "trace", help="run a program and record signals scan by scan (CSV, plot, sparklines)",
        description="Run a program in simulated time, record the given signals after every "
                    "scan (or every N-th), write them as CSV or a PNG/SVG plot and print a "
                    "sparkline per signal.",
        epilog="SIG is an address (I0.0, VW100, T37, T37:BIT, VD200:REAL), a symbol, or "
               "axis<slot>.<axis>.<position|mechanical|speed> with --plant. "
               "Each sample is taken at the end of a scan and stamped with the simulated "
               "time then (the first 10 ms scan is at 0.01 s).")
    add_program_args(p)
    p.add_argument("--signal", action="append", required=True, metavar="SIG",
                   help="a signal to record (repeat for more)")
    add_scan_ms_arg(p)
    add_run_length_args(p)
    add_long_run_args(p)
    add_set_args(p)
    p.add_argument("--every", type=int, default=1, metavar="N",
                   help="record after every N-th scan only (default 1: every scan)")
    p.add_argument("--csv", metavar="F", help="write the samples to this CSV file")
    p.add_argument("--plot", metavar="F",
                   help="plot the signals to this file (.png or .svg; needs plcrt[plot])")
    p.add_argument("--quiet", action="store_true",
                   help="print nothing but errors (no progress bar, no trend, no warnings)")
    p.set_defaults(func=cmd_trace)


def cmd_trace(args: argparse.Namespace) -> int:
    """``plcrt trace``: exit 0, 1 for bad input or options, 2 after a fault."""
    from ..term.options import check_run_length, load_for_run, parse_sets
    from ..term.progress import WallTimeExceeded, run_with_progress
    from ..term.report import EXIT_ERROR, EXIT_FAULT, EXIT_OK, EXIT_WALL, print_diagnostics
    from .plot import plot, plot_format, require_matplotlib
    from .recorder import Trace
    from .spark import trend

    def report(diags: Sequence[Diagnostic]) -> None:
        print_diagnostics([d for d in diags if d.severity == "error"] if args.quiet
                          else diags)

    try:
        check_run_length(args)
        if args.every < 1:
            raise PlcConfigError(f"--every must be at least 1, got {args.every}")
        if args.plot:
            # before a long run: a wrong file name or a missing matplotlib
            # should not cost the user the run
            plot_format(args.plot)
            require_matplotlib()
        for option, target in (("--csv", args.csv), ("--plot", args.plot)):
            if target:
                _check_writable(option, target)
        writes = parse_sets(args.set)
        plc = load_for_run(args, writes, report=report)
        trace = Trace(plc, args.signal, every=args.every)
    except PlcError as e:
        print_diagnostics(e.diagnostics)
        return EXIT_ERROR

    fault: PlcError | None = None
    stopped: PlcError | None = None
    interrupted = False
    loaded = len(plc.diagnostics)
    try:
        run_with_progress(plc, seconds=args.seconds, scans=args.scans, quiet=args.quiet,
                          max_wall=args.max_wall, progress=args.progress)
    except PlcRuntimeError as e:
        fault = e
    except WallTimeExceeded as e:
        # like Ctrl-C: the samples recorded up to here are written
        stopped = e
        trace._even_out()
    except KeyboardInterrupt:
        # Ctrl-C ends the run between two scans; the samples so far are kept
        interrupted = True
        trace._even_out()
        print(f"plcrt: interrupted after {plc.scans} scan(s); writing the "
              f"{len(trace)} sample(s) recorded so far", file=sys.stderr)
    finally:
        trace.detach()
    report(plc.diagnostics[loaded:])

    status = EXIT_OK
    outputs = []
    if args.csv:
        outputs.append((args.csv, lambda: trace.to_csv(args.csv)))
    if args.plot:
        outputs.append((args.plot, lambda: plot(trace, args.plot,
                                                title=", ".join(args.programs))))
    for target, write in outputs:
        try:
            write()
        except OSError as e:
            print(printable(f"plcrt: error: cannot write '{target}': {e.strerror or e}"),
                  file=sys.stderr)
            status = EXIT_ERROR
        except PlcError as e:   # a plot of an empty trace, say
            print_diagnostics(e.diagnostics)
            status = EXIT_ERROR

    if not args.quiet:
        # names come from the command line and the symbol table: no raw
        # control characters on the terminal
        print(printable(f"{args.programs[0]}: {plc.scans} scan(s), {plc.time:g} s simulated, "
                        f"mode {plc.mode}"))
        print("\n".join(printable(line) for line in trend(trace).split("\n")))
    if fault is not None:
        print_diagnostics(fault.diagnostics)
        return EXIT_FAULT
    if stopped is not None:
        print_diagnostics(stopped.diagnostics)
        return EXIT_WALL
    if interrupted:
        return EXIT_INTERRUPTED
    return status


def _check_writable(option: str, target: str) -> None:
    """Refuse an output file that cannot be written, before the run: its
    folder does not exist, or it names a folder.  (Other failures, such as
    a full disk, are reported when the file is written.)

    Raises:
        PlcConfigError: naming the option and the file.
    """
    import os
    from pathlib import Path

    path = Path(target)
    if target.endswith(("/", os.sep)) or path.is_dir():
        raise PlcConfigError(f"{option} {target}: this is a folder, not a file")
    folder = path.parent
    if not folder.is_dir():
        raise PlcConfigError(f"{option} {target}: the folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise PlcConfigError(f"{option} {target}: no permission to write this file")


__all__ = ["cmd_trace", "register"]
