"""The seven instructions of the EM253 library ``EM253_Ext_v1.0``
(EM253 user manual, chapter 3.2) as built-in blocks.

Each CALL site gets its own block object (the instance memory a library
subroutine has on the CPU).  The generated code calls it with the IN values
and writes back what it returns (see ``library/EM253_Ext_v1.0.toml``).

Common rules (manual 3.2, notes 1-5; decisions in docs/em253.md):

* MOTION_EN3 must have run for the module earlier in the same scan;
  otherwise a motion instruction does nothing and a diagnostic says why.
* InnerState must be 0 before first use; the block sets it to 257.  If the
  program changes it later the block stops its axis at once (the manual
  only says the output "will be wrong") and reports it.
* Update != 0 applies changed parameters to a running operation; the block
  clears it.  E_Stop stops the pulses at once; a new start needs a new
  rising edge of Run.  C_Status: 0 before the first run, 1 while running,
  8 once stopped.
* SpdSs must not be above SpdSet (note 4), speeds are limited by the output
  type (200 kHz single-ended, 500 kHz differential): otherwise the module's
  behaviour is kept (no start / clamped) and a diagnostic is emitted.
"""

from __future__ import annotations

from fractions import Fraction
from functools import partial
from typing import Any, Optional

from ...blocks import register_block
from ...compiler.operands import POINTER_AREA_NAMES
from ..motion import plan_distance, plan_hold, ramp_distance, sqrt_floor
from .axis import Axis, distance_plan, stop_plan, velocity_plan
from .module import EM253Module

INNER_OK = 257
ST_IDLE, ST_RUN, ST_STOPPED = 0, 1, 8
STEP_BYTES = 12   #: POS_RUN table: AccTime W, DecTime W, SpdSet D, PosSet D
MAX_STEPS = 32


def _rate(v_set: int, v_ss: int, ms: int) -> Fraction:
    """Ramp rate (Hz per µs) from note 3: (SpdSet - SpdSs) / time; a time
    below 1 ms counts as 1 ms."""
    return Fraction(max(v_set - v_ss, 1), max(ms, 1) * 1000)


