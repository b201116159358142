"""The modes of operation of a simulated CiA 402 drive (HCFA §7.5, §7.6).

What it is: one engine per mode the HCFA drive supports (6502h = 0xA5):
:class:`ProfilePosition` (PP, 1), :class:`ProfileVelocity` (PV, 3),
:class:`Homing` (HM, 6; the geometry is a :class:`~.homing_plan.HomingPlan`)
and :class:`CyclicPosition` (CSP, 8).  Each turns controlword bits 4–8 and
its objects into motion of the drive's :class:`~.axis.Axis` and reports the
mode's statusword bits 8 and 10–15.

What it is not: no power state machine and no time loop.  The
:class:`~.drive.Drive` calls an engine only in OPERATION ENABLED (``enable``,
``controlword``, ``parameter``, ``cycle``), tells it when the axis comes to
rest (``motion_end``) or reaches a limit switch (``limit``), and asks it for
its bits.  Engines read objects through ``drive.param`` and log through
``drive.note`` (every refusal names the object, the value and the section);
what they use of the drive is :class:`~.drive_view.ModeDrive`.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Optional

from .drive_view import ModeDrive
from .homing import homing_status
from .homing_plan import HomingPlan, HomingRequest, HomingStep, Watch
from .store import key


__all__ = ["Mode", "NoMode", "ProfilePosition", "ProfileVelocity", "Homing",
           "CyclicPosition", "MODE_NAMES"]

MODE_NAMES = {0: "no mode", 1: "PP", 3: "PV", 6: "HM", 8: "CSP"}

NEW_SETPOINT, CHANGE_IMMEDIATELY, RELATIVE, HALT = 0x10, 0x20, 0x40, 0x100  # HCFA §7.4.1
B8, B10, B11, B12, B13, B14, B15 = 0x100, 0x400, 0x800, 0x1000, 0x2000, 0x4000, 0x8000
_K6065, _K607A, _K6080 = key(0x6065, 0), key(0x607A, 0), key(0x6080, 0)


class Mode:
    """Base engine: no motion of its own, the idle statusword."""

    number = 0
    #: Whether the engine acts on written objects (overrides :meth:`parameter`);
    #: set for each subclass by ``__init_subclass__``.
    takes_parameters = False

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        # perf: the drive stores a received object without its write hook
        # when the engine has no parameter() of its own
        cls.takes_parameters = cls.parameter is not Mode.parameter

    def __init__(self, drive: ModeDrive) -> None:
        self.d = drive
        self.limit_stop = False

    def enable(self, t: int) -> None:
        """OPERATION ENABLED entered (transition 4 or 16) or mode selected in it."""
        self.limit_stop = False

    def disable(self, t: int) -> None:
        """OPERATION ENABLED left, or another mode selected; the axis is stopped."""

    def controlword(self, t: int, old: int, new: int) -> None:
        """Controlword written in OPERATION ENABLED."""

    def parameter(self, t: int, index: int, sub: int) -> None:
        """A master wrote an object (SDO or PDO)."""

    def cycle(self, t: int) -> None:
        """One bus cycle at *t* (after the RxPDO image is applied)."""

    def motion_end(self, t: int) -> None:
        """The axis's plan is over at *t*."""
        self.d.axis.settle(t)

    def limit(self, t: int, which: str) -> None:
        """A hardware limit switch became active while moving toward it:
        stop on the quick-stop deceleration 6085h (0: at once), bits 8 and 11."""
        self.limit_stop = True
        dec = self.d.param(0x6085)
        self.d.axis.stop(t, dec)
        self.d.note(t, "HCFA §7.4.2, §7.5.3 note 1",
                    f"{which} active at count {self.d.axis.position(t)}: motion toward it stops "
                    f"on 6085h = {dec} P/s²" + (" (0: at once)" if dec == 0 else "")
                    + "; bits 8 (abnormal stop) and 11 (limit) set; motion away is allowed")

    def bits(self, t: int) -> Optional[int]:
        """Statusword bits 8, 10–15 (None: the HCFA §7.3 idle value)."""
        return None

    def _limit_bits(self, t: int) -> int:
        return (B11 if self.d.limit_active(t) else 0) | (B8 if self.limit_stop else 0)


