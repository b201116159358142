"""Recording signals of a running program, one sample per scan.

A :class:`Trace` is an observer of :class:`plcrt.Plc`: the engine calls it
after every scan, once the outputs are written, and it appends the current
value of each signal to a column.  The hot path only appends Python ints
and floats to lists (or to bounded deques for ``limit=``); numpy arrays are
built on first access and cached until the next sample.

What a sample means: the state of memory and of the simulated axes at the
*end* of a scan, stamped with the simulated time at that moment, which is
``plc.time`` after the scan (scan 1 of a 10 ms program is stamped 0.01 s).
A scan that faults is not recorded (the engine raises before observers run)
and nothing is recorded in STOP mode (no scan runs).

This module is not a plotter or a formatter (see :mod:`plcrt.trace.plot`
and :mod:`plcrt.trace.spark`) and never changes the PLC's memory.
"""

from __future__ import annotations

import csv
import math
import re
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, Callable, Sequence

import numpy as np

from ..engine.values import MAX_STEPS, shown_value
from ..errors import PlcAddressError, PlcConfigError, PlcError, PlcKeyError
from ..paths import check_path
from ..safetext import printable

#: axis quantities a trace can record, and whether they are floats
AXIS_QUANTITIES = {"position": False, "mechanical": False, "speed": True}

_AXIS_RE = re.compile(r"axis(\d+)\.(\d+)\.(\w+)", re.IGNORECASE)
_AXIS_PREFIX_RE = re.compile(r"axis\d*\.", re.IGNORECASE)

#: bus-drive quantities a trace can record (fields of plcrt.devices.DriveState)
DRIVE_QUANTITIES = ("position", "velocity", "statusword", "controlword", "mode",
                    "following_error", "error_code")
_DRIVE_RE = re.compile(r"drive(?:(\d+)\.)?(\d+)\.(\w+)", re.IGNORECASE)
_DRIVE_PREFIX_RE = re.compile(r"drive\d*\.", re.IGNORECASE)



@dataclass(frozen=True)
class Signal:
    """One recorded signal: its name as given, its kind and its reader.

    ``kind`` is ``"bit"`` (0/1), ``"int"`` (bytes unsigned, words and double
    words signed, timer/counter values, axis positions) or ``"real"`` (REAL
    double words, axis speed).
    """

    name: str
    kind: str
    read: Callable[[], int | float]

    @property
    def dtype(self) -> type:
        return np.float64 if self.kind == "real" else np.int64


def is_device_signal(text: str) -> bool:
    """Whether *text* names an axis or drive quantity (``axis0.0.speed``,
    ``drive1.position``) rather than an address or a symbol."""
    name = text.strip()
    return bool(_AXIS_PREFIX_RE.match(name) or _DRIVE_PREFIX_RE.match(name))


def parse_signal(plc: Any, text: str) -> Signal:
    """Validate one signal string against ``plc`` and build its reader.

    Raises:
        PlcConfigError: a malformed signal (unknown ``:suffix`` or axis quantity).
        PlcAddressError: an address, symbol or axis that does not exist.
    """
    if not isinstance(text, str) or not text.strip():
        raise PlcConfigError(f"trace signal {shown_value(text)}: give an address, a symbol or "
                             f"axis<slot>.<axis>.<quantity>")
    name = text.strip()
    if _AXIS_PREFIX_RE.match(name):
        return _axis_signal(plc, name)
    if _DRIVE_PREFIX_RE.match(name):
        return _drive_signal(plc, name)
    try:
        kind, read = plc.reader(name)
    except PlcError as e:
        raise PlcAddressError(f"trace signal {name!r}: {e.message}") from None
    return Signal(name, kind, read)


def _axis_signal(plc: Any, name: str) -> Signal:
    m = _AXIS_RE.fullmatch(name)
    if m is None or m.group(3).lower() not in AXIS_QUANTITIES:
        raise PlcConfigError(f"trace signal {name!r}: an axis signal is "
                             f"axis<slot>.<axis>.<quantity> with quantity "
                             f"{'|'.join(AXIS_QUANTITIES)}, e.g. axis0.0.speed")
    slot, axis, quantity = int(m.group(1)), int(m.group(2)), m.group(3).lower()
    if not plc.modules:
        raise PlcAddressError(f"trace signal {name!r}: no plant is loaded, so there "
                              f"are no axes (load the program with plant=... or --plant)")
    try:
        plc.axis(slot, axis)
    except PlcError as e:
        raise PlcAddressError(f"trace signal {name!r}: {e.message}") from None
    kind = "real" if AXIS_QUANTITIES[quantity] else "int"
    axes = getattr(plc.module(slot), "axes", None)
    method = getattr(axes[axis], quantity, None) if isinstance(axes, list) else None
    if callable(method):
        # perf: ask the axis object directly for the value at the end of the
        # scan instead of building the snapshot dictionaries of plc.axis().
        return Signal(name, kind, lambda: method(plc._t_us))
    return Signal(name, kind, lambda: plc.axis(slot, axis)[quantity])