class _Base:
    """Shared per-call-site logic: module lookup, InnerState, diagnostics."""

    name = ""

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        self.plc = plc
        self.loc = loc
        self.itf = itf
        self.status = ST_IDLE
        self.initialised = False
        self.prev_run = 0
        self.axis: Optional[Axis] = None
        self.module: Optional[EM253Module] = None
        self._axis_no: Optional[int] = None
        self.stopping = False
        self.last_pos = 0
        self.last_spd = 0
        self.top = 0  #: SpdSet in force (after clamping to the output limit)

    # -- helpers -----------------------------------------------------------
    def warn(self, msg: str, code: str) -> None:
        self.plc.warn(f"{self.name}: {msg}", self.loc, f"{self.name}:{code}:{id(self)}")

    def now(self) -> int:
        return self.plc.now_us

    def find(self, em_no: int, axis_no: int | None) -> bool:
        """Locate the module/axis; check that MOTION_EN3 ran this scan."""
        mod = self.module
        # perf: the same module and axis as last time, enabled in this scan
        if mod is not None and mod.slot == em_no and mod.enabled_scan == self.plc.scans \
                and self._axis_no == axis_no:
            return True
        mod = self.plc.modules.get(em_no)
        if mod is None:
            self.warn(f"no EM253 module in slot {em_no} (EmNo); configure one in the plant "
                      f"file", "nomodule")
            return False
        if axis_no is not None and axis_no not in (0, 1):
            self.warn(f"AxisNo must be 0 or 1, got {axis_no}", "axisno")
            return False
        if mod.enabled_scan != self.plc.scans:
            self.warn(f"MOTION_EN3 for slot {em_no} has not run before this instruction in "
                      f"this scan; the module ignores the instruction (call MOTION_EN3 with "
                      f"SM0.0 first)", "noen")
            return False
        self.module = mod
        self.axis = mod.axes[axis_no] if axis_no is not None else None
        self._axis_no = axis_no
        return True

    def inner(self, value: int) -> bool:
        """Check InnerState; False when the block must not run."""
        if value == INNER_OK and self.initialised:
            return True
        if not self.initialised:
            if value != 0:
                self.warn(f"InnerState must be 0 before the first call (it is {value}); "
                          f"the instruction does not run until it is cleared", "inner0")
                return False
            self.initialised = True
            return True
        if value != INNER_OK:
            moving = self.axis is not None and self.axis.moving and self.owns()
            self.warn(f"InnerState was changed by the program (reads {value}, the block "
                      f"keeps it at 257)" + ("; the axis is stopped at once" if moving else ""),
                      f"innerw{self.plc.scans}" if moving else "innerw")
            if moving:
                assert self.axis is not None
                self.axis.stop_now(self.now())
                self.status = ST_STOPPED
        return True

    def owns(self) -> bool:
        return self.axis is not None and getattr(self.axis, "owner", None) is self

    def speeds_ok(self, v_ss: int, v_set: int,
                  allow_equal: bool = False) -> Optional[tuple[int, int]]:
        """Validate speeds; returns (SpdSs, SpdSet), both limited to the
        output's maximum (2.1: 200 kHz single-ended, 500 kHz differential),
        or None when the motor does not start.

        Note 4: the start speed must be below the run speed, else the motor
        does not start (checked on the values the program gives).  An
        envelope step may run at SpdSs itself (``allow_equal``): the
        manual's own POS_RUN table ends with one.
        """
        assert self.module is not None
        if v_ss < 0 or v_set <= 0:
            self.warn(f"speeds must be positive (SpdSs {v_ss}, SpdSet {v_set})", "spdneg")
            return None
        if v_ss > v_set or (v_ss == v_set and not allow_equal):
            self.warn(f"SpdSs ({v_ss} Hz) is not below SpdSet ({v_set} Hz): the motor does "
                      f"not start (manual note 4)", "ssset")
            return None
        lim = self.module.max_hz
        if v_set > lim:
            kind = "differential" if self.module.differential else "single-ended"
            self.warn(f"SpdSet {v_set} Hz is above the {kind} output limit of {lim} Hz; "
                      f"the module runs at {lim} Hz", "maxhz")
            if v_ss > lim:
                self.warn(f"SpdSs {v_ss} Hz is above the {kind} output limit too; the "
                          f"pulses start and stop at {lim} Hz", "maxss")
            return min(v_ss, lim), lim
        return v_ss, v_set

    def limit_watch(self, direction: int) -> list:
        """Thresholds that stop the axis at a hard limit in ``direction``."""
        assert self.axis is not None
        p = self.axis.plant
        lim = p.limit_pos if direction > 0 else p.limit_neg
        if lim is None:
            return []
        return [(lim, self._hit_limit)]

    def limit_active(self, direction: int) -> bool:
        return self.limit_active_at(direction, self.now())

    def limit_active_at(self, direction: int, t: int) -> bool:
        assert self.axis is not None
        p, m = self.axis.plant, self.axis.mechanical(t)
        if direction > 0:
            return p.limit_pos is not None and m >= p.limit_pos
        return p.limit_neg is not None and m <= p.limit_neg

    def _hit_limit(self, t: int, pos: int) -> None:
        assert self.axis is not None
        self.axis.stop_now(t)
        self.status = ST_STOPPED
        self.warn(f"hard limit reached at position {pos} ({t / 1e6:.6f} s): the axis "
                  f"stopped at once", f"limit{t}")

    def begin(self, direction: int, segs: list, keep: bool = False) -> None:
        assert self.axis is not None
        ax = self.axis
        t = self.now()
        ax.owner = self
        ax.start(t, direction, segs, self._done, keep_travel=keep)
        ax.watch_positions(t, self.limit_watch(direction))
        self.status = ST_RUN
        self.stopping = False

    def _done(self, t: int) -> None:
        self.status = ST_STOPPED

    def ramp_down(self, t: int, v_ss: int, rate: Fraction,
                  end: Optional[Fraction] = None) -> None:
        """Run went to 0: decelerate to SpdSs and stop (planned once).

        ``end`` is the travel at which the move is programmed to end (the
        PosSet of POS_GOTO_R, the envelope's total); the stop never passes
        it (see :meth:`bounded_stop`).
        """
        if self.stopping:
            return
        ax = self.axis
        assert ax is not None
        x, v = ax.exact_state(t)
        self.begin(ax.direction, self.bounded_stop(t, x, v, v_ss, rate, end, "Run = 0"),
                   keep=True)
        self.stopping = True

    def bounded_stop(self, t: int, x: Fraction, v: Fraction, v_ss: int, rate: Fraction,
                     end: Optional[Fraction], why: str) -> list:
        """Segments that slow from ``v`` to SpdSs at ``rate`` and stop, but
        never beyond the travel ``end`` of the programmed move.

        A positioning module's pulse count is the program's: where the ramp
        at ``rate`` would need more pulses than remain, the ramp is made
        steeper so that it ends exactly at ``end`` at SpdSs, and a diagnostic
        gives the rate used (docs/em253.md, decisions log).
        """
        vss = Fraction(v_ss)
        if end is None or v <= vss or x + ramp_distance(v, vss, rate) <= end:
            return stop_plan(t, x, v, vss, rate)
        left = end - x
        if left <= 0:
            # the last pulse of the move is out: the pulse train ends now
            self.warn(f"{why}: the programmed end is reached at {float(v):.0f} Hz; the "
                      f"pulses stop at once", f"steep{self.plc.scans}")
            return stop_plan(t, x, v, v, rate)
        need = (v * v - vss * vss) / (2 * left * 1_000_000)  # Hz per µs
        self.warn(f"{why}: slowing down from {float(v):.0f} Hz at the set rate of "
                  f"{float(rate) * 1000:.3f} Hz/ms needs "
                  f"{float(ramp_distance(v, vss, rate)):.0f} pulses but only {float(left):.0f} "
                  f"remain to the programmed end; the axis slows down at "
                  f"{float(need) * 1000:.3f} Hz/ms and stops exactly at the end",
                  f"steep{self.plc.scans}")
        segs, _ = plan_distance(Fraction(t), x, v, v, vss, left, rate, need)
        return segs

    def output_limit_lowered(self, t: int) -> None:
        """P_DorCCW went from differential (500 kHz) to single-ended
        (200 kHz) while this block's move runs above 200 kHz: the move's
        parameters are applied again, as an Update would, so that the speed
        ramps down to the new limit (with the block's DecTime) and a
        positioning move still ends exactly on its count."""
        if not self.running() or self.stopping or not getattr(self, "applied", None):
            return
        self.warn("P_DorCCW switched to single-ended while the axis runs above "
                  "200 kHz: the speed is brought down to the single-ended limit",
                  f"dorccw{self.plc.scans}")
        self._update(t, *self.applied)

    def restart_while_stopping(self, rising: bool, update: int) -> None:
        """Run back to 1 (or an Update) while the axis slows down after Run = 0.

        The module finishes the stop it was commanded (C_Status stays 1
        until the pulses end, then reads 8); a Run edge after that starts
        again.  Nothing in the manual says a stop can be taken back, so the
        command is not acted on, and the diagnostic says so.
        """
        if rising:
            self.warn("Run went back to 1 while the axis slows down after Run = 0: the "
                      "stop is completed first; set Run to 0 and back to 1 after C_Status "
                      "reads 8 to start again", f"rerun{self.plc.scans}")
        if update:
            self.warn("Update while the axis slows down after Run = 0 is not applied",
                      f"updstop{self.plc.scans}")

    def estop(self) -> None:
        if self.axis is not None and self.axis.moving and self.owns():
            self.axis.stop_now(self.now())
        if self.status == ST_RUN:
            self.status = ST_STOPPED

    def running(self) -> bool:
        ax = self.axis
        return ax is not None and ax.owner is self and bool(ax.segs)

    def can_start(self, direction: int) -> bool:
        """Checks before a Run edge starts a motion; each refusal is reported."""
        ax = self.axis
        assert ax is not None
        if ax.segs:
            self.warn("the axis is already moved by another instruction: this Run edge "
                      "is ignored", "busy")
            return False
        if ax.stf:
            self.warn("the STF emergency-stop input of the axis is active: the axis does "
                      "not start", "stfstart")
            return False
        if self.limit_active(direction):
            self.warn("the hard limit in the moving direction is active: the axis does "
                      "not start", "limstart")
            return False
        return True