def capped_ramps(d: ModeDrive, t: int, acc: int, dec: int, acc_name: str,
                 dec_name: str) -> tuple[int, int]:
    """*acc* and *dec* limited to 60C5h / 60C6h (max acceleration /
    deceleration, HCFA §7.5.1: they act in PP and HM), with a note."""
    for name, value, cap_index, cap_name in ((acc_name, acc, 0x60C5, "60C5h (max acceleration)"),
                                             (dec_name, dec, 0x60C6, "60C6h (max deceleration)")):
        cap = d.param(cap_index)
        if cap == 0:
            # a zero limit would never move: taken as no limit (docs/cia402.md decisions)
            d.note(t, "HCFA §7.5.1", f"{cap_name} = 0 is no limit (a ramp at 0 never moves)")
        elif value > cap:
            d.note(t, "HCFA §7.5.1", f"{name} = {value} P/s² above {cap_name} = {cap}: "
                   "limited to it")
            if cap_index == 0x60C5:
                acc = cap
            else:
                dec = cap
    return acc, dec


def homing_limits(d: ModeDrive, t: int, req: HomingRequest) -> HomingRequest:
    """The homing speeds limited to 6080h (max motor speed) and 609Ah to
    60C5h / 60C6h (HCFA §7.5.1, §7.5.4: 6080h and 60C5h/60C6h act in HM;
    609Ah is both ramps of a homing, so the lower of the two caps it)."""
    v_max = d.param(0x6080)
    fast, slow = min(req.fast, v_max), min(req.slow, v_max)
    if (fast, slow) != (req.fast, req.slow):
        d.note(t, "HCFA §7.5.1, §7.5.4", f"homing speeds 6099h:01 = {req.fast}, 6099h:02 = "
               f"{req.slow} P/s limited to 6080h (max motor speed) = {v_max}")
    acc, dec = capped_ramps(d, t, req.accel, req.accel, "609Ah", "609Ah")
    accel = min(acc, dec)
    if (fast, slow, accel) == (req.fast, req.slow, req.accel):
        return req
    return replace(req, fast=fast, slow=slow, accel=accel)


class NoMode(Mode):
    """6061h = 0 (Kinco's default): nothing moves."""


