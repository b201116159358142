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
from typing import Any, Callable, Optional

from ..motion import Seg, cruise, first_time_at, plan_distance, ramp

F0 = Fraction(0)
NEVER = 1 << 62   #: a time after every simulated time (µs)
#: the "segment" of a stopped axis: travel 0 and speed 0 at every time
_STOPPED = Seg(F0, None, F0, F0, F0)


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
        #: the module that steps the axis (its quiet time ends whenever
        #: :attr:`wake` is set), or None
        self.module: Optional[Any] = None
        self._wake = 0              #: see :attr:`wake`
        self._stopped_window()
        self.owner: object = None   #: the block instance that commands the axis

    @property
    def wake(self) -> int:
        """perf: before this time (µs) the module need not look at the axis:
        no watched crossing, no end of the move and no change of an input
        bit (RPS, L+, L-, Z) is due (:meth:`next_change`).  Whatever changes
        the axis sets it to 0, so the next step looks again; every setting
        also ends the module's quiet time (EM253Module.quiet_to), which the
        module computes again from the new value after its step."""
        return self._wake

    @wake.setter
    def wake(self, t: int) -> None:
        self._wake = t
        if self.module is not None:
            self.module.quiet_to = 0

    # -- state at a time ----------------------------------------------------
    @property
    def moving(self) -> bool:
        return bool(self.segs)

    def _stopped_window(self) -> None:
        """perf: the window of a stopped axis covers all time (travel 0)."""
        self._w_lo, self._w_hi, self._w_seg, self._w_hz = -NEVER, NEVER, _STOPPED, 0
        self._w_pos = (0, 0, self.counter, 1)

    def _seg_at(self, t: int) -> Seg:
        """The segment of the current move that holds time ``t``; it and its
        time window become the reader's window (see :meth:`travel`)."""
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
        s = segs[i]
        # perf: the times in which segment i is the one _seg_at finds: from
        # the end of the one before (all time before for the first) to its
        # own end (all time after for an endless cruise; at and after the
        # end of the last segment the travel stops growing: not in it)
        self._w_seg = s
        self._w_lo = (segs[i - 1].t1_ceil or 0) if i else -NEVER
        self._w_hi = NEVER if s.t1_ceil is None else s.t1_ceil
        # perf: a segment at constant speed (a cruise: HA 0) has its signed
        # speed computed once for the window (the direction is only set by
        # start(), which empties the window); None: compute it per time
        self._w_hz = self.direction * (s.HB // s.HD) if s.HA == 0 else None
        self._w_pos = self._position_poly(s)
        return s

    def _position_poly(self, s: Seg) -> tuple[int, int, int, int]:
        """perf: (a, b, c, d) with the position counter at every time t of
        segment ``s`` equal to ((a t + b) t + c) // d: the counter and the
        direction folded into the travel's polynomial.  Going forward that
        is counter + N // D (N the travel's numerator); going backwards,
        counter - N // D, and -(N // D) == (D - 1 - N) // D for D > 0.
        Valid while the counter and the direction stay (a window is left
        or recomputed whenever they change)."""
        base = self.counter * s.D
        if self.direction > 0:
            return s.A, s.B, s.C + base, s.D
        return -s.A, -s.B, base - s.C + s.D - 1, s.D

    def travel(self, t: int) -> int:
        """Whole pulses of the current move emitted by time ``t``."""
        # perf: inside the window of the last segment found, the segment's
        # polynomial (Seg.pulses) inline; readers ask at every scan start.
        # The window test is two comparisons joined by ``and`` here and in
        # the blocks' shortcuts: CPython 3.11 runs fewer instructions for
        # that than for the chained ``lo <= t < hi``
        if self._w_lo <= t and t < self._w_hi:
            s = self._w_seg
            return ((s.A * t + s.B) * t + s.C) // s.D
        if not self.segs:
            return 0
        s = self._seg_at(t)
        if s.t1_ceil is not None and t >= s.t1_ceil:
            x = s.x1
            return x.numerator // x.denominator
        return s.pulses(t)

    def position(self, t: int) -> int:
        """The module's position counter at time ``t``."""
        if self._w_lo <= t and t < self._w_hi:   # perf: the window's counter polynomial
            a, b, c, d = self._w_pos
            return ((a * t + b) * t + c) // d
        return self.counter + self.direction * self.travel(t)

    def mechanical(self, t: int) -> int:
        """Mechanical position at time ``t`` (pulses)."""
        if self.masked:
            return self.frozen
        return self.position(t) + self.mech_offset

    def speed(self, t: int) -> int:
        """Signed output frequency in Hz (0 when stopped)."""
        if self._w_lo <= t and t < self._w_hi:   # perf: Seg.hz inline, as in travel()
            hz = self._w_hz
            if hz is None:
                s = self._w_seg
                hz = self.direction * ((s.HA * t + s.HB) // s.HD)
            return hz
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
        # scan end: a stopped axis is not looked at again until it changes
        self.wake = 0
        self.segs = []
        self.si = 0
        self._stopped_window()
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
        self.wake = 0
        self.segs = segs
        self.si = 0
        if segs:
            self._w_lo = self._w_hi = 0   # no window until a reader finds one
        else:
            self._stopped_window()
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
        self.wake = 0
        self._arm(t)

    def set_position(self, t: int, value: int) -> None:
        """SET_AbsPos / homing: the counter reads ``value`` now."""
        n = self.travel(t)
        mech = self.mechanical(t)
        self.wake = 0
        self.counter = value - self.direction * n
        # the window's position polynomial holds the old counter
        if self.segs:
            self._w_lo = self._w_hi = 0   # no window until a reader finds one
        else:
            self._stopped_window()
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
        self.wake = 0   # the next event may be earlier than the module knows
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
        """First µs at or after ``t`` at which the move's travel reaches
        ``need`` whole pulses, or None when the move ends before."""
        self._seg_at(t)   # the search starts in the segment of ``t``
        for i in range(self.si, len(self.segs)):
            s = self.segs[i]
            lo = t if i == self.si else max(t, -((-s.t0.numerator) // s.t0.denominator))
            te = first_time_at(s, need, lo)
            if te is not None:
                if s.t1_ceil is not None and te > s.t1_ceil:
                    continue
                return te
        return None

    # -- when to look again -----------------------------------------------
    def next_change(self, t: int) -> int:
        """The earliest time after ``t`` at which the axis does something by
        itself: a watched crossing, the end of its move, or a change of one
        of its input bits (RPS, L+, L-, Z), which depend on the mechanical
        position only.  :data:`NEVER` for a stopped axis.  Until then its
        terminal bytes are those at ``t`` and :meth:`advance` has nothing
        to do (perf: the module skips the axis until then)."""
        if not self.segs:
            return NEVER
        nxt = self._next
        wake = NEVER if nxt is None else nxt[0]
        t_end = self.t_end
        if t_end is not None and t_end < wake:
            wake = t_end
        if self.masked:
            return wake   # the mechanics stay put: no input bit changes
        d = self.direction
        base = self.counter + self.mech_offset
        edge = self._next_edge(base + d * self.travel(t), d)
        if edge is not None:
            te = self._time_of_travel((edge - base) * d, t)
            if te is not None and te < wake:
                wake = te
        return wake

    def _next_edge(self, m: int, d: int) -> Optional[int]:
        """The nearest mechanical position beyond ``m`` in direction ``d`` at
        which an input bit changes (module._bytes: RPS active in [lo, hi],
        L+ at and above limit_pos, L- at and below limit_neg, Z on the
        positions z_offset + k z_period), or None."""
        p = self.plant
        best: Optional[int] = None
        edges: list[int] = []
        if p.rps is not None:
            lo, hi = p.rps
            edges += (lo, hi + 1) if d > 0 else (hi, lo - 1)
        if p.limit_pos is not None:
            edges.append(p.limit_pos if d > 0 else p.limit_pos - 1)
        if p.limit_neg is not None:
            edges.append(p.limit_neg + 1 if d > 0 else p.limit_neg)
        if p.z_period:
            r = (m - p.z_offset) % p.z_period
            if d > 0:
                edges.append(m + (p.z_period - r if r else p.z_period))
            else:
                edges.append(m - (r or p.z_period))
            if not r:
                edges.append(m + d)   # leaving the Z mark it stands on
        for e in edges:
            if (e - m) * d > 0 and (best is None or (e - best) * d < 0):
                best = e
        return best

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