@register_block("MOTION_EN3")
class MotionEn3(_Base):
    name = "MOTION_EN3"

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self._last_key: tuple = ()
        self._last_out: tuple = ()

    def __call__(self, em_no: int, p_dor_ccw: int, sev0: int, sev1: int,
                 clr0: int, clr1: int) -> tuple:
        mod = self.plc.modules.get(em_no)
        if mod is None:
            self.warn(f"no EM253 module in slot {em_no} (EmNo): Status 4", "nomodule")
            return clr0, clr1, 4
        mod.enabled_scan = self.plc.scans
        key = (em_no, p_dor_ccw, sev0, sev1, clr0, clr1)
        # perf: nothing to do when the inputs are as last scan and no CLR
        # pulse or emergency stop is pending
        if key == self._last_key and not mod.clr_pending and not mod.stf_any \
                and self._last_out[2] == 1:
            return self._last_out
        t = self.now()
        lowered = mod.differential and not p_dor_ccw
        mod.differential = bool(p_dor_ccw)
        if lowered:
            for ax in mod.axes:
                owner = ax.owner
                if ax.segs and abs(ax.speed(t)) > mod.max_hz and owner is not None:
                    if hasattr(owner, "_update"):
                        owner.output_limit_lowered(t)
                    else:
                        owner.warn("P_DorCCW switched to single-ended while the homing "
                                   "runs above 200 kHz: the homing keeps its speeds",
                                   "dorccw")
        out = []
        for i, (sev, clr) in enumerate(((sev0, clr0), (sev1, clr1))):
            ax = mod.axes[i]
            if sev and ax.moving and not ax.masked:
                self.warn(f"SevOn{i} masks pulse and direction while axis {i} moves: the "
                          f"counter keeps counting but the motor does not follow", f"sev{i}")
            ax.set_masked(t, bool(sev))
            until = mod.clr_until[i]
            if clr and until is None:
                mod.clr_until[i] = t + 200_000
            elif until is not None and t >= until:
                mod.clr_until[i] = None
                clr = 0  # the bit clears itself after the pulse (manual 3.2.1)
            out.append(clr)
        status = 4 if any(a.stf for a in mod.axes) else 1
        mod.clr_pending = any(u is not None for u in mod.clr_until)
        mod.stf_any = status == 4
        result = (out[0], out[1], status)
        self._last_key, self._last_out = (em_no, p_dor_ccw, sev0, sev1, out[0], out[1]), result
        return result


