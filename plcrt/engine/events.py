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

_NEVER = 1 << 62    #: "no limit" for a source's next event


class EventSource(Protocol):
    """Something that has events at exact times."""

    def live(self) -> bool:
        """Whether it may have events at all (cheap; the others are skipped)."""

    def next_time(self, after: int, until: int) -> Optional[int]:
        """The time (µs) of the first event in (*after*, *until*], or None."""

    def fire(self, t: int) -> Optional[int]:
        """Handle the events due at *t* (the devices are at *t*); it may
        return its next event's time (after *t*) when it knows it without
        being asked, else None."""


class Scheduler:
    """The sources and devices of one PLC, run in time order."""

    def __init__(self, plc: Any, sources: list[EventSource],
                 after: Any = None) -> None:
        self.plc = plc
        self.sources = sources
        #: called once after the events of one instant fired (the interrupt
        #: system runs the routines they posted)
        self.after = after
        #: bumped by whatever may move a source's next event (an instruction
        #: such as PLS, HSC or ATCH; the end of a pulse train)
        self.gen = 0
        self._rows: list[list[Any]] = []
        #: (row, second, gen): the row due alone next when the last run
        #: ended, the earliest other row's time, and the gen they hold for
        self._carry: Optional[tuple[list[Any], int, int]] = None

    def _make_rows(self) -> list[list[Any]]:
        return [[src, -1, None, src.cacheable, getattr(src, "moves_others", False)]
                for src in self.sources]

    def add(self, source: EventSource) -> None:
        """A new source (an HDEF'd counter on a pulse output), lowest priority."""
        self.sources.append(source)
        self._rows = []
        self._carry = None

    def reset(self, sources: list[EventSource]) -> None:
        """Replace the sources (a forked PLC's own)."""
        self.sources[:] = sources
        self._rows = []
        self._carry = None

    def touch(self) -> None:
        """A source's next event may have moved: ask them all again."""
        self.gen += 1

    def run(self, t_from: int, t_to: int, first: bool = True) -> None:
        """Run (t_from, t_to]: events in time order, devices advanced to each.
        *first*: t_from is the scan's start (a linked network runs a scan in
        pieces; the events at a later piece's t_from fired in the piece
        before)."""
        plc, devices, on_instant = self.plc, self.plc.devices, self.after
        t = t_from
        # perf: a source's next event is asked once and kept until it fires
        # or something touches the sources: one [source, gen, time, cacheable,
        # moves others] row each, kept between scans
        rows = self._rows
        if not rows:
            rows = self._rows = self._make_rows()
        # events that the program itself caused at the scan's instant (a
        # pulse train started by PLS reaching a counter's PV at once) are
        # asked for from just before it
        after = t_from - 1 if first else t_from
        quick: Any = None      # a row known to be due alone next (see below)
        second = _NEVER
        carry = self._carry
        if carry is not None and carry[2] == self.gen and rows is self._rows:
            # perf: the last run's end already knew the row due next
            quick, second, _ = carry
            volatile = False
        self._carry = None
        while True:
            gen = self.gen
            if quick is not None:
                # perf: the row that fired alone knows its next event, nothing
                # touched the sources and every row is cacheable: the scan
                # below would find it due alone, before *second*
                due, best, ties = quick, quick[2], None
            else:
                best = second = _NEVER
                due = None                 # the row due first
                ties = None                # all rows due, when several are
                volatile = False           # a row that must be asked each time
                for row in rows:           # in priority order: ties fire in this order
                    if row[1] != gen or not row[3]:
                        src = row[0]
                        row[2] = src.next_time(after, _NEVER) if src.live() else None
                        row[1], row[3] = gen, src.cacheable
                        volatile = volatile or not row[3]
                    te = row[2]
                    if te is None:
                        continue
                    if te > best:
                        if te < second:
                            second = te
                    elif te < best:
                        second, best, due, ties = best, te, row, None
                    elif ties is None:
                        ties = [due, row]
                    else:
                        ties.append(row)
            if best > t_to:
                if ties is None and due is not None and not volatile:
                    self._carry = (due, second, gen)
                break
            if best > t:
                for dev in devices:
                    dev.step(plc, t, best)
                t = best
            quick = None
            # perf: one row due is the common case (a one-item tuple, no list)
            for row in (ties or (due,)):
                # a source may answer with its next event (kept like an
                # asked one); None: asked again at the next instant
                nxt = row[0].fire(best)
                if nxt is None:
                    row[1] = -1
                else:
                    row[2] = nxt
                if row[4]:
                    self.gen += 1      # e.g. a train ended: a counter on it moves too
            if on_instant is not None:
                on_instant(best)
            after = best
            if rows is not self._rows:   # HDEF in a routine added a counter
                rows = self._rows = self._make_rows()
            elif (ties is None and nxt is not None and nxt < second and not volatile
                  and self.gen == gen and due[1] == gen):
                quick = due
        if t < t_to:
            for dev in devices:
                dev.step(plc, t, t_to)
