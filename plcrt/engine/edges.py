"""Edge interrupts of I0.0–I0.3 from signals the plant drives at exact times.

What it is: :class:`SignalEdges`, an event source of the scan's time line
(:mod:`plcrt.engine.events`).  An input wired to a pulse output in the plant
(``[cpu] wire = { "I0.0" = "Q0.0" }``) or driven by an encoder
(``[[cpu.encoder]]``) changes between the scan starts, at times known in
closed form; when its edge event (0–7) is attached, every rising or falling
edge runs the routine at its own µs:

* a PTO pulse rises at the train's pulse times and falls half a cycle later
  (50 % duty, the first half high; :mod:`plcrt.engine.pulse`);
* an encoder's A signal rises at start + k/hz and falls half a period later;
  B lags A by a quarter period (leads it when the direction is down);
* a device that lists the input in ``edge_bits`` (a machine's sensor or
  button, :mod:`plcrt.devices.machines`) answers ``input_edge_after(bit,
  after, rising)`` itself; its edges move with the program's outputs, so
  the source is then asked again at every instant (not cacheable).

What it is not: inputs that change only between scans (``--set``, the
harness, ordinary outputs wired to inputs) have their edges at the scan
start (:meth:`plcrt.engine.interrupts.Interrupts.edges`).
"""

from __future__ import annotations

from typing import Any, Optional

from .interrupts import EDGES

__all__ = ["SignalEdges"]


def _ceil_div(a: int, b: int) -> int:
    return -(-a // b)


class SignalEdges:
    """The exactly timed edges of I0.0–I0.3 (events 0–7)."""

    #: its next edge moves only by ATCH/DTCH, PLS or a train's end, which all
    #: touch the scheduler, or by its own events
    cacheable = True

    def __init__(self, plc: Any) -> None:
        self.plc = plc
        #: False while a device drives an attached input (see the module docstring)
        self.cacheable = True
        self.last: Optional[int] = None           #: the time of the last edge fired
        self._version = -1                        #: the interrupts' version _inputs is for
        self._inputs: list[tuple[int, int, int, Any, int]] = []

    def _driven(self) -> list[tuple[int, int, int, Any, int]]:
        """(bit, rise event, fall event, source, phase) of attached edge inputs
        driven by a signal: source a pulse output or an encoder; phase the
        encoder quarter period (0 for A, 1 or 3 for B)."""
        irq = self.plc.interrupts
        # perf: derived again only when ATCH/DTCH changed what is attached
        # (the wiring and the encoders are fixed when the PLC is built)
        if irq.version != self._version:
            self._inputs = self._derive()
            self._version = irq.version
        return self._inputs

    def _derive(self) -> list[tuple[int, int, int, Any, int]]:
        plc, attached = self.plc, self.plc.interrupts.attached
        out = []
        for bit, (rise, fall) in EDGES.items():
            if rise not in attached and fall not in attached:
                continue
            out_bit = plc.wiring.get(bit)
            if out_bit in (0, 1):
                out.append((bit, rise, fall, plc.pulse[out_bit], 0))
                continue
            for enc in plc.encoders.values():
                if enc.a == bit:
                    out.append((bit, rise, fall, enc, 0))
                elif enc.b == bit:
                    out.append((bit, rise, fall, enc, 1 if enc.direction > 0 else 3))
            for dev in plc.devices:
                if bit in getattr(dev, "edge_bits", ()):
                    out.append((bit, rise, fall, dev, bit))    # the phase slot holds the bit
        self.cacheable = not any(hasattr(src, "input_edge_after") for *_, src, _p in out)
        return out

    def live(self) -> bool:
        return bool(self._driven())

    def _next_edges(self, after: int) -> list[tuple[int, int]]:
        """(time, event) of each driven input's first edge after *after*."""
        out = []
        attached = self.plc.interrupts.attached
        for _bit, rise, fall, src, phase in self._driven():
            for event, rising in ((rise, True), (fall, False)):
                if event in attached:
                    te = self._edge(src, phase, after, rising)
                    if te is not None:
                        out.append((te, event))
        return out

    @staticmethod
    def _edge(src: Any, phase: int, after: int, rising: bool) -> Optional[int]:
        if hasattr(src, "input_edge_after"):      # a device's input (phase: the bit)
            return src.input_edge_after(phase, after, rising)
        if hasattr(src, "hz"):                    # an encoder
            if src.stop is not None and after >= src.stop:
                return None
            quarter = 4 * src.hz                  # quarter periods per second
            # the signal's edges: rising at quarter 4k + phase, falling at 4k + phase + 2
            offset = phase + (0 if rising else 2)
            since = max(after - src.start + 1, 0)  # first µs of interest, from start
            q = _ceil_div(since * quarter, 1_000_000)      # first quarter at or after it
            k = _ceil_div(q - offset, 4) if q > offset else 0
            te = src.start + _ceil_div((4 * k + offset) * 1_000_000, quarter)
            while te <= after:
                k += 1
                te = src.start + _ceil_div((4 * k + offset) * 1_000_000, quarter)
            return te if src.stop is None or te <= src.stop else None
        return src.edge_after(after, rising)      # a pulse output

    def next_time(self, after: int, until: int) -> Optional[int]:
        if self.last is not None and after < self.last:
            after = self.last
        times = [te for te, _ in self._next_edges(after) if te <= until]
        return min(times) if times else None

    def fire(self, t: int) -> None:
        for te, event in sorted(self._next_edges(t - 1)):
            if te == t:
                self.plc.interrupts.post(event, t)
        self.last = t