@register_block("GET_AbsPos")
class GetAbsPos(_Base):
    name = "GET_AbsPos"
    last_out = (0, 0)

    def __call__(self, em_no: int, axis_no: int) -> tuple:
        mod = self.module
        if mod is not None and mod.enabled_scan == self.plc.scans and mod.slot == em_no \
                and self._axis_no == axis_no:  # perf: the usual case
            assert self.axis is not None
            self.last_out = (self.axis.position(self.plc.now_us), 1)
            return self.last_out
        if not self.find(em_no, axis_no):
            return self.last_out
        assert self.axis is not None
        self.last_out = (self.axis.position(self.now()), 1)
        return self.last_out


@register_block("SET_AbsPos")
class SetAbsPos(_Base):
    name = "SET_AbsPos"

    def __call__(self, em_no: int, axis_no: int, pos: int, start: int) -> tuple:
        if not self.find(em_no, axis_no):
            return start, self.status
        assert self.axis is not None
        if start:
            self.axis.set_position(self.now(), pos)
            self.status = 1
            return 0, self.status
        return 0, self.status


@register_block("SPD_CTRL")
class SpdCtrl(_Base):
    name = "SPD_CTRL"

    def __call__(self, em_no, axis_no, acc, dec, v_ss, v_set, inner, update, direction,
                 e_stop, run) -> tuple:
        # perf: steady running (Run held, nothing to update) only reports speed
        mod, ax = self.module, self.axis
        if run and self.prev_run and not update and not e_stop and inner == INNER_OK \
                and mod is not None and ax is not None and ax.owner is self and ax.segs \
                and mod.enabled_scan == self.plc.scans and mod.slot == em_no \
                and self._axis_no == axis_no and self.initialised:
            self.last_spd = spd = ax.speed(self.plc.now_us)
            return INNER_OK, 0, self.status, spd
        rising = run and not self.prev_run
        self.prev_run = run
        if not self.find(em_no, axis_no) or not self.inner(inner):
            return inner, update, self.status, self.last_spd
        ax = self.axis
        assert ax is not None
        t = self.now()
        d = 1 if direction else -1
        if e_stop:
            self.estop()
        elif self.running():
            if not run:
                v_ss = min(v_ss, self.top)
                self.ramp_down(t, v_ss, _rate(self.top, v_ss, dec))
            elif self.stopping:
                self.restart_while_stopping(rising, update)
            elif update:
                self.applied = (acc, dec, v_ss, v_set, d)
                self._update(t, *self.applied)
        elif rising and self.can_start(d):
            sp = self.speeds_ok(v_ss, v_set)
            if sp is not None:
                self.applied = (acc, dec, v_ss, v_set, d)
                v_ss, self.top = sp
                top = self.top
                self.begin(d, velocity_plan(t, Fraction(0), Fraction(0), Fraction(v_ss),
                                            Fraction(top), _rate(top, v_ss, acc),
                                            _rate(top, v_ss, dec)))
        spd = ax.speed(t) if self.owns() else 0
        if self.status == ST_RUN and not self.running():
            self.status = ST_STOPPED
        self.last_spd = spd
        return INNER_OK, 0, self.status, spd

    def _update(self, t, acc, dec, v_ss, v_set, d) -> None:
        ax = self.axis
        assert ax is not None
        sp = self.speeds_ok(v_ss, v_set)
        if sp is None:
            return
        v_ss, top = sp
        x, v = ax.exact_state(t)
        ra, rd = _rate(top, v_ss, acc), _rate(top, v_ss, dec)
        if d != ax.direction:
            # note 5: Update applies the direction too ("不建议在运行过程中更改方向",
            # not recommended): the axis slows to SpdSs with the new DecTime,
            # the pulses stop, and it starts again the other way from SpdSs
            self.warn("direction changed with Update while running (not recommended, "
                      "manual note 5): the axis slows down to SpdSs, stops and runs the "
                      "other way", "dirchg")
            self.top = top
            self.begin(ax.direction, stop_plan(t, x, v, Fraction(v_ss), rd), keep=True)
            # a partial, not a closure: fork() deep-copies the device state
            ax.on_done = partial(self._reverse, d=d, v_ss=v_ss, top=top, ra=ra, rd=rd)
            return
        self.top = top
        self.begin(ax.direction, velocity_plan(t, x, v, Fraction(v_ss), Fraction(top), ra, rd),
                   keep=True)

    def _reverse(self, t: int, d: int, v_ss: int, top: int, ra: Fraction,
                 rd: Fraction) -> None:
        """The stop before a reversal ended at ``t``: start the other way."""
        ax = self.axis
        assert ax is not None
        if ax.stf or self.limit_active_at(d, t):
            self.warn("the reversal does not start: the STF input or the hard limit in "
                      "the new direction is active", "revblocked")
            self.status = ST_STOPPED
            return
        ax.owner = self
        ax.start(t, d, velocity_plan(t, Fraction(0), Fraction(0), Fraction(v_ss),
                                     Fraction(top), ra, rd), self._done)
        ax.watch_positions(t, self.limit_watch(d))


