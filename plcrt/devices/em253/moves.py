"""The EM253 instructions that make one move of an axis (EM253 user
manual 3.2.4, 3.2.5, 3.2.7): SPD_CTRL (run at a speed), POS_GOTO_R (go a
distance) and HOMING (start a homing sequence).

Each block's ``__call__`` is the scan's shortcut (``# perf:``) for a call
that changes nothing; ``call_exact`` is the instruction; the start, stop
and Update of a move go through :meth:`.base.MotionBlock.command`.  The
common rules of the library (MOTION_EN3 first, InnerState, Update, E_Stop,
C_Status, speed limits) are in :mod:`.blocks`; the homing modes and their
sequence in :mod:`.homing`.

It is *not* where a module is enabled or the position counter is read or
set (MOTION_EN3, GET_AbsPos, SET_AbsPos: :mod:`.blocks`), nor the
multi-step envelope (POS_RUN: :mod:`.pos_run`).
"""

from __future__ import annotations

from fractions import Fraction
from functools import partial
from typing import Any

from ...blocks import register_block
from .axis import distance_plan, stop_plan, velocity_plan
from .base import INNER_OK, ST_RUN, ST_STOPPED, MotionBlock, ramp_rate
# imported with the library, not at the first homing: the import (its
# dataclasses are compiled) took milliseconds inside that scan
from .homing import MODES, HomingSequence

__all__ = ["Homing", "PosGotoR", "SpdCtrl"]