class ProfilePosition(Mode):
    """PP: set-points by the bit 4 handshake, one buffered (HCFA §7.5.3)."""

    number = 1

    def __init__(self, drive: ModeDrive) -> None:
        super().__init__(drive)
        self.target = 0
        self.pending: Optional[tuple[int, int, int, int]] = None
        self.profile = (0, 0, 0)
        self.ack = self.halted = self.busy = self.param_zero = False

    def enable(self, t: int) -> None:
        super().enable(t)
        self.target = self.d.axis.position(t)
        self.pending, self.busy = None, False
        self.ack = self.param_zero = False
        self.halted = bool(self.d.controlword & HALT)

    def disable(self, t: int) -> None:
        self.pending, self.busy, self.ack = None, False, False

    def controlword(self, t: int, old: int, new: int) -> None:
        if (new ^ old) & HALT:
            self._halt(t, bool(new & HALT))
        if new & NEW_SETPOINT and not old & NEW_SETPOINT:
            self._new_setpoint(t, new)
        self._update_ack(new)

    def _update_ack(self, cw: int) -> None:
        # bit 12 clears once bit 4 is back to 0 and the buffer is free (§7.5.3 note 2)
        if self.ack and not cw & NEW_SETPOINT and self.pending is None:
            self.ack = False

    def _new_setpoint(self, t: int, cw: int) -> None:
        d = self.d
        v, acc, dec = d.param(0x6081), d.param(0x6083), d.param(0x6084)
        raw = d.param(0x607A)
        if 0 in (v, acc, dec):
            self.param_zero = True
            zero = [n for n, x in (("6081h", v), ("6083h", acc), ("6084h", dec)) if x == 0]
            d.note(t, "HCFA §7.5.3 bit 14",
                   f"set-point 607Ah = {raw} refused: {', '.join(zero)} = 0 (6081h = {v}, 6083h "
                   f"= {acc}, 6084h = {dec}); statusword bit 14 set until a set-point is taken")
            return
        v_max = d.param(0x6080)
        if v_max == 0:
            self.param_zero = True
            d.note(t, "HCFA §7.5.1", f"set-point 607Ah = {raw} refused: 6080h (max motor speed) "
                   "= 0")
            return
        if v > v_max:
            d.note(t, "HCFA §7.5.1", f"6081h = {v} P/s above 6080h = {v_max}: limited to 6080h")
            v = v_max
        acc, dec = capped_ramps(d, t, acc, dec, "6083h", "6084h")
        immediate = bool(cw & CHANGE_IMMEDIATELY)
        if self.pending is not None and not immediate:
            d.note(t, "HCFA §7.5.3 bit 12",
                   f"set-point 607Ah = {raw} refused: the buffer holds one set-point "
                   f"(target {self.pending[0]}) and bit 5 (change immediately) is 0; wait for "
                   "bit 12 to fall")
            return
        base = self.target if (self.busy or self.pending) else d.axis.position(t)
        relative = bool(cw & RELATIVE)
        target = base + raw if relative else raw
        pos = d.axis.position(t)
        toward = d.limit_toward(t, 1 if target > pos else -1) if target != pos else None
        if toward and not self.busy:
            d.note(t, "HCFA §7.4.2 bit 11",
                   f"set-point 607Ah = {raw} ({'relative' if relative else 'absolute'}, target "
                   f"{target}) refused: {toward} is active and the target lies beyond it")
            return
        self.param_zero = False
        self.ack = True
        how = f"{'relative' if relative else 'absolute'} set-point 607Ah = {raw} -> target {target}"
        if immediate or not self.busy:
            self.pending = None
            self._start(t, target, (v, acc, dec))
            d.note(t, "HCFA §7.5.3", f"{how} taken{' at once (bit 5)' if immediate else ''}")
        else:
            self.pending = (target, v, acc, dec)
            d.note(t, "HCFA §7.5.3", f"{how} buffered; it starts when target {self.target} "
                   "is reached")

    def _start(self, t: int, target: int, profile: tuple[int, int, int]) -> None:
        self.target, self.profile, self.busy = target, profile, True
        self.limit_stop = False
        if not self.halted:
            self.d.axis.go_to(t, target, *profile)

    def _halt(self, t: int, on: bool) -> None:
        self.halted = on
        if on:
            self.d.axis.stop(t, self.d.param(0x6084))
            self.d.note(t, "HCFA §7.4.1 bit 8", "halt: the axis stops on 6084h; the set-point "
                        "resumes when bit 8 returns to 0")
        elif self.busy:
            self.d.axis.go_to(t, self.target, *self.profile)

    def motion_end(self, t: int) -> None:
        self.d.axis.settle(t)
        if self.halted or self.limit_stop:
            return
        if self.pending is not None:
            target, v, acc, dec = self.pending
            self.pending = None
            self._start(t, target, (v, acc, dec))
            self._update_ack(self.d.controlword)
        else:
            self.busy = False

    def limit(self, t: int, which: str) -> None:
        super().limit(t, which)
        self.pending, self.busy = None, False
        self._update_ack(self.d.controlword)

    def bits(self, t: int) -> int:
        moving = self.d.axis.moving(t)
        at_rest_done = not moving and self.pending is None and (
            not self.busy or self.halted or self.d.axis.position(t) == self.target)
        b = self._limit_bits(t) | (B8 if self.halted else 0)
        b |= B10 if at_rest_done else 0
        b |= B12 if self.ack else 0
        b |= B14 if self.param_zero else 0
        stops = self.d.stops
        if stops is not None and stops.over is not None \
                and self.d.sm.personality.pp_following_error_bit13:
            b |= B13                       # Kinco §2.6: |60F4h| beyond 6065h (stops.py)
        if not self.ack and not self.halted:
            b |= B15                       # HCFA §7.5.3: bit 15 = NOT bit 12
        return b


class ProfileVelocity(Mode):
    """PV: 60FFh with 6083h / 6084h ramps, runs as soon as enabled (HCFA §7.6)."""

    number = 3

    def __init__(self, drive: ModeDrive) -> None:
        super().__init__(drive)
        self.v_target = 0
        self._key: Optional[tuple[int, int, int]] = None

    def enable(self, t: int) -> None:
        super().enable(t)
        self._key = None
        self._plan(t)

    def disable(self, t: int) -> None:
        self._key, self.v_target = None, 0

    def controlword(self, t: int, old: int, new: int) -> None:
        if (new ^ old) & HALT:
            self._plan(t)

    def parameter(self, t: int, index: int, sub: int) -> None:
        if index in (0x60FF, 0x6083, 0x6084, 0x6080):
            self._plan(t)

    def _plan(self, t: int) -> None:
        d = self.d
        vt = d.param(0x60FF)
        v_max = d.param(0x6080)
        if abs(vt) > v_max:
            vt = v_max if vt > 0 else -v_max
        if d.controlword & HALT:
            vt = 0
        if vt and d.limit_toward(t, 1 if vt > 0 else -1):
            vt = 0
        else:
            self.limit_stop = False
        key = (vt, d.param(0x6083), d.param(0x6084))
        if key == self._key:
            return
        self._key, self.v_target = key, vt
        d.axis.run_at(t, vt, key[1], key[2])

    def limit(self, t: int, which: str) -> None:
        super().limit(t, which)
        self._key, self.v_target = (0, -1, -1), 0

    def bits(self, t: int) -> int:
        v = self.d.axis.exact(t)[1]
        b = self._limit_bits(t) | (B8 if self.d.controlword & HALT else 0)
        b |= B10 if v == self.v_target else 0
        b |= B12 if v == 0 or self.v_target == 0 else 0
        return b