@register_block("POS_GOTO_R")
class PosGotoR(_Base):
    name = "POS_GOTO_R"
    c_pos = 0   #: the C_Pos last written

    def __call__(self, em_no, axis_no, acc, dec, v_ss, v_set, pos, inner, update, e_stop,
                 run) -> tuple:
        # perf: a move in progress with Run held only reports C_Pos and C_Spd
        mod, ax = self.module, self.axis
        if run and self.prev_run and not update and not e_stop and inner == INNER_OK \
                and mod is not None and ax is not None and ax.owner is self and ax.segs \
                and mod.enabled_scan == self.plc.scans and mod.slot == em_no \
                and self._axis_no == axis_no and self.initialised:
            t = self.plc.now_us
            self.last_spd = spd = ax.speed(t)
            self.c_pos = c_pos = ax.travel(t)
            return INNER_OK, 0, self.status, c_pos, spd
        rising = run and not self.prev_run
        self.prev_run = run
        if not self.find(em_no, axis_no) or not self.inner(inner):
            # an ignored call leaves its outputs as they were
            return inner, update, self.status, self.c_pos, self.last_spd
        ax = self.axis
        assert ax is not None
        t = self.now()
        if e_stop:
            self.estop()
        elif self.running():
            if not run:
                v_ss = min(v_ss, self.top)
                self.ramp_down(t, v_ss, _rate(self.top, v_ss, dec), self.target)
            elif self.stopping:
                self.restart_while_stopping(rising, update)
            elif update:
                self.applied = (acc, dec, v_ss, v_set, pos)
                self._update(t, *self.applied)
        elif rising:
            d = 1 if pos > 0 else -1
            if pos == 0:
                self.status = ST_STOPPED
            elif self.can_start(d):
                sp = self.speeds_ok(v_ss, v_set)
                if sp is not None:
                    self.applied = (acc, dec, v_ss, v_set, pos)
                    v_ss, top = sp
                    self.top = top
                    segs, _ = distance_plan(t, Fraction(0), Fraction(0), Fraction(v_ss),
                                            Fraction(top), Fraction(abs(pos)),
                                            _rate(top, v_ss, acc), _rate(top, v_ss, dec))
                    self.target = Fraction(abs(pos))
                    self.begin(d, segs)
        if ax.owner is not self:
            # another instruction moves the axis: C_Pos keeps this block's
            # last move until its next start (3.2.5 "已发送脉冲数")
            self.c_pos, self.last_spd = self.last_pos, 0
        elif ax.segs:
            self.c_pos, self.last_spd = ax.travel(t), ax.speed(t)
        else:
            self.c_pos, self.last_spd = self.last_pos, 0
            if self.status == ST_RUN:
                self.status = ST_STOPPED
        return INNER_OK, 0, self.status, self.c_pos, self.last_spd

    def _done(self, t: int) -> None:
        assert self.axis is not None
        self.last_pos = self.axis.last_travel
        self.status = ST_STOPPED

    def _update(self, t, acc, dec, v_ss, v_set, pos) -> None:
        ax = self.axis
        assert ax is not None
        sp = self.speeds_ok(v_ss, v_set)
        if sp is None:
            return
        v_ss, top = sp
        d = 1 if pos > 0 else -1
        x, v = ax.exact_state(t)
        if pos != 0 and d != ax.direction:   # 0 has no sign: a total already passed
            self.warn("PosSet changed sign while moving: a direction change is not "
                      "allowed during a move; the new PosSet is ignored", "dirchg")
            return
        remaining = Fraction(abs(pos)) - x
        self.top = top
        ra, rd = _rate(top, v_ss, acc), _rate(top, v_ss, dec)
        sent = x.numerator // x.denominator
        if sent > abs(pos):
            # physically impossible: the pulses are already out
            self.warn(f"the updated PosSet {abs(pos)} is already passed ({sent} pulses of "
                      f"this move are sent): the axis decelerates with DecTime and stops "
                      f"beyond it", "passed")
            segs = stop_plan(t, x, v, Fraction(v_ss), rd)
        else:
            self.target = Fraction(abs(pos))
            segs, ok = distance_plan(t, x, v, Fraction(v_ss), Fraction(top), remaining, ra, rd)
            if not ok:
                # the new ramps cannot end at PosSet from this speed: PosSet
                # (the number of pulses, 3.2.5) wins over DecTime
                segs = self.bounded_stop(t, x, v, v_ss, rd, self.target, "Update")
        self.begin(ax.direction, segs, keep=True)


