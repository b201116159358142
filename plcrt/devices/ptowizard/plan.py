"""Motion of the PTO wizard blocks as PTO trains: ramps and constant speeds.

What it is: pure functions from speeds (pulses/s) and the ``[pto.N]``
configuration to :class:`plcrt.engine.pulse.Train` lists, the form the
CPU's multi-segment PTO hardware runs (System Manual, "Pulse Output (PLS)",
multi-segment operation: each segment's cycle changes by a fixed delta per
pulse).  The wizard's own ramp algorithm is not public; plcrt's (a decision,
docs/pto-wizard.md):

* a speed change from va to vb takes the pulses of a linear speed ramp at
  the configured rate, ``N = round(|vb² − va²| / (2·a))`` with
  ``a = (MAX_SPEED − SS_SPEED) / accel_ms`` (decel_ms when slowing down);
* the ramp is cut at speeds va, 1.2·va, 1.44·va, ... vb (each at most 20 %
  above the one before; pulses up to speed v: ``round(|v² − va²| / 2a)``);
  inside a piece the cycle changes linearly per pulse, in whole µs, from
  the piece's first to its last speed: ``Δ = round((c_b − c_a) / n)``
  (the manual's formula for a segment's delta), first cycle
  ``c_a + round(Δ / 2)``, cycles ``c = round(10⁶ / v)`` µs; a piece that
  changes by less than a µs per pulse is a constant train per whole µs
  instead (pulse i: ``round(c_a + (i + ½)·(c_b − c_a)/n)``).  Pieces of
  20 % keep the ramp's time within about 2 % of the linear ramp's (a
  single piece from 200 to 5000 pulses/s would take seven times as long);
* a start from rest begins at SS_SPEED; a change while running begins after
  the pulse in progress; a stop ends at SS_SPEED.

What it is not: no time line and no state; :mod:`.blocks` starts the trains
on the pulse output.
"""

from __future__ import annotations

from typing import Any

from ...engine.pulse import Train

#: pulses of a "continuous" train: 10¹⁵ pulses last 317 years at 100 kHz
FOREVER = 10 ** 15


def cycle_us(speed: int) -> int:
    """The cycle of *speed* pulses/s in whole µs (halves up)."""
    return (2_000_000 + speed) // (2 * speed)


def speed_of(cycle: int) -> int:
    """The speed of a *cycle* µs pulse in whole pulses/s (halves up)."""
    return (2_000_000 + cycle) // (2 * cycle)


def _round_div(num: int, den: int) -> int:
    """num / den to the nearest integer, halves up (den > 0)."""
    return (2 * num + den) // (2 * den)


def _pulses_to(v_from: int, v: int, cfg: Any, decel: bool) -> int:
    """Pulses of the linear speed ramp from *v_from* up or down to *v*."""
    ms = cfg.decel_ms if decel else cfg.accel_ms
    span = cfg.max_speed - cfg.ss_speed
    if ms == 0 or span <= 0:
        return 0
    return _round_div(abs(v * v - v_from * v_from) * ms, 2000 * span)


def ramp_pulses(v_from: int, v_to: int, cfg: Any, decel: bool) -> int:
    """Pulses of the ramp from *v_from* to *v_to* (pulses/s) at the rate of
    *cfg* (accel_ms or decel_ms per MAX_SPEED − SS_SPEED); 0 for no ramp."""
    return _pulses_to(v_from, v_to, cfg, decel) if v_from != v_to else 0


