"""Exact pulse kinematics of plcrt.devices.motion: unit and property tests.

Every check is done in exact rational arithmetic against the definition of
a segment (x = x0 + v0 (t - t0) + a (t - t0)^2 / 2, speeds in Hz, times in
µs), independently of the integer polynomial the module stores:

* plans are contiguous (time, travel and speed continuous), cover exactly
  the requested distance, keep their speeds within the allowed band and
  never change speed faster than the given rates (EM253 manual note 3:
  the rate is (SpdSet - SpdSs) / AccTime);
* ``first_time_at`` returns the first whole microsecond at which the whole
  pulses travelled reach a target (brute force on small cases).
"""

from __future__ import annotations

from fractions import Fraction
from math import floor
from typing import Optional

import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from plcrt.devices.motion import (US, Seg, cruise, first_time_at, plan_distance, plan_hold,
                                  ramp, ramp_distance)

F = Fraction
SETTINGS = settings(max_examples=300, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


# -- an independent model of a segment --------------------------------------
def accel(s: Seg) -> Fraction:
    """Acceleration in Hz per µs from the segment's end points."""
    if s.t1 is None or s.t1 == s.t0:
        return F(0)
    return (s.v1 - s.v0) / (s.t1 - s.t0)


def exact_travel(s: Seg, t: Fraction | int) -> Fraction:
    """Travel by definition; at and after the end it stays at the end value."""
    if s.t1 is not None and t >= s.t1:
        t = s.t1
    dt = F(t) - s.t0
    return s.x0 + s.v0 * dt / US + accel(s) * dt * dt / (2 * US)


def exact_speed(s: Seg, t: Fraction | int) -> Fraction:
    return s.v0 + accel(s) * (F(t) - s.t0)


def whole_pulses(s: Seg, lo: int, hi: int) -> list[int]:
    """floor(travel) at every µs of [lo, hi] by definition, in integers:
    with dt = t - t0, travel = x0 + v0 dt / US + a dt^2 / (2 US), clamped
    to x1 at and after t1."""
    a = accel(s)
    # travel as c2 t^2 + c1 t + c0 over one denominator (expanding dt)
    c2 = a / (2 * US)
    c1 = s.v0 / US - a * s.t0 / US
    c0 = s.x0 - s.v0 * s.t0 / US + a * s.t0 * s.t0 / (2 * US)
    den = c2.denominator * c1.denominator * c0.denominator
    n2, n1, n0 = (int(c * den) for c in (c2, c1, c0))
    assert s.t1 is not None
    end = floor(s.x1)
    return [end if t >= s.t1 else (n2 * t * t + n1 * t + n0) // den for t in range(lo, hi + 1)]


def check_plan(segs: list[Seg], t0: Fraction, x0: Fraction, v_in: Fraction,
               length: Fraction, v_lo: Fraction, v_hi: Fraction,
               r_up: Fraction, r_down: Fraction) -> None:
    """Contiguity, exact length, the speed band and the rate limits."""
    assert segs, "a positive length needs at least one segment"
    t, x, v = t0, x0, v_in
    for s in segs:
        assert s.t1 is not None
        assert (s.t0, s.x0, s.v0) == (t, x, v), "segments must be contiguous"
        assert s.t1 >= s.t0
        # the stored integer polynomial agrees with the definition
        assert s.travel(s.t0) == s.x0
        assert s.x1 == exact_travel(s, s.t1)
        assert s.speed(s.t0) == s.v0 and s.speed(s.t1) == s.v1
        for w in (s.v0, s.v1):
            assert v_lo <= w <= v_hi, f"speed {w} outside [{v_lo}, {v_hi}]"
        dt = s.t1 - s.t0
        if s.v1 > s.v0:
            assert s.v1 - s.v0 <= r_up * dt, "accelerates faster than the rate"
        elif s.v1 < s.v0:
            assert s.v0 - s.v1 <= r_down * dt, "decelerates faster than the rate"
        if dt > 0:
            assert s.v0 + s.v1 > 0, "a segment with duration must move"
        t, x, v = s.t1, s.x1, s.v1
    assert x == x0 + length, f"travel {x - x0} != length {length}"


# -- strategies ---------------------------------------------------------------
speeds = st.integers(0, 500_000)
positive_speeds = st.integers(1, 500_000)


@st.composite
def rates(draw: st.DrawFn) -> Fraction:
    """(SpdSet - SpdSs) / (AccTime ms): Hz per µs, as the blocks compute it."""
    return F(draw(st.integers(1, 500_000)), 1000 * draw(st.integers(1, 65_535)))


@st.composite
def maybe_fractional(draw: st.DrawFn, base: st.SearchStrategy[int]) -> Fraction:
    """Mostly whole numbers; sometimes a rational (a speed or travel read
    in the middle of a ramp)."""
    v = F(draw(base))
    if draw(st.booleans()) and v > 0:
        v -= F(draw(st.integers(1, 996)), 997)
    return v


@st.composite
def starts(draw: st.DrawFn) -> tuple[Fraction, Fraction]:
    t0 = draw(maybe_fractional(st.integers(0, 10**8)))
    x0 = draw(maybe_fractional(st.integers(0, 10**7)))
    return t0, x0


# -- plan_distance ------------------------------------------------------------
@SETTINGS
@given(start=starts(), v_in=maybe_fractional(speeds), v_max=positive_speeds,
       v_end_frac=st.fractions(0, 1), length=maybe_fractional(st.integers(1, 3_000_000)),
       r_acc=rates(), r_dec=rates())
@example(start=(F(0), F(0)), v_in=F(100_000), v_max=100_000, v_end_frac=F(1, 20),
         length=F(1000), r_acc=F(1, 10), r_dec=F(1, 10))       # cannot slow down to v_end
@example(start=(F(0), F(0)), v_in=F(0), v_max=1000, v_end_frac=F(0), length=F(7),
         r_acc=F(1, 1000), r_dec=F(1, 1000))                   # stop at 0 Hz
@example(start=(F(0), F(0)), v_in=F(0), v_max=1, v_end_frac=F(0), length=F(1),
         r_acc=F(1, 65_535_000), r_dec=F(1, 65_535_000))       # peak below 1 Hz
def test_plan_distance_properties(start: tuple[Fraction, Fraction], v_in: Fraction,
                                  v_max: int, v_end_frac: Fraction, length: Fraction,
                                  r_acc: Fraction, r_dec: Fraction) -> None:
    """Exact length, contiguity, speed band, rates; the end speed is reached
    whenever the distance allows it, and the peak is the highest whole Hz
    the distance allows."""
    t0, x0 = start
    v_end = F(floor(v_max * v_end_frac))
    vm = F(v_max)
    segs, ok = plan_distance(t0, x0, v_in, vm, v_end, length, r_acc, r_dec)
    lo, hi = min(v_in, v_end), max(v_in, vm)
    check_plan(segs, t0, x0, v_in, length, lo, hi, r_acc, r_dec)
    if v_in <= vm:
        assert max(s.v1 for s in segs) <= vm
    last = segs[-1].v1
    if v_in > v_end:
        reachable = ramp_distance(v_in, v_end, r_dec) <= length
    else:
        reachable = ramp_distance(v_in, v_end, r_acc) <= length
    assert ok == reachable
    if ok:
        assert last == v_end
    elif v_in > v_end:
        # slowed down as far as possible, to within 1 Hz
        exact_sq = v_in * v_in - 2 * r_dec * length * US
        assert v_end < last and (last - 1) ** 2 < exact_sq <= last * last
    else:
        exact_sq = v_in * v_in + 2 * r_acc * length * US
        assert last < v_end and last * last <= exact_sq
    if ok and v_in < vm:
        peak = max(max(s.v0, s.v1) for s in segs)
        peak_sq = (2 * length * US * r_acc * r_dec + r_dec * v_in * v_in
                   + r_acc * v_end * v_end) / (r_acc + r_dec)
        assert peak == vm or (peak + 1) ** 2 > peak_sq, "the peak is lower than it must be"


def test_plan_distance_manual_example_profile() -> None:
    """Manual 3.2.5 example: 5 kHz -> 80 kHz in 4800 ms, 1 000 000 pulses.

    Ramp rate (80000 - 5000) / 4800 ms; each ramp covers
    (5000 + 80000) / 2 * 4.8 s = 204 000 pulses; the cruise the rest."""
    r = F(75_000, 4_800_000)
    segs, ok = plan_distance(F(0), F(0), F(5000), F(80_000), F(5000), F(1_000_000), r, r)
    assert ok
    assert [(s.v0, s.v1) for s in segs] == [(5000, 80_000), (80_000, 80_000), (80_000, 5000)]
    assert [s.end[0] - s.t0 for s in segs] == [4_800_000, F(592_000 * US, 80_000), 4_800_000]
    assert segs[0].x1 == 204_000 and segs[-1].x1 == 1_000_000


def test_plan_distance_cannot_stop_in_time_travels_exactly_length() -> None:
    """Regression: a too-short distance from a high speed overshot the
    length (the reachable speed was rounded down, i.e. a longer ramp)."""
    segs, ok = plan_distance(F(0), F(0), F(100_000), F(100_000), F(5000), F(1000),
                             F(1, 10), F(1, 10))
    assert not ok
    assert segs[-1].x1 == 1000
    assert segs[-1].v0 - segs[-1].v1 <= F(1, 10) * (segs[-1].end[0] - segs[-1].t0)


def test_plan_distance_below_end_speed_is_not_overshot() -> None:
    """Regression: starting below v_end with a short distance ran a full
    ramp to v_end (12 500 pulses for a 10-pulse move)."""
    segs, ok = plan_distance(F(0), F(0), F(0), F(100_000), F(50_000), F(10), F(1, 10),
                             F(1, 10))
    assert not ok and segs[-1].x1 == 10 and segs[-1].v1 < 50_000


def test_plan_distance_end_speed_above_max_is_clamped() -> None:
    segs, ok = plan_distance(F(0), F(0), F(1000), F(2000), F(5000), F(100_000), F(1), F(1))
    assert ok and segs[-1].x1 == 100_000
    assert max(s.v1 for s in segs) == 2000 and segs[-1].v1 == 2000


def test_plan_distance_zero_length_and_bad_speed() -> None:
    assert plan_distance(F(0), F(0), F(0), F(10), F(0), F(0), F(1), F(1)) == ([], True)
    with pytest.raises(ValueError):
        plan_distance(F(0), F(0), F(0), F(0), F(0), F(5), F(1), F(1))


# -- plan_hold ------------------------------------------------------------------
@SETTINGS
@given(start=starts(), v_in=maybe_fractional(speeds), v_target=positive_speeds,
       length=maybe_fractional(st.integers(1, 3_000_000)), r_up=rates(), r_down=rates())
@example(start=(F(0), F(0)), v_in=F(100_000), v_target=5000, length=F(1000),
         r_up=F(1, 10), r_down=F(1, 10))      # cannot slow down to the target
@example(start=(F(0), F(0)), v_in=F(0), v_target=1, length=F(1),
         r_up=F(1, 65_535_000), r_down=F(1))  # reachable speed below 1 Hz
def test_plan_hold_properties(start: tuple[Fraction, Fraction], v_in: Fraction,
                              v_target: int, length: Fraction, r_up: Fraction,
                              r_down: Fraction) -> None:
    """Exact length, speeds between v_in and the target, rates kept; the
    target is reached when the distance allows, else within 1 Hz of the
    speed the distance allows."""
    t0, x0 = start
    vt = F(v_target)
    segs = plan_hold(t0, x0, v_in, vt, length, r_up, r_down)
    check_plan(segs, t0, x0, v_in, length, min(v_in, vt), max(v_in, vt), r_up, r_down)
    last = segs[-1].v1
    if vt > v_in:
        if ramp_distance(v_in, vt, r_up) <= length:
            assert last == vt
        else:
            exact_sq = v_in * v_in + 2 * r_up * length * US
            assert last * last <= exact_sq
            assert last == v_in or (last + 1) ** 2 > exact_sq or last < 1
    elif vt < v_in:
        if ramp_distance(v_in, vt, r_down) <= length:
            assert last == vt
        else:
            exact_sq = v_in * v_in - 2 * r_down * length * US
            assert exact_sq <= last * last and (last == v_in or (last - 1) ** 2 < exact_sq)
    else:
        assert all(s.v0 == s.v1 == vt for s in segs)


def test_plan_hold_decelerating_travels_exactly_length() -> None:
    """Regression: slowing down over a too-short step overshot the step."""
    segs = plan_hold(F(0), F(0), F(100_000), F(5000), F(1000), F(1, 10), F(1, 10))
    assert segs[-1].x1 == 1000
    assert segs[-1].v1 < 100_000


def test_plan_hold_requires_a_positive_target() -> None:
    assert plan_hold(F(0), F(0), F(5), F(7), F(0), F(1), F(1)) == []
    with pytest.raises(ValueError):
        plan_hold(F(0), F(0), F(5), F(0), F(10), F(1), F(1))


# -- Seg ------------------------------------------------------------------------
@SETTINGS
@given(start=starts(), v0=maybe_fractional(speeds), v1=maybe_fractional(speeds),
       r=rates(), data=st.data())
def test_seg_integer_polynomial_is_exact(start: tuple[Fraction, Fraction], v0: Fraction,
                                         v1: Fraction, r: Fraction, data: st.DataObject) -> None:
    """pulses(t) and hz(t) are the floors of the exact travel and speed."""
    t0, x0 = start
    assume(v0 != v1)
    s = ramp(t0, x0, v0, v1, r)
    assert s.t1 is not None and s.t1_ceil is not None
    lo = -((-t0.numerator) // t0.denominator)
    assume(lo <= s.t1)
    for _ in range(5):
        t = data.draw(st.integers(lo, floor(s.t1)))
        assert s.pulses(t) == floor(exact_travel(s, t))
        assert s.hz(t) == floor(exact_speed(s, t))
        assert s.travel(t) == exact_travel(s, t)


def test_seg_cruise_and_ramp_basics() -> None:
    s = cruise(F(10), F(5), F(1000), F(3))
    assert s.t1 == 3010 and s.x1 == 8
    assert s.pulses(1009) == 5 and s.pulses(1010) == 6 and s.pulses(3010) == 8
    r = ramp(F(0), F(0), F(0), F(2000), F(1))
    assert r.t1 == 2000 and r.x1 == 2 and r.hz(1000) == 1000
    e = cruise(F(0), F(0), F(500))
    assert e.t1 is None and e.t1_ceil is None and e.pulses(2_000_000) == 1000


# -- first_time_at ----------------------------------------------------------------
@st.composite
def small_plans(draw: st.DrawFn) -> list[Seg]:
    """Short moves (a few ms) so that brute force over every µs is cheap."""
    t0, x0 = draw(starts())
    v_max = F(draw(st.integers(2_000, 500_000)))
    v_in = draw(maybe_fractional(st.integers(0, int(v_max))))
    v_end = F(draw(st.integers(0, int(v_max) - 1)))
    length = draw(maybe_fractional(st.integers(1, 12)))
    r = F(draw(st.integers(1, 500_000)), draw(st.integers(1, 2000)))
    r2 = F(draw(st.integers(1, 500_000)), draw(st.integers(1, 2000)))
    if draw(st.booleans()):
        segs, _ = plan_distance(t0, x0, v_in, v_max, v_end, length, r, r2)
    else:
        segs = plan_hold(t0, x0, v_in, v_max, length, r, r2)
    assume(len(segs) > 0 and sum(s.end[0] - s.t0 for s in segs) <= 3_000)
    return segs


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(segs=small_plans(), data=st.data())
@example(segs=plan_distance(F(0), F(0), F(0), F(1000), F(0), F(7), F(1, 1000),
                            F(1, 1000))[0], data=None)  # last pulse of a stop at 0 Hz
def test_first_time_at_matches_brute_force(segs: list[Seg],
                                           data: Optional[st.DataObject]) -> None:
    """For every segment and every whole-pulse target in it (and a
    fractional one), first_time_at equals stepping through the µs."""
    for s in segs:
        assert s.t1 is not None and s.t1_ceil is not None
        t0c = -((-s.t0.numerator) // s.t0.denominator)
        floors = whole_pulses(s, t0c, s.t1_ceil)
        los = [t0c]
        if data is not None:
            los.append(data.draw(st.integers(t0c, s.t1_ceil)))
        targets: list[Fraction | int] = list(range(floor(s.x0), floor(s.x1) + 2))
        targets.append(s.x0 + (s.x1 - s.x0) / 3)
        for lo in los:
            for target in targets:
                want = next((t0c + i for i in range(lo - t0c, len(floors))
                             if floors[i] >= target), None)
                assert first_time_at(s, target, lo) == want, (s, target, lo)


@SETTINGS
@given(t0=st.integers(0, 10**6), x0=maybe_fractional(st.integers(0, 1000)),
       v=st.integers(2000, 500_000), lo_off=st.integers(0, 3000), need=st.integers(-2, 10),
       frac=st.fractions(0, 1))
def test_first_time_at_endless_cruise(t0: int, x0: Fraction, v: int, lo_off: int, need: int,
                                      frac: Fraction) -> None:
    """An endless cruise: the answer is the first µs with enough whole pulses."""
    s = cruise(F(t0), x0, F(v))
    lo = t0 + lo_off
    target = floor(s.travel(lo)) + need + frac
    # by definition, in integers: floor(x0 + v (t - t0) / 10^6)
    p, q = x0.numerator, x0.denominator
    want = lo
    while (p * US + q * v * (want - t0)) // (q * US) < target:
        want += 1
    assert first_time_at(s, target, lo) == want


def test_first_time_at_last_pulse_of_a_stop_at_zero_hz() -> None:
    """Regression: past the end of a ramp down to 0 Hz the quadratic falls
    again, so the final pulse (at the end of the ramp) was never found."""
    segs, _ = plan_distance(F(0), F(0), F(0), F(1000), F(0), F(7), F(1, 1000), F(1, 1000))
    last = segs[-1]
    assert last.x1 == 7 and last.t1_ceil is not None
    assert first_time_at(last, 7, 0) == last.t1_ceil
    assert first_time_at(last, 8, 0) is None


def test_first_time_at_outside_the_segment() -> None:
    s = cruise(F(0), F(0), F(1000), F(10))  # ends at 10 000 µs
    assert first_time_at(s, 3, 20_000) is None
    assert first_time_at(s, 3, 0) == 3000
    assert first_time_at(s, 0, 500) == 500
    assert first_time_at(cruise(F(0), F(0), F(0)), 1, 0) is None
