"""What the EM253 library instructions share: the per-CALL block base
class (module and axis lookup, InnerState, speed checks against note 4 and
the output limit, limit switches, Run = 0 and E_Stop) and note 3's ramp
rate.  The instructions themselves are in :mod:`.blocks` and
:mod:`.pos_run`; this module registers none of them.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any, Optional

from ..motion import plan_distance, ramp_distance
from .axis import Axis, stop_plan
from .module import EM253Module

INNER_OK = 257
ST_IDLE, ST_RUN, ST_STOPPED = 0, 1, 8


def dint(v: int) -> int:
    """The DINT that holds the low 32 bits of ``v`` (a counter past 2**31
    wraps, as a masked store of it does)."""
    return (v + 0x8000_0000) % 0x1_0000_0000 - 0x8000_0000


def ramp_rate(v_set: int, v_ss: int, ms: int) -> Fraction:
    """Ramp rate (Hz per µs) from note 3: (SpdSet - SpdSs) / time; a time
    below 1 ms counts as 1 ms."""
    return Fraction(max(v_set - v_ss, 1), max(ms, 1) * 1000)


class MotionBlock:
    """Shared per-call-site logic: module lookup, InnerState, diagnostics."""

    name = ""
    #: perf: the results every call returns exactly, in the interface's
    #: order, and those of them always within their parameter's type: the
    #: call site unpacks them and writes those without a mask
    #: (plcrt.blocks.call)
    exact_results: tuple[str, ...] = ()

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
        #: perf: what the instructions' shortcuts compare a call with, one
        #: integer each (a tuple would be built and compared per call):
        #: EmNo and AxisNo of the module and axis found by the last call
        #: (None before), and 257 once InnerState is initialised (None
        #: before: no argument equals None)
        self._em: Optional[int] = None
        self._axn: Optional[int] = None
        self._inner: Optional[int] = None
        #: perf: the call site gives EmNo and AxisNo as constants
        #: (:meth:`constant_args`); once a call found them, every call of
        #: the site names them: then _site_ok is True and _inner_fixed is
        #: 257 once InnerState is initialised, and a shortcut compares
        #: InnerState alone
        self._fixed = False
        self._site_ok = False
        self._inner_fixed: Optional[int] = None
        self.stopping = False
        self.last_pos = 0
        self.last_spd = 0
        self.top = 0  #: SpdSet in force (after clamping to the output limit)

    def constant_args(self, names: frozenset[str]) -> None:
        """The IN parameters the call site gives as constants (the
        compiler tells each block once, plcrt.blocks.call)."""
        self._fixed = "EmNo" in names and (
            "AxisNo" in names or all(p.name != "AxisNo" for p in self.itf.params))

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
        self._em, self._axn = mod.slot, axis_no
        if self._fixed:
            self._site_ok = True
            self._inner_fixed = self._inner
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
            self._inner = INNER_OK
            if self._site_ok:
                self._inner_fixed = INNER_OK
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

    def command(self, t: int, run: int, rising: bool, update: int, e_stop: int,
                params: tuple) -> None:
        """The rules SPD_CTRL, POS_GOTO_R and POS_RUN share (3.2.4-3.2.6):
        E_Stop stops at once; while this block's move runs, Run = 0 ramps
        it down (:meth:`stop_move`), Run back to 1 during that ramp is
        reported, Update applies ``params`` (``_update``); otherwise a Run
        edge starts a move (:meth:`start_move`).  ``params`` are the
        block's inputs that a start or an Update applies."""
        if e_stop:
            self.estop()
        elif self.running():
            if not run:
                self.stop_move(t, params)
            elif self.stopping:
                self.restart_while_stopping(rising, update)
            elif update:
                self.applied = params
                self._update(t, *params)  # type: ignore[attr-defined]
        elif rising:
            self.start_move(t, params)

    def start_move(self, t: int, params: tuple) -> None:
        """A Run edge: start a move with ``params`` (per instruction)."""
        raise NotImplementedError

    def stop_move(self, t: int, params: tuple) -> None:
        """Run = 0 while the move runs: ramp down (per instruction)."""
        raise NotImplementedError

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