@register_block("SPD_CTRL")
class SpdCtrl(MotionBlock):
    name = "SPD_CTRL"
    #: InnerState and Update are 257 and 0 or the inputs as read, C_Spd a
    #: speed within the output limit (500 kHz at most)
    exact_results = ("InnerState", "Update", "C_Status", "C_Spd")

    def __call__(self, em_no, axis_no, acc, dec, v_ss, v_set, inner, update, direction,
                 e_stop, run) -> tuple:
        # perf: no E_Stop, InnerState as the block keeps it, the module and
        # axis of the last call (at a site with constant EmNo and AxisNo,
        # InnerState alone tells: MotionBlock._inner_fixed) enabled in this
        # scan, and either steady running (the block's own move, Run held,
        # nothing to update) or nothing to start (no move of this block, no
        # Run edge): command() has nothing to do, only C_Spd and C_Status to
        # report
        plc = self.plc
        if (inner == self._inner_fixed
                or inner == self._inner and em_no == self._em and axis_no == self._axn) \
                and not e_stop and not update \
                and self.module.enabled_scan == plc.scans:  # type: ignore[union-attr]
            ax = self.axis
            if ax.owner is self and ax.segs:
                if run and self.prev_run:
                    t = plc._t_us
                    if ax._w_lo <= t and t < ax._w_hi:
                        # perf: Axis.speed inline (its window test and formula)
                        spd = ax._w_hz
                        if spd is None:
                            s = ax._w_seg
                            spd = ax.direction * ((s.HA * t + s.HB) // s.HD)
                    else:
                        spd = ax.speed(t)
                    self.last_spd = spd
                    return INNER_OK, 0, self.status, spd
            elif self.prev_run or not run:
                self.prev_run = run
                if self.status == ST_RUN:
                    self.status = ST_STOPPED
                self.last_spd = 0
                return INNER_OK, 0, self.status, 0
        return self.call_exact(em_no, axis_no, acc, dec, v_ss, v_set, inner, update,
                               direction, e_stop, run)

    def call_exact(self, em_no, axis_no, acc, dec, v_ss, v_set, inner, update, direction,
                   e_stop, run) -> tuple:
        """The instruction without the shortcut of :meth:`__call__`."""
        rising = run and not self.prev_run
        self.prev_run = run
        if not self.find(em_no, axis_no) or not self.inner(inner):
            return inner, update, self.status, self.last_spd
        ax = self.axis
        assert ax is not None
        t = self.now()
        d = 1 if direction else -1
        self.command(t, run, rising, update, e_stop, (acc, dec, v_ss, v_set, d))
        spd = ax.speed(t) if self.owns() else 0
        if self.status == ST_RUN and not self.running():
            self.status = ST_STOPPED
        self.last_spd = spd
        return INNER_OK, 0, self.status, spd

    def stop_move(self, t: int, params: tuple) -> None:
        acc, dec, v_ss, v_set, d = params
        v_ss = min(v_ss, self.top)
        self.ramp_down(t, v_ss, ramp_rate(self.top, v_ss, dec))

    def start_move(self, t: int, params: tuple) -> None:
        acc, dec, v_ss, v_set, d = params
        if not self.can_start(d):
            return
        sp = self.speeds_ok(v_ss, v_set)
        if sp is not None:
            self.applied = params
            v_ss, self.top = sp
            top = self.top
            self.begin(d, velocity_plan(t, Fraction(0), Fraction(0), Fraction(v_ss),
                                        Fraction(top), ramp_rate(top, v_ss, acc),
                                        ramp_rate(top, v_ss, dec)))

    def _update(self, t, acc, dec, v_ss, v_set, d) -> None:
        ax = self.axis
        assert ax is not None
        sp = self.speeds_ok(v_ss, v_set)
        if sp is None:
            return
        v_ss, top = sp
        x, v = ax.exact_state(t)
        ra, rd = ramp_rate(top, v_ss, acc), ramp_rate(top, v_ss, dec)
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
class PosGotoR(MotionBlock):
    name = "POS_GOTO_R"
    #: C_Pos counts up to |PosSet|, which is 2**31 for PosSet -2**31: masked
    exact_results = ("InnerState", "Update", "C_Status", "C_Spd")
    c_pos = 0   #: the C_Pos last written

    def __call__(self, em_no, axis_no, acc, dec, v_ss, v_set, pos, inner, update, e_stop,
                 run) -> tuple:
        # perf: no E_Stop, InnerState as the block keeps it, the module and
        # axis of the last call enabled in this scan, and either a move of
        # this block running with Run held and nothing to update, or nothing
        # to start (no move of this block, no Run edge): command() has
        # nothing to do, only C_Pos, C_Spd and C_Status to report
        plc = self.plc
        if (inner == self._inner_fixed
                or inner == self._inner and em_no == self._em and axis_no == self._axn) \
                and not e_stop and not update \
                and self.module.enabled_scan == plc.scans:  # type: ignore[union-attr]
            ax = self.axis
            if ax.owner is self and ax.segs:
                if run and self.prev_run:
                    t = plc._t_us
                    if ax._w_lo <= t and t < ax._w_hi:
                        # perf: Axis.speed and Axis.travel inline (their
                        # window test and formulas)
                        s = ax._w_seg
                        spd = ax._w_hz
                        if spd is None:
                            spd = ax.direction * ((s.HA * t + s.HB) // s.HD)
                        c_pos = ((s.A * t + s.B) * t + s.C) // s.D
                    else:
                        spd, c_pos = ax.speed(t), ax.travel(t)
                    self.last_spd, self.c_pos = spd, c_pos
                    return INNER_OK, 0, self.status, c_pos, spd
            elif self.prev_run or not run:
                self.prev_run = run
                # C_Pos keeps this block's last move (see call_exact)
                self.c_pos, self.last_spd = self.last_pos, 0
                if self.status == ST_RUN and ax.owner is self:
                    self.status = ST_STOPPED
                return INNER_OK, 0, self.status, self.c_pos, 0
        return self.call_exact(em_no, axis_no, acc, dec, v_ss, v_set, pos, inner, update,
                               e_stop, run)

    def call_exact(self, em_no, axis_no, acc, dec, v_ss, v_set, pos, inner, update, e_stop,
                   run) -> tuple:
        """The instruction without the shortcut of :meth:`__call__`."""
        rising = run and not self.prev_run
        self.prev_run = run
        if not self.find(em_no, axis_no) or not self.inner(inner):
            # an ignored call leaves its outputs as they were
            return inner, update, self.status, self.c_pos, self.last_spd
        ax = self.axis
        assert ax is not None
        t = self.now()
        self.command(t, run, rising, update, e_stop, (acc, dec, v_ss, v_set, pos))
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

    def stop_move(self, t: int, params: tuple) -> None:
        acc, dec, v_ss, v_set, pos = params
        v_ss = min(v_ss, self.top)
        self.ramp_down(t, v_ss, ramp_rate(self.top, v_ss, dec), self.target)

    def start_move(self, t: int, params: tuple) -> None:
        acc, dec, v_ss, v_set, pos = params
        d = 1 if pos > 0 else -1
        if pos == 0:
            self.status = ST_STOPPED
            return
        if not self.can_start(d):
            return
        sp = self.speeds_ok(v_ss, v_set)
        if sp is not None:
            self.applied = params
            v_ss, top = sp
            self.top = top
            segs, _ = distance_plan(t, Fraction(0), Fraction(0), Fraction(v_ss),
                                    Fraction(top), Fraction(abs(pos)),
                                    ramp_rate(top, v_ss, acc), ramp_rate(top, v_ss, dec))
            self.target = Fraction(abs(pos))
            self.begin(d, segs)

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
        ra, rd = ramp_rate(top, v_ss, acc), ramp_rate(top, v_ss, dec)
        sent = x.numerator // x.denominator
        if sent > abs(pos):
            # physically impossible: the pulses are already out
            self.warn(f"the updated PosSet {abs(pos)} is already passed ({sent} pulses of "
                      f"this move are sent): the axis decelerates with DecTime and stops "
                      f"beyond it, but not beyond the PosSet it was moving to", "passed")
            segs = self.bounded_stop(t, x, v, v_ss, rd, self.target, "Update")
        else:
            self.target = Fraction(abs(pos))
            segs, ok = distance_plan(t, x, v, Fraction(v_ss), Fraction(top), remaining, ra,
                                     rd) if remaining > 0 else ([], False)
            if not ok:
                # the new ramps cannot end at PosSet from this speed: PosSet
                # (the number of pulses, 3.2.5) wins over DecTime
                segs = self.bounded_stop(t, x, v, v_ss, rd, self.target, "Update")
        self.begin(ax.direction, segs, keep=True)


@register_block("HOMING")
class Homing(MotionBlock):
    """HOMING (manual 3.2.7); the modes and their sequence are in
    :mod:`.homing`."""

    name = "HOMING"
    exact_results = ("InnerState", "C_Status", "C_Spd")

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self.seq: Any = None   #: the HomingSequence of the last start

    def __call__(self, em_no, axis_no, mode, v_low, v_high, offset, inner, e_stop,
                 run) -> tuple:
        # perf: no Run edge, no E_Stop, InnerState as the block keeps it,
        # the module and axis of the last call enabled in this scan, and
        # either the axis moving for this block (poll() has nothing to
        # report) with Run held or no homing active, or no homing active
        # and the axis not moving for it: only C_Spd and C_Status to report
        plc = self.plc
        if (inner == self._inner_fixed
                or inner == self._inner and em_no == self._em and axis_no == self._axn) \
                and not e_stop and (self.prev_run or not run) \
                and self.module.enabled_scan == plc.scans:  # type: ignore[union-attr]
            ax, seq = self.axis, self.seq
            if ax.owner is self and ax.segs:
                if run or seq is None or not seq.active:
                    self.prev_run = run
                    t = plc._t_us
                    if ax._w_lo <= t and t < ax._w_hi:
                        # perf: Axis.speed inline (its window test and formula)
                        spd = ax._w_hz
                        if spd is None:
                            s = ax._w_seg
                            spd = ax.direction * ((s.HA * t + s.HB) // s.HD)
                    else:
                        spd = ax.speed(t)
                    self.last_spd = spd
                    return INNER_OK, self.status, spd
            elif seq is None or not seq.active:
                self.prev_run = run
                if self.status == ST_RUN:
                    self.status = ST_STOPPED
                self.last_spd = 0
                return INNER_OK, self.status, 0
        return self.call_exact(em_no, axis_no, mode, v_low, v_high, offset, inner, e_stop,
                               run)

    def call_exact(self, em_no, axis_no, mode, v_low, v_high, offset, inner, e_stop,
                   run) -> tuple:
        """The instruction without the shortcut of :meth:`__call__`."""
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

    def output_limit_lowered(self, t: int) -> None:
        """HOMING has no parameters to apply again (its speeds are fixed at
        the start): it keeps them and says so."""
        self.warn("P_DorCCW switched to single-ended while the homing runs above "
                  "200 kHz: the homing keeps its speeds", "dorccw")

    def _start(self, t: int, mode: int, v_low: int, v_high: int, offset: int) -> None:
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