def ramp(v_from: int, v_to: int, cfg: Any, segment: int) -> list[Train]:
    """The ramp from *v_from* to *v_to* as trains (start times 0: see
    :func:`_chain`): pieces of at most 20 % speed change, each linear in
    cycle per pulse."""
    decel = v_to < v_from
    lo, hi = min(v_from, v_to), max(v_from, v_to)
    points = [lo]
    while points[-1] < hi:
        points.append(min(hi, max(points[-1] + 1, points[-1] * 6 // 5)))
    if decel:
        points.reverse()
    out = []
    done, va = 0, points[0]
    for vb in points[1:]:
        upto = _pulses_to(v_from, vb, cfg, decel)
        n = upto - done
        if n <= 0:
            continue            # no pulse yet: the piece goes on to the next speed
        out += _piece(cycle_us(va), cycle_us(vb), n, segment)
        done, va = upto, vb
    return out


def _piece(ca: int, cb: int, n: int, segment: int) -> list[Train]:
    """*n* pulses whose cycle goes linearly from *ca* to *cb* µs.  A change
    of at least a µs per pulse is one train, ``Δ = round((cb − ca) / n)``;
    a slower one (a whole µs would overshoot) is one constant train per
    whole µs, pulse i taking the cycle round(ca + (i + ½)·(cb − ca)/n)."""
    d = cb - ca
    if abs(d) >= n:
        delta = _round_div(d, n)
        return [Train(0, n, ca + _round_div(delta, 2), delta, segment)]
    k = abs(d)
    step = 1 if d > 0 else -1
    out, below = [], 0
    for j in range(k + 1):
        # pulses i with (i + ½)/n < (j + ½)/k: cycles rounded to ca + step·j or less far
        upto = n if j == k else min(n, max(0, -(-(n * (2 * j + 1) - k) // (2 * k))))
        if upto > below:
            out.append(Train(0, upto - below, ca + step * j, 0, segment))
            below = upto
    return out


def _chain(trains: list[Train], start: int) -> list[Train]:
    """Lay *trains* (their start times ignored) end to end from *start*."""
    t = start
    for tr in trains:
        tr.shift(t - tr.start)
        t = tr.end
    return trains


def profile_trains(start: int, cfg: Any, profile: Any) -> list[Train]:
    """A wizard profile from rest at *start*; each train's segment is its
    step (C_Step).  Relative: each step's pulses hold its ramp in (from the
    previous speed) and, for the last step, the stop; continuous: the ramp
    to the speed, then pulses without end."""
    if profile.mode == "continuous":
        return continuous_trains(start, cfg, profile.speed)
    ss = cfg.ss_speed
    out: list[Train] = []
    prev = ss
    steps = profile.steps
    for i, step in enumerate(steps):
        c = cycle_us(step.speed)
        n_in = ramp_pulses(prev, step.speed, cfg, decel=step.speed < prev)
        n_out = ramp_pulses(step.speed, ss, cfg, decel=True) if i == len(steps) - 1 else 0
        out += ramp(prev, step.speed, cfg, i)
        const = step.pulses - n_in - n_out
        if const:
            out.append(Train(0, const, c, 0, i))
        if n_out:
            out += ramp(step.speed, ss, cfg, i)
        prev = step.speed
    return _chain(out, start)


def continuous_trains(start: int, cfg: Any, speed: int) -> list[Train]:
    """From rest at *start*: the ramp from SS_SPEED to *speed*, then that
    speed without end (a continuous profile, manual mode)."""
    c = cycle_us(speed)
    out = ramp(cfg.ss_speed, speed, cfg, 0)
    out.append(Train(0, FOREVER, c, 0, 0))
    return _chain(out, start)


def change_trains(start: int, c_now: int, speed: int, cfg: Any, segment: int) -> list[Train]:
    """From the cycle *c_now* (the pulse in progress ends at *start*) to
    *speed*, then at that speed without end (manual mode)."""
    out = ramp(speed_of(c_now), speed, cfg, segment)
    out.append(Train(0, FOREVER, cycle_us(speed), 0, segment))
    return _chain(out, start)


def stop_trains(start: int, c_now: int, cfg: Any, segment: int,
                total: int | None = None) -> list[Train]:
    """A decelerated stop from the cycle *c_now* (the pulse in progress ends
    at *start*) to SS_SPEED at the configured rate.  With *total* (PTOx_ADV)
    exactly *total* more pulses: the speed is held, then the same ramp."""
    v_now = speed_of(c_now)
    down = ramp(v_now, cfg.ss_speed, cfg, segment) if v_now > cfg.ss_speed else []
    out: list[Train] = []
    if total is not None:
        # the plant's stop_pulses cover the ramp from the profile's speed
        # (config.py checks it), and the speed now is not above it
        hold = total - sum(tr.count for tr in down)
        if hold > 0:
            out.append(Train(0, hold, c_now, 0, segment))
    return _chain(out + down, start)