@register_block("POS_RUN")
class PosRun(_Base):
    name = "POS_RUN"

    def __call__(self, em_no, axis_no, mode, v_ss, ptr, steps, inner, update, e_stop,
                 run) -> tuple:
        rising = run and not self.prev_run
        self.prev_run = run
        if not self.find(em_no, axis_no) or not self.inner(inner):
            step, c_pos = getattr(self, "last", (0, 0))
            return inner, update, self.status, c_pos, self.last_spd, step
        ax = self.axis
        assert ax is not None
        t = self.now()
        if e_stop:
            self.estop()
        elif self.running():
            if not run:
                # the running step's DecTime (3.2.6 gives each step its own
                # DecTime); never beyond the envelope's end
                x = self.axis.travel(t) if self.axis is not None else 0
                k, _ = self._step_at(x)
                self.ramp_down(t, min(v_ss, self.module.max_hz) if self.module else v_ss,
                               self.step_rd[max(k - 1, 0)], self.bounds[-1])
            elif self.stopping:
                self.restart_while_stopping(rising, update)
            elif update:
                self.applied = (v_ss, ptr, steps)
                self._update(t, *self.applied)
        elif rising and self.can_start(-1 if self._first_sign(ptr, steps) < 0 else 1):
            if mode != 0:
                self.warn(f"Mode {mode} is not defined (manual: 0); running as mode 0", "mode")
            table = self._table(ptr, steps)
            if table is not None:
                self.applied = (v_ss, ptr, steps)
                self._start(t, v_ss, table)
        step, c_pos = self._progress(t)
        if self.status == ST_RUN and not self.running():
            self.status = ST_STOPPED
        spd = ax.speed(t) if self.owns() else 0
        self.last_spd = spd
        return INNER_OK, 0, self.status, c_pos, spd, step

    def _first_sign(self, ptr: int, steps: int) -> int:
        """Direction of the envelope in the table (without diagnostics)."""
        area = POINTER_AREA_NAMES.get(ptr >> 24)
        buf = self.plc.mem.areas.get({"T": "TV", "C": "CV"}.get(area, area)) if area else None
        off = ptr & 0xFFFFFF
        for i in range(min(max(steps, 0), MAX_STEPS)):
            b = off + i * STEP_BYTES + 8
            if buf is None or b + 4 > len(buf):
                break
            v = int.from_bytes(buf[b:b + 4], "big", signed=True)
            if v:
                return v
        return 1

    def _table(self, ptr: int, steps: int,
               update: bool = False) -> Optional[list[tuple[int, int, int, int]]]:
        """The profile table's rows, or None (with a diagnostic) when the
        envelope cannot run: at a Run edge it then does not start, on an
        Update the running envelope goes on as planned."""
        refused = ("the Update is ignored and the running envelope goes on as planned"
                   if update else "the envelope does not start")
        key = "upd" if update else ""
        if not 1 <= steps <= MAX_STEPS:
            self.warn(f"Step is {steps}; the module runs 1..{MAX_STEPS} steps: {refused}",
                      "steps" + key)
            return None
        area = POINTER_AREA_NAMES.get(ptr >> 24)
        off = ptr & 0xFFFFFF
        buf = self.plc.mem.areas.get({"T": "TV", "C": "CV"}.get(area, area)) if area else None
        if buf is None or off + steps * STEP_BYTES > len(buf):
            self.warn(f"ProfilePtr 16#{ptr:08X} does not point to {steps} x {STEP_BYTES} "
                      f"bytes of memory: {refused}", "ptr" + key)
            return None
        rows = []
        for i in range(steps):
            b = off + i * STEP_BYTES
            acc = int.from_bytes(buf[b:b + 2], "big")
            dec = int.from_bytes(buf[b + 2:b + 4], "big")
            spd = int.from_bytes(buf[b + 4:b + 8], "big", signed=True)
            pos = int.from_bytes(buf[b + 8:b + 12], "big", signed=True)
            rows.append((acc, dec, spd, pos))
        moves = [(i, 1 if r[3] > 0 else -1) for i, r in enumerate(rows) if r[3] != 0]
        if len({sign for _, sign in moves}) > 1:
            # the first step that moves against the first step that moves
            k = next(i for i, sign in moves if sign != moves[0][1])
            self.warn(f"step {k + 1} changes direction inside the envelope, which the module "
                      f"does not allow (manual 3.2.6): {refused}", "dir" + key)
            return None
        return rows

    def _plan(self, t: int, x0: Fraction, v0: Fraction, v_ss: int, rows: list,
              first: int, start: Fraction) -> Optional[tuple[list, list, list]]:
        """Segments, step end positions and step deceleration rates for steps
        ``first``.. of ``rows``, starting at time ``t`` with travel ``x0`` and
        speed ``v0``; ``start`` is where step ``first`` began (its PosSet
        counts from there).

        The steps run back to back (3.2.6: "每段指令可不必减速到 0"), each
        ramping toward its SpdSet with its own rates, with look-ahead: a step
        slows down before its end (with its own DecTime rate) as far as the
        following steps need to reach SpdSs exactly at the envelope's end
        with theirs.
        """
        n = len(rows)
        lens: list[Fraction] = []
        tops: list[int] = []
        rates: list[tuple[Fraction, Fraction]] = []
        x, v = x0, v0
        for i in range(first, n):
            acc, dec, spd, pos = rows[i]
            sp = self.speeds_ok(v_ss, spd, allow_equal=True)
            if sp is None:
                return None
            v_ss, top = sp
            end = (start if i == first else x) + abs(pos)
            length = max(end - x, Fraction(0))
            if top > v_ss:
                ra, rd = _rate(top, v_ss, acc), _rate(top, v_ss, dec)
            else:
                # a step at SpdSs: note 3's (SpdSet - SpdSs) / time is 0, so the
                # step's times apply to the change from the speed it enters
                # with (the speed the step before it holds)
                change = max(abs(int(v) - top), 1)
                ra = Fraction(change, max(acc, 1) * 1000)
                rd = Fraction(change, max(dec, 1) * 1000)
            lens.append(length)
            tops.append(top)
            rates.append((ra, rd))
            # the speed the next step is entered with, without look-ahead:
            # a step at SpdSs takes its rates from it
            held = plan_hold(Fraction(t), x, v, Fraction(top), length, ra, rd)
            x, v = end, (held[-1].v1 if held else v)
        # look-ahead: the highest speed at which each step may end so that
        # every later step can still slow down to SpdSs by the envelope's end
        m = len(lens)
        cap = [Fraction(v_ss)] * m
        for j in range(m - 1, 0, -1):
            cap[j - 1] = sqrt_floor(cap[j] * cap[j] + 2 * rates[j][1] * lens[j] * 1_000_000)
        segs: list = []
        bounds: list = []
        x, v, tt = x0, v0, Fraction(t)
        for j in range(m):
            ra, rd = rates[j]
            top = Fraction(tops[j])
            if j == m - 1:
                part, ok = _last(tt, x, v, v_ss, tops[j], lens[j], ra, rd)
                if not ok:
                    self.warn("the last step is too short to decelerate to SpdSs; the "
                              "pulses stop at a higher speed", "short")
            else:
                part = plan_hold(tt, x, v, top, lens[j], ra, rd)
                if part and part[-1].v1 > cap[j]:
                    part, _ = plan_distance(tt, x, v, top, cap[j], lens[j], ra, rd)
            if part:
                segs.extend(part)
                tt, x, v = part[-1].t1, part[-1].x1, part[-1].v1
            bounds.append(x)
        return segs, bounds, [r[1] for r in rates]

    def _start(self, t: int, v_ss: int, rows: list) -> None:
        assert self.axis is not None and self.module is not None
        d = -1 if any(r[3] < 0 for r in rows) else 1
        v0 = Fraction(min(v_ss, self.module.max_hz))
        plan = self._plan(t, Fraction(0), v0, v_ss, rows, 0, Fraction(0))
        if plan is None:
            return
        segs, bounds, self.step_rd = plan
        self.bounds = bounds
        self.direction = d
        self.begin(d, segs)

    def _update(self, t: int, v_ss: int, ptr: int, steps: int) -> None:
        """Update while the envelope runs: re-read the table and continue
        from the current step with its new values (manual 3.2.6: positions
        may change in the same direction, not the direction)."""
        ax = self.axis
        assert ax is not None
        rows = self._table(ptr, steps, update=True)
        if rows is None:
            return
        d = -1 if any(r[3] < 0 for r in rows) else 1
        if any(r[3] for r in rows) and d != self.direction:
            self.warn("Update changes the direction of the running envelope, which the "
                      "module does not allow (manual 3.2.6): the Update is ignored and the "
                      "running envelope goes on as planned", "upddir")
            return
        x, v = ax.exact_state(t)
        k = next((i for i, b in enumerate(self.bounds) if x < b), len(self.bounds) - 1)
        k = min(k, len(rows) - 1)
        start = Fraction(self.bounds[k - 1]) if k > 0 else Fraction(0)
        plan = self._plan(t, x, v, v_ss, rows, k, start)
        if plan is None:
            return
        segs, bounds, rds = plan
        self.bounds = self.bounds[:k] + bounds
        self.step_rd = self.step_rd[:k] + rds
        self.begin(ax.direction, segs, keep=True)

    def _step_at(self, x: int) -> tuple[int, int]:
        """(C_Step, C_Pos) at envelope travel ``x``: the step whose pulses are
        being sent and the pulses sent in it (3.2.6: "当前步数发送的脉冲数").

        At a boundary the next step has begun (0 pulses sent in it); at the
        envelope's end the last step is complete.
        """
        start = 0
        last = len(self.bounds) - 1
        for i, b in enumerate(self.bounds):
            if x < b or i == last:
                return i + 1, x - start
            start = int(b)
        return 0, 0

    def _progress(self, t: int) -> tuple[int, int]:
        if not self.owns() or not hasattr(self, "bounds"):
            return getattr(self, "last", (0, 0))
        assert self.axis is not None
        if not self.axis.moving:
            return getattr(self, "last", (0, 0))
        self.last = res = self._step_at(self.axis.travel(t))
        return res

    def _done(self, t: int) -> None:
        # the move ended for any reason (its end, Run = 0, E_Stop, STF, a
        # limit, InnerState written): report the step that was running
        assert self.axis is not None
        self.last = self._step_at(self.axis.last_travel)
        self.status = ST_STOPPED


