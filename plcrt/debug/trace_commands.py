"""The debugger's trace commands: record signals once per scan during a
session and look at them there (``trace``, ``trend``, ``csv``, ``plot``).

``trace SIG...`` attaches a :class:`plcrt.trace.Trace` to the session's PLC,
the recorder of ``plcrt trace``: one sample at the end of every scan,
stamped with the simulated time then.  ``trend`` prints its sparklines
(:func:`plcrt.trace.trend`), ``csv`` and ``plot`` write its samples
(:meth:`plcrt.trace.Trace.to_csv`, :func:`plcrt.trace.plot`).  A session
has at most one trace, kept in ``SessionState._trace``; a new ``trace SIG...``
replaces it.

None of these commands runs a scan, so all of them work while paused at a
breakpoint: they read what has been recorded, and a trace started then
takes its first sample at the end of the scan in progress.

This module is not a recorder, a formatter or a plotter (those are
:mod:`plcrt.trace`'s) and not the command table: its :data:`TRACE_COMMANDS`
are entered into :data:`plcrt.debug.commands.COMMANDS`, which ``help``
lists.
"""

from __future__ import annotations

import re

from ..trace.plot import plot
from ..trace.recorder import Trace
from ..trace.spark import trend
from .base import Command
from .panels import key_values
from .state import CommandError, SessionState

#: columns of ``trend`` without a width, as ``plcrt trace`` prints
DEFAULT_TREND_WIDTH = 60
#: the widest ``trend`` accepted
MAX_TREND_WIDTH = 500

_NO_TRACE = "no trace yet: start one with 'trace SIG...' and run some scans"


# ---------------------------------------------------------------------------
# The handlers
# ---------------------------------------------------------------------------

def _cmd_trace(s: SessionState, args: list[str]) -> None:
    if not args:
        _list(s)
        return
    if len(args) == 1 and args[0].lower() in ("stop", "clear"):
        word = args[0].lower()
        _symbol_note(s, args[0])
        if word == "stop":
            _stop(s)
        else:
            _clear(s)
        return
    _start(s, args)


def _start(s: SessionState, signals: list[str]) -> None:
    old = s._trace
    # a bad signal raises here, before anything is attached: the old trace
    # (if any) goes on recording
    trace = Trace(s.plc, signals)
    if old is not None:
        old.detach()
        s._print(f"replaced the trace of {_names(old)} ({_samples(len(old))} dropped)")
    s._trace = trace
    s._print(f"tracing {_names(trace)}: a sample at the end of every scan, "
             f"from scan {s.plc.scans + 1} on")
    _stop_mode_note(s)


def _stop(s: SessionState) -> None:
    trace = s._trace
    if trace is None:
        raise CommandError("no trace to stop")
    if not trace.attached:
        s._print(f"the trace of {_names(trace)} is already stopped "
                 f"({_samples(len(trace))})")
        return
    trace.detach()
    s._print(f"stopped the trace of {_names(trace)} ({_samples(len(trace))} kept for "
             f"trend, csv and plot)")


def _clear(s: SessionState) -> None:
    old = s._trace
    if old is None:
        raise CommandError("no trace to clear: start one with 'trace SIG...'")
    old.detach()
    # the signals were checked when the trace started; they still exist
    s._trace = Trace(s.plc, old.names)
    s._print(f"cleared {_samples(len(old))}; tracing {_names(old)} again, "
             f"from scan {s.plc.scans + 1} on")
    _stop_mode_note(s)


def _list(s: SessionState) -> None:
    trace = s._trace
    if trace is None:
        s._print("no trace (start one with 'trace SIG...')")
        return
    state = ("recording, a sample at the end of every scan" if trace.attached
             else "stopped ('trace clear' records again from empty)")
    samples = str(len(trace))
    if len(trace):
        t = trace.time
        samples += f", t = {t[0].item()!r}..{t[-1].item()!r} s"
    for line in key_values([("signals", _names(trace)), ("state", state),
                            ("samples", samples)]):
        s._print(line)


def _cmd_trend(s: SessionState, args: list[str]) -> None:
    width = DEFAULT_TREND_WIDTH
    if args:
        if len(args) > 1 or not re.fullmatch(r"\d+", args[0]) or \
                not 1 <= int(args[0]) <= MAX_TREND_WIDTH:
            raise CommandError(f"trend takes a width in columns (1..{MAX_TREND_WIDTH}), "
                               f"got '{' '.join(args)}'")
        width = int(args[0])
    trace = _need_trace(s)
    s._print(trend(trace, width))
    if not len(trace):
        s._print("(a sample is taken at the end of each scan: run some scans)")


