"""A test harness around a loaded PLC: time control, stimuli, forcing, motion.

:class:`Harness` is what a unit test of a ladder program talks to, with or
without pytest (the pytest plugin only creates harnesses and reports on
them).  Everything runs in simulated time, so a test that waits "5 s" for a
condition costs only the scans it needs, and gives the same result on every
machine.

It is not a second engine: every scan is :meth:`plcrt.engine.Plc.scan`, and
every read and write goes through the PLC's memory image.  A harness has
every public method and property of :class:`~plcrt.engine.Plc` with the same
parameters (a test written against ``plcrt.load(...)`` runs unchanged on the
``plc`` fixture); methods that return nothing on the PLC return the harness
here, so calls chain.

This module holds the class with its loading, watching, time control and
waiting (with the failure messages of a wait), state and forking; the
class takes its stimuli from :mod:`plcrt.testing.stimuli` and its axes and
drives from :mod:`plcrt.testing.motion`.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ..devices import AxisState
from ..engine.runtime import Plc
from ..engine.values import Duration, duration_us, scan_number, shown_value, step_count
from ..engine.values import duration as parse_duration
from ..errors import PlcConfigError, PlcError, SourceLoc
from ..loader import load
from .conditions import Condition, Value, addresses_of, condition, quoted, reader
from .motion import Motion
from .stimuli import Stimuli


class PlcTimeout(AssertionError):
    """A condition was not met within its simulated-time limit.

    An ``AssertionError``, so pytest reports it as a test failure (with the
    PLC trace), not as an error in the test code.
    """


def seconds(d: Duration) -> float:
    """A duration in seconds from ``1.5``, ``"1.5s"``, ``"200ms"``, ``"2min"``
    (:func:`plcrt.engine.values.duration`, as ``Plc.run`` reads it)."""
    return parse_duration(d)


class Harness(Stimuli, Motion):
    """Drive one PLC from a test: run, stimulate, force, read, fork.

    Create it with :meth:`Harness.load` (or wrap an existing
    :class:`~plcrt.engine.Plc`).  ``watch`` names addresses whose values
    over the last ``history`` scans are kept for failure reports.
    """

    def __init__(self, plc: Plc, *, watch: Sequence[str] = (), history: int = 20,
                 name: str = "", max_time: Duration | None = None) -> None:
        if not isinstance(plc, Plc):
            raise PlcConfigError(f"Harness() wraps a plcrt.Plc (or use Harness.load(program, "
                                 f"...)), got {type(plc).__name__}")
        if isinstance(watch, str) or not isinstance(watch, (list, tuple)):
            raise PlcConfigError(f"watch is a list of addresses such as ['Q0.0', 'VW10'], "
                                 f"got {type(watch).__name__} {shown_value(watch)}")
        history = scan_number(history, "history (a number of scans)")
        self.plc = plc
        self.name = name or str(plc.program.file)
        self.history: deque[tuple[int, float, tuple[Value, ...]]] = deque(maxlen=max(1, history))
        self.watched: list[str] = []
        self._readers: list[Callable[[], Value]] = []
        self._recording = False
        #: harnesses made by :meth:`fork` (the pytest plugin reports on them too)
        self.forks: list[Harness] = []
        self.max_time: float | None = None
        self.watch(*watch)
        if max_time is not None:
            self.limit_time(max_time)

    def limit_time(self, max_time: Duration) -> Harness:
        """Fail (:class:`PlcTimeout`) as soon as the simulated time passes
        ``max_time`` (counted from power-up), whatever runs the scans: a
        per-test time limit, in simulated time, so a test that waits for
        something that never comes ends quickly and the same way everywhere."""
        limit_us = duration_us(max_time)
        if self.max_time is None:
            self.plc.observers.append(self._check_time)
        self.max_time = limit_us / 1e6
        self._limit_us = limit_us
        return self

    def _check_time(self, plc: Plc) -> None:
        if plc.now_us > self._limit_us:
            raise PlcTimeout(f"the test ran past its limit of {self.max_time:g} s of "
                             f"simulated time (max_time); at t = {plc.time:.3f} s, "
                             f"scan {plc.scans}")

    @classmethod
    def load(cls, program: str | Path | Sequence[str | Path], *, symbols: Any = None,
             data: Any = None, plant: Any = None, scan_ms: float = 10.0,
             cpu: str | None = None, watch: Sequence[str] = (), history: int = 20,
             instrument: bool = False, max_time: Duration | None = None,
             encoding: str | None = None, clock: Any = None,
             backend: str | None = None) -> Harness:
        """Load a program (paths, STL text, or an already parsed
        :class:`plcrt.lang.ir.Program`) and wrap it.

        ``instrument=True`` compiles the network-coverage and breakpoint
        probes in (slightly slower scans).  ``max_time`` limits the simulated
        time (see :meth:`limit_time`).  ``encoding`` is the text encoding of
        the files (detected by default, as in :func:`plcrt.load`);
        ``clock`` the real-time clock's start (as in :func:`plcrt.load`);
        ``backend`` the code generator (``"auto"``, ``"python"`` or
        ``"native"``, as in :func:`plcrt.load`; default ``$PLCRT_BACKEND``,
        else auto: native where llvmlite works).
        """
        from ..lang import ir

        def path(x: Any) -> Any:   # a one-line string names a file ("" is refused by load)
            return Path(x) if isinstance(x, str) and x.strip() and "\n" not in x else x

        symbols, data, plant = path(symbols), path(data), path(plant)
        if isinstance(program, ir.Program):
            # already parsed (the pytest plugin parses each file once per
            # session and compiles it per test)
            plc = _plc_from_parsed(program, symbols=symbols, data=data, plant=plant,
                                   scan_ms=scan_ms, cpu=cpu, instrument=instrument,
                                   encoding=encoding, clock=clock, backend=backend)
            return cls(plc, watch=watch, history=history, max_time=max_time)
        program = path(program)
        plc = load(program, symbols=symbols, data=data, plant=plant,
                   scan_ms=scan_ms, cpu=cpu, instrument=instrument, encoding=encoding,
                   clock=clock, backend=backend)
        return cls(plc, watch=watch, history=history, max_time=max_time)

    def __repr__(self) -> str:
        return (f"<Harness {Path(self.name).name} t={self.time:.3f} s "
                f"scan {self.scans} {self.plc.mode}>")

    # -- watching ---------------------------------------------------------
    def watch(self, *addresses: str) -> Harness:
        """Add addresses to the per-scan history (``VD4:REAL`` reads a float)."""
        for a in addresses:
            if a in self.watched:
                continue
            self._readers.append(reader(self.plc, a))
            self.watched.append(a)
        if self.watched and not self._recording:
            self.plc.observers.append(self._record)
            self._recording = True
        return self

    def _record(self, plc: Plc) -> None:
        self.history.append((plc.scans, plc.time, tuple(r() for r in self._readers)))

    def history_rows(self, n: int | None = None) -> list[tuple[int, float, tuple[Value, ...]]]:
        """The last ``n`` recorded scans (all with None): (scan number, time
        after it, values)."""
        rows = list(self.history)
        if n is None:
            return rows
        n = scan_number(n, "the number of rows")
        return rows[len(rows) - n:] if n < len(rows) else rows

    def history_table(self, n: int | None = None) -> str:
        """The watched values over the last scans as a plain text table."""
        rows = self.history_rows(n)
        if not self.watched:
            return "(no addresses watched)"
        head = ["scan", "t [s]"] + self.watched
        body = [[str(s), f"{t:.3f}"] + [_fmt(v) for v in vals] for s, t, vals in rows]
        if not body:
            return "(no scan recorded yet)"
        widths = [max(len(r[i]) for r in [head] + body) for i in range(len(head))]
        line = lambda cells: "  ".join(c.rjust(w) for c, w in zip(cells, widths))  # noqa: E731
        out = [line(head), line(["-" * w for w in widths])]
        out += [line(r) for r in body]
        return "\n".join(out)

    # -- time -------------------------------------------------------------
    @property
    def time(self) -> float:
        """Simulated time in seconds."""
        return self.plc.time

    @property
    def now_us(self) -> int:
        """Simulated time in µs (as :attr:`Plc.now_us`)."""
        return self.plc.now_us

    @property
    def scans(self) -> int:
        """Scans run since power-up."""
        return self.plc.scans

    def scan(self, n: int = 1) -> Harness:
        """Run ``n`` scans (a non-negative int)."""
        self.plc.scan(n)
        return self

    def run(self, seconds: Duration | None = None, scans: int | None = None) -> Harness:
        """Run for a simulated duration (``2``, ``"1.5s"``, ``"200ms"``,
        ``seconds=1.5``) or a number of ``scans``, as :meth:`Plc.run`."""
        self.plc.run(seconds, scans)
        return self

    def _scans_for(self, d: Duration, what: str = "") -> int:
        return step_count(duration_us(d, what), self.plc.scan_us, d, what)

    def run_until(self, cond: Condition, *, timeout: Duration = 10.0,
                  message: str = "") -> float:
        """Scan until ``cond`` holds after a scan; return the simulated seconds
        that took.  Fails with :class:`PlcTimeout` when ``timeout`` (simulated)
        passes first, or the CPU goes to STOP."""
        __tracebackhide__ = True  # pytest: report the test's line, not ours
        _check_message(message)
        pred, what = condition(self, cond)
        t0 = self.plc.now_us
        limit = self._scans_for(timeout, "timeout")
        plc = self.plc
        for _ in range(limit):
            plc.scan(1)
            if plc.mode != "RUN":
                self._timeout(f"the CPU went to STOP before {quoted(what)} became true",
                              message, cond)
            if self._check(pred, what):
                return (plc.now_us - t0) / 1e6
        self._timeout(f"{quoted(what)} did not become true within {seconds(timeout):g} s of "
                      f"simulated time ({limit} scans)", message, cond)
        raise AssertionError  # pragma: no cover - _timeout raises

    def run_while(self, cond: Condition, *, timeout: Duration = 10.0, message: str = "") -> float:
        """Scan while ``cond`` holds (the opposite of :meth:`run_until`)."""
        __tracebackhide__ = True  # pytest: report the test's line, not ours
        pred, what = condition(self, cond)
        t0 = self.plc.now_us
        limit = self._scans_for(timeout)
        plc = self.plc
        for _ in range(limit):
            plc.scan(1)
            if plc.mode != "RUN":
                self._timeout(f"the CPU went to STOP while {quoted(what)} was still true",
                              message, cond)
            if not self._check(pred, what):
                return (plc.now_us - t0) / 1e6
        self._timeout(f"{quoted(what)} stayed true for the whole {seconds(timeout):g} s "
                      f"of simulated time ({limit} scans)", message, cond)
        raise AssertionError  # pragma: no cover - _timeout raises

    def stays(self, cond: Condition, duration: Duration, *, message: str = "") -> Harness:
        """Run for ``duration`` and fail at the first scan where ``cond`` is false."""
        __tracebackhide__ = True  # pytest: report the test's line, not ours
        _check_message(message)
        pred, what = condition(self, cond)
        plc = self.plc
        t0 = plc.time
        expected = (f"expected {quoted(what)} to stay true for {seconds(duration):g} s "
                    f"from t = {t0:.3f} s")
        for _ in range(self._scans_for(duration, "duration")):
            plc.scan(1)
            if plc.mode != "RUN":
                # time stands still in STOP: the duration would never pass
                self._timeout(f"{expected}; the CPU went to STOP before {seconds(duration):g} s "
                              f"had passed, so it was not seen to stay true", message, cond,
                              exc=AssertionError)
            if not self._check(pred, what):
                self._timeout(f"{expected}; it became false {plc.time - t0:.3f} s later",
                              message, cond, exc=AssertionError)
        return self

    def _check(self, pred: Callable[[], bool], what: str) -> bool:
        """``pred()``; an exception of a condition function propagates with
        a note saying when it was checked (the scans before it have run)."""
        try:
            return pred()
        except Exception as e:
            if hasattr(e, "add_note"):
                e.add_note(f"while checking the condition {quoted(what)} after scan "
                           f"{self.scans} (t = {self.time:.3f} s)")
            raise

    def _timeout(self, text: str, message: str, cond: Condition | None = None,
                 exc: type[AssertionError] = PlcTimeout, shown: Sequence[str] = ()) -> None:
        """Raise ``exc``: the test's message, what was expected and what
        happened (*text*), when, and the values of the condition's address,
        of *shown* and of the watched addresses at that moment."""
        __tracebackhide__ = True  # pytest: report the test's line, not ours
        parts = [message, text] if message else [text]
        parts.append(f"at t = {self.time:.3f} s, scan {self.scans}")
        values = self._values_now([*addresses_of(cond), *shown, *self.watched])
        if values:
            parts.append(values)
        raise exc("; ".join(parts))

    def _values_now(self, specs: Sequence[str]) -> str:
        """``"VW100 = 3, Q0.0 = 0"`` for the addresses and signals *specs*
        (each once, in order; one that cannot be read is left out)."""
        shown = []
        for spec in dict.fromkeys(specs):
            try:
                shown.append(f"{spec} = {_fmt(reader(self.plc, spec)())}")
            except PlcError:
                continue
        return ", ".join(shown)
    # -- state ------------------------------------------------------------
    def snapshot(self) -> Plc:
        """The whole PLC state now (memory, timers, devices, time)."""
        return self.plc.snapshot()

    def restore(self, snapshot: Plc) -> Harness:
        """Go back to a :meth:`snapshot`."""
        self.plc.restore(snapshot)
        return self

    def fork(self) -> Harness:
        """An independent copy in the same state (e.g. after a long warm-up)."""
        return self._twin(self.plc.fork())

    def recompiled(self, *, instrument: bool | None = None,
                   backend: str | None = None) -> Harness:
        """A copy in the same state, its program compiled with other probes
        or another backend (:meth:`plcrt.Plc.recompiled`): e.g. warm up on
        the native backend, then look at coverage from there on."""
        return self._twin(self.plc.recompiled(instrument=instrument, backend=backend))

    def _twin(self, plc: Plc) -> Harness:
        """A harness of ``plc``, a copy of this one's PLC: the same watch
        list, history, name and time limit, reported with this one's."""
        h = Harness(plc, watch=self.watched, history=self.history.maxlen or 20,
                    name=self.name, max_time=self.max_time)
        h.history.extend(self.history)
        self.forks.append(h)
        return h

    # -- results ----------------------------------------------------------
    @property
    def backend(self) -> dict[str, Any]:
        """How the program runs (:attr:`plcrt.Plc.backend`): Python, or
        which pieces run as machine code on the native backend."""
        return self.plc.backend

    @property
    def diagnostics(self) -> list[Any]:
        """Compile-time and run-time diagnostics so far."""
        return list(self.plc.diagnostics)

    def warnings(self, contains: str = "") -> list[str]:
        """Messages of the warnings so far (optionally containing a text)."""
        if not isinstance(contains, str):
            raise PlcConfigError(f"warnings(contains=...) takes a str, got "
                                 f"{type(contains).__name__}")
        return [d.message for d in self.plc.diagnostics
                if d.severity == "warning" and contains in d.message]

    @property
    def coverage(self) -> Any:
        """Network/output coverage (``instrument=True`` only, else None)."""
        return self.plc.coverage

    # -- the rest of the Plc interface, delegated -----------------------------
    @property
    def mode(self) -> str:
        """``"RUN"`` or ``"STOP"``."""
        return self.plc.mode

    @property
    def fault(self) -> PlcError | None:
        """The fault that put the CPU in STOP, if any."""
        return self.plc.fault

    @property
    def source(self) -> str:
        """The generated Python."""
        return self.plc.source

    @property
    def compiled(self) -> Any:
        """The compiled program (:attr:`plcrt.Plc.compiled`: shared,
        picklable; ``Plc.from_program`` builds another PLC of it)."""
        return self.plc.compiled

    @property
    def program(self) -> Any:
        """The parsed program (:class:`plcrt.lang.ir.Program`)."""
        return self.plc.program

    @property
    def symbols(self) -> Any:
        """The symbol table, or None."""
        return self.plc.symbols

    @property
    def forces(self) -> dict[str, int | float]:
        """Forced addresses and their values."""
        return self.plc.forces

    def locate(self, spec: str) -> tuple[bytearray, int, int, int, str]:
        """Where an address spec lives (see :meth:`Plc.locate`)."""
        return self.plc.locate(spec)

    def reader(self, spec: str) -> tuple[str, Callable[[], int | float]]:
        """``(kind, read)`` of an address spec (see :meth:`Plc.reader`)."""
        return self.plc.reader(spec)

    @property
    def stop_requested(self) -> bool:
        """A STOP instruction (or :meth:`request_stop`) ran: the CPU goes to
        STOP at the end of the scan."""
        return self.plc.stop_requested

    def request_stop(self) -> Harness:
        """Go to STOP at the end of the next scan, as the STOP instruction."""
        self.plc.request_stop()
        return self

    def set_mode(self, mode: str) -> Harness:
        """Switch the CPU to ``"RUN"`` or ``"STOP"`` now, as the mode switch
        or a programming device does (:meth:`Plc.set_mode`): RUN from STOP
        makes the next scan a first scan."""
        self.plc.set_mode(mode)
        return self

    def power_cycle(self, *, retentive_lost: bool = False) -> Harness:
        """Switch the CPU off and on (:meth:`Plc.power_cycle`): the retentive
        ranges keep their values, the rest is cleared, V outside them comes
        back from the data block, the CPU starts in its start-up mode."""
        self.plc.power_cycle(retentive_lost=retentive_lost)
        return self

    def warn(self, message: str, loc: SourceLoc | None, key: str) -> Harness:
        """Add a run-time warning (reported once per ``key``), as :meth:`Plc.warn`."""
        self.plc.warn(message, loc, key)
        return self

    def trace(self, *signals: str, every: int = 1, limit: int | None = None) -> Any:
        """Start recording ``signals`` (addresses, ``VD4:REAL``, ``T37:BIT``,
        ``axis0.0.speed``) once per scan from now on; returns the
        :class:`plcrt.trace.Trace`, whose arrays are numpy (``tr["Q0.0"]``,
        ``tr.time``).  ``tr.detach()`` stops it."""
        from ..trace import Trace
        return Trace(self.plc, list(signals), every=every, limit=limit)


