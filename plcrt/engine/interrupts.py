"""Interrupts of the CPU: events, their routines, priorities and queues.

What it is: :class:`Interrupts`, the S7-200's interrupt system (System
Manual, "Interrupt instructions" and "Understanding the interrupt routine
instructions", table of interrupt events):

* ``ATCH INT, EVNT`` attaches a routine to an event and enables the event;
  ``DTCH EVNT`` disables it (its occurrences are then ignored);
  ``CEVNT EVNT`` (SMART) clears its queued occurrences.
* ``ENI`` enables interrupt processing, ``DISI`` disables it; in RUN the
  CPU starts with interrupts disabled.  While disabled, occurrences of
  attached events are queued.
* Three priority groups, highest first: communications, discrete (I/O:
  input edges, HSC, PTO complete), timed.  Within a group occurrences run in
  the order they happened.  Each group's queue holds 4 / 16 / 8
  occurrences; one more is lost and sets SM4.0 / SM4.1 / SM4.2, which the
  CPU clears when the queues are empty and the main program continues.
* A routine runs to its end and is never interrupted by another one; the
  CPU saves and restores the accumulators and the status bits SMB1 around
  it, so the main program does not see them change.
* Timed interrupts 0 and 1 (events 10, 11): the interval in ms is read
  from SMB34 / SMB35 when the event is attached, and timing starts then;
  attaching again restarts it.

When routines run (plcrt's time model, docs/decisions.md "Interrupts"): the
main program runs at the scan's start instant; every occurrence inside the
scan interval runs its routine at its own exact time, after the main
program and before the next scan, with the devices advanced to that time.
Occurrences at the scan's start (input edges from the outside world) run
before the main program reads the inputs.  ``ENI`` runs what is queued at
the point of the ``ENI``.

What it is not: no instructions (see :mod:`plcrt.isa.interrupts`), no
high-speed counters or pulse outputs (they post their events here).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Any, Callable, Optional

__all__ = ["Interrupts", "EVENTS", "GROUPS", "Event"]


@dataclass(frozen=True, slots=True)
class Event:
    """One interrupt event of the event table."""

    number: int
    name: str
    group: int          #: 0 communications, 1 discrete, 2 timed (priority order)


#: The S7-200 interrupt events (System Manual, table "Interrupt events",
#: reference digest §4.2), by number.
EVENTS: dict[int, Event] = {e.number: e for e in (
    Event(8, "port 0 receive character", 0), Event(9, "port 0 transmit complete", 0),
    Event(23, "port 0 receive message complete", 0),
    Event(24, "port 1 receive message complete", 0),
    Event(25, "port 1 receive character", 0), Event(26, "port 1 transmit complete", 0),
    Event(0, "I0.0 rising edge", 1), Event(1, "I0.0 falling edge", 1),
    Event(2, "I0.1 rising edge", 1), Event(3, "I0.1 falling edge", 1),
    Event(4, "I0.2 rising edge", 1), Event(5, "I0.2 falling edge", 1),
    Event(6, "I0.3 rising edge", 1), Event(7, "I0.3 falling edge", 1),
    Event(19, "PLS0 PTO complete", 1), Event(20, "PLS1 PTO complete", 1),
    Event(12, "HSC0 CV=PV", 1), Event(27, "HSC0 direction changed", 1),
    Event(28, "HSC0 external reset", 1),
    Event(13, "HSC1 CV=PV", 1), Event(14, "HSC1 direction changed", 1),
    Event(15, "HSC1 external reset", 1),
    Event(16, "HSC2 CV=PV", 1), Event(17, "HSC2 direction changed", 1),
    Event(18, "HSC2 external reset", 1),
    Event(32, "HSC3 CV=PV", 1),
    Event(29, "HSC4 CV=PV", 1), Event(30, "HSC4 direction changed", 1),
    Event(31, "HSC4 external reset", 1),
    Event(33, "HSC5 CV=PV", 1),
    Event(10, "timed interrupt 0", 2), Event(11, "timed interrupt 1", 2),
    Event(21, "T32 CT=PT", 2), Event(22, "T96 CT=PT", 2),
)}

#: event number -> its group (perf: one lookup when an event is posted)
GROUP_OF: dict[int, int] = {n: e.group for n, e in EVENTS.items()}

#: (name, queue depth, SM4 overflow bit) per group, highest priority first
GROUPS: tuple[tuple[str, int, int], ...] = (
    ("communications", 4, 0x01), ("discrete", 16, 0x02), ("timed", 8, 0x04))

#: communication event -> its port (System Manual, table "Interrupt events")
PORT_OF_EVENT: dict[int, int] = {8: 0, 9: 0, 23: 0, 25: 1, 26: 1, 24: 1}
#: timed interrupt event -> its interval byte in SM (SMB34, SMB35)
TIMED: dict[int, int] = {10: 34, 11: 35}
#: input edge events: I0.x bit -> (rising event, falling event)
EDGES: dict[int, tuple[int, int]] = {0: (0, 1), 1: (2, 3), 2: (4, 5), 3: (6, 7)}


class Interrupts:
    """The interrupt system of one CPU.

    *run_routine(int_number)* executes an interrupt routine (the engine's
    generated code); *warn(message, key)* reports a diagnostic once."""

    def __init__(self, sm: bytearray, run_routine: Callable[[int], None],
                 warn: Callable[[str, str], None]) -> None:
        self.sm = sm
        self.run_routine = run_routine
        self.warn = warn
        self.attached: dict[int, int] = {}          #: event -> INT number
        self.enabled = False                         #: ENI / DISI
        self.queues: tuple[deque[tuple[int, int]], ...] = (deque(), deque(), deque())
        self.running = False                         #: a routine is executing
        self.queued = False                          #: an occurrence waits (perf: one test)
        self.timed_next: dict[int, int] = {}         #: timed event -> next time (µs)
        self.timed_period: dict[int, int] = {}       #: timed event -> interval (µs)
        self.timed_fired: set[int] = set()           #: timed events that fired since ATCH
        self.timers: Any = None                      #: the timer bank (events 21, 22)
        #: bumped by ATCH/DTCH (perf: sources that depend on what is attached
        #: keep what they derived from it until it changes)
        self.version = 0
        #: the scheduler may keep this source's next event until it fires or
        #: something touches the sources; not while T32/T96 CT=PT is attached
        #: (a routine's TON moves that time without touching anything)
        self.cacheable = True
        #: how many communication ports the CPU has (plcrt.engine.ports sets
        #: it; their events 8, 9, 23 / 24, 25, 26 occur); ATCH to the events
        #: of a port it lacks is diagnosed
        self.ports = 0

    # ------------------------------------------------------------ instructions
    def attach(self, int_number: int, event: int, t: int) -> None:
        """ATCH: *event* runs INT *int_number* from now on."""
        self.attached[event] = int_number
        self._attached_changed()
        if EVENTS[event].group == 0 and PORT_OF_EVENT[event] >= self.ports:
            self.warn(f"event {event} ({EVENTS[event].name}) comes from a communication "
                      f"port, which this CPU does not have: INT {int_number} is attached "
                      f"but never runs", f"irq-port-{event}")
        sm_byte = TIMED.get(event)
        if sm_byte is None:
            return
        ms = self.sm[sm_byte]
        if event in self.timed_next and event not in self.timed_fired:
            self.warn(f"timed interrupt {event - 10} (event {event}) attached again before its "
                      f"first interval of {self.timed_period[event] // 1000} ms elapsed: "
                      f"attaching restarts the timing, so it never fires while ATCH runs "
                      f"every scan (attach it once, e.g. on SM0.1)", f"irq-reattach-{event}")
        self.timed_fired.discard(event)
        if ms == 0:
            self.timed_next.pop(event, None)
            self.warn(f"timed interrupt {event - 10} (event {event}) attached with SMB{sm_byte} = 0: "
                      f"the interval must be 1..255 ms, so it never fires", f"irq-zero-{event}")
            return
        self.timed_period[event] = ms * 1000
        self.timed_next[event] = t + ms * 1000

    def detach(self, event: int) -> None:
        """DTCH: *event* is disabled; its occurrences are ignored."""
        self.attached.pop(event, None)
        self.timed_next.pop(event, None)
        self._attached_changed()

    def _attached_changed(self) -> None:
        self.version += 1
        self.cacheable = 21 not in self.attached and 22 not in self.attached

    def clear(self, event: int) -> None:
        """CEVNT (SMART): drop the queued occurrences of *event*."""
        for q in self.queues:
            kept = [x for x in q if x[1] != event]
            q.clear()
            q.extend(kept)
        self.queued = any(self.queues)

    def enable(self, t: int) -> None:
        """ENI: interrupts are processed; what is queued runs now."""
        self.enabled = True
        self.dispatch(t)

    def disable(self) -> None:
        """DISI: occurrences are queued, not processed."""
        self.enabled = False

    # ------------------------------------------------------------ events
    def post(self, event: int, t: int) -> None:
        """An occurrence of *event* at *t* (ignored unless attached)."""
        if event not in self.attached:
            return
        group = GROUP_OF[event]
        q = self.queues[group]
        if len(q) >= GROUPS[group][1]:
            name, depth, bit = GROUPS[group]
            self.sm[4] |= bit
            self.warn(f"interrupt queue overflow: the {name} queue holds {depth} events; "
                      f"event {event} ({EVENTS[event].name}) at {t / 1e6:.6f} s was lost "
                      f"(SM4.{bit.bit_length() - 1} set)", f"irq-overflow-{event}")
            return
        q.append((t, event))
        self.queued = True

    def dispatch(self, t: int) -> None:
        """Run the queued routines, highest priority first, if enabled."""
        if not self.enabled or self.running:
            return
        q0, q1, q2 = self.queues
        attached, run = self.attached, self.run_routine
        self.running = True
        try:
            while q0 or q1 or q2:
                q = q0 or q1 or q2      # perf: the highest group with an occurrence
                event = q.popleft()[1]
                number = attached.get(event)
                if number is None:
                    continue            # detached while queued
                run(number)
        finally:
            self.running = False
        self.queued = bool(q0 or q1 or q2)
        if not self.queued:
            # System Manual: the overflow bits are reset when the queues are
            # empty and control returns to the main program
            self.sm[4] &= ~0x07 & 0xFF

    def edges(self, old: int, new: int, t: int) -> None:
        """Input edge events of I0.0–I0.3 for the input byte changing *old* -> *new*."""
        changed = (old ^ new) & 0x0F
        if not changed:
            return
        for bit, (rise, fall) in EDGES.items():
            if changed >> bit & 1:
                self.post(rise if new >> bit & 1 else fall, t)

    # ------------------------------------------------------------ timed
    def live(self) -> bool:
        """Whether a timed interrupt runs, or T32/T96 CT=PT is attached (the
        scheduler asks only live sources)."""
        return bool(self.timed_next) or not self.cacheable   # not cacheable: 21/22 attached

    def next_time(self, after: int, until: int) -> Optional[int]:
        """The first timed occurrence in (*after*, *until*], if any."""
        best = None
        if self.timed_next:
            te = min(self.timed_next.values())   # perf: always after the last one fired
            if after < te <= until:
                best = te
        if not self.cacheable:                   # T32/T96 CT=PT attached
            te = self._timer_next(after, until)
            if te is not None and (best is None or te < best):
                best = te
        return best

    def fire(self, t: int) -> Optional[int]:
        """The scheduler's call (:class:`plcrt.engine.events.EventSource`):
        post the timed occurrences due at *t* and schedule their next ones
        (the engine runs the routines once every source of the instant has
        fired); returns the next timed occurrence when that is all there
        is to know (no CT=PT event attached)."""
        timed = self.timed_next
        # event order: 10 before 11 at one instant (perf: no sort for one;
        # only values change, so the dict itself can be iterated)
        for event in (sorted(timed) if len(timed) > 1 else timed):
            if timed[event] == t:
                timed[event] = t + self.timed_period[event]
                if event not in self.timed_fired:
                    self.timed_fired.add(event)
                self.post(event, t)
        if not self.cacheable:
            for event, n in ((21, 32), (22, 96)):
                if event in self.attached and self.timers.ct_pt_time(n) == t:
                    self.timers.refresh_1ms(t)       # CV = PT now: no second event
                    self.post(event, t)
            return None
        # perf: the scheduler keeps this instead of asking live/next_time
        return min(timed.values()) if timed else None

    def attach_timer_events(self, timers: Any) -> None:
        """Events 21 / 22: T32 / T96 CT=PT, from the timer bank."""
        self.timers = timers

    def _timer_next(self, after: int, until: int) -> Optional[int]:
        best = None
        for event, n in ((21, 32), (22, 96)):
            if event in self.attached:
                te = self.timers.ct_pt_time(n)
                if te is not None and after < te <= until and (best is None or te < best):
                    best = te
        return best
