"""The exact, signed position of a CiA 402 drive's axis in simulated time.

What it is: :class:`Axis`, a position in counts (pulses) that moves along a
plan of *legs*.  A profiled leg is a chain of :class:`~plcrt.devices.motion.Seg`
ments in one direction (ramps and cruises from :mod:`plcrt.devices.motion`,
travel an integer polynomial in µs); a linear leg is a straight line between
two integer positions over one bus cycle (CSP interpolation).  A plan has at
most two legs (stop, then go the other way).  Positions are exact rationals;
the reported count is ``floor`` of the exact position, so a move that ends on
an integer target reads exactly that target and a move never reads past it.

Crossing times (a limit switch, a position a homing plan watches) are found
by bisection on the polynomial at 1 µs resolution, never by stepping through
pulses: the cost of simulating a second does not depend on the speed.
``evaluations`` counts polynomial evaluations, so tests can show that.

Mechanical ends (``bounds``, the plant's ``neg_stop`` / ``pos_stop``): the
plan is the *demand*, which may run past an end; the axis itself is the
demand clamped to the ends, at rest there while the demand is beyond
(:meth:`demand` / :meth:`demand_position` read the demand, everything else
the axis).  :mod:`.stops` finds the times and reacts.

What it is not: no drive logic; the modes (:mod:`.modes`) decide what to plan.
Speeds are P/s, accelerations P/s², times integer µs.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Optional, Union

from ..motion import US, Seg, cruise, plan_distance, ramp, ramp_distance

__all__ = ["Axis", "Leg", "LinLeg"]


@dataclass(slots=True)
class Leg:
    """Motion in one direction: ``origin + direction * travel(t)``."""

    direction: int          #: +1 or -1
    origin: Fraction        #: exact position where the leg starts
    segs: list[Seg]         #: absolute times, travel from 0

    @property
    def t_end(self) -> Optional[int]:
        return self.segs[-1].t1_ceil


@dataclass(slots=True)
class LinLeg:
    """Straight line from ``x0`` at ``t0`` to ``x1`` at ``t1`` (integers)."""

    t0: int
    t1: int
    x0: int
    x1: int

    @property
    def direction(self) -> int:
        return (self.x1 > self.x0) - (self.x1 < self.x0)

    @property
    def t_end(self) -> int:
        return self.t1


AnyLeg = Union[Leg, LinLeg]
ZERO = Fraction(0)


class Axis:
    """One axis: at rest at an exact position, or following a plan."""

    def __init__(self, position: int = 0) -> None:
        # perf: the rest position is an int after a CSP line (exact() makes
        # it a Fraction when asked); _count is its floor, kept with it
        self._rest: Fraction | int = Fraction(position)
        self._count = position
        self.shift = 0              #: count - mechanical position (set by homing)
        self._dir = 1
        self.legs: list[AnyLeg] = []
        # perf: the plan's only leg when it is a CSP line (else None): the
        # bus cycle's questions answered without looking through legs
        self._line: Optional[LinLeg] = None
        self.evaluations = 0        #: polynomial evaluations (for cost tests)
        self.version = 0            #: changes whenever the plan changes
        self._memo: tuple = (None, None, None)
        #: mechanical ends (neg, pos) in the plant's frame; None: no end (plant.neg_stop/pos_stop)
        self.bounds: Optional[tuple[Optional[int], Optional[int]]] = None

    # ---------------------------------------------------------------- state
    def _leg_x(self, leg: AnyLeg, t: int | Fraction) -> tuple[Fraction, Fraction]:
        """Exact (position, signed speed) of *leg* at *t*, clamped to the leg."""
        self.evaluations += 1
        if isinstance(leg, LinLeg):
            if t >= leg.t1:
                return Fraction(leg.x1), ZERO
            tt = max(t, leg.t0)
            return (leg.x0 + Fraction((leg.x1 - leg.x0) * (tt - leg.t0), leg.t1 - leg.t0),
                    Fraction((leg.x1 - leg.x0) * US, leg.t1 - leg.t0))
        for seg in leg.segs:
            if seg.t1_ceil is None or t < seg.t1_ceil:
                if isinstance(t, int) and t * seg.t0.denominator >= seg.t0.numerator:
                    # integer polynomial (the common case): one normalisation each
                    num = (seg.A * t + seg.B) * t + seg.C
                    return (leg.origin + Fraction(leg.direction * num, seg.D),
                            Fraction(leg.direction * (2 * seg.A * t + seg.B) * US, seg.D))
                tt = max(Fraction(t), seg.t0)
                return (leg.origin + leg.direction * seg.travel(tt),
                        leg.direction * seg.speed(tt))
        last = leg.segs[-1]
        return leg.origin + leg.direction * last.x1, leg.direction * last.v1

    def exact(self, t: int) -> tuple[Fraction, Fraction]:
        """Exact position and signed speed (P/s) of the axis at integer µs
        *t*: the demand, held at a mechanical end it runs past."""
        out = self.demand(t)
        if self.bounds is not None:
            neg, pos = self.bounds
            if neg is not None and out[0] < neg:
                return Fraction(neg), ZERO
            if pos is not None and out[0] > pos:
                return Fraction(pos), ZERO
        return out

    def demand_position(self, t: int) -> int:
        """6062h outside CSP: whole counts of the demand (plus the shift)."""
        x = self.demand(t)[0]
        return x.numerator // x.denominator + self.shift

    def demand(self, t: int) -> tuple[Fraction, Fraction]:
        """Exact position and signed speed (P/s) of the plan at integer µs *t*."""
        if self._memo[0] == t and self._memo[1] == self.version:
            return self._memo[2]
        rest = self._rest
        if rest.__class__ is int:
            rest = self._rest = Fraction(rest)
        out = rest, ZERO
        for leg in self.legs:
            end = leg.t_end
            if end is None or t < end:
                out = self._leg_x(leg, t)
                break
        self._memo = (t, self.version, out)
        return out

    def position(self, t: int) -> int:
        """6064h: whole counts (floor of the exact position, plus the shift
        homing set)."""
        return self.mechanical(t) + self.shift

    def mechanical(self, t: int) -> int:
        """Whole counts in the plant's frame (switch positions), which
        homing does not move."""
        leg = self._line
        if leg is not None and self.bounds is None:     # perf: CSP, integers only
            if t >= leg.t1:
                return leg.x1
            tt = leg.t0 if t < leg.t0 else t
            return leg.x0 + (leg.x1 - leg.x0) * (tt - leg.t0) // (leg.t1 - leg.t0)
        if not self.legs and self.bounds is None:
            return self._count          # perf: floor of the rest position, kept
        x = self.exact(t)[0]              # perhaps held at a mechanical end
        return x.numerator // x.denominator

    def velocity(self, t: int) -> int:
        """606Ch: whole P/s, truncated toward 0."""
        leg = self._line
        if leg is not None and self.bounds is None:               # perf: CSP, integers only
            if t >= leg.t1 or t < leg.t0:
                return 0
            num, den = (leg.x1 - leg.x0) * US, leg.t1 - leg.t0
            return num // den if num >= 0 else -(-num // den)
        if not self.legs:
            return 0
        return int(self.exact(t)[1])

    def end_time(self) -> Optional[int]:
        """First µs at which the plan is over; None at rest or when endless."""
        if not self.legs:
            return None
        return self.legs[-1].t_end

    def moving(self, t: int) -> bool:
        if self._line is not None:
            return t < self._line.t1        # perf: a CSP line
        if not self.legs:
            return False
        end = self.legs[-1].t_end
        return end is None or t < end

    def final_speed(self) -> Fraction:
        """Signed speed the plan ends (or cruises endlessly) at."""
        if not self.legs:
            return Fraction(0)
        leg = self.legs[-1]
        if isinstance(leg, LinLeg):
            return Fraction(0)
        return leg.direction * leg.segs[-1].v1

    def settle(self, t: int) -> None:
        """The plan is over at *t*: keep its end position (the demand, also
        past a mechanical end), drop the plan."""
        x, _ = self.demand(t)
        self._set(x, [])

    def _set(self, rest: Fraction, legs: list[AnyLeg]) -> None:
        self._rest = rest
        if legs:
            self._dir = legs[-1].direction or self._dir
            last = legs[-1]
            if isinstance(last, LinLeg):
                self._rest = last.x1        # perf: an int, made a Fraction when asked
            elif last.t_end is not None:
                self._rest = last.origin + last.direction * last.segs[-1].x1
        rest = self._rest
        self._count = rest if rest.__class__ is int else rest.numerator // rest.denominator
        self.legs = legs
        self._line = legs[0] if len(legs) == 1 and legs[0].__class__ is LinLeg else None
        self.version += 1

    # ---------------------------------------------------------------- planning
    def stop_at_once(self, t: int) -> None:
        """Stop where the axis is (a drive switched off, a zero deceleration);
        a demand past a mechanical end comes back to the axis held there."""
        self._set(self.exact(t)[0], [])

    def set_position(self, t: int, value: int) -> None:
        """Stop; the count becomes *value* where the axis is (homing): the
        mechanical position stays, the shift changes."""
        self.stop_at_once(t)
        self.shift = value - self.mechanical(t)

    def _stop_leg(self, t: Fraction, x: Fraction, v: Fraction, dec: int) -> Optional[Leg]:
        if v == 0 or dec <= 0:
            return None
        seg = ramp(t, Fraction(0), abs(v), Fraction(0), Fraction(dec, US))
        return Leg(1 if v > 0 else -1, x, [seg])

    def _stop_first(self, t0: Fraction, x: Fraction, v: Fraction, dec: int,
                    legs: list[AnyLeg]) -> tuple[Fraction, Fraction]:
        """Append the ramp to rest (if any) to *legs*; returns the time and
        position where the axis is then at rest."""
        leg = self._stop_leg(t0, x, v, dec)
        if leg is None:
            return t0, x
        legs.append(leg)
        t_end, travel = leg.segs[-1].end
        return t_end, x + leg.direction * travel

    def stop(self, t: int, dec: int) -> None:
        """Ramp the demand to rest at *dec* P/s² (0: at once)."""
        x, v = self.demand(t)
        leg = self._stop_leg(Fraction(t), x, v, dec)
        self._set(x, [leg] if leg else [])

    def go_to(self, t: int, target: int, v_max: int, acc: int, dec: int,
              mechanical: bool = False) -> None:
        """Move to count *target* (a plant position with *mechanical*) and
        stop there exactly: from any speed, stopping first (and coming back)
        if the axis cannot stop before it."""
        if not mechanical:
            target -= self.shift
        x, v = self.demand(t)
        legs: list[AnyLeg] = []
        t0: Fraction = Fraction(t)
        r_dec = Fraction(dec, US)
        dist = target - x
        if v != 0 and ((dist > 0) != (v > 0) or dist == 0
                       or ramp_distance(abs(v), Fraction(0), r_dec) > abs(dist)):
            t0, x = self._stop_first(t0, x, v, dec, legs)
            v = Fraction(0)
        length = abs(target - x)
        if length > 0:
            direction = 1 if target > x else -1
            segs, _ = plan_distance(t0, Fraction(0), abs(v), Fraction(v_max), Fraction(0),
                                    length, Fraction(acc, US), r_dec)
            legs.append(Leg(direction, x, segs))
        self._set(self.demand(t)[0] if not legs else x, legs)

    def run_at(self, t: int, v_target: int, acc: int, dec: int) -> None:
        """Change speed to *v_target* (signed P/s) with *acc* when the speed
        grows and *dec* when it falls (0: at once), then cruise without end."""
        x, v = self.demand(t)
        legs: list[AnyLeg] = []
        t0: Fraction = Fraction(t)
        if v != 0 and (v_target == 0 or (v_target > 0) != (v > 0)):
            t0, x = self._stop_first(t0, x, v, dec, legs)
            v = Fraction(0)
        if v_target != 0:
            direction = 1 if v_target > 0 else -1
            s0, s1 = abs(v), Fraction(abs(v_target))
            segs: list[Seg] = []
            rate = acc if s1 > s0 else dec
            if s1 != s0 and rate > 0:
                segs.append(ramp(t0, Fraction(0), s0, s1, Fraction(rate, US)))
                t0, travel = segs[-1].end
            else:
                travel = Fraction(0)
            segs.append(cruise(t0, travel, s1))
            legs.append(Leg(direction, x, segs))
        self._set(x, legs)

    def linear(self, t0: int, t1: int, target: int, v_max: int,
               x0: Optional[int] = None) -> None:
        """CSP: from the count at *t0* to *target* at *t1*, at most *v_max*
        P/s (then it ends short, at a whole count).  *x0*: the plant
        position at *t0* when the caller has it (``mechanical(t0)``)."""
        if x0 is None:
            x0 = self.mechanical(t0)
        x1 = target - self.shift
        cap = v_max * (t1 - t0) // US
        if x1 > x0 + cap:
            x1 = x0 + cap
        elif x1 < x0 - cap:
            x1 = x0 - cap
        if x1 == x0:
            if self.legs or self._rest != x0:
                self._set(Fraction(x0), [])
        else:
            # perf: _set(x0, [line]) written out: the rest is x1, an int
            self._dir = 1 if x1 > x0 else -1
            self._rest = self._count = x1
            self._line = line = LinLeg(t0, t1, x0, x1)
            self.legs = [line]
            self.version += 1

    # ---------------------------------------------------------------- crossings
    def first_reach(self, t_from: int, level: int, direction: int,
                    mechanical: bool = False, demand: bool = False) -> Optional[int]:
        """First integer µs ``>= t_from`` at which the count (the plant
        position with *mechanical*) reaches *level* moving in *direction*
        (+1: count >= level; -1: count <= level), or None.  Only legs moving
        that way count.  The axis never reaches a level past a mechanical
        end; the *demand* does."""
        if not mechanical:
            level -= self.shift
        if self.bounds is not None and not demand:
            neg, pos = self.bounds
            if (direction > 0 and pos is not None and level > pos) or \
                    (direction < 0 and neg is not None and level < neg):
                return None

        def cond(x: Fraction) -> bool:
            return x >= level if direction > 0 else x < level + 1

        for leg in self.legs:
            if leg.direction != direction:
                continue
            if isinstance(leg, LinLeg):
                spans = [(leg.t0, leg.t1)]
            else:
                spans = []
                for seg in leg.segs:
                    lo = -((-seg.t0.numerator) // seg.t0.denominator)
                    if seg.t1_ceil is not None:
                        spans.append((lo, seg.t1_ceil))
                    else:
                        x_lo = self._leg_x(leg, max(lo, t_from))[0]
                        need = abs(level - x_lo) + 1
                        spans.append((lo, max(lo, t_from) + int(need * US / seg.v0) + 2))
            for lo, hi in spans:
                lo = max(lo, t_from)
                if hi < lo:
                    continue
                if not cond(self._leg_x(leg, hi)[0]):
                    continue
                if cond(self._leg_x(leg, lo)[0]):
                    return lo
                while hi - lo > 1:
                    mid = (lo + hi) // 2
                    if cond(self._leg_x(leg, mid)[0]):
                        hi = mid
                    else:
                        lo = mid
                return hi
        return None