def _plc_from_parsed(program: Any, *, symbols: Any, data: Any, plant: Any, scan_ms: float,
                     cpu: str | None, instrument: bool, encoding: str | None = None,
                     clock: Any = None, backend: str | None = None) -> Plc:
    """:func:`plcrt.load` for a program that is already parsed: the same
    handling of the symbol table, data block and plant arguments (the tables
    are decoded alone here; :func:`plcrt.lang.sources.read_program` decodes
    them together with the program)."""
    from ..engine.runtime import _text_or_path
    from ..lang import parse_datablock, parse_symbols
    from ..lang.codepage import string_codepage
    from ..lang.encoding import resolve_encoding
    encoding = resolve_encoding(encoding)
    if isinstance(plant, (str, Path, dict)):
        from ..devices.plant import load_plant
        plant = load_plant(plant)
    if isinstance(symbols, (str, Path)):
        symbols = parse_symbols(*_text_or_path(symbols, encoding))
    if isinstance(data, (str, Path)):
        data = parse_datablock(*_text_or_path(data, encoding),
                               codepage=string_codepage(encoding or ""))
    return Plc(program, symbols=symbols, data=data, scan_ms=scan_ms, cpu=cpu, plant=plant,
               instrument=instrument, clock=clock, backend=backend)


def _check_message(message: Any) -> None:
    if not isinstance(message, str):
        raise PlcConfigError(f"message= is the text a failure starts with, a str; got "
                             f"{type(message).__name__}")



def _fmt(v: Value) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


__all__ = ["AxisState", "Harness", "PlcTimeout", "condition", "reader", "seconds"]
