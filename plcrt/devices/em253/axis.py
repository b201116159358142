"""One EM253 axis: the pulse generator, its position counter and the
mechanics it drives, advanced exactly from event to event.

The axis executes *moves* planned by :mod:`plcrt.devices.motion` and
watches *thresholds*: mechanical positions whose crossing matters (a
reference-switch edge, a hard limit, a Z pulse, the home point).  Crossing
times are solved exactly, so a switch edge is seen at the microsecond the
pulse reaching it is emitted, not at the next scan.

Position counter and mechanics: the counter counts every pulse the axis
generates (signed by direction).  The mechanical position follows the
counter while the output is enabled; while SevOn masks pulse and direction
(EM253 manual 3.2.1) the counter still counts but the mechanics stay put.

This module holds no PLC knowledge: the library instructions
(:mod:`.blocks`) drive it through the methods below.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Callable, Optional

from ..motion import Seg, cruise, first_time_at, plan_distance, ramp

F0 = Fraction(0)


@dataclass
class AxisPlant:
    """The machine around one axis (from the plant file)."""

    start: int = 0                         #: mechanical position at power-up
    rps: Optional[tuple[int, int]] = None  #: reference switch active in [lo, hi]
    limit_neg: Optional[int] = None        #: L- active at and below
    limit_pos: Optional[int] = None        #: L+ active at and above
    z_period: Optional[int] = None         #: pulses per revolution (one Z each)
    z_offset: int = 0                      #: mechanical position of one Z pulse
    events: list[tuple[int, str, bool]] = field(default_factory=list)  #: (t_us, input, value)


Threshold = tuple[int, Callable[[int, int], None]]  # (mechanical position, handler(t, pos))


class Axis:
    """Pulse generator + counter + mechanics of one axis."""

    def __init__(self, plant: AxisPlant) -> None:
        self.plant = plant
        self.counter = 0            #: position counter at the start of the move
        self.mech_offset = plant.start  #: mechanical position minus counter (unmasked)
        self.frozen = plant.start   #: mechanical position while masked
        self.direction = 1
        self.segs: list[Seg] = []
        self.si = 0                 #: current segment
        self.t_end: Optional[int] = None  #: integer µs at which the move ends
        self.on_done: Optional[Callable[[int], None]] = None
        self.masked = False         #: SevOn: pulses/direction masked
        self.stf = False            #: hardware emergency-stop input
        self.watch: list[Threshold] = []
        self._next: Optional[tuple[int, int, Callable]] = None  # (t, pos, handler)
        self.pulses_total = 0       #: statistics: pulses generated
        self.last_travel = 0
        self.dirty = True           #: terminals need rewriting (state changed while stopped)
        self._tc_t = -1
        self._tc_segs: list = []
        self._tc_n = 0
        self.owner: object = None   #: the block instance that commands the axis

    # -- state at a time ----------------------------------------------------
    @property
    def moving(self) -> bool:
        return bool(self.segs)

    def _seg_at(self, t: int) -> Seg:
        segs = self.segs
        i = self.si
        # perf: time mostly moves forward, so the index mostly advances;
        # a query at an earlier time (a reader after an event) steps back
        while i > 0 and t < (segs[i - 1].t1_ceil or 0):  # earlier segments all end
            i -= 1
        while i + 1 < len(segs):
            end = segs[i].t1_ceil
            if end is None or t < end:
                break
            i += 1
        self.si = i
        return segs[i]

    def travel(self, t: int) -> int:
        """Whole pulses of the current move emitted by time ``t``."""
        if not self.segs:
            return 0
        if t == self._tc_t and self._tc_segs is self.segs:
            return self._tc_n  # perf: several readers per scan
        s = self._seg_at(t)
        if s.t1_ceil is not None and t >= s.t1_ceil:
            x = s.x1
            n = x.numerator // x.denominator
        else:
            n = s.pulses(t)
        self._tc_t, self._tc_segs, self._tc_n = t, self.segs, n
        return n

    def position(self, t: int) -> int:
        """The module's position counter at time ``t``."""
        return self.counter + self.direction * self.travel(t)

    def mechanical(self, t: int) -> int:
        """Mechanical position at time ``t`` (pulses)."""
        if self.masked:
            return self.frozen
        return self.position(t) + self.mech_offset

    def speed(self, t: int) -> int:
        """Signed output frequency in Hz (0 when stopped)."""
        if not self.segs:
            return 0
        s = self._seg_at(t)
        if s.t1_ceil is not None and t >= s.t1_ceil:
            return 0
        return self.direction * s.hz(t)

    def exact_state(self, t: int) -> tuple[Fraction, Fraction]:
        """(exact travel, exact speed in Hz) at time ``t`` of the current move."""
        if not self.segs:
            return F0, F0
        s = self._seg_at(t)
        if s.t1_ceil is not None and t >= s.t1_ceil:
            return s.x1, F0
        return s.travel(t), s.speed(t)

    # -- commands --------------------------------------------------------
    def _rebase(self, t: int) -> None:
        """Fold the emitted pulses of the current move into the counters."""
        n = self.travel(t)
        self.counter += self.direction * n
        self.pulses_total += n
        self.last_travel = n  #: pulses of the move just folded in (for C_Pos)

    def stop_now(self, t: int) -> None:
        """Stop the pulse train at ``t`` (E_Stop, STF, a hard limit, or the
        end of the move) and tell the move's owner."""
        self._rebase(t)
        # the terminals (P, D, limits, Z) must be recomputed at the next
        # scan end: a stopped axis is no longer recomputed every scan
        self.dirty = True
        self.segs = []
        self.si = 0
        self.t_end = None
        self.watch = []
        self._next = None
        done, self.on_done = self.on_done, None
        if done is not None:
            done(t)

    def start(self, t: int, direction: int, segs: list[Seg],
              on_done: Optional[Callable[[int], None]] = None,
              keep_travel: bool = False) -> None:
        """Begin (or re-plan) a move whose segments start at time ``t``.

        With ``keep_travel`` the segments continue the current move's travel
        (used when the plan changes mid-move); otherwise the emitted pulses
        are folded into the counter and the new move starts at travel 0.
        """
        if not keep_travel or not segs:
            # an empty plan has no travel of its own: fold the pulses of the
            # current move in now, or they would be lost from the counter
            self._rebase(t)
        self.direction = direction
        self.dirty = True
        self.segs = segs
        self.si = 0
        self.on_done = on_done
        last = segs[-1] if segs else None
        self.t_end = None if last is None or last.t1_ceil is None else last.t1_ceil
        if not segs:
            self.t_end = t
        self._arm(t)

    def set_masked(self, t: int, masked: bool) -> None:
        """SevOn: while masked the counter counts but the mechanics stay put."""
        if masked == self.masked:
            return
        if masked:
            self.frozen = self.mechanical(t)
        else:
            self.mech_offset = self.frozen - self.position(t)
        self.masked = masked
        self.dirty = True
        self._arm(t)

    def set_position(self, t: int, value: int) -> None:
        """SET_AbsPos / homing: the counter reads ``value`` now."""
        n = self.travel(t)
        mech = self.mechanical(t)
        self.dirty = True
        self.counter = value - self.direction * n
        if not self.masked:
            self.mech_offset = mech - value

    # -- thresholds ------------------------------------------------------
    def watch_positions(self, t: int, items: list[Threshold]) -> None:
        """Replace the watched mechanical positions (re-solved at once)."""
        self.watch = list(items)
        self._arm(t)

    def _arm(self, t: int) -> None:
        """Find the earliest watched crossing ahead in the current move."""
        self._next = None
        if not self.segs or self.masked or not self.watch:
            return
        d = self.direction
        base = self.counter + self.mech_offset
        best: Optional[tuple[int, int, Callable]] = None
        for pos, handler in self.watch:
            need = (pos - base) * d
            if need < self.travel(t):
                continue
            te = self._time_of_travel(need, t)
            if te is not None and (best is None or te < best[0]):
                best = (te, pos, handler)
        self._next = best

    def _time_of_travel(self, need: int, t: int) -> Optional[int]:
        for i in range(self.si, len(self.segs)):
            s = self.segs[i]
            lo = t if i == self.si else max(t, -((-s.t0.numerator) // s.t0.denominator))
            te = first_time_at(s, need, lo)
            if te is not None:
                if s.t1_ceil is not None and te > s.t1_ceil:
                    continue
                return te
        return None

    # -- time advance ------------------------------------------------------
    def advance(self, t_to: int) -> None:
        """Process every event up to ``t_to`` in time order."""
        guard = 0
        while self.segs:
            guard += 1
            if guard > 10000:  # pragma: no cover - defensive: an event loop that never ends
                raise RuntimeError("axis event loop did not settle")
            nxt = self._next
            te_done = self.t_end
            if nxt is not None and nxt[0] <= t_to and (te_done is None or nxt[0] <= te_done):
                t, pos, handler = nxt
                self.watch = [w for w in self.watch if not (w[0] == pos and w[1] is handler)]
                self._next = None
                handler(t, pos)
                if self.segs:
                    self._arm(t)
                continue
            if te_done is not None and te_done <= t_to:
                # the move ends on its last pulse: the same as stopping there
                self.stop_now(te_done)
                continue
            break


def velocity_plan(t: int, x: Fraction, v_now: Fraction, v_ss: Fraction, v_set: Fraction,
                  r_acc: Fraction, r_dec: Fraction) -> list[Seg]:
    """Run endlessly at ``v_set``: jump to the start speed if stopped, ramp, cruise."""
    t0 = Fraction(t)
    segs: list[Seg] = []
    v = v_now if v_now > 0 else v_ss
    if v < v_set:
        segs.append(ramp(t0, x, v, v_set, r_acc))
    elif v > v_set:
        segs.append(ramp(t0, x, v, v_set, r_dec))
    if segs:
        t0, x = segs[-1].end
    segs.append(cruise(t0, x, v_set))
    return segs


def stop_plan(t: int, x: Fraction, v_now: Fraction, v_ss: Fraction, r_dec: Fraction) -> list[Seg]:
    """Decelerate to the stop speed, then stop (the pulse train ends)."""
    if v_now <= v_ss:
        return [cruise(Fraction(t), x, v_now, Fraction(0))] if v_now > 0 else []
    return [ramp(Fraction(t), x, v_now, v_ss, r_dec)]


def distance_plan(t: int, x: Fraction, v_now: Fraction, v_ss: Fraction, v_set: Fraction,
                  length: Fraction, r_acc: Fraction, r_dec: Fraction) -> tuple[list[Seg], bool]:
    """Travel exactly to ``x + length`` and stop at the stop speed."""
    v = v_now if v_now > 0 else v_ss
    return plan_distance(Fraction(t), x, v, v_set, v_ss, length, r_acc, r_dec)
