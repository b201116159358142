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

This module does not record anything (see :mod:`plcrt.trace.recorder`) and
parses no option (see :mod:`plcrt.term.options`).
"""

from __future__ import annotations

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


#: the longest run the command line accepts, in simulated µs: times are
#: counted in whole microseconds, and beyond a signed 64-bit count (about
#: 292 000 years) a span is not something any tool of plcrt can count
MAX_RUN_US = 2**63 - 1


def check_run_span(seconds: float | None, scans: int | None, scan_us: int,
                   options: tuple[str, str] = ("--seconds", "--scans")) -> None:
    """Refuse a run longer than :data:`MAX_RUN_US` of simulated time.

    Raises:
        PlcConfigError: naming the option and the longest run.
    """
    longest = f"{MAX_RUN_US / 1e6:.3g} s of simulated time (2^63 µs, about 292 000 years)"
    if seconds is not None and seconds * 1e6 > MAX_RUN_US:
        raise PlcConfigError(f"{options[0]} {seconds:g} is longer than a run can be counted: "
                             f"at most {longest}")
    if scans is not None and scans * scan_us > MAX_RUN_US:
        shown = str(scans) if scans < 10**12 else f"{scans:.3g}"
        raise PlcConfigError(f"{options[1]} {shown} is longer than a run can be counted: "
                             f"at most {longest} ({scan_us / 1000:g} ms a scan)")


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


#: the largest finite float: a limit at or past it cannot be added to a clock
_FLOAT_MAX = sys.float_info.max


def check_max_wall(max_wall: float | None) -> None:
    """Refuse a wall-time limit that is not a positive finite number (an
    int too large for a float is no finite number of seconds either).

    Raises:
        PlcConfigError: naming ``--max-wall``.
    """
    if max_wall is not None and (isinstance(max_wall, bool)
                                 or not isinstance(max_wall, (int, float))
                                 or not 0 < max_wall < _FLOAT_MAX):
        raise PlcConfigError(f"--max-wall must be a positive number of seconds, "
                             f"got {type(max_wall).__name__} {_shown(max_wall)}")


def run_with_progress(plc: Any, *, seconds: float | None = None, scans: int | None = None,
                      quiet: bool = False, stream: TextIO | None = None,
                      max_wall: float | None = None, progress: bool = False,
                      clock: Callable[[], float] = time.monotonic,
                      sleep: Callable[[float], None] = time.sleep) -> None:
    """Run ``plc`` like ``plc.run(seconds=..., scans=...)``.

    A progress bar is drawn on ``stream`` (default: stderr) only if it is a
    terminal, the run is longer than :data:`MIN_SCANS_FOR_BAR` scans and
    ``quiet`` is false; the bar goes away when the run ends.  Off a
    terminal, ``progress`` prints a plain line every
    :data:`PROGRESS_EVERY_S` seconds (and one at the end); it is printed
    even when ``quiet``, since it was asked for.  ``max_wall`` stops the run
    after that many wall-clock seconds, at real-time pace too (the sleeps
    between scans end at the limit).

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
    plan = getattr(plc, "_tier_plan", None)
    if plan is not None:      # the run in chunks is one run, the command's last
        plan(total, final=True)   # (engine/tiering.py)
    out = sys.stderr if stream is None else stream
    terminal = _is_terminal(out)
    if terminal and (progress or not quiet and total > MIN_SCANS_FOR_BAR):
        _run_with_bar(plc, total, out, max_wall=max_wall, clock=clock, sleep=sleep)
    elif max_wall is not None or progress:
        _run_watched(plc, total, out if progress else None, max_wall, clock, sleep)
    else:
        plc.run(seconds=seconds, scans=scans)   # the plain run, by construction


def _stopped(plc: Any, done: int, total: int, max_wall: float) -> WallTimeExceeded:
    # a count past fifteen digits reads better as a magnitude (9.22e+17 scans)
    of = str(total) if total < 10**15 else f"{total:.3g}"
    return WallTimeExceeded(
        f"stopped by --max-wall after {max_wall:g} s of wall-clock time, at {plc.time:g} s "
        f"simulated ({done} of {of} scans run); the results are those of that moment")


def _scan(plc: Any, n: int, deadline: float | None, clock: Callable[[], float],
          sleep: Callable[[float], None]) -> None:
    """``n`` scans, as ``plc.scan(n)``.  A PLC at real-time pace is paced
    here, scan by scan, so that the wall-clock ``deadline`` also ends its
    sleeps: the engine's own pacing would sleep through a whole chunk."""
    if plc.pace != "realtime":
        plc.scan(n)
        return
    period = plc.scan_us / 1e6
    plc.pace = "simulated"   # the same scans; only who sleeps changes
    try:
        for _ in range(n):
            if plc.mode != "RUN":
                return
            end = clock() + period
            plc.scan(1)
            if deadline is not None:
                end = min(end, deadline)
            left = end - clock()
            if left > 0:
                sleep(left)
            if deadline is not None and clock() >= deadline:
                return
    finally:
        plc.pace = "realtime"


def _run_watched(plc: Any, total: int, out: TextIO | None, max_wall: float | None,
                 clock: Callable[[], float],
                 sleep: Callable[[float], None] = time.sleep) -> None:
    """Run ``total`` scans in chunks sized to take about :data:`_CHUNK_S`,
    printing a progress line to ``out`` (if any) every few seconds and
    stopping at ``max_wall``."""
    start = clock()
    deadline = None if max_wall is None else start + max_wall
    next_line = start + PROGRESS_EVERY_S
    first = plc.scans
    done = 0
    chunk = 100
    while done < total and plc.mode == "RUN":
        n = min(chunk, total - done)
        t0 = clock()
        _scan(plc, n, deadline, clock, sleep)
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
                  clock: Callable[[], float] = time.monotonic,
                  sleep: Callable[[float], None] = time.sleep) -> None:
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
    if plc.pace == "realtime":
        # a chunk at real-time pace lasts its simulated time: keep it short
        chunk = max(1, min(chunk, int(_CHUNK_S * 1e6 // plc.scan_us)))
    start = clock()
    deadline = None if max_wall is None else start + max_wall
    first = plc.scans
    with Progress(*columns, console=console, transient=True) as bar:
        task = bar.add_task("running", total=total, sim=f"{plc.time:.3f} s")
        done = 0
        while done < total and plc.mode == "RUN":
            n = min(chunk, total - done)
            _scan(plc, n, deadline, clock, sleep)
            done = plc.scans - first
            bar.update(task, completed=done, sim=f"{plc.time:.3f} s")
            if max_wall is not None and clock() - start >= max_wall and done < total:
                raise _stopped(plc, done, total, max_wall)


__all__ = ["MAX_RUN_US", "MIN_SCANS_FOR_BAR", "check_run_span", "PROGRESS_EVERY_S", "WallTimeExceeded", "check_max_wall",
           "run_with_progress", "scan_count"]
