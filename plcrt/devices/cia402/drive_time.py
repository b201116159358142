"""The time line of a simulated CiA 402 drive: its events in exact µs.

What it is: :class:`Timeline`, the part of :class:`~.drive.Drive` that moves
simulated time forward (:meth:`advance`): it finds the next event before the
time asked (the end of a move or a quick stop, a limit switch, a watched
homing position, the homing time limit, a mechanical end of :mod:`.stops`)
in closed form on the axis's plan, makes it happen at its µs, and repeats.
The cost does not depend on the speed.

What it is not: what an event does to a mode (:mod:`.modes`) or to the
power state machine (:meth:`Drive._do`).  It is a base class of
:class:`~.drive.Drive` and works on a drive's attributes.
"""

from __future__ import annotations

from typing import Any, Optional

from ...errors import PlcError
from .axis import LinLeg
from .modes import Homing
from .statemachine import State

__all__ = ["Timeline"]

_MAX_EVENTS = 100_000  # per advance: a homing plan that never moves on is an error


class Timeline:
    """The events of a :class:`~.drive.Drive` in time (see the module docstring)."""

    # the attributes it reads of the drive (set by Drive.__init__; it also
    # calls the drive's methods)
    now: int
    mode_number: int
    engines: dict[int, Any]
    axis: Any
    sm: Any
    plant: Any
    store: Any
    stops: Any
    _qs_wait: bool
    _batch: bool
    _cache_version: int
    _cache: dict[tuple, Optional[int]]

    def _eventless(self) -> bool:
        """No event can come, whatever the time: no homing (its time limit),
        and the axis at rest, or on a CSP line with no switch to watch and
        no quick stop waiting for its end (:meth:`_next_event` would find none)."""
        legs = self.axis.legs
        return self.mode_number != 6 and self.stops is None and (not legs or (
            not self._qs_wait and legs[-1].__class__ is LinLeg
            and self.plant.pos_limit is None and self.plant.neg_limit is None))

    def _next_event(self, t_to: int) -> Optional[tuple[int, str, object]]:
        if self._eventless():
            return None       # perf: the search below would find nothing
        ax = self.axis
        if ax.version != self._cache_version:
            self._cache_version, self._cache = ax.version, {}
        best: Optional[tuple[int, str, object]] = None

        def offer(te: Optional[int], kind: str, data: object) -> None:
            nonlocal best
            if te is not None and te <= t_to and (
                    best is None or te < best[0]
                    # a move that ends on a limit switch's first count reaches
                    # the switch at its end: the limit stop comes first, or the
                    # end settles the axis and the switch is never watched again
                    # (HCFA §7.4.2 bit 11, §7.5.3 note 1)
                    or (te == best[0] and kind == "limit" and best[1] == "end")):
                best = (te, kind, data)

        end = ax.end_time()
        if ax.legs and end is not None and (self._qs_wait or not isinstance(ax.legs[-1], LinLeg)):
            # a CSP line needs no end event: its end position holds by itself
            offer(max(end, self.now), "end", None)
        if ax.legs:
            watches: list[tuple[str, int, int, object]] = []
            if self.mode_number == 6:
                hm = self.engines[6]
                assert isinstance(hm, Homing)
                watches = [("watch", w.position, w.direction, w) for w in hm.watches]
            elif self.sm.state in (State.OPERATION_ENABLED, State.QUICK_STOP_ACTIVE):
                if self.plant.pos_limit is not None:
                    watches.append(("limit", self.plant.pos_limit, 1, "PLS"))
                if self.plant.neg_limit is not None:
                    watches.append(("limit", self.plant.neg_limit, -1, "NLS"))
            for kind, level, direction, data in watches:
                key = (kind, level, direction)
                if key not in self._cache:
                    te = ax.first_reach(self.now, level, direction, mechanical=True)
                    self._cache[key] = None if te == self.now else te
                te = self._cache[key]
                if te is not None and te >= self.now:
                    offer(te, kind, data)
        if self.mode_number == 6:
            hm = self.engines[6]
            assert isinstance(hm, Homing)
            if hm.deadline is not None:
                offer(max(hm.deadline, self.now), "timeout", None)
        if self.stops is not None:                     # mechanical ends (stops.py)
            for te, ev in self.stops.events():
                offer(te, "stop", ev)
        return best

    def advance(self, t_us: int, hold: bool = False) -> None:
        """Move simulated time forward to *t_us* (integer µs), exactly.
        *hold*: the drive's own objects at *t_us* are held for the SYNC's
        TPDOs and the bus cycle that follows (:meth:`publish_deferred`)."""
        with self.store.lock:          # a canopen port writes from its Notifier thread
            if hold and t_us >= self.now and not self._batch and self._eventless():
                self.now = t_us        # perf: what _advance does when no event can come
                self.publish_deferred()
                return
            self._advance(t_us, hold)

    def _advance(self, t_us: int, hold: bool = False) -> None:
        if t_us < self.now:
            raise PlcError(f"drive time cannot go back: now {self.now} µs, asked {t_us} µs")
        for _ in range(_MAX_EVENTS):
            ev = self._next_event(t_us)
            if ev is None:
                break
            te, kind, data = ev
            self.now = te
            if kind == "end":
                if self._qs_wait:
                    self.axis.settle(te)
                    self._qs_wait = False
                    self._do(te, self.sm.motion_stopped(te / 1e6))
                elif self.stops is None or not self.stops.holds_end(te):
                    self.mode.motion_end(te)
                if self.axis.legs and self.axis.end_time() == te:
                    self.axis.settle(te)
            elif kind == "limit":
                self._cache[("limit", self.plant.pos_limit if data == "PLS"
                             else self.plant.neg_limit, 1 if data == "PLS" else -1)] = None
                switch = "positive limit switch (PLS)" if data == "PLS" \
                    else "negative limit switch (NLS)"
                if self._qs_wait:
                    self.note(te, "HCFA §7.4.2", f"{switch} reached during the quick stop")
                else:
                    self.mode.limit(te, switch)
            elif kind == "watch":
                hm = self.engines[6]
                assert isinstance(hm, Homing)
                self._cache[("watch", data.position, data.direction)] = None  # type: ignore
                hm.watch_hit(te, data)  # type: ignore[arg-type]
            elif kind == "timeout":
                hm = self.engines[6]
                assert isinstance(hm, Homing)
                hm.timeout(te)
            elif kind == "stop":
                assert self.stops is not None
                self.stops.on_event(te, data)  # type: ignore[arg-type]
        else:
            raise PlcError(f"drive: more than {_MAX_EVENTS} events before {t_us} µs "
                           "(a homing plan that does not move on?)")
        self.now = t_us
        if not self._batch:
            if hold:
                self.publish_deferred()
            else:
                self.publish()
