"""One time line for everything that happens between two scan starts.

What it is: :class:`Scheduler`, which runs the scan interval (t0, t1] in
time order.  Every *event source* (the timed interrupts today; the CPU's
high-speed counters, pulse outputs and ports as they come) says when its
next event is; the scheduler takes the earliest, advances every *device*
(EM253 modules, the fieldbus module and its drives) to that time, and lets
the source fire it (post an interrupt event, run the routines).  When no
source has an event left, the devices run on to t1::

    t0 ── OB1 ──┬──────────┬──────────────┬────────── t1
                │ devices  │ devices      │ devices
                ▼ to te1   ▼ to te2       ▼ to t1
             fire(te1)  fire(te2)

Devices keep their own exact event engines inside each step (a move's end,
a limit switch, a bus cycle); they are stepped over sub-intervals that join
exactly, so their results do not depend on where the interval is cut.

What it is not: it runs no program code itself; a source's ``fire`` does
(the interrupt system runs the routines).
"""

from __future__ import annotations

from typing import Any, Optional, Protocol

__all__ = ["EventSource", "Scheduler"]


class EventSource(Protocol):
    """Something that has events at exact times."""

    def live(self) -> bool:
        """Whether it may have events at all (cheap; the others are skipped)."""

    def next_time(self, after: int, until: int) -> Optional[int]:
        """The time (µs) of the first event in (*after*, *until*], or None."""

    def fire(self, t: int) -> None:
        """Handle the events due at *t* (the devices are at *t*)."""


class Scheduler:
    """The sources and devices of one PLC, run in time order."""

    def __init__(self, plc: Any, sources: list[EventSource],
                 after: Any = None) -> None:
        self.plc = plc
        self.sources = sources
        #: called once after the events of one instant fired (the interrupt
        #: system runs the routines they posted)
        self.after = after

    def busy(self, t_from: int, t_to: int) -> bool:
        """Whether a source has an event in (t_from, t_to]."""
        return any(src.next_time(t_from, t_to) is not None for src in self.sources)

    def run(self, t_from: int, t_to: int) -> None:
        """Run (t_from, t_to]: events in time order, devices advanced to each."""
        plc, devices = self.plc, self.plc.devices
        t = t_from
        while True:
            # perf: only the live sources are asked (a routine may wake others)
            live = [src for src in self.sources if src.live()]
            best: Optional[int] = None
            due: list[Any] = []
            for src in live:        # in priority order: ties fire in this order
                te = src.next_time(t, t_to)
                if te is None:
                    continue
                if best is None or te < best:
                    best, due = te, [src]
                elif te == best:
                    due.append(src)
            if best is None:
                break
            for dev in devices:
                dev.step(plc, t, best)
            for src in due:
                src.fire(best)
            if self.after is not None:
                self.after(best)
            t = best
        if t < t_to:
            for dev in devices:
                dev.step(plc, t, t_to)
