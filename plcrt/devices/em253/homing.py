"""The 14 homing modes of the EM253 (manual, appendix 1) and mode 0.

Every mode is described by geometry, not by edge names (which sources use
inconsistently): which reference-switch (RPS) edge defines home, the
direction of the final approach across it, whether the home point is that
crossing or the first Z pulse beyond it, and the first search direction
(toward the limit switch the mode uses).  The RPS is active over the
closed range ``[lo, hi]`` of mechanical positions (plant file ``rps``).

=====  ======  ==========  ========  ====  ===================================
mode   search  edge        final     Z     home position
=====  ======  ==========  ========  ====  ===================================
1      -       right (hi)  +         yes   first Z >= hi + 1 (right, outside)
2      +       left (lo)   -         yes   first Z <= lo - 1 (left, outside)
3      -       right (hi)  +         no    hi + 1 (where the RPS is left)
4      +       left (lo)   -         no    lo - 1 (where the RPS is left)
5      -       -           -         yes   first Z <= start - 1
6      +       -           +         yes   first Z >= start + 1
7      +       left (lo)   -         yes   first Z <= lo - 1 (outside)
8      +       left (lo)   +         yes   first Z >= lo (inside)
9      +       right (hi)  -         yes   first Z <= hi (inside)
10     +       right (hi)  +         yes   first Z >= hi + 1 (outside)
11     -       right (hi)  +         yes   first Z >= hi + 1 (outside)
12     -       right (hi)  -         yes   first Z <= hi (inside)
13     -       left (lo)   +         yes   first Z >= lo (inside)
14     -       left (lo)   -         yes   first Z <= lo - 1 (outside)
0      -       -           -         -     the current position (no motion)
=====  ======  ==========  ========  ====  ===================================

The edge crossings and the Z search are the pure functions of
:mod:`plcrt.devices.homing_geometry`, shared with the CiA 402 methods.
Modes 7-14 have the geometry of CiA 402 methods 7-14 (digest
shared/reference/homing-and-motion.md, table 1.2).  Modes 1-4 follow the
appendix text: "机械往原点开关方向运动，在检测到原点开关信号后减速停止，再反转
退出原点开关" (move toward the switch, slow down and stop on it, reverse out
of it), then "找电机的下一个 Z 信号" (modes 1, 2) or "找原点开关信号下降沿"
(modes 3, 4).

Sequence: search at up to SpdHigh toward the switch (a limit switch in the
way reverses the search once, appendix 1 tracks 1 and 3: "根据检测到原点开关
与限位开关的先后"); on reaching the switch decelerate to SpdLow and stop; if
needed move back at SpdLow until on the approach side of the edge; then
cross the edge at SpdLow and stop at once at the home point
("电机立刻停止").  Starting inside the switch skips the search (appendix 1,
track 2: modes 7, 8, 13, 14 then move in the negative direction first,
9-12 in the positive one, which is what the geometry above gives).

Decisions (where appendix 1 leaves the behaviour open; user-facing text in
docs/em253.md, "HOMING" and "Homing modes"):

* The home point is the first position at which the decisive signal is
  seen while the final approach moves: for mode 3/4 the first position
  outside the switch (the pulse at which the RPS input falls), for a Z mode
  the first Z at or beyond that crossing.  A Z that coincides with the
  crossing therefore counts (mode 8 with a Z at ``lo`` homes at ``lo``);
  a Z on the other side of the edge does not (mode 7 with a Z at ``lo``
  homes one Z period further left).
* Modes 5/6 ("找到下一个 Z 相信号"): the *next* Z is strictly beyond the
  start; an axis that starts on a Z moves one Z period (no edge of the Z
  input is seen at the position it starts on).
* PosOffset (3.2.7 "用户设定原点的偏移位置(距离)"): after the home point is
  found the axis moves PosOffset pulses in the sign of PosOffset (positive
  = positive direction, whatever the mode's approach direction) at up to
  SpdHigh and the position counter is set to 0 there.  With PosOffset 0 the
  counter reads 0 at the home point itself.
* C_Status (3.2.7): 0 before the first run, 1 while the axis moves for the
  homing (also while it decelerates after Run went to 0), 8 once stopped,
  whether home was found or not.  A diagnostic says why when it was not.
* Run = 0 decelerates to SpdLow and stops; E_Stop, the STF input and an
  InnerState written by the program stop at once; none of them sets a
  home position.  A homing does not start while the axis's STF input is
  active.
* A limit switch met during the search reverses it (once); a limit met in
  any later phase (moving back, final approach, PosOffset move), or a
  second limit during the search, ends the homing with a diagnostic: the
  switch or the Z pulse the mode needs is not where the plant says.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from functools import partial
from typing import Any

from ..homing_geometry import edge_crossing, index_at_or_beyond
from ..motion import Seg, cruise, plan_distance, ramp_distance
from .axis import Axis, stop_plan, velocity_plan

HOMING_RAMP_US = 100_000  #: SpdLow <-> SpdHigh ramp time (HOMING has no ramp inputs)

F0 = Fraction(0)


@dataclass(frozen=True)
class Mode:
    """Geometry of one homing mode (see the module docstring)."""

    search: int            #: first search direction
    edge: str | None    #: "lo" / "hi" RPS edge, None for Z-only modes
    final: int             #: direction of the final approach
    z: bool                #: home is the first Z beyond the crossing


MODES: dict[int, Mode | None] = {
    0: None,
    1: Mode(-1, "hi", +1, True), 2: Mode(+1, "lo", -1, True),
    3: Mode(-1, "hi", +1, False), 4: Mode(+1, "lo", -1, False),
    5: Mode(-1, None, -1, True), 6: Mode(+1, None, +1, True),
    7: Mode(+1, "lo", -1, True), 8: Mode(+1, "lo", +1, True),
    # Mode 9: the appendix heading says "左边沿以右" (right of the left edge,
    # which would repeat mode 8), but its text says "Z 相信号处于原点开关信号
    # 右边沿以左的位置" and that the axis inside the switch first moves in the
    # positive direction; CiA 402 method 9 agrees.  We follow the text: the
    # first Z left of the right edge (inside the switch).
    9: Mode(+1, "hi", -1, True), 10: Mode(+1, "hi", +1, True),
    11: Mode(-1, "hi", +1, True), 12: Mode(-1, "hi", -1, True),
    13: Mode(-1, "lo", +1, True), 14: Mode(-1, "lo", -1, True),
}


def crossing(mode: Mode, rps: tuple[int, int]) -> int:
    """Mechanical position at which the final approach crosses the edge
    (the first position on the far side)."""
    assert mode.edge is not None
    return edge_crossing(mode.edge, mode.final, *rps)


def z_at_or_beyond(pos: int, direction: int, period: int, offset: int) -> int:
    """First Z position at or beyond ``pos`` in ``direction``."""
    return index_at_or_beyond(pos, direction, period, offset)


def home_position(mode: Mode, plant: Any, start: int) -> int | None:
    """Where ``mode`` defines home (None when the plant lacks the signals).

    ``start`` matters only for the Z-only modes 5 and 6, whose home is the
    next Z strictly beyond it (module docstring, decisions).
    """
    if mode.edge is None:
        c = start + mode.final
    else:
        if plant.rps is None:
            return None
        c = crossing(mode, plant.rps)
    if not mode.z:
        return c
    if not plant.z_period:
        return None
    return z_at_or_beyond(c, mode.final, plant.z_period, plant.z_offset)


class HomingSequence:
    """Runs one homing operation on an axis for a HOMING block.

    The sequence is a chain of axis moves; each phase starts the next from
    an axis event (a watched position or the end of a finite move), so the
    result is exact and independent of the scan time.  ``phase`` is one of
    idle, search (including the deceleration after the switch), back,
    final, offset, done, failed, aborted.
    """

    def __init__(self, block: Any, axis: Axis, mode_no: int, v_low: int, v_high: int,
                 offset: int) -> None:
        self.block = block
        self.ax = axis
        self.mode_no = mode_no
        self.mode = MODES[mode_no]
        self.v_low = Fraction(v_low)
        self.v_high = Fraction(max(v_high, v_low))
        self.offset = offset
        span = max(v_high - v_low, 1)
        self.rate = Fraction(span, HOMING_RAMP_US)
        self.active = False
        self.phase = "idle"
        self.reversed = False
        self.home: int | None = None   #: mechanical home point, once known
        #: (switch edge, speed) while slowing down after the switch was found
        self.braking: tuple[int, Fraction] | None = None
        self._end: int | None = None   #: planned end (µs) of the current finite move

    # -- helpers ----------------------------------------------------------------
    def _limit(self, d: int) -> int | None:
        p = self.ax.plant
        return p.limit_pos if d > 0 else p.limit_neg

    def _limit_active(self, t: int, d: int) -> bool:
        lim = self._limit(d)
        if lim is None:
            return False
        m = self.ax.mechanical(t)
        return m >= lim if d > 0 else m <= lim

    def _limit_watch(self, d: int) -> list:
        lim = self._limit(d)
        if lim is None:
            return []
        # partials of bound methods, not closures: a PLC snapshot deep-copies
        # the device state, and copied closures would still point here
        return [(lim, partial(self._limit_reached, d))]

    def _limit_reached(self, d: int, t: int, pos: int) -> None:
        self._on_limit(t, d)

    def _guarded(self, fn: Callable[[int], None]) -> Callable[[int], None]:
        """Wrap the end-of-move continuation of a phase.

        The axis calls ``on_done`` both at the planned end of a move and when
        something stops it early (STF, InnerState written by the program);
        only the planned end may continue the homing.
        """
        return partial(self._guarded_done, fn)

    def _guarded_done(self, fn: Callable[[int], None], t: int) -> None:
        if not self.active:
            return
        if self.ax.stf:
            self._interrupted(t, "the STF emergency stop input stopped the axis")
            return
        if t != self._end:
            self._interrupted(t, "the axis was stopped from outside (InnerState "
                                 "written by the program?)")
            return
        fn(t)

    def _move(self, t: int, d: int, segs: list[Seg], watch: list,
              on_done: Callable[[int], None] | None = None, keep: bool = False) -> None:
        """Start (``keep``: re-plan) a move of the sequence, watching the
        limit switch in its direction."""
        ax = self.ax
        if not keep and self._limit_active(t, d):
            # already on or beyond the limit in this direction: the threshold
            # would never be crossed, so act as if it was just reached
            self._on_limit(t, d)
            return
        ax.owner = self.block
        ax.start(t, d, segs, self._guarded(on_done) if on_done else None, keep_travel=keep)
        self._end = ax.t_end
        ax.watch_positions(t, watch + self._limit_watch(d))
        if not segs and on_done is not None:
            ax.on_done = None   # an empty plan never ends on its own
            on_done(t)

    def fail(self, t: int, why: str) -> None:
        """End the homing without a home position (status 8, diagnostic)."""
        ax = self.ax
        if ax.moving and ax.owner is self.block:
            ax.on_done = None
            ax.stop_now(t)
        self.active = False
        self.phase = "failed"
        self.block.status = 8
        self.block.warn(f"homing mode {self.mode_no} failed: {why}; no home position "
                        f"was set", f"fail{t}")

    def _interrupted(self, t: int, why: str) -> None:
        self.active = False
        self.phase = "aborted"
        self.block.status = 8
        self.block.warn(f"homing mode {self.mode_no} interrupted: {why}; no home position "
                        f"was set", f"intr{t}")

    def abort(self, t: int | None = None) -> None:
        """Run went to 0 or E_Stop: forget the sequence.  The block stops or
        decelerates the axis; no phase may continue from a later event."""
        self.active = False
        self.phase = "aborted"
        ax = self.ax
        if ax.owner is self.block:
            ax.on_done = None
            if t is not None:
                ax.watch_positions(t, [])

    def poll(self, t: int) -> None:
        """Called by the block every scan: an active sequence always has its
        axis moving, so a stopped axis means an outside stop (the STF input
        stops the pulses without telling the block, manual 2.1 item 6)."""
        ax = self.ax
        if self.active and not (ax.moving and ax.owner is self.block):
            self._interrupted(t, "the axis stopped (STF emergency stop input)")

    # -- phases ------------------------------------------------------------------
    def start(self, t: int) -> None:
        self.active = True
        m = self.mode
        ax = self.ax
        p = ax.plant
        if ax.stf:
            self.fail(t, "the STF emergency stop input of the axis is active")
            return
        if m is None:
            self._at_home(t)
            return
        if m.edge is not None and p.rps is None:
            self.fail(t, "the plant has no reference switch (rps) for this axis")
            return
        if m.z and not p.z_period:
            self.fail(t, "the plant has no Z pulses (z_period) for this axis")
            return
        if m.edge is None:
            self._final(t)
            return
        self._seek(t, m.search)

    def _rps(self) -> tuple[int, int]:
        rps = self.ax.plant.rps
        assert rps is not None   # checked in start()
        return rps

    def _seek(self, t: int, d: int) -> None:
        """Inside the switch: position for the final approach at once
        (appendix 1, track 2); outside: search in direction ``d``."""
        lo, hi = self._rps()
        if lo <= self.ax.mechanical(t) <= hi:
            self._position(t)
        else:
            self._search(t, d)

    def _search(self, t: int, d: int) -> None:
        self.phase = "search"
        ax = self.ax
        lo, hi = self._rps()
        m = ax.mechanical(t)
        entry = lo if d > 0 and m < lo else hi if d < 0 and m > hi else None
        watch = [] if entry is None else [(entry, self._found_switch)]
        if entry is None and self._limit(d) is None:
            self.block.warn("the reference switch is not ahead and there is no limit switch "
                            "to reverse at: the search runs without end", "nolimit")
        self._move(t, d, velocity_plan(t, F0, F0, self.v_low, self.v_high,
                                       self.rate, self.rate), watch)

    def _on_limit(self, t: int, d: int) -> None:
        ax = self.ax
        pos = ax.mechanical(t)
        if ax.moving:
            ax.on_done = None
            ax.stop_now(t)   # a hard limit stops the pulses at once
        name = "L+" if d > 0 else "L-"
        if self.phase != "search" or self.reversed:
            what = "again during the search" if self.phase == "search" else \
                f"during the {self.phase} phase"
            self.fail(t, f"limit switch {name} reached at {pos} {what}" + self._why_braking(pos))
            return
        self.braking = None
        self.reversed = True   # appendix 1, tracks 1/3: reverse at the limit
        self._seek(t, -d)

    def _why_braking(self, limit_at: int) -> str:
        """Why a limit was reached while slowing down on the switch: the
        fixed 100 ms ramp (HOMING has no DecTime) needs more pulses than lie
        between the switch edge and the limit.  A real module cannot brake
        harder than its ramp either, so it too meets the limit; this says
        what to change."""
        if self.braking is None:
            return ""
        edge, v = self.braking
        need = ramp_distance(v, self.v_low, self.rate)
        room = abs(limit_at - edge)
        v_max = max(int(20 * room - self.v_low), 0)   # (V + SpdLow) / 2 x 0.1 s <= room
        return (f", while slowing down from {float(v):.0f} Hz to SpdLow after the reference "
                f"switch edge at {edge}: the fixed {HOMING_RAMP_US // 1000} ms homing ramp "
                f"needs {float(need):.0f} pulses but the limit is {room} pulses past the "
                f"edge (use SpdHigh of at most {v_max} Hz, or move the switch farther from "
                f"the limit)")

    def _found_switch(self, t: int, pos: int) -> None:
        """The RPS came on during the search: decelerate to SpdLow and stop
        ("检测到原点开关信号后减速停止"); the stop may lie past the switch."""
        ax = self.ax
        x, v = ax.exact_state(t)
        self.braking = (pos, v)
        self._move(t, ax.direction, stop_plan(t, x, v, self.v_low, self.rate), [],
                   self._position, keep=True)

    def _position(self, t: int) -> None:
        """Get to the approach side of the edge at SpdLow if needed."""
        self.braking = None
        m = self.mode
        assert m is not None and m.edge is not None
        c = crossing(m, self._rps())
        here = self.ax.mechanical(t)
        if (m.final > 0 and here < c) or (m.final < 0 and here > c):
            self._final(t)
            return
        self.phase = "back"
        target = c - 1 if m.final > 0 else c + 1
        self._move(t, -m.final, [cruise(Fraction(t), F0, self.v_low)],
                   [(target, self._back_done)])

    def _back_done(self, t: int, pos: int) -> None:
        self.ax.on_done = None
        self.ax.stop_now(t)
        self._final(t)

    def _final(self, t: int) -> None:
        m = self.mode
        assert m is not None
        self.phase = "final"
        here = self.ax.mechanical(t)
        home = home_position(m, self.ax.plant, here)
        if home is None:
            self.fail(t, "the plant lacks the signals this mode needs")
            return
        self.home = home
        if home == here:   # pragma: no cover - the geometry always puts home ahead
            self._at_home(t)
            return
        self._move(t, m.final, [cruise(Fraction(t), F0, self.v_low)],
                   [(home, self._reached)])

    def _reached(self, t: int, pos: int) -> None:
        self.ax.on_done = None
        self.ax.stop_now(t)   # "电机立刻停止": no deceleration at the home point
        self._at_home(t)

    def _at_home(self, t: int) -> None:
        if self.offset:
            self.phase = "offset"
            d = 1 if self.offset > 0 else -1
            segs, _ = plan_distance(Fraction(t), F0, self.v_low, self.v_high,
                                    self.v_low, Fraction(abs(self.offset)), self.rate, self.rate)
            self._move(t, d, segs, [], self._offset_done)
            return
        self.ax.set_position(t, 0)
        self._finish(t)

    def _offset_done(self, t: int) -> None:
        self.ax.set_position(t, 0)
        self._finish(t)

    def _finish(self, t: int) -> None:
        self.active = False
        self.phase = "done"
        self.block.status = 8
