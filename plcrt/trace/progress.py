"""Running a PLC for a long time with a progress bar on a terminal.

:func:`run_with_progress` does exactly what ``plc.run(...)`` does; when the
run is long, the stream is a terminal and the caller is not quiet, it runs
the scans in chunks and shows a rich progress bar between them.  Scans are
deterministic and independent of how they are grouped, so the results are
the same either way.  rich is imported only when the bar is shown.

This module does not record anything (see :mod:`plcrt.trace.recorder`).
"""

from __future__ import annotations

import sys
from typing import Any, TextIO

from ..engine.values import scan_total

#: runs of at most this many scans never show a bar (they end too soon)
MIN_SCANS_FOR_BAR = 2000


def scan_count(plc: Any, seconds: float | None = None, scans: int | None = None) -> int:
    """The number of scans ``plc.run(seconds=..., scans=...)`` runs
    (a partial last scan counts as a scan, as in the engine)."""
    return scan_total(plc.scan_us, seconds, scans)


def _is_terminal(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):   # no isatty, or a closed stream
        return False


def run_with_progress(plc: Any, *, seconds: float | None = None, scans: int | None = None,
                      quiet: bool = False, stream: TextIO | None = None) -> None:
    """Run ``plc`` like ``plc.run(seconds=..., scans=...)``.

    A progress bar is drawn on ``stream`` (default: stderr) only if it is a
    terminal, the run is longer than :data:`MIN_SCANS_FOR_BAR` scans and
    ``quiet`` is false; the bar goes away when the run ends.

    Raises:
        PlcConfigError: neither or both of seconds/scans, or a negative one.
        PlcRuntimeError: a fault of the program (as ``plc.run`` raises it).
    """
    total = scan_count(plc, seconds, scans)
    out = sys.stderr if stream is None else stream
    if quiet or total <= MIN_SCANS_FOR_BAR or not _is_terminal(out):
        plc.run(seconds=seconds, scans=scans)   # the plain run, by construction
        return
    _run_with_bar(plc, total, out)


def _run_with_bar(plc: Any, total: int, out: TextIO) -> None:
    from rich.console import Console
    from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn,
                               TimeElapsedColumn, TimeRemainingColumn)

    # Chunks of about 1/200 of the run redraw the bar often enough, and at
    # a few µs per scan 100 scans are still far more than a call's cost.
    chunk = min(2000, max(100, total // 200))
    console = Console(file=out, force_terminal=True)
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TextColumn("scans"), TextColumn("{task.fields[sim]}"),
               TimeElapsedColumn(), TimeRemainingColumn())
    with Progress(*columns, console=console, transient=True) as bar:
        task = bar.add_task("running", total=total, sim=f"{plc.time:.3f} s")
        done = 0
        while done < total and plc.mode == "RUN":
            n = min(chunk, total - done)
            plc.scan(n)
            done += n
            bar.update(task, completed=done, sim=f"{plc.time:.3f} s")


__all__ = ["MIN_SCANS_FOR_BAR", "run_with_progress", "scan_count"]
