"""Running a PLC for a long time: a progress bar or progress lines, and a
limit on wall-clock time.

:func:`run_with_progress` does exactly what ``plc.run(...)`` does; when the
run is long, the stream is a terminal and the caller is not quiet, it runs
the scans in chunks and shows a rich progress bar between them.  Off a
terminal, ``progress=True`` prints a plain line every few seconds instead
(a CI log shows that a long run is alive).  ``max_wall`` bounds the run in
wall-clock seconds: it stops between two scans with :class:`WallTimeExceeded`,
which says how far the simulated time got.  Scans are deterministic and
independent of how they are grouped, so the results are the same either
way.  rich is imported only when the bar is shown.

This module does not record anything (see :mod:`plcrt.trace.recorder`).
"""

from __future__ import annotations

import math
import sys
import time
from typing import Any, Callable, TextIO

from ..engine.values import scan_total
from ..engine.values import shown_value as _shown
from ..errors import PlcConfigError, PlcError

#: runs of at most this many scans never show a bar (they end too soon)
MIN_SCANS_FOR_BAR = 2000

#: wall seconds between two progress lines (``progress=True`` off a terminal)
PROGRESS_EVERY_S = 5.0

#: wall seconds a chunk of scans should take when the run is watched
#: (progress lines or a wall-time limit): short enough to stop on time
_CHUNK_S = 0.05


class WallTimeExceeded(PlcError):
    """The run reached its wall-clock limit (``max_wall``) and was stopped
    between two scans; the PLC is in the state of the last full scan."""


def scan_count(plc: Any, seconds: float | None = None, scans: int | None = None,
               bounded: bool = True) -> int:
    """The number of scans ``plc.run(seconds=..., scans=...)`` runs
    (a partial last scan counts as a scan, as in the engine); ``bounded``:
    at most :data:`~plcrt.engine.values.MAX_STEPS`, as ``plc.run``."""
    return scan_total(plc.scan_us, seconds, scans, bounded=bounded)


def _is_terminal(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):   # no isatty, or a closed stream
        return False


def check_max_wall(max_wall: float | None) -> None:
    """Refuse a wall-time limit that is not a positive finite number.

    Raises:
        PlcConfigError: naming ``--max-wall``.
    """
    if max_wall is not None and (isinstance(max_wall, bool)
                                 or not isinstance(max_wall, (int, float))
                                 or not 0 < max_wall < math.inf):
        raise PlcConfigError(f"--max-wall must be a positive number of seconds, "
                             f"got {type(max_wall).__name__} {_shown(max_wall)}")


def run_with_progress(plc: Any, *, seconds: float | None = None, scans: int | None = None,
                      quiet: bool = False, stream: TextIO | None = None,
                      max_wall: float | None = None, progress: bool = False,
                      clock: Callable[[], float] = time.monotonic) -> None:
    """Run ``plc`` like ``plc.run(seconds=..., scans=...)``.

    A progress bar is drawn on ``stream`` (default: stderr) only if it is a
    terminal, the run is longer than :data:`MIN_SCANS_FOR_BAR` scans and
    ``quiet`` is false; the bar goes away when the run ends.  Off a
    terminal, ``progress`` prints a plain line every
    :data:`PROGRESS_EVERY_S` seconds (and one at the end); it is printed
    even when ``quiet``, since it was asked for.  ``max_wall`` stops the run
    after that many wall-clock seconds.

    Raises:
        PlcConfigError: neither or both of seconds/scans, or a negative one,
            or a bad ``max_wall``.
        PlcRuntimeError: a fault of the program (as ``plc.run`` raises it).
        WallTimeExceeded: ``max_wall`` seconds passed before the run ended.
    """
    from ..engine.runtime import Plc
    if not isinstance(plc, Plc):
        raise PlcConfigError(f"run_with_progress() runs a plcrt.Plc, got {type(plc).__name__}")
    if stream is not None and not callable(getattr(stream, "write", None)):
        raise PlcConfigError(f"stream= is a text stream (sys.stderr, a file), got "
                             f"{type(stream).__name__}")
    if not callable(clock):
        raise PlcConfigError(f"clock= is a function returning seconds, got "
                             f"{type(clock).__name__}")
    # a wall-time limit ends a run of any simulated length
    check_max_wall(max_wall)
    total = scan_count(plc, seconds, scans, bounded=max_wall is None)
    out = sys.stderr if stream is None else stream
    terminal = _is_terminal(out)
    if terminal and (progress or not quiet and total > MIN_SCANS_FOR_BAR):
        _run_with_bar(plc, total, out, max_wall=max_wall, clock=clock)
    elif max_wall is not None or progress:
        _run_watched(plc, total, out if progress else None, max_wall, clock)
    else:
        plc.run(seconds=seconds, scans=scans)   # the plain run, by construction


def _stopped(plc: Any, done: int, total: int, max_wall: float) -> WallTimeExceeded:
    return WallTimeExceeded(
        f"stopped by --max-wall after {max_wall:g} s of wall-clock time, at {plc.time:g} s "
        f"simulated ({done} of {total} scans run); the results are those of that moment")


def _run_watched(plc: Any, total: int, out: TextIO | None, max_wall: float | None,
                 clock: Callable[[], float]) -> None:
    """Run ``total`` scans in chunks sized to take about :data:`_CHUNK_S`,
    printing a progress line to ``out`` (if any) every few seconds and
    stopping at ``max_wall``."""
    start = clock()
    next_line = start + PROGRESS_EVERY_S
    first = plc.scans
    done = 0
    chunk = 100
    while done < total and plc.mode == "RUN":
        n = min(chunk, total - done)
        t0 = clock()
        plc.scan(n)
        done = plc.scans - first   # fewer than asked when a STOP ended the run
        now = clock()
        took = now - t0
        # perf: chunks grow until one takes about _CHUNK_S, so the clock is
        # read a few dozen times a second whatever the scan costs
        if took < _CHUNK_S / 2:
            chunk = min(chunk * 2, 1_000_000)
        elif took > _CHUNK_S * 2 and chunk > 1:
            chunk //= 2
        stop = max_wall is not None and now - start >= max_wall and done < total
        if out is not None and (now >= next_line or done >= total or stop):
            _line(out, plc, done, total, now - start)
            next_line = now + PROGRESS_EVERY_S
        if stop:
            assert max_wall is not None
            raise _stopped(plc, done, total, max_wall)


def _line(out: TextIO, plc: Any, done: int, total: int, elapsed: float) -> None:
    share = 100.0 * done / total if total else 100.0
    out.write(f"plcrt: {done}/{total} scans ({share:.1f} %), {plc.time:g} s simulated, "
              f"{elapsed:.1f} s elapsed\n")
    out.flush()


def _run_with_bar(plc: Any, total: int, out: TextIO, *, max_wall: float | None = None,
                  clock: Callable[[], float] = time.monotonic) -> None:
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
    start = clock()
    with Progress(*columns, console=console, transient=True) as bar:
        task = bar.add_task("running", total=total, sim=f"{plc.time:.3f} s")
        done = 0
        while done < total and plc.mode == "RUN":
            n = min(chunk, total - done)
            plc.scan(n)
            done += n
            bar.update(task, completed=done, sim=f"{plc.time:.3f} s")
            if max_wall is not None and clock() - start >= max_wall and done < total:
                raise _stopped(plc, done, total, max_wall)


__all__ = ["MIN_SCANS_FOR_BAR", "PROGRESS_EVERY_S", "WallTimeExceeded", "check_max_wall",
           "run_with_progress", "scan_count"]
