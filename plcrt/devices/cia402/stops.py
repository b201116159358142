"""Mechanical ends (hard stops) of a simulated CiA 402 drive's axis.

What it is: :class:`HardStops`, the part of a :class:`~.drive.Drive` that
knows the plant's ``neg_stop`` / ``pos_stop``.  The axis
(:class:`~.axis.Axis`, ``bounds``) is the demand clamped to the ends: when
a plan reaches an end the axis stands there from that µs on while the
demand goes on, so the following error 60F4h = 6062h - 6064h grows.  This
module finds, exactly and without stepping (bisection of the plan's
polynomial at 1 µs, :meth:`~.axis.Axis.first_reach`), the times at which

* the demand reaches an end (``"reach"``: a diagnostic in the drive's log
  naming the end, the objects and the section);
* |60F4h| goes beyond the following error window 6065h (``"over"``) and
  comes back within it (``"back"``), and the window has been exceeded for
  the time out 6066h (``"fault"``: 603Fh = 0x8611, the code CSP raises for
  its following error, HCFA §7.5.1; CiA 402) - in PP, PV and HM; CSP keeps
  its own supervision at each bus cycle, Kinco -17 / -18 use the following
  error as their stall criterion instead (Kinco §2.5);
* a homing plan's timer runs out (``"timer"``: the stall criteria of
  Kinco -17 / -18 hold, :mod:`.homing_adapter`).

It also decides that a move whose demand ends past an end is not over for
the mode (the axis did not get there: PP target reached, bit 10, stays 0).

What it is not: it plans no motion and knows no mode's bits; the drive
calls :meth:`events` from its event search and :meth:`on_event` when one is
due; what this module uses of the drive is :class:`~.drive_view.StopsDrive`.
Decisions: docs/cia402.md, "Mechanical ends".
"""

from __future__ import annotations

from typing import Optional

from .drive_view import StopsDrive
from .homing_plan import Watch
from .statemachine import State
from .states import Cia402Error


__all__ = ["HardStops", "FOLLOWING_ERROR", "STALL_METHODS"]

FOLLOWING_ERROR = 0x8611          #: 603Fh, CiA 402 following error (as CSP, HCFA §7.5.1)
STALL_METHODS = (-17, -18)        #: Kinco §2.5: the following error is the stall criterion
SUPERVISED = (1, 3, 6)            #: PP, PV, HM: supervised here (CSP at its bus cycle)
SECTION = "Kinco §2.5; CiA 402 6065h/6066h, HCFA §7.5.1"
NAMES = {-1: "neg_stop", 1: "pos_stop"}


