"""Stimuli of the test harness: reading, writing, forcing, patches and
stimulus tables.

What it is: the methods of :class:`plcrt.testing.Harness` that put values
into the PLC (``h["I0.0"] = 1``, :meth:`~Stimuli.set`,
:meth:`~Stimuli.patch`, :meth:`~Stimuli.pulse`, :meth:`~Stimuli.force`,
:meth:`~Stimuli.forced`, a time-ordered :meth:`~Stimuli.stimulus` table)
and read them back, each through the PLC's memory image.  What it is not:
the harness itself (:mod:`plcrt.testing.harness` combines this mixin with
its time control, which the stimulus table runs on).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, Self

from ..engine.values import Duration, check_address, duration_us, scan_number, shown_value
from ..errors import PlcAddressError, PlcConfigError, PlcError
from .conditions import Value

if TYPE_CHECKING:
    from ..engine.runtime import Plc


class Stimuli:
    """Reading, writing and forcing addresses; patches and stimulus tables
    (a mixin of :class:`plcrt.testing.Harness`)."""

    plc: Plc
    # provided by the harness (plcrt.testing.harness)
    scan: Callable[[int], Any]
    _scans_for: Callable[..., int]

    def __getitem__(self, address: str) -> Value:
        return self.read(address)

    def __setitem__(self, address: str, value: Value) -> None:
        self.write(address, value)

    def read(self, address: str, kind: str | None = None) -> Value:
        """Read an address or symbol (``kind`` "REAL" or "BIT"; or ``VD4:REAL``)."""
        return self.plc.read(address, kind)

    def write(self, address: str, value: Value) -> None:
        """Write an address or symbol; an input keeps its value (a switch left on)."""
        self.plc.write(address, value)

    def set(self, values: Mapping[str, Value]) -> Self:
        """Write several addresses at once (they hold until changed)."""
        for a, v in _mapping(values, "set").items():
            self.write(a, v)
        return self

    def values(self, *addresses: str) -> dict[str, Value]:
        """Several addresses at once, as a dict."""
        return {a: self.read(a) for a in addresses}

    def patch(self, values: Mapping[str, Value], scans: int = 1) -> Self:
        """Hold values for ``scans`` scans (default one), then put the old
        values back: a push button pressed for exactly one scan."""
        values = _mapping(values, "patch")
        scan_number(scans, "scans")
        for a, v in values.items():
            self.plc._writable(a, v)   # all checked before any is written
        old = {a: self.read(a) for a in values}
        for a, v in values.items():
            self.write(a, v)
        self.scan(scans)
        for a, v in old.items():
            self.write(a, v)
        return self

    def pulse(self, address: str, scans: int = 1, value: Value = 1) -> Self:
        """Set ``address`` to ``value`` for ``scans`` scans, then back."""
        return self.patch({check_address(address): value}, scans)

    def force(self, address: str, value: Value) -> _Forced:
        """Force an address until :meth:`unforce` (or the end of a ``with``).

        Returns an object that is also a context manager:
        ``with h.force("I0.1", 0): ...`` releases the force at the end."""
        self.plc.force(address, value)
        return _Forced(self, [address])

    @contextmanager
    def forced(self, values: Mapping[str, Value]) -> Iterator[Self]:
        """``with h.forced({"I0.1": 0, "VW10": 5}):`` forces inside the block only."""
        values = _mapping(values, "forced")
        for a, v in values.items():
            self.plc._writable(a, v)   # all checked before any is forced
        for a, v in values.items():
            self.plc.force(a, v)
        try:
            yield self
        finally:
            _release(self.plc, values)

    def unforce(self, address: str | None = None) -> Self:
        """Release one force (by the symbol or the address: a force belongs
        to the memory location), or all of them."""
        self.plc.unforce(address)
        return self

    def stimulus(self, table: Iterable[tuple[Duration, str, Value]], *,
                 until: Duration | None = None) -> Self:
        """Play a time-ordered table of ``(time, address, value)`` rows.

        Times count from now.  A row takes effect before the first scan that
        starts at or after its time (scans are the only moments a PLC reads
        its inputs).  After the last row the PLC runs on to ``until`` if it
        is given.
        """
        if not isinstance(table, Iterable) or isinstance(table, (str, bytes, Mapping)):
            raise PlcConfigError(f"a stimulus is a list of (time, address, value) rows, got "
                                 f"{type(table).__name__}")
        rows = []
        for i, row in enumerate(table):
            try:
                t, addr, value = row
            except (TypeError, ValueError):
                raise PlcConfigError(f"stimulus row {i + 1}: expected (time, address, value), "
                                     f"got {shown_value(row)}") from None
            try:
                t_us = duration_us(t)
                self._scans_for(t)   # a time no run can reach is refused up front
            except PlcConfigError as e:
                raise PlcConfigError(f"stimulus row {i + 1} {shown_value(row)}: "
                                     f"{e.message}") from None
            try:   # every row is checked before the first scan runs
                self.plc._writable(addr, value)
            except PlcError as e:
                raise type(e)(f"stimulus row {i + 1} {shown_value(row)}: {e.message}") from None
            rows.append((t_us, i, addr, value))
        if until is not None:
            self._scans_for(until, "until")
        rows.sort()
        plc = self.plc
        t0 = plc.now_us
        for t_us, _, addr, value in rows:
            while plc.now_us < t0 + t_us and plc.mode == "RUN":
                plc.scan(1)
            self.write(addr, value)
        if until is not None:
            end = t0 + duration_us(until, "until")
            while plc.now_us < end and plc.mode == "RUN":
                plc.scan(1)
        return self


class _Forced:
    """The result of :meth:`Harness.force`: persistent, or a context manager."""

    def __init__(self, h: Stimuli, addresses: list[str]) -> None:
        self._h = h
        self._addresses = addresses

    def __enter__(self) -> Stimuli:
        return self._h

    def __exit__(self, *exc: Any) -> None:
        _release(self._h.plc, self._addresses)


def _release(plc: Plc, addresses: Iterable[str]) -> None:
    """Release the forces of ``addresses`` that are still forced (by the
    same location: a force re-made under another name counts too)."""
    for a in addresses:
        try:
            plc.unforce(a)
        except PlcAddressError:
            pass   # released inside the block already


def _mapping(values: Any, method: str) -> Mapping[str, Any]:
    if not isinstance(values, Mapping):
        raise PlcConfigError(f"{method}() takes a dict of address -> value, got "
                             f"{type(values).__name__}")
    return values


__all__ = ["Stimuli"]
