"""Exact, event-driven pulse kinematics shared by simulated motion devices.

A move is a chain of :class:`Seg` ments (start-speed jumps, linear ramps,
cruises) along one direction.  Within a segment the distance travelled is a
quadratic in absolute time with rational coefficients, stored as integers
over one denominator, so that at any integer microsecond ``t``::

    pulses(t) = floor((A*t*t + B*t + C) / D)

is exact: pulse counts are integers and never drift, whatever the scan time.
Event times (a switch or Z position reached, the end of a ramp) are found
in closed form / by integer bisection on that polynomial, at 1 µs
resolution, never by stepping through pulses, so simulating a second costs
the same at 5 kHz and at 500 kHz.

Speeds are in Hz (pulses per second), rates in Hz per µs, times in µs.
Where a ramp would end at an irrational speed (the peak of a triangular
profile, the speed a too-short distance can reach), the speed is rounded
to a whole Hz (finer below 1 Hz) in the direction that keeps the ramp
within its rate -- a peak down, with a short cruise making up the exact
distance; the end speed of a too-short deceleration up -- so distances are
exact and speed limits and ramp rates are never exceeded.

This module knows nothing about PLCs, modules or instructions.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from math import gcd, isqrt
from typing import Optional

US = 10**6  #: microseconds per second


def _lcm(a: int, b: int) -> int:
    return a // gcd(a, b) * b


@dataclass(slots=True)
class Seg:
    """One phase: speed goes linearly from ``v0`` to ``v1`` (Hz) over
    ``[t0, t1]`` (µs, rational; ``t1`` None = endless cruise)."""

    t0: Fraction
    t1: Optional[Fraction]
    x0: Fraction          #: travel (pulses) at t0
    v0: Fraction          #: Hz at t0
    v1: Fraction          #: Hz at t1 (= v0 for a cruise)
    # integer polynomial of travel in absolute time: (A t^2 + B t + C) / D
    A: int = 0
    B: int = 0
    C: int = 0
    D: int = 1
    t1_ceil: Optional[int] = None  #: first integer µs at or after t1
    #: perf: speed in Hz is (HA t + HB) // HD: hz() without its
    #: multiplications, over the smallest denominator (a divisor of one
    #: machine digit divides faster than D, often of two)
    HA: int = 0
    HB: int = 0
    HD: int = 1

    def __post_init__(self) -> None:
        if self.t1 is None or self.t1 == self.t0:
            a = Fraction(0)
        else:
            a = (self.v1 - self.v0) / (self.t1 - self.t0)  # Hz per µs
        # x(t) = x0 + v0 (t - t0)/US + a (t - t0)^2 / (2 US)
        c2 = a / (2 * US)
        c1 = self.v0 / US - 2 * c2 * self.t0
        c0 = self.x0 - self.v0 * self.t0 / US + c2 * self.t0 * self.t0
        d = _lcm(_lcm(c2.denominator, c1.denominator), c0.denominator)
        self.A = c2.numerator * (d // c2.denominator)
        self.B = c1.numerator * (d // c1.denominator)
        self.C = c0.numerator * (d // c0.denominator)
        self.D = d
        ha, hb = 2 * self.A * US, self.B * US
        g = gcd(gcd(ha, hb), d)
        self.HA, self.HB, self.HD = ha // g, hb // g, d // g
        if self.t1 is not None:
            self.t1_ceil = -((-self.t1.numerator) // self.t1.denominator)

    # perf: plain integer arithmetic; called every scan for moving axes
    def pulses(self, t: int) -> int:
        """Whole pulses travelled at integer time ``t`` (inside the segment)."""
        return ((self.A * t + self.B) * t + self.C) // self.D

    def hz(self, t: int) -> int:
        """Speed in whole Hz at integer time ``t`` (integer arithmetic)."""
        return (self.HA * t + self.HB) // self.HD

    def travel(self, t: Fraction | int) -> Fraction:
        """Exact travel at any time inside the segment."""
        return Fraction(self.A * t * t + self.B * t + self.C) / self.D

    def speed(self, t: int | Fraction) -> Fraction:
        """Speed in Hz at time ``t`` inside the segment."""
        return Fraction((2 * self.A * t + self.B) * US, self.D)

    @property
    def x1(self) -> Fraction:
        assert self.t1 is not None
        return self.travel(self.t1)

    @property
    def end(self) -> tuple[Fraction, Fraction]:
        """(t1, x1): where a segment that ends hands over to the next."""
        assert self.t1 is not None
        return self.t1, self.travel(self.t1)


def ramp(t0: Fraction, x0: Fraction, v0: Fraction, v1: Fraction, rate: Fraction) -> Seg:
    """A linear speed change from v0 to v1 at ``rate`` Hz/µs (> 0)."""
    dt = abs(v1 - v0) / rate
    return Seg(t0, t0 + dt, x0, v0, v1)


def cruise(t0: Fraction, x0: Fraction, v: Fraction, distance: Fraction | None = None) -> Seg:
    """Constant speed, for ``distance`` pulses or without end."""
    if distance is None:
        return Seg(t0, None, x0, v, v)
    dt = distance * US / v if v else Fraction(0)
    return Seg(t0, t0 + dt, x0, v, v)


def ramp_distance(v0: Fraction, v1: Fraction, rate: Fraction) -> Fraction:
    """Pulses travelled while ramping from v0 to v1 at ``rate``."""
    return (v0 + v1) * abs(v1 - v0) / (2 * rate * US)


def plan_distance(t0: Fraction, x0: Fraction, v_in: Fraction, v_max: Fraction,
                  v_end: Fraction, length: Fraction, r_acc: Fraction,
                  r_dec: Fraction) -> tuple[list[Seg], bool]:
    """Segments covering exactly ``length`` pulses from speed ``v_in``:
    ramp toward ``v_max``, cruise, ramp down to ``v_end`` at the end.

    ``v_end`` above ``v_max`` is taken as ``v_max`` (the stop speed is
    below the run speed, EM253 manual note 4).  Speeds stay within
    ``[min(v_in, v_end), max(v_in, v_max)]``; speed increases never exceed
    ``r_acc`` and decreases never exceed ``r_dec``; peaks and unreachable
    end speeds are rounded (to whole Hz) in the direction that keeps both.

    Returns the segments and whether the end speed is reached (False when
    the distance is too short to slow down from ``v_in`` -- the last
    segment then ends above ``v_end`` -- or, starting below ``v_end``, to
    speed up to it).
    """
    segs: list[Seg] = []
    if length <= 0:
        return segs, True
    if v_max <= 0:
        raise ValueError("plan_distance: v_max must be positive")
    v_end = min(v_end, v_max)
    x_end = x0 + length
    if v_in > v_end and ramp_distance(v_in, v_end, r_dec) >= length:
        # too short to slow down to v_end: slow down as far as it allows
        v_reach = max(_sqrt_ceil(v_in * v_in - 2 * r_dec * length * US), v_end)
        if v_reach >= v_in:
            segs.append(cruise(t0, x0, v_in, length))
        else:
            segs.append(_final_ramp(t0, x0, v_in, v_reach, x_end))
        return segs, v_reach == v_end
    if v_in < v_end and ramp_distance(v_in, v_end, r_acc) >= length:
        # too short to speed up to v_end: speed up as far as it allows
        v_reach = min(_sqrt_floor(v_in * v_in + 2 * r_acc * length * US), v_end)
        if v_reach <= v_in:
            segs.append(cruise(t0, x0, v_in, length))
        else:
            segs.append(_final_ramp(t0, x0, v_in, v_reach, x_end))
        return segs, v_reach == v_end
    t, x = t0, x0
    if v_in >= v_max:
        # at or above the peak: slow down to v_max, cruise, slow down to v_end
        peak = v_max
        if v_in > peak:
            segs.append(ramp(t, x, v_in, peak, r_dec))
            t, x = segs[-1].end
    else:
        d_acc = ramp_distance(v_in, v_max, r_acc)
        d_dec = ramp_distance(v_max, v_end, r_dec)
        peak = v_max
        if d_acc + d_dec > length:
            # triangular: peak^2 solves the two ramps; round it down
            num = 2 * length * US * r_acc * r_dec + r_dec * v_in * v_in + r_acc * v_end * v_end
            peak = max(_sqrt_floor(num / (r_acc + r_dec)), v_in, v_end)
        if peak > v_in:
            segs.append(ramp(t, x, v_in, peak, r_acc))
            t, x = segs[-1].end
    rest = x_end - x - ramp_distance(peak, v_end, r_dec)
    if rest > 0:
        segs.append(cruise(t, x, peak, rest))
        t, x = segs[-1].end
    if peak > v_end and x < x_end:
        segs.append(_final_ramp(t, x, peak, v_end, x_end))
    return segs, True


def plan_hold(t0: Fraction, x0: Fraction, v_in: Fraction, v_target: Fraction,
              length: Fraction, r_up: Fraction, r_down: Fraction) -> list[Seg]:
    """Exactly ``length`` pulses: change speed toward ``v_target`` (at
    ``r_up`` / ``r_down``) as far as the distance allows, then hold it.
    Used for the inner segments of an envelope, which do not stop.

    Speeds stay between ``v_in`` and ``v_target`` (which must be positive).
    """
    segs: list[Seg] = []
    t, x = t0, x0
    if length <= 0:
        return segs
    if v_target <= 0:
        raise ValueError("plan_hold: v_target must be positive")
    v = v_in
    if v_target > v_in:
        if ramp_distance(v_in, v_target, r_up) <= length:
            v = v_target
        else:
            v = max(min(_sqrt_floor(v_in * v_in + 2 * r_up * length * US), v_target), v_in)
        if v > v_in:
            segs.append(ramp(t, x, v_in, v, r_up))
    elif v_target < v_in:
        if ramp_distance(v_in, v_target, r_down) <= length:
            v = v_target
        else:
            v = min(max(_sqrt_ceil(v_in * v_in - 2 * r_down * length * US), v_target), v_in)
        if v < v_in:
            segs.append(ramp(t, x, v_in, v, r_down))
    if segs:
        t, x = segs[-1].end
    rest = x0 + length - x
    if rest > 0:
        segs.append(cruise(t, x, v, rest))
    return segs


def _final_ramp(t: Fraction, x: Fraction, v0: Fraction, v1: Fraction, x_end: Fraction) -> Seg:
    """A linear ramp from v0 to v1 ending exactly at ``x_end``."""
    dist = x_end - x
    dt = 2 * dist * US / (v0 + v1)
    return Seg(t, t + dt, x, v0, v1)


_FINE = 2**20  #: resolution (1/_FINE Hz) of speeds below 1 Hz


def _sqrt_floor(sq: Fraction) -> Fraction:
    """A speed at most ``sqrt(sq)``: whole Hz, or finer below 1 Hz (so
    that a positive square never gives speed 0)."""
    if sq <= 0:
        return Fraction(0)
    if sq >= 1:
        return Fraction(isqrt(sq.numerator // sq.denominator))
    return Fraction(isqrt((sq * _FINE * _FINE).numerator // (sq * _FINE * _FINE).denominator),
                    _FINE)


sqrt_floor = _sqrt_floor  #: public name: the look-ahead of envelopes bounds speeds with it


def _sqrt_ceil(sq: Fraction) -> Fraction:
    """The smallest whole Hz at least ``sqrt(sq)``."""
    if sq <= 0:
        return Fraction(0)
    n = -(-sq.numerator // sq.denominator)
    r = isqrt(n)
    return Fraction(r if r * r == n else r + 1)


def first_time_at(seg: Seg, target: Fraction | int, lo: int) -> Optional[int]:
    """First integer µs ``t >= lo`` inside ``seg`` at which its travel has
    reached ``target`` pulses (``floor`` semantics: whole pulses), or None.

    At and after the segment's end ``t1`` the travel counts as ``x1`` (a
    following segment starts there and the quadratic must not be
    extrapolated: past the end of a ramp down to 0 it would fall again).
    """
    # perf: an int first (isinstance() against Fraction, an ABC, is slow)
    if type(target) is int:
        tgt = target
    else:
        tgt = -((-target.numerator) // target.denominator) if isinstance(target, Fraction) \
            else int(target)
    end = seg.t1_ceil
    if end is not None and end < lo:
        return None
    if seg.A == 0 and seg.B > 0:
        # perf: a cruise: B t + C >= tgt D is linear in t, so the first whole
        # µs is a ceiling division (what the bisection below finds: pulses()
        # floors (B t + C) / D with D > 0).  Before the end that µs is the
        # answer (the travel there is below x1, so x1 reaches tgt too); at
        # and after the end the travel counts as x1
        first = max(lo, -((seg.C - tgt * seg.D) // seg.B))
        if end is None or first < end:
            return first
        x1 = seg.x1
        return end if x1.numerator // x1.denominator >= tgt else None
    hi = end
    if hi is None:
        v = seg.v0
        if v <= 0:
            return None
        # endless cruise: travel grows linearly; solve directly, then bisect
        need = tgt - seg.travel(lo)
        if need <= 0:
            return lo
        hi = lo + int(need * US / v) + 2
    else:
        x1 = seg.x1
        if x1.numerator // x1.denominator < tgt:
            return None
    pulses = seg.pulses

    def reached(t: int) -> bool:
        if end is not None and t >= end:
            return True  # floor(x1) >= tgt was checked above
        return pulses(t) >= tgt

    if reached(lo):
        return lo
    # travel is non-decreasing inside a segment: bisect on integers
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if reached(mid):
            hi = mid
        else:
            lo = mid
    return hi
