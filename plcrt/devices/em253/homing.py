"""The 14 homing modes of the EM253 (manual, appendix 1) and mode 0.

Every mode is described by geometry, not by edge names (which sources use
inconsistently): which reference-switch (RPS) edge defines home, the
direction of the final approach across it, whether the home point is that
crossing or the first Z pulse beyond it, and the first search direction
(toward the limit switch the mode uses).

=====  ======  ==========  ========  ====  ===================================
mode   search  edge        final     Z     home position
=====  ======  ==========  ========  ====  ===================================
1      -       right (hi)  +         yes   first Z right of the RPS (outside)
2      +       left (lo)   -         yes   first Z left of the RPS (outside)
3      -       right (hi)  +         no    where the RPS is left (hi + 1)
4      +       left (lo)   -         no    where the RPS is left (lo - 1)
5      -       -           -         yes   next Z in the negative direction
6      +       -           +         yes   next Z in the positive direction
7      +       left (lo)   -         yes   first Z left of the left edge (outside)
8      +       left (lo)   +         yes   first Z right of the left edge (inside)
9      +       right (hi)  -         yes   first Z left of the right edge (inside)
10     +       right (hi)  +         yes   first Z right of the right edge (outside)
11     -       right (hi)  +         yes   first Z right of the right edge (outside)
12     -       right (hi)  -         yes   first Z left of the right edge (inside)
13     -       left (lo)   +         yes   first Z right of the left edge (inside)
14     -       left (lo)   -         yes   first Z left of the left edge (outside)
0      -       -           -         -     the current position (no motion)
=====  ======  ==========  ========  ====  ===================================

Sequence (appendix 1, mode 1 text): search at SpdHigh toward the switch
(a limit in the way reverses the search); on reaching the switch
decelerate and stop; if needed move back at SpdLow until on the approach
side of the edge; then cross the edge at SpdLow and stop at once at the
home point ("电机立刻停止").  Starting inside the switch skips the search
(appendix 1, track 2).  The home point then reads 0 on the position
counter; a non-zero PosOffset moves that many pulses further and sets 0
there (docs/em253.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Optional

from ..motion import cruise, plan_distance
from .axis import Axis, stop_plan, velocity_plan

HOMING_RAMP_US = 100_000  #: SpdLow <-> SpdHigh ramp time (HOMING has no ramp inputs)


@dataclass(frozen=True)
class Mode:
    search: int            #: first search direction
    edge: Optional[str]    #: "lo" / "hi" RPS edge, None for Z-only modes
    final: int             #: direction of the final approach
    z: bool                #: home is the first Z beyond the crossing


MODES: dict[int, Optional[Mode]] = {
    0: None,
    1: Mode(-1, "hi", +1, True), 2: Mode(+1, "lo", -1, True),
    3: Mode(-1, "hi", +1, False), 4: Mode(+1, "lo", -1, False),
    5: Mode(-1, None, -1, True), 6: Mode(+1, None, +1, True),
    7: Mode(+1, "lo", -1, True), 8: Mode(+1, "lo", +1, True),
    9: Mode(+1, "hi", -1, True), 10: Mode(+1, "hi", +1, True),
    11: Mode(-1, "hi", +1, True), 12: Mode(-1, "hi", -1, True),
    13: Mode(-1, "lo", +1, True), 14: Mode(-1, "lo", -1, True),
}


def crossing(mode: Mode, rps: tuple[int, int]) -> int:
    """Mechanical position at which the final approach crosses the edge
    (the first position on the far side)."""
    lo, hi = rps
    return {("lo", -1): lo - 1, ("lo", 1): lo, ("hi", -1): hi, ("hi", 1): hi + 1}[
        (mode.edge, mode.final)]


def z_at_or_beyond(pos: int, direction: int, period: int, offset: int) -> int:
    """First Z position at or beyond ``pos`` in ``direction``."""
    if direction > 0:
        k = -((offset - pos) // period)   # ceil((pos - offset) / period)
    else:
        k = (pos - offset) // period      # floor
    return offset + k * period


def home_position(mode: Mode, plant: Any, start: int) -> Optional[int]:
    """Where ``mode`` defines home (None when the plant lacks the signals)."""
    if mode.edge is None:
        c = start
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
    """Runs one homing operation on an axis for a HOMING block."""

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
        self.reversed = False
        self.home: Optional[int] = None

    # -- helpers ----------------------------------------------------------------
    def _limit_watch(self, d: int) -> list:
        p = self.ax.plant
        lim = p.limit_pos if d > 0 else p.limit_neg
        return [] if lim is None else [(lim, self._limit)]

    def _move(self, t: int, d: int, segs: list, watch: list, on_done=None) -> None:
        self.ax.owner = self.block
        self.ax.start(t, d, segs, on_done)
        self.ax.watch_positions(t, watch + self._limit_watch(d))

    def fail(self, t: int, why: str) -> None:
        if self.ax.moving:
            self.ax.on_done = None
            self.ax.stop_now(t)
        self.active = False
        self.block.status = 8
        self.block.warn(f"homing mode {self.mode_no} failed: {why}", f"fail{t}")

    def abort(self) -> None:
        self.active = False

    # -- phases ------------------------------------------------------------------
    def start(self, t: int) -> None:
        self.active = True
        m = self.mode
        ax = self.ax
        p = ax.plant
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
        lo, hi = p.rps
        if lo <= ax.mechanical(t) <= hi:
            self._position(t)   # inside the switch: no search (appendix 1, track 2)
        else:
            self._search(t, m.search)

    def _search(self, t: int, d: int) -> None:
        ax = self.ax
        lo, hi = ax.plant.rps
        m = ax.mechanical(t)
        entry = lo if d > 0 and m < lo else hi if d < 0 and m > hi else None
        watch = [] if entry is None else [(entry, self._found_switch)]
        lim = ax.plant.limit_pos if d > 0 else ax.plant.limit_neg
        if entry is None and lim is None:
            self.block.warn("the reference switch is not ahead and there is no limit switch "
                            "to reverse at: the search runs without end", "nolimit")
        self._move(t, d, velocity_plan(t, Fraction(0), Fraction(0), self.v_low, self.v_high,
                                       self.rate, self.rate), watch)

    def _limit(self, t: int, pos: int) -> None:
        ax = self.ax
        d = ax.direction
        ax.on_done = None
        ax.stop_now(t)
        if self.reversed or self.phase_final:
            self.fail(t, f"limit switch reached at {pos} during the "
                         f"{'final approach' if self.phase_final else 'reversed search'}")
            return
        self.reversed = True
        self._search(t, -d)

    phase_final = False

    def _found_switch(self, t: int, pos: int) -> None:
        ax = self.ax
        x, v = ax.exact_state(t)
        ax.start(t, ax.direction, stop_plan(t, x, v, self.v_low, self.rate),
                 self._stopped_after_switch, keep_travel=True)
        ax.watch_positions(t, self._limit_watch(ax.direction))

    def _stopped_after_switch(self, t: int) -> None:
        self._position(t)

    def _position(self, t: int) -> None:
        """Get to the approach side of the edge at SpdLow if needed."""
        m = self.mode
        assert m is not None and m.edge is not None
        c = crossing(m, self.ax.plant.rps)
        here = self.ax.mechanical(t)
        if (m.final > 0 and here < c) or (m.final < 0 and here > c):
            self._final(t)
            return
        back = -m.final
        target = c - 1 if m.final > 0 else c + 1
        self._move(t, back, [cruise(Fraction(t), Fraction(0), self.v_low)],
                   [(target, self._back_done)])

    def _back_done(self, t: int, pos: int) -> None:
        self.ax.on_done = None
        self.ax.stop_now(t)
        self._final(t)

    def _final(self, t: int) -> None:
        m = self.mode
        assert m is not None
        self.phase_final = True
        home = home_position(m, self.ax.plant, self.ax.mechanical(t))
        if home is None:
            self.fail(t, "the plant lacks the signals this mode needs")
            return
        self.home = home
        if home == self.ax.mechanical(t):
            self._at_home(t)
            return
        self._move(t, m.final, [cruise(Fraction(t), Fraction(0), self.v_low)],
                   [(home, self._reached)])

    def _reached(self, t: int, pos: int) -> None:
        self.ax.on_done = None
        self.ax.stop_now(t)   # "电机立刻停止": no deceleration at the home point
        self._at_home(t)

    def _at_home(self, t: int) -> None:
        ax = self.ax
        if self.offset:
            d = 1 if self.offset > 0 else -1
            segs, _ = plan_distance(Fraction(t), Fraction(0), self.v_low, self.v_high,
                                    self.v_low, Fraction(abs(self.offset)), self.rate, self.rate)
            self._move(t, d, segs, [], self._offset_done)
            return
        ax.set_position(t, 0)
        self._finish(t)

    def _offset_done(self, t: int) -> None:
        self.ax.set_position(t, 0)
        self._finish(t)

    def _finish(self, t: int) -> None:
        self.active = False
        self.block.status = 8
