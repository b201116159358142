"""POS_RUN (EM253 user manual 3.2.6): the multi-step envelope.

The profile table (12 bytes per step), the plan of the steps with
look-ahead, Update of a running envelope, and C_Step / C_Pos.  Decisions
(stride, signs, steps at SpdSs, the stop ramp) are logged in docs/em253.md.
"""

from __future__ import annotations

from bisect import bisect_right
from fractions import Fraction
from typing import Optional

from ...blocks import register_block
from ...compiler.operands import POINTER_AREA_NAMES
from ..motion import plan_distance, plan_hold, sqrt_floor
from .base import INNER_OK, ST_RUN, ST_STOPPED, MotionBlock, ramp_rate

STEP_BYTES = 12   #: POS_RUN table: AccTime W, DecTime W, SpdSet D, PosSet D
MAX_STEPS = 32


@register_block("POS_RUN")
class PosRun(MotionBlock):
    name = "POS_RUN"
    #: C_Step is 0..32; C_Pos (pulses of a step, up to |PosSet|) is masked
    exact_results = ("InnerState", "Update", "C_Status", "C_Spd", "C_Step")
    mode_in = 0   #: the Mode input of the current call
    _b_of: object = None   #: the bounds list _b_ceil and _b_floor were made from

    def __call__(self, em_no, axis_no, mode, v_ss, ptr, steps, inner, update, e_stop,
                 run) -> tuple:
        # perf: no E_Stop, InnerState as the block keeps it, the module and
        # axis of the last call enabled in this scan, and either the
        # envelope of this block running with Run held and nothing to
        # update, or nothing to start (no envelope of this block running,
        # no Run edge): command() has nothing to do, only C_Step, C_Pos,
        # C_Spd and C_Status to report
        plc = self.plc
        if (inner == self._inner_fixed
                or inner == self._inner and em_no == self._em and axis_no == self._axn) \
                and not e_stop and not update \
                and self.module.enabled_scan == plc.scans:  # type: ignore[union-attr]
            ax = self.axis
            if ax.owner is self and ax.segs:
                if run and self.prev_run:
                    t = plc._t_us
                    self.mode_in = mode
                    if ax._w_lo <= t and t < ax._w_hi:
                        # perf: Axis.travel and Axis.speed inline (their
                        # window test and formulas)
                        s = ax._w_seg
                        x = ((s.A * t + s.B) * t + s.C) // s.D
                        spd = ax._w_hz
                        if spd is None:
                            spd = ax.direction * ((s.HA * t + s.HB) // s.HD)
                    else:
                        x, spd = ax.travel(t), ax.speed(t)
                    self.last = (step, c_pos) = self._step_at(x)
                    self.last_spd = spd
                    return INNER_OK, 0, self.status, c_pos, spd, step
            elif self.prev_run or not run:
                self.prev_run = run
                self.mode_in = mode
                step, c_pos = getattr(self, "last", (0, 0))
                if self.status == ST_RUN:
                    self.status = ST_STOPPED
                self.last_spd = 0
                return INNER_OK, 0, self.status, c_pos, 0, step
        return self.call_exact(em_no, axis_no, mode, v_ss, ptr, steps, inner, update, e_stop,
                               run)

    def call_exact(self, em_no, axis_no, mode, v_ss, ptr, steps, inner, update, e_stop,
                   run) -> tuple:
        """The instruction without the shortcut of :meth:`__call__`."""
        rising = run and not self.prev_run
        self.prev_run = run
        if not self.find(em_no, axis_no) or not self.inner(inner):
            step, c_pos = getattr(self, "last", (0, 0))
            return inner, update, self.status, c_pos, self.last_spd, step
        ax = self.axis
        assert ax is not None
        t = self.now()
        self.mode_in = mode
        self.command(t, run, rising, update, e_stop, (v_ss, ptr, steps))
        step, c_pos = self._progress(t)
        if self.status == ST_RUN and not self.running():
            self.status = ST_STOPPED
        spd = ax.speed(t) if self.owns() else 0
        self.last_spd = spd
        return INNER_OK, 0, self.status, c_pos, spd, step

    def stop_move(self, t: int, params: tuple) -> None:
        # the running step's DecTime (3.2.6 gives each step its own
        # DecTime); never beyond the envelope's end
        v_ss = params[0]
        assert self.axis is not None and self.module is not None
        k, _ = self._step_at(self.axis.travel(t))
        self.ramp_down(t, min(v_ss, self.module.max_hz), self.step_rd[max(k - 1, 0)],
                       self.bounds[-1])

    def start_move(self, t: int, params: tuple) -> None:
        v_ss, ptr, steps = params
        if not self.can_start(-1 if self._first_sign(ptr, steps) < 0 else 1):
            return
        if self.mode_in != 0:
            self.warn(f"Mode {self.mode_in} is not defined (manual: 0); running as mode 0",
                      "mode")
        table = self._table(ptr, steps)
        if table is not None:
            self.applied = params
            self._start(t, v_ss, table)

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
                ra, rd = ramp_rate(top, v_ss, acc), ramp_rate(top, v_ss, dec)
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
        bounds = self.bounds
        if not bounds:
            return 0, 0
        # perf: x is whole, so x < b exactly when x < ceil(b); the ceilings
        # and floors of the step ends are computed once per plan, and the
        # step found by bisection (a Fraction comparison per step was the
        # slow part)
        if self._b_of is not bounds:
            self._b_ceil = [-((-b.numerator) // b.denominator) for b in map(Fraction, bounds)]
            self._b_floor = [int(b) for b in bounds]
            self._b_of = bounds
        i = min(bisect_right(self._b_ceil, x), len(bounds) - 1)
        return i + 1, x - (self._b_floor[i - 1] if i else 0)

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
    return plan_distance(t0, x, v if v > 0 else Fraction(v_ss), Fraction(top),
                         Fraction(v_ss), length, ra, rd)