class HardStops:
    """The mechanical ends of one drive's axis (see the module docstring)."""

    def __init__(self, drive: StopsDrive) -> None:
        self.d = drive
        plant = drive.plant
        self.ends = {s: e for s, e in ((-1, plant.neg_stop), (1, plant.pos_stop))
                     if e is not None}
        start = drive.axis.mechanical(drive.now)
        side = plant.beyond_stop(start)
        if side is not None:
            raise Cia402Error(f"plant: the axis powers up at mechanical position {start}, "
                              f"beyond {side} = {getattr(plant, side)}")
        drive.axis.bounds = (plant.neg_stop, plant.pos_stop)
        self.held: Optional[int] = None      #: side of the end the axis is known held at
        self.over: Optional[tuple[int, int]] = None   #: (since µs, side) |60F4h| > 6065h
        self._cache: dict[tuple, Optional[int]] = {}
        self._version = -1

    # ---------------------------------------------------------------- state
    def _supervised(self) -> bool:
        d = self.d
        if d.sm.state not in (State.OPERATION_ENABLED, State.QUICK_STOP_ACTIVE):
            return False
        if d.mode_number == 6:         # a running -17/-18 takes 60F4h as its stall criterion
            running = d.engines[6].plan is not None  # type: ignore[attr-defined]
            return not running or d.param(0x6098) not in STALL_METHODS
        return d.mode_number in SUPERVISED

    def side_held(self, t: int) -> Optional[int]:
        """The side (-1 / +1) of the end the axis stands at with the demand past it."""
        x = self.d.axis.demand(t)[0]
        for side, end in self.ends.items():
            if (x - end) * side > 0:
                return side
        return None

    def holds_end(self, t: int) -> bool:
        """The plan ends at *t* with the demand past an end: outside HM the
        move is not over for the mode (the axis never got to its target)."""
        side = self.side_held(t)
        if side is None or self.d.mode_number == 6:
            return False
        d = self.d
        d.note(t, SECTION, f"the demand ends at count {d.axis.demand_position(t)} but the axis "
                           f"stands at the mechanical end {NAMES[side]} = {self.ends[side]}: the "
                           "move is not over (PP: target reached, bit 10, stays 0)", "plant")
        return True

    # ---------------------------------------------------------------- events
    def _reach(self, key: tuple, level: int, direction: int) -> Optional[int]:
        if key not in self._cache:
            self._cache[key] = self.d.axis.first_reach(self.d.now, level, direction,
                                                       mechanical=True, demand=True)
        return self._cache[key]

    def events(self) -> list[tuple[int, tuple]]:
        """The next time of each kind of event, from the drive's present time."""
        d, ax, now = self.d, self.d.axis, self.d.now
        if ax.version != self._version:
            self._version, self._cache = ax.version, {}
        if self.held is not None and ax.exact(now)[0] != self.ends[self.held]:
            self.held = None                  # the axis has left the end
        out: list[tuple[int, tuple]] = []
        if ax.legs:
            for side, end in self.ends.items():
                if side == self.held:
                    continue
                # the first µs the demand is at or past the end (+: x >= end, -: x <= end)
                te = self._reach(("reach", side), end if side > 0 else end - 1, side)
                if te is not None and side < 0 and te > now and ax.demand(te - 1)[0] <= end:
                    te -= 1
                if te is not None:
                    out.append((te, ("reach", side)))
        if self._supervised():
            window = d.param(0x6065)
            fe = self._fe(now)
            if self.over is None and abs(fe) > window:
                # already beyond (6065h lowered, or supervision resumed): from now
                out.append((now, ("over", 1 if fe > 0 else -1)))
            elif self.over is None and ax.legs:
                for side, end in self.ends.items():
                    te = self._reach(("over", side, window), end + side * (window + 1), side)
                    if te is not None:
                        out.append((te, ("over", side)))
            elif self.over is not None and abs(fe) <= window:
                out.append((now, ("back", self.over[1])))
            elif self.over is not None:
                since, side = self.over
                out.append((max(now, since + d.param(0x6066) * 1000), ("fault", side)))
                if ax.legs:
                    te = self._reach(("back", side, window), self.ends[side] + side * window,
                                     -side)
                    if te is not None:
                        out.append((te, ("back", side)))
        elif self.over is not None:
            self.over = None
        if d.mode_number == 6:
            timer = getattr(d.engines[6].plan, "timer", None)
            if timer is not None:
                out.append((max(now, timer[0]), ("timer", timer[1])))
        return [(te, ev) for te, ev in out if te >= now]

    def on_event(self, t: int, event: tuple) -> None:
        kind, what = event
        d = self.d
        self._cache = {k: v for k, v in self._cache.items() if k[0] != kind}
        if kind == "reach":
            self.held = what
            self._note_reach(t, what)
            hm = d.engines[6]
            if d.mode_number == 6 and getattr(hm.plan, "stop_watch", False):  # type: ignore
                hm.watch_hit(t, Watch("hard_stop", self.ends[what], what))  # type: ignore
        elif kind == "over":
            self.over = (t, what)
            d.note(t, SECTION, f"following error 60F4h = {self._fe(t)} beyond 6065h = "
                               f"{d.param(0x6065)} at the mechanical end {NAMES[what]} = "
                               f"{self.ends[what]}; fault after 6066h = {d.param(0x6066)} ms "
                               "unless it comes back", "plant")
        elif kind == "back":
            self.over = None
            d.note(t, SECTION, f"following error 60F4h = {self._fe(t)} back within 6065h = "
                               f"{d.param(0x6065)}", "plant")
        elif kind == "fault":
            since = self.over[0] if self.over else t
            self.over = None
            fe = self._fe(t)
            d.fault(t, FOLLOWING_ERROR, None,
                    f"following error 60F4h = {fe} beyond 6065h = {d.param(0x6065)} for "
                    f"{(t - since) / 1000:g} ms (6066h = {d.param(0x6066)} ms): the axis stands "
                    f"at the mechanical end {NAMES[what]} = {self.ends[what]} while the demand "
                    f"6062h = {fe + d.axis.position(t)} goes on ({SECTION})")
        elif kind == "timer":
            hm = d.engines[6]
            hm.watch_hit(t, Watch(what, d.axis.mechanical(t), 0))  # type: ignore[attr-defined]

    def _fe(self, t: int) -> int:
        return self.d.axis.demand_position(t) - self.d.axis.position(t)

    def _note_reach(self, t: int, side: int) -> None:
        d = self.d
        end = self.ends[side]
        if d.mode_number == 6 and d.param(0x6098) in STALL_METHODS:
            then = (f"homing method {d.param(0x6098)} watches for the stall (60F4h against "
                    f"6065h, 6099h:04, 606Ch against 60F9h:0A)")
        elif d.mode_number == 8:
            then = (f"CSP supervises 60F4h at each bus cycle (6065h = {d.param(0x6065)}, "
                    f"6066h = {d.param(0x6066)} ms)")
        elif self._supervised():
            then = (f"60F4h is supervised against 6065h = {d.param(0x6065)} for 6066h = "
                    f"{d.param(0x6066)} ms")
        else:
            then = "the drive is not enabled, nothing supervises it"
        d.note(t, SECTION, f"mechanical end {NAMES[side]} = {end} reached: the axis stands "
                           f"there (6064h = {d.axis.position(t)}, 606Ch = 0) while the demand "
                           f"goes on, so the following error 60F4h grows; {then}", "plant")