class CyclicPosition(Mode):
    """CSP: 607Ah taken every bus cycle and reached one cycle later at most
    at 6080h; following error 6065h / 6066h (HCFA §7.5.1, CiA 402)."""

    number = 8

    def __init__(self, drive: ModeDrive) -> None:
        super().__init__(drive)
        self.demand = 0
        self.following_error = 0
        self._fe_since: Optional[int] = None
        self._last: Optional[int] = None

    def enable(self, t: int) -> None:
        super().enable(t)
        self.demand = self.d.axis.position(t)
        self.following_error, self._fe_since, self._last = 0, None, None

    def disable(self, t: int) -> None:
        self.following_error, self._fe_since, self._last = 0, None, None

    def cycle(self, t: int) -> None:
        d = self.d
        ax = d.axis
        mech = ax.mechanical(t)
        pos = mech + ax.shift                      # axis.position(t)
        fe = self.demand - pos
        self.following_error = fe
        # perf: the integer objects read from the store's values directly
        # (what d.param does first), d.param for anything else
        live = d._live
        window = live.get(_K6065)
        if window.__class__ is not int:
            window = d.param(0x6065)
        if fe > window or -fe > window:
            if self._fe_since is None:
                self._fe_since = t
            limit_us = d.param(0x6066) * 1000
            if t - self._fe_since >= limit_us:
                d.fault(t, 0x8611, None,
                        f"following error 60F4h = {fe} beyond 6065h = {window} for "
                        f"{(t - self._fe_since) / 1000:g} ms (6066h = {d.param(0x6066)} ms)")
                return
        else:
            self._fe_since = None
        period = t - self._last if self._last is not None else d.bus_period_us()
        self._last = t
        target = live.get(_K607A)
        if target.__class__ is not int:
            target = d.param(0x607A)
        v_max = live.get(_K6080)
        if v_max.__class__ is not int:
            v_max = d.param(0x6080)
        plant = d.plant
        if plant.pos_limit is None and plant.neg_limit is None:
            # perf: no limit switch, so none is active or lies ahead
            # (d.limit_toward and d.limit_active say so then)
            self.limit_stop = False
        else:
            if target != pos and d.limit_toward(t, 1 if target > pos else -1):
                self.limit_stop = True
                self.demand = target
                return
            if not d.limit_active(t):
                self.limit_stop = False
        ax.linear(t, t + (period if period > 1 else 1), target, v_max, mech)
        self.demand = target

    def bits(self, t: int) -> int:
        d = self.d
        plant = d.plant
        if plant.pos_limit is None and plant.neg_limit is None:
            b = (B8 if self.limit_stop else 0) | B12   # perf: _limit_bits, no switch to ask
        else:
            b = self._limit_bits(t) | B12
        b |= 0 if d.axis.moving(t) else B10
        b |= B13 if self._fe_since is not None else 0
        return b