def _last(t0, x, v, v_ss, top, length, ra, rd):
    from ..motion import plan_distance
    return plan_distance(t0, x, v if v > 0 else Fraction(v_ss), Fraction(top),
                         Fraction(v_ss), length, ra, rd)


@register_block("HOMING")
class Homing(_Base):
    """HOMING (manual 3.2.7); the modes and their sequence are in
    :mod:`.homing`."""

    name = "HOMING"

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self.seq: Any = None   #: the HomingSequence of the last start

    def __call__(self, em_no, axis_no, mode, v_low, v_high, offset, inner, e_stop,
                 run) -> tuple:
        rising = run and not self.prev_run
        self.prev_run = run
        if not self.find(em_no, axis_no) or not self.inner(inner):
            return inner, self.status, self.last_spd   # an ignored call: outputs kept
        ax = self.axis
        assert ax is not None
        t = self.now()
        seq = self.seq
        if seq is not None and seq.active:
            seq.poll(t)   # an STF stop ends the sequence (status 8, diagnostic)
        if e_stop:
            # 3.2.7 E_Stop: the pulses stop at once, no deceleration
            if seq is not None and seq.active:
                seq.abort(t)
            self.estop()
        elif seq is not None and seq.active:
            if not run:
                # Run = 0: decelerate to SpdLow and stop; no home is set
                seq.abort(t)
                x, v = ax.exact_state(t)
                self.begin(ax.direction, stop_plan(t, x, v, seq.v_low, seq.rate), keep=True)
        elif rising and ax.moving and ax.owner is self:
            self.restart_while_stopping(rising, 0)
        elif rising and ax.moving:
            self.warn("the axis is already moved by another instruction: the homing does "
                      "not start", "busy")
        elif rising:
            self._start(t, mode, v_low, v_high, offset)
        self.last_spd = spd = ax.speed(t) if self.owns() else 0
        # C_Status stays 1 while the axis still moves for this block (also
        # while it decelerates after Run = 0) and reads 8 once it stopped
        if self.status == ST_RUN and not self.running():
            self.status = ST_STOPPED
        return INNER_OK, self.status, spd

    def _start(self, t: int, mode: int, v_low: int, v_high: int, offset: int) -> None:
        from .homing import MODES, HomingSequence
        assert self.axis is not None
        if mode not in MODES:
            self.warn(f"HomingMode {mode} is not one of 0..14: nothing happens", "mode")
            return
        if v_low <= 0 or v_high < v_low:
            self.warn(f"homing needs 0 < SpdLow <= SpdHigh (got {v_low}, {v_high})", "speeds")
            return
        top = min(v_high, self.module.max_hz) if self.module else v_high
        if top < v_high:
            self.warn(f"SpdHigh {v_high} Hz is above the output limit; using {top} Hz",
                      "maxhz")
        self.seq = HomingSequence(self, self.axis, mode, min(v_low, top), top, offset)
        self.status = ST_RUN
        self.seq.start(t)