def _cmd_csv(s: SessionState, args: list[str]) -> None:
    path = _file(args, "csv FILE")
    trace = _need_trace(s)
    try:
        trace.to_csv(path)
    except OSError as e:
        raise CommandError(f"cannot write '{path}': {e.strerror or e}") from None
    s._print(f"wrote {_samples(len(trace))} of {_names(trace)} to {path}")


def _cmd_plot(s: SessionState, args: list[str]) -> None:
    path = _file(args, "plot FILE.png|FILE.svg")
    trace = _need_trace(s)
    files = sorted({p.loc.file for p in s.plc.program.pous}) or [s.plc.program.file]
    try:
        # a bad extension, an empty trace and a missing matplotlib raise
        # PlcConfigError, which the session prints as an error line
        plot(trace, path, title=", ".join(files))
    except OSError as e:
        raise CommandError(f"cannot write '{path}': {e.strerror or e}") from None
    s._print(f"plotted {_names(trace)} ({_samples(len(trace))}) to {path}")


# ---------------------------------------------------------------------------
# Helpers
# ---------------------------------------------------------------------------

def trace_summary(trace: Trace) -> str:
    """One line about a trace, for ``status``."""
    state = "recording" if trace.attached else "stopped"
    return f"{_names(trace)} ({_samples(len(trace))}, {state})"


def _names(trace: Trace) -> str:
    return ", ".join(trace.names)


def _samples(n: int) -> str:
    return f"{n} sample{'' if n == 1 else 's'}"


def _need_trace(s: SessionState) -> Trace:
    if s._trace is None:
        raise CommandError(_NO_TRACE)
    return s._trace


def _file(args: list[str], usage: str) -> str:
    if len(args) != 1:
        raise CommandError(f"write '{usage}' (one file name, without spaces)")
    return args[0]


def _stop_mode_note(s: SessionState) -> None:
    if s.plc.mode != "RUN":
        s._print("note: the CPU is in STOP mode: no scan runs, so nothing is recorded")


def _symbol_note(s: SessionState, word: str) -> None:
    """``trace Stop`` stops the trace even when the program has a symbol
    ``Stop``: say how to record that symbol instead."""
    lookup = getattr(s.plc.symbols, "lookup", None)
    sym = lookup(word) if lookup is not None else None
    if sym is not None:
        s._print(f"note: 'trace {word}' means 'trace {word.lower()}'; to record the "
                 f"symbol {word}, give its address: trace {sym.address}")


# ---------------------------------------------------------------------------
# Their entries of the command table
# ---------------------------------------------------------------------------

TRACE_COMMANDS: tuple[Command, ...] = (
    Command("trace", _cmd_trace, "trace [SIG...|stop|clear]",
            "record signals at the end of every scan (alone: what is recorded)",
            "SIG as for 'plcrt trace --signal': I0.0, VW100, T37 (its value), T37:BIT,\n"
            "VD4:REAL, symbols, axis0.0.speed (position, mechanical, speed).  The first\n"
            "sample is taken at the end of the next scan (of the scan in progress when\n"
            "paused), stamped with the simulated time then.  A new 'trace SIG...'\n"
            "replaces the running one.  'trace stop' stops recording and keeps the\n"
            "samples; 'trace clear' drops them and records the same signals again.\n"
            "Then 'trend', 'csv FILE' and 'plot FILE.svg'."),
    Command("trend", _cmd_trend, "trend [WIDTH]",
            "the recorded signals as sparklines: min..max, last value",
            f"WIDTH: columns of each sparkline (default {DEFAULT_TREND_WIDTH}).  A column of\n"
            "many samples shows their mean, of a bit their maximum, so a short pulse\n"
            "still shows."),
    Command("csv", _cmd_csv, "csv FILE",
            "write the recorded samples to a CSV file (time_s, then one column a signal)"),
    Command("plot", _cmd_plot, "plot FILE.png|FILE.svg",
            "plot the recorded signals to a PNG or SVG file (needs matplotlib)",
            "One subplot per signal on a shared time axis; bits and integers as steps.\n"
            "matplotlib is optional: the 'plot' extra (README.md, 'Quick start')."),
)


__all__ = ["DEFAULT_TREND_WIDTH", "MAX_TREND_WIDTH", "TRACE_COMMANDS", "trace_summary"]