class Homing(Mode):
    """HM: bit 4 starts a :class:`HomingPlan` (HCFA §7.5.4)."""

    number = 6

    def __init__(self, drive: ModeDrive) -> None:
        super().__init__(drive)
        self.plan: Optional[HomingPlan] = None
        self.status = "idle"       # idle running attained error interrupted halted
        self.watches: tuple[Watch, ...] = ()
        self.deadline: Optional[int] = None
        self.param_zero = False

    def enable(self, t: int) -> None:
        super().enable(t)
        self._end("idle")

    def disable(self, t: int) -> None:
        self._end("idle")

    def _end(self, status: str) -> None:
        self.plan, self.status, self.watches, self.deadline = None, status, (), None

    def controlword(self, t: int, old: int, new: int) -> None:
        d = self.d
        if new & HALT and not old & HALT and self.status == "running":
            d.axis.stop(t, d.param(0x609A))
            self._end("halted")
            d.note(t, "HCFA §7.4.1 bit 8", "halt: homing stops on 609Ah and is abandoned")
        if new & NEW_SETPOINT and not old & NEW_SETPOINT:
            self._start(t)
        elif old & NEW_SETPOINT and not new & NEW_SETPOINT and self.status == "running":
            d.axis.stop_at_once(t)
            self._end("interrupted")
            d.note(t, "HCFA §7.5.4", "bit 4 1->0 during homing: the motor stops at once")

    def _start(self, t: int) -> None:
        d = self.d
        method = d.param(0x6098)
        req = HomingRequest(d.model, method, d.param(0x6099, 1), d.param(0x6099, 2),
                            d.param(0x609A), d.param(0x607C), d.axis.position(t),
                            d.axis.mechanical(t), t, d.plant,
                            offset_mode=d.param(0x6099, 5), blind_zone=d.param(0x6099, 6),
                            timeout_ms=d.param(0x2003, 7),
                            following_error_window=d.param(0x6065),
                            max_current=d.param(0x6099, 4), velocity_window=d.param(0x60F9, 10))
        req = homing_limits(d, t, req)
        zero = [n for n, x in (("6098h", method), ("6099h:01", req.fast),
                               ("6099h:02", req.slow), ("609Ah", req.accel))
                if x == 0 and (n != "6098h" or 0 not in d.homing_plans)]
        if zero and method not in (35, 37):
            self.param_zero = True
            d.note(t, "HCFA §7.5.4 bit 14", f"homing method {method} refused: "
                   f"{', '.join(zero)} = 0; statusword bit 14 set")
            return
        self.param_zero = False
        factory = d.homing_plans.get(method)
        if factory is None:
            self._end("error")
            d.fault(t, 62, 62, f"6098h = {method} is not a homing method this drive simulates "
                    f"(simulated: {sorted(d.homing_plans)})")
            return
        self.plan, self.status = factory(), "running"
        d.sm.homed = False      # Kinco §2.6: bit 15 clears when a new homing starts
        limit_ms = d.param(0x2003, 7)
        self.deadline = t + limit_ms * 1000 if limit_ms else None
        d.note(t, "HCFA §7.5.4", f"homing method {method} started at count {req.position}")
        self._apply(t, self.plan.start(req))

    def _apply(self, t: int, step: HomingStep) -> None:
        d = self.d
        if step.note:
            d.note(t, "HCFA §7.5.4", step.note)
        if step.fault is not None:
            d.axis.stop_at_once(t)
            self._end("error")
            d.fault(t, *step.fault)
            return
        if step.outcome == "attained":
            home = step.home_position if step.home_position is not None else d.axis.position(t)
            d.axis.set_position(t, home)
            self._end("attained")
            d.sm.homed = True
            return
        if step.outcome == "error":
            d.axis.stop_at_once(t)
            self._end("error")
            return
        m = step.motion
        if m is not None and m.kind == "position" and m.speed <= 0:
            d.axis.stop_at_once(t)
            self._end("error")
            d.note(t, "HCFA §7.5.4", f"homing plan asked for a move to {m.value} at speed "
                   f"{m.speed}: a positioning needs a positive speed; homing error")
            return
        if m is not None:
            if m.from_rest:
                d.axis.stop_at_once(t)
            if m.kind == "velocity":
                d.axis.run_at(t, m.value, m.accel, m.accel)
            elif m.kind == "position":
                d.axis.go_to(t, m.value, m.speed, m.accel, m.accel, mechanical=True)
            else:
                d.axis.stop(t, m.accel)
        self.watches = step.watches

    def motion_end(self, t: int) -> None:
        self.d.axis.settle(t)
        if self.plan is not None:
            self._apply(t, self.plan.event("stopped", t, self.d.axis.mechanical(t)))

    def watch_hit(self, t: int, watch: Watch) -> None:
        if self.plan is not None:
            self._apply(t, self.plan.event(watch.name, t, self.d.axis.mechanical(t)))

    def timeout(self, t: int) -> None:
        self.d.axis.stop_at_once(t)
        self._end("error")
        self.d.fault(t, 63, 63, f"homing not done within P03.07 = {self.d.param(0x2003, 7)} ms")

    def limit(self, t: int, which: str) -> None:   # pragma: no cover - not armed in HM
        pass

    def bits(self, t: int) -> Optional[int]:
        z = B14 if self.param_zero else 0
        if self.status == "idle":
            return None if not z else (self.d.idle_mode_bits() | z)
        state = {"running": "running", "attained": "done", "error": "failed",
                 "interrupted": "aborted", "halted": "aborted"}[self.status]
        bits = homing_status(self.d.model, state, self.d.sm.homed)
        if self.status == "halted":        # §7.3 halt word 0x0737: bit 8, bit 15 clear
            bits = (bits & ~B15) | B8
        return z | bits