def _drive_signal(plc: Any, name: str) -> Signal:
    m = _DRIVE_RE.fullmatch(name)
    if m is None or m.group(3).lower() not in DRIVE_QUANTITIES:
        raise PlcConfigError(f"trace signal {name!r}: a drive signal is "
                             f"drive<node>.<quantity> (or drive<slot>.<node>.<quantity>) with "
                             f"quantity {'|'.join(DRIVE_QUANTITIES)}, e.g. drive1.position")
    slot = int(m.group(1)) if m.group(1) is not None else None
    node, quantity = int(m.group(2)), m.group(3).lower()
    try:
        state = plc.drive(node, slot)
    except PlcError as e:
        raise PlcAddressError(f"trace signal {name!r}: {e.message}") from None
    module = plc.module(state.slot)
    return Signal(name, "int", lambda: getattr(module.drive_state(node), quantity))


class Trace:
    """Record signals of ``plc`` after every scan (or every ``every``-th).

    Args:
        plc: the running program.
        signals: addresses (``I0.0``, ``VW100``, ``VD200:REAL``, ``T37``,
            ``T37:BIT``, symbols), axis quantities (``axis0.0.speed``) or
            bus-drive quantities (``drive1.position``, ``drive1.statusword``).
        every: record only after scans whose number (``plc.scans``, counted
            from power-up) is a multiple of ``every``.
        limit: keep only the last ``limit`` samples (a ring buffer).

    The trace attaches itself to ``plc.observers``; :meth:`detach` (or
    leaving a ``with`` block) stops the recording and keeps the samples.

    Raises:
        PlcConfigError, PlcAddressError: for a bad signal or option, before
            anything is attached.
    """

    def __init__(self, plc: Any, signals: Sequence[str], *, every: int = 1,
                 limit: int | None = None) -> None:
        from ..engine.runtime import Plc
        if not isinstance(plc, Plc):
            raise PlcConfigError(f"a trace records a plcrt.Plc, got {type(plc).__name__}")
        if isinstance(signals, str):
            signals = [signals]
        if not isinstance(signals, (list, tuple)):
            raise PlcConfigError(f"the signals of a trace are a list of names such as "
                                 f"['Q0.0', 'VW10'], got {type(signals).__name__}")
        if not signals:
            raise PlcConfigError("a trace needs at least one signal")
        if not isinstance(every, int) or isinstance(every, bool) or every < 1:
            raise PlcConfigError(f"every must be a whole number of scans >= 1, got "
                                 f"{shown_value(every)}")
        if limit is not None and (not isinstance(limit, int) or isinstance(limit, bool)
                                  or not 1 <= limit <= MAX_STEPS):
            raise PlcConfigError(f"limit must be a number of samples >= 1, got "
                                 f"{shown_value(limit)}")
        parsed = [parse_signal(plc, s) for s in signals]
        seen: set[str] = set()
        for sig in parsed:
            if sig.name in seen:
                raise PlcConfigError(f"trace signal {sig.name!r} is given twice")
            seen.add(sig.name)
        self.plc = plc
        self.every = every
        self.limit = limit
        self._signals = parsed
        self._index = {s.name: i for i, s in enumerate(parsed)}

        def column() -> Any:
            return deque(maxlen=limit) if limit is not None else []

        self._t_us = column()            # sample times, integer µs
        self._cols = [column() for _ in parsed]
        # perf: bound appends and readers, zipped once for the hot path
        self._hot = tuple((c.append, s.read) for c, s in zip(self._cols, parsed))
        self._t_append = self._t_us.append
        self._recorded = 0               # samples ever taken (cache key)
        self._cache: dict[Any, tuple[int, np.ndarray]] = {}
        self.attached = False
        self.attach()

    # -- recording ---------------------------------------------------------
    def _record(self, plc: Any) -> None:
        if self.every != 1 and plc.scans % self.every:
            return
        self._t_append(plc._t_us)
        for append, read in self._hot:
            append(read())
        self._recorded += 1

    def _even_out(self) -> None:
        """Drop a sample that an interruption (Ctrl-C) cut in half: every
        column as long as the shortest one."""
        n = min([len(self._t_us)] + [len(c) for c in self._cols])
        for col in [self._t_us, *self._cols]:
            while len(col) > n:
                col.pop()
        self._cache.clear()

    def attach(self) -> None:
        """(Re)start recording; called by the constructor."""
        if not self.attached:
            self.plc.observers.append(self._record)
            self.attached = True

    def detach(self) -> None:
        """Stop recording (the samples stay); calling it twice is harmless."""
        if self.attached:
            obs = self.plc.observers
            for i, fn in enumerate(obs):
                if fn == self._record:
                    del obs[i]
                    break
            self.attached = False

    def __enter__(self) -> Trace:
        return self

    def __exit__(self, *exc: object) -> None:
        self.detach()

    # -- access --------------------------------------------------------------
    @property
    def names(self) -> list[str]:
        """The signal names, in the order given."""
        return [s.name for s in self._signals]

    def kind(self, name: str) -> str:
        """``"bit"``, ``"int"`` or ``"real"`` (see :class:`Signal`)."""
        return self._signals[self._lookup(name)].kind

    def __len__(self) -> int:
        return len(self._t_us)

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name in self._index

    def _lookup(self, name: str) -> int:
        try:
            return self._index[name.strip() if isinstance(name, str) else name]
        except (KeyError, TypeError):   # TypeError: an unhashable name
            raise PlcKeyError(f"no signal {shown_value(name)} in this trace "
                              f"(signals: {', '.join(self.names)})") from None

    def _cached(self, key: Any, build: Callable[[], np.ndarray]) -> np.ndarray:
        hit = self._cache.get(key)
        if hit is not None and hit[0] == self._recorded:
            return hit[1]
        arr = build()
        arr.flags.writeable = False   # shared by later calls: keep it intact
        self._cache[key] = (self._recorded, arr)
        return arr

    @property
    def time(self) -> np.ndarray:
        """Sample times in simulated seconds (float64), one per sample."""
        return self._cached("time", lambda: np.array(self._t_us, dtype=np.int64) / 1e6)

    def array(self, name: str) -> np.ndarray:
        """The samples of one signal: int64, or float64 for REAL and speed."""
        i = self._lookup(name)
        sig = self._signals[i]
        return self._cached(i, lambda: np.array(self._cols[i], dtype=sig.dtype))

    __getitem__ = array

    def last(self, n: int = 1) -> list[tuple[int | float, ...]]:
        """The last ``n`` samples as rows ``(time_s, value, ...)``."""
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise PlcConfigError(f"the number of samples is a whole number >= 0, got "
                                 f"{shown_value(n)}")
        return self._rows(max(0, len(self) - n), len(self))

    def _rows(self, start: int, stop: int) -> list[tuple[int | float, ...]]:
        cols = [self.time] + [self.array(s.name) for s in self._signals]
        return [tuple(c[k].item() for c in cols) for k in range(start, stop)]

    def changes(self, name: str) -> np.ndarray:
        """Times of the samples whose value differs from the sample before."""
        v = self.array(name)
        differ = v[1:] != v[:-1]
        if v.dtype.kind == "f":
            differ &= ~(np.isnan(v[1:]) & np.isnan(v[:-1]))   # NaN stays NaN
        return self.time[1:][differ]

    def table(self, n: int = 10) -> list[list[str]]:
        """The last ``n`` samples as text: a header row, then one row each."""
        rows = [["time_s", *self.names]]
        for row in self.last(n):
            rows.append([repr(row[0])] + [format_value(v) for v in row[1:]])
        return rows

    def to_csv(self, path_or_file: str | Path | IO[str]) -> None:
        """Write ``time_s,<names>`` and one row per sample.

        Bits are 0/1, integers in decimal, floats (REAL, speed, time) with
        ``repr`` precision, so reading the file back gives the same numbers.
        """
        if callable(getattr(path_or_file, "write", None)):
            self._write_csv(path_or_file)
            return
        path = check_path(path_or_file, "to_csv(): the file name")
        try:
            with open(path, "w", encoding="utf-8", newline="") as f:
                self._write_csv(f)
        except OSError as e:
            raise PlcConfigError(f"cannot write the trace to '{printable(str(path))[:80]}': "
                                 f"{e.strerror or type(e).__name__}") from None

    def _write_csv(self, f: IO[str]) -> None:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["time_s", *self.names])
        fmt = [repr if s.kind == "real" else str for s in self._signals]
        cols = [[float(v) if s.kind == "real" else v for v in c]
                for s, c in zip(self._signals, self._cols)]
        for k, t in enumerate(self._t_us):
            w.writerow([repr(t / 1e6)] + [f(c[k]) for f, c in zip(fmt, cols)])

    def __repr__(self) -> str:
        state = "recording" if self.attached else "detached"
        return f"<Trace {', '.join(self.names)}: {len(self)} sample(s), {state}>"


def format_value(value: int | float) -> str:
    """A value for people: integers as they are, floats with 7 significant
    digits (what a REAL holds)."""
    if isinstance(value, float):
        return f"{value:.7g}" if math.isfinite(value) else str(value)
    return str(value)


__all__ = ["AXIS_QUANTITIES", "Signal", "Trace", "format_value", "parse_signal"]
