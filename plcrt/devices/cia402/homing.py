"""CiA 402 homing (mode 6, HM) as a sequence of exact motion phases.

The method rows are in :mod:`.homing_methods`; this module drives one
homing operation through them.  It knows nothing of the statusword, the
controlword or the object dictionary: the drive core reads 6098h, 6099h,
609Ah, 607Ch (and Kinco's 6099h:05/:06) into :class:`HomingParams`, the
plant into :class:`~.homing_methods.HomingPlant`, and calls the sequence.

Protocol (what the drive calls)::

    seq = HomingSequence("kinco-servo", params, plant)
    step = seq.start(t, position)          # Phase | Done | Failed
    while isinstance(step, Phase):
        t, position, event = step.first_event()     # or the drive's own detection
        step = seq.on_event(t, position, event)

* A :class:`Phase` starts at integer µs ``t0`` at mechanical position ``x0``
  and moves in ``direction`` (+1 / -1, or standing still) along ``segs``
  (:mod:`plcrt.devices.motion` segments of travel from 0, in absolute time).
  ``position_at(t)`` / ``speed_at(t)`` give the axis state inside it.
* The drive reports the first of: a watched position reached (``Watch.event``),
  the end of a finite phase (``"end"``; a phase with no segments stands still
  until ``until``), the ``deadline`` (``"timeout"``, HCFA P03.07).
  :meth:`Phase.first_event` finds it exactly.  The position reported for a
  watch is the watched position itself.  A watch reached at the µs a phase ends
  comes before the end.
* :class:`Done` carries the home point (mechanical, where the home event was
  latched), the final mechanical position and ``position_shift``: the value to
  add to mechanical positions so that 6064h reads as the model's offset rule
  says.  :class:`Failed` carries the explanation (method, the missing or
  unexpected signal, the manual section) and the alarm number where the manual
  gives one (HCFA 62 invalid method, 63 timeout).
* ``seq.abort(t)`` (controlword bit 4 1 -> 0, halt, quick stop) ends the
  sequence; the drive stops the axis by its own rules.

Paths (HCFA §10.1, for both models; Kinco is silent on speeds): search at
6099h:01 with 609Ah; on the first switch edge slow to 6099h:02 (continuing,
when the next target lies ahead) or decelerate with 609Ah to a stop and
reverse; the defining edge is approached and the index searched at 6099h:02; a
start on the switch leaves it at 6099h:02, except methods 4, 6, 20, 22, which
leave at 6099h:01 (HCFA §10.1 4A, 6B, 20B, 22B) and off the switch approach at
6099h:02 at once.  A limit switch in the search direction of 7-14 / 23-30 stops
the axis at once and reverses the search (path B). Phases at 6099h:02 start and
stop at once; the axis stops at once at the home event.  Kinco latches the
defining edge in the search when the search crosses it in the final direction
(§2.5, method 12 from the + side); HCFA re-approaches it at 6099h:02. Kinco
-17/-18 (§2.5) search at 6099h:01 toward the mechanical end, past the limits;
from the end on, a standing "stall" phase lasts until the first armed criterion
(6065h, 6099h:04, 60F9h:0A) holds, timed on the command that still runs at
6099h:01; a start at the end stalls at once, the command starting from rest.
Decisions are logged in docs/cia402.md, "Homing".
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Union

from ...errors import PlcConfigError, PlcRuntimeError
from ..homing_geometry import index_at_or_beyond
from ..motion import US, Seg, cruise, first_time_at, plan_distance, ramp
from .homing_methods import (HARD_STOP, HERE, HS_NEG, HS_POS, INDEX, NLS, PLS,
                             SIGNAL_NAMES, HomingPlant, Method, method_table)

__all__ = ["Done", "Failed", "HomingParams", "HomingSequence", "Phase", "Watch",
           "homing_status", "power_on_homing", "run"]

F0 = Fraction(0)
LIMIT_NAME = {NLS: "negative limit (NLS)", PLS: "positive limit (PLS)"}
#: methods leaving the switch at 6099h:01 when started on it (HCFA §10.1 4A, 6B, 20B, 22B)
FAST_LEAVE = (4, 6, 20, 22)
#: §7.5.4 error table: methods in which each limit going active is a homing error
HCFA_LIMIT_ERRORS = {NLS: {2, *range(7, 11), *range(23, 27), 3, 4, 19, 20, 33, 34},
                     PLS: {1, *range(11, 15), *range(27, 31), 3, 4, 19, 20, 33, 34}}
BLIND_QUARTERS = {0: 0, 1: 1, 2: 2}   #: Kinco 6099h:06: 0, 1/4, 1/2 revolution (§2.4)


@dataclass(frozen=True)
class HomingParams:
    """The homing objects as the drive holds them."""

    method: int                    #: 6098h
    v_search: int                  #: 6099h:01, counts/s
    v_zero: int                    #: 6099h:02, counts/s
    accel: int                     #: 609Ah, counts/s^2
    offset: int = 0                #: 607Ch
    offset_mode: int = 0           #: Kinco 6099h:05 (§2.3-3)
    blind_zone: int = 0            #: Kinco 6099h:06 (§2.4)
    timeout_ms: int = 0            #: HCFA P03.07, 0 = off (§8.2; unit taken as ms)
    following_error_window: int = 0  #: 6065h (Kinco -17/-18 criterion 1)
    max_current: int = 0           #: Kinco 6099h:04 (criterion 2; > 0 arms it)
    velocity_window: int = 0       #: Kinco 60F9h:0A (criterion 3)


@dataclass(frozen=True)
class Watch:
    position: int
    event: str


@dataclass(frozen=True)
class Phase:
    """One stretch of motion the drive runs until its first event."""

    name: str
    t0: int
    x0: int
    direction: int
    segs: tuple[Seg, ...]
    watches: tuple[Watch, ...] = ()
    deadline: int | None = None
    until: int | None = None       #: end of a standing phase (no segments)

    def _seg_at(self, t: int) -> Seg | None:
        for s in self.segs:
            if s.t1 is None or t < s.t1:
                return s
        return self.segs[-1] if self.segs else None

    def travel_at(self, t: int) -> Fraction:
        s = self._seg_at(t)
        if s is None:
            return F0
        return s.x1 if s.t1 is not None and t >= s.t1 else s.travel(t)

    def position_at(self, t: int) -> int:
        tr = self.travel_at(t)
        return self.x0 + self.direction * (tr.numerator // tr.denominator)

    def speed_at(self, t: int) -> Fraction:
        s = self._seg_at(t)
        if s is None or (s.t1 is not None and t >= s.t1):
            return s.v1 if s is not None else F0
        return s.speed(t)

    def end_time(self) -> int | None:
        if not self.segs:
            return self.until
        return self.segs[-1].t1_ceil

    def time_at_travel(self, need: Fraction | int) -> int | None:
        """First integer µs at which the travel reaches ``need``."""
        for s in self.segs:
            lo = max(self.t0, -((-s.t0.numerator) // s.t0.denominator))
            t = first_time_at(s, need, lo)
            if t is not None:
                return t
        return None

    def first_event(self) -> tuple[int, int, str]:
        """(time, position, event) of the first event of this phase."""
        best: tuple[int, int, int, str] | None = None
        for w in self.watches:
            need = (w.position - self.x0) * self.direction
            if need <= 0 or not self.segs:
                continue
            t = self.time_at_travel(need)
            if t is not None and (best is None or t < best[0]):
                best = (t, 0, w.position, w.event)
        end = self.end_time()
        if end is not None and (best is None or end < best[0]):
            best = (end, 1, self.position_at(end), "end")
        if self.deadline is not None and (best is None or self.deadline < best[0]):
            best = (self.deadline, 2, self.position_at(self.deadline), "timeout")
        if best is None:
            raise PlcRuntimeError(f"homing phase {self.name!r} has no end: nothing to watch")
        return best[0], best[2], best[3]


@dataclass(frozen=True)
class Done:
    t: int
    home_point: int        #: mechanical position of the home event
    position: int          #: mechanical position where the axis stands
    position_shift: int    #: 6064h = mechanical + position_shift
    explanation: str = ""


@dataclass(frozen=True)
class Failed:
    t: int
    position: int
    explanation: str
    alarm: int | None = None    #: HCFA alarm number (62, 63), None where none applies


Step = Union[Phase, Done, Failed]


def power_on_homing(setting: int) -> str:
    """Kinco 6099h:03 (§2.1, §2.3-1): "off", "home" (home once after each
    power-up; the drive must also be set to enable itself, 0x200000) or
    "restore" (a multi-turn absolute encoder keeps its stored home)."""
    try:
        return {0: "off", 1: "home", 2: "restore"}[setting]
    except KeyError:
        raise PlcConfigError(f"6099h:03 = {setting}: power-on homing takes 0, 1 or 2 "
                             f"(Kinco §2.1)") from None


#: statusword bits 10 / 12 / 13 per homing state (HCFA §7.5.4, HM §1.3 table); bit 15 apart
_STATUS_BITS = {"idle": 0x0400, "aborted": 0x0400, "running": 0x0000,
                "done": 0x1400, "failed": 0x2400}


def homing_status(model: str, state: str, homed: bool) -> int:
    """Statusword bits 10, 12, 13 and 15 in HM for a sequence ``state``
    (idle, running, done, failed, aborted).

    Bit 15 differs by model (digest §2.2): HCFA "homing can be triggered"
    (1 while idle or after an abort, 0 once triggered or done, §7.5.4);
    Kinco "reference found" (§2.6): set by a successful homing and kept,
    cleared when a new homing starts (``homed`` is the drive's flag).
    """
    try:
        bits = _STATUS_BITS[state]
    except KeyError:
        raise PlcConfigError(f"homing state {state!r} is not one of "
                             f"{', '.join(_STATUS_BITS)}") from None
    if model == "kinco-servo":
        return bits | (0x8000 if homed else 0)
    return bits | (0x8000 if state in ("idle", "aborted") else 0)


class HomingSequence:
    """One homing operation of ``model`` (see the module docstring).

    ``state`` names the current phase (search, decelerate, leave, pass,
    back, final, offset, stall search, stall) or the outcome (idle, done,
    failed, aborted); ``home`` is the home point once it is known.
    """

    def __init__(self, model: str, params: HomingParams, plant: HomingPlant) -> None:
        table = method_table(model)
        self.model = model
        self.params = params
        self.plant = plant
        self.kinco = model == "kinco-servo"
        self.method: Method | None = table.get(params.method)
        self.vh = Fraction(max(params.v_search, params.v_zero))   # 6099h:01
        self.vl = Fraction(params.v_zero)                          # 6099h:02
        self.rate = Fraction(params.accel, US)                     # 609Ah in Hz per µs
        self.state = "idle"
        self.reversed = False          #: the search has reversed at its limit
        self.home: int | None = None
        self.phase: Phase | None = None
        self.deadline: int | None = None
        self.t_ramp_end: int | None = None

    # -- explanations ---------------------------------------------------------------
    def _label(self) -> str:
        m = self.method
        src = m.source if m else "6098h"
        return f"homing method {self.params.method} ({src})"

    def _fail(self, t: int, x: int, why: str, alarm: int | None = None) -> Failed:
        self.state = "failed"
        return Failed(t, x, f"{self._label()} failed: {why}; no home was set", alarm)

    def _limit_error(self, t: int, x: int, which: str, phase: str = "") -> Failed:
        m = self.method
        assert m is not None
        if self.reversed and which != m.reverse_at:
            rule = "both limits were seen (HCFA §7.5.4)"
        elif not self.kinco and m.number in HCFA_LIMIT_ERRORS[which]:
            rule = "HCFA §7.5.4 lists this limit as a homing error for this method"
        else:
            rule = ("the method does not use this limit in this phase (plcrt extends the "
                    "§7.5.4 error table, docs/cia402.md)")
        return self._fail(t, x, f"{LIMIT_NAME[which]} active at {x} in the {phase or self.state} "
                                f"phase; {rule}")

    # -- phase builders -------------------------------------------------------------
    def _phase(self, name: str, t: int, x: int, d: int, segs: list[Seg],
               watches: list[Watch], limits: bool = True) -> Phase:
        self.state = name
        w = list(watches)
        if limits and d:
            which = PLS if d > 0 else NLS
            lim = self.plant.limit_position(which)
            if lim is not None and (lim - x) * d > 0:
                w.append(Watch(lim, "limit"))
        self.phase = Phase(name, t, x, d, tuple(segs), tuple(w), self.deadline)
        return self.phase

    def _to_speed(self, t: int, v0: Fraction, v: Fraction) -> list[Seg]:
        """Ramp from ``v0`` to ``v`` with 609Ah, then cruise without end; a
        start at or below 6099h:02 jumps to it (stepper start speed)."""
        T = Fraction(t)
        if v0 < v and v <= self.vl:
            return [cruise(T, F0, v)]
        segs: list[Seg] = []
        x = F0
        if v0 != v:
            segs.append(ramp(T, x, v0, v, self.rate))
            T, x = segs[-1].end
            self.t_ramp_end = segs[-1].t1_ceil
        segs.append(cruise(T, x, v))
        return segs

    def _stop_then(self, t: int, x: int, v: Fraction) -> Step:
        """Decelerate to a stop with 609Ah (at once from 6099h:02 or less),
        then approach the edge from rest."""
        d = self.phase.direction if self.phase else 0
        if v <= self.vl:
            return self._position(t, x)
        return self._phase("decelerate", t, x, d, [ramp(Fraction(t), F0, v, F0, self.rate)], [])

    # -- start ----------------------------------------------------------------------
    def start(self, t: int, x: int) -> Step:
        p, m, plant = self.params, self.method, self.plant
        if m is None:
            known = ", ".join(str(n) for n in sorted(method_table(self.model)))
            where = "Kinco §2.2" if self.kinco else "HCFA §7.5.4, §10.1; alarm 62"
            return self._fail(t, x, f"6098h = {p.method} is not a method of {self.model} "
                                    f"(supported: {known}; {where})",
                              None if self.kinco else 62)
        if self.kinco and p.blind_zone not in BLIND_QUARTERS:
            return self._fail(t, x, f"6099h:06 = {p.blind_zone}: the index blind zone takes "
                                    f"0, 1 or 2 (0, 1/4, 1/2 rev, Kinco §2.4)")
        if self.kinco and p.offset_mode not in (0, 1):
            return self._fail(t, x, f"6099h:05 = {p.offset_mode}: the offset mode takes 0 or 1 "
                                    f"(Kinco §2.1, §2.3-3)")
        if m.signal != HERE and min(p.v_search, p.v_zero, p.accel) <= 0:
            return self._fail(t, x, "6099h:01, 6099h:02 and 609Ah must all be non-zero "
                                    "(statusword bit 14, HCFA §7.5.4)")
        for need in m.needs():
            missing = {NLS: plant.neg_limit, PLS: plant.pos_limit,
                       "home_switch": plant.home_switch, "index_period": plant.index_period,
                       "neg_stop": plant.neg_stop, "pos_stop": plant.pos_stop}[need] is None
            if missing:
                what = SIGNAL_NAMES.get(need, need)
                extra = " (an index method needs closed loop and an encoder with Z, HCFA §2.2)" \
                    if need == "index_period" else ""
                return self._fail(t, x, f"the method needs the plant's {what} "
                                        f"({need}) and the plant has none{extra}",
                                  62 if need == "index_period" and not self.kinco else None)
        if p.timeout_ms and not self.kinco:
            self.deadline = t + p.timeout_ms * 1000
        if m.signal == HERE:
            return self._done(t, x)
        if m.signal == HARD_STOP:
            return self._stall_search(t, x)
        for which in (NLS, PLS):
            if plant.limit_active(which, x) and which not in (m.signal, m.reverse_at):
                self.state = "start"
                return self._limit_error(t, x, which)
        if m.signal == INDEX:
            if not self.kinco and plant.home_switch is not None \
                    and plant.home_switch[0] <= x <= plant.home_switch[1]:
                return self._fail(t, x, "the home switch is active at the start; HCFA §7.5.4 "
                                        "lists it as a homing error in methods 33, 34")
            return self._final(t, x, F0)
        if m.active(plant, x):
            if m.number in FAST_LEAVE:
                return self._leave(t, x)
            return self._position(t, x)
        if m.reverse_at and plant.limit_active(m.reverse_at, x):
            self.reversed = True
            return self._search(t, x, -m.search, F0)
        if m.signal in (HS_POS, HS_NEG) and m.final == m.search:
            return self._position(t, x)   # 4B, 6A, 20B, 22A: straight at 6099h:02
        return self._search(t, x, m.search, F0)

    # -- phases ---------------------------------------------------------------------
    def _search(self, t: int, x: int, d: int, v0: Fraction) -> Step:
        m = self.method
        assert m is not None
        e = m.entry(self.plant, x, d)
        watches = [] if e is None else [Watch(e, "entry")]
        lim = self.plant.limit_position(PLS if d > 0 else NLS)
        if e is None and (lim is None or (lim - x) * d <= 0):
            return self._fail(t, x, f"the {SIGNAL_NAMES[m.signal]} is not ahead moving "
                                    f"{'+' if d > 0 else '-'} from {x} and there is no limit "
                                    f"to reverse at")
        return self._phase("search", t, x, d, self._to_speed(t, v0, self.vh), watches,
                           limits=m.signal not in (NLS, PLS))

    def _leave(self, t: int, x: int) -> Step:
        """Methods 4, 6, 20, 22 started on the switch: leave at 6099h:01."""
        m = self.method
        assert m is not None
        c = m.crossing(self.plant, x)
        b = c - m.final
        return self._phase("leave", t, x, -m.final, self._to_speed(t, F0, self.vh),
                           [Watch(b, "left")])

    def _position(self, t: int, x: int) -> Step:
        """From rest: approach the edge at 6099h:02, first moving back to
        its approach side when the axis is not there."""
        m = self.method
        assert m is not None
        c = m.crossing(self.plant, x)
        if (x - c) * m.final < 0:
            return self._final(t, x, F0)
        b = c - m.final
        return self._phase("back", t, x, -m.final, self._to_speed(t, F0, self.vl),
                           [Watch(b, "back")])

    def _home_point(self, x: int) -> int:
        m, p, plant = self.method, self.params, self.plant
        assert m is not None
        c = m.crossing(plant, x)
        if not m.index:
            return c
        assert plant.index_period is not None
        blind = 0
        if self.kinco and m.signal != INDEX:
            blind = plant.index_period * BLIND_QUARTERS[p.blind_zone] // 4
        return index_at_or_beyond(c + m.final * blind, m.final, plant.index_period,
                                  plant.index_phase)

    def _final(self, t: int, x: int, v0: Fraction) -> Step:
        m = self.method
        assert m is not None
        self.home = self._home_point(x)
        if self.home == x:
            return self._done(t, x)   # the search met the home event itself (Kinco latch)
        watches = [Watch(self.home, "home")]
        if m.signal == INDEX and not self.kinco and self.plant.home_switch is not None:
            hs = self.plant.home_switch
            e = hs[0] if m.final > 0 and x < hs[0] else hs[1] if m.final < 0 and x > hs[1] else None
            if e is not None and (self.home - e) * m.final >= 0:
                watches.append(Watch(e, "switch"))
        return self._phase("final", t, x, m.final, self._to_speed(t, v0, self.vl), watches)

    def _stall_search(self, t: int, x: int) -> Step:
        m = self.method
        assert m is not None
        stop = self.plant.neg_stop if m.search < 0 else self.plant.pos_stop
        assert stop is not None
        at_stop = (stop - x) * m.search <= 0
        # the command runs at 6099h:01 from rest also from a start at the end: it
        # times the following error and velocity window criteria (Kinco §2.5)
        phase = self._phase("stall search", t, stop if at_stop else x, m.search,
                            self._to_speed(t, F0, self.vh), [Watch(stop, "hard_stop")],
                            limits=False)
        return self._stall(t, stop, t) if at_stop else phase

    def _stall(self, t: int, x: int, t_stall: int) -> Step:
        """Kinco §2.5: the first of three criteria zeroes the position."""
        p = self.params
        times = []
        if p.velocity_window > 0:
            times.append(max(t_stall, self.t_ramp_end or t_stall))
        if p.max_current > 0:
            times.append(t_stall)
        if p.following_error_window > 0 and self.phase is not None:
            need = (x - self.phase.x0) * self.phase.direction + p.following_error_window
            tf = self.phase.time_at_travel(need)
            if tf is not None:
                times.append(tf)
        if not times:
            return self._fail(t, x, "no stall criterion is armed: set 6065h, 6099h:04 or "
                                    "60F9h:0A (Kinco §2.5)")
        self.home = x
        self.state = "stall"
        self.phase = Phase("stall", t, x, 0, (), (), None, until=min(times))
        return self.phase

    # -- events ---------------------------------------------------------------------
    def on_event(self, t: int, x: int, event: str) -> Step:
        m, ph = self.method, self.phase
        assert m is not None and ph is not None
        v = ph.speed_at(t)
        if event == "timeout":
            return self._fail(t, x, f"homing time limit P03.07 = {self.params.timeout_ms} ms "
                                    f"exceeded in the {self.state} phase (HCFA §8.2, alarm 63)",
                              63)
        if event == "limit":
            which = PLS if ph.direction > 0 else NLS
            if self.state == "search" and which == m.reverse_at and not self.reversed:
                self.reversed = True   # HCFA §10.1 path B: reverse at 6099h:01
                return self._search(t, x, -ph.direction, F0)
            return self._limit_error(t, x, which)
        if event == "switch":
            return self._fail(t, x, f"the home switch went active at {x}; HCFA §7.5.4 lists "
                                    f"it as a homing error in methods 33, 34")
        if event == "entry":
            return self._entry(t, x, v)
        if event == "left":
            return self._stop_then(t, x, v)
        if event == "back":
            return self._final(t, x, F0)
        if event == "home":
            return self._done(t, x)
        if event == "hard_stop":
            return self._stall(t, x, t)
        if event == "end" and self.state == "decelerate":
            return self._position(t, x)
        if event == "end" and self.state == "stall":
            return self._done(t, x)
        if event == "end" and self.state == "offset":
            return Done(t, self.home if self.home is not None else x, x, -x,
                        f"{self._label()}: home at {self.home}, moved 607Ch = "
                        f"{self.params.offset} and set 6064h = 0 (offset mode 0, Kinco §2.3-3)")
        raise PlcRuntimeError(f"{self._label()}: event {event!r} is not expected in the "
                             f"{self.state} phase")

    def _entry(self, t: int, e: int, v: Fraction) -> Step:
        """The search reached the switch at ``e`` moving at speed ``v``."""
        m, ph = self.method, self.phase
        assert m is not None and ph is not None
        s, f = ph.direction, m.final
        c = m.crossing(self.plant, e)
        approach = (e - c) * f < 0
        if f == s and approach:
            return self._final(t, e, v)
        if f == s and self.kinco and e == c:
            return self._final(t, e, v)     # Kinco §2.5, method 12 track 1
        if f == -s and not approach:
            b = c - f
            return self._phase("pass", t, e, s, self._to_speed(t, v, self.vl),
                               [Watch(b, "left")])
        return self._stop_then(t, e, v)

    def abort(self, t: int) -> None:
        """Controlword bit 4 1 -> 0, halt or quick stop: no home is set."""
        self.state = "aborted"
        self.phase = None

    # -- the end --------------------------------------------------------------------
    def _done(self, t: int, x: int) -> Step:
        p = self.params
        home = x if self.home is None else self.home
        self.home = home
        if not self.kinco:
            self.state = "done"
            return Done(t, home, x, p.offset - home,
                        f"{self._label()}: home at {home}; 6064h there = 607Ch = {p.offset} "
                        f"(HCFA: actual = +607Ch at the home point, docs/cia402.md)")
        if p.offset_mode == 1 or p.offset == 0:
            self.state = "done"
            return Done(t, home, x, -p.offset - home,
                        f"{self._label()}: home at {home}; 6064h there = -607Ch = {-p.offset} "
                        f"(offset mode {p.offset_mode}, Kinco §2.3-3)")
        d = 1 if p.offset > 0 else -1
        m = self.method
        if m is not None and m.signal == HARD_STOP and d == m.search:
            return self._fail(t, x, f"607Ch = {p.offset} points into the mechanical end "
                                    f"(offset mode 0 moves it, Kinco §2.3-3)")
        if self.plant.limit_active(PLS if d > 0 else NLS, x):   # into it: docs/cia402.md
            return self._limit_error(t, x, PLS if d > 0 else NLS, "offset")
        segs, _ = plan_distance(Fraction(t), F0, F0, self.vh, F0, Fraction(abs(p.offset)),
                                self.rate, self.rate)
        return self._phase("offset", t, x, d, segs, [])


def run(seq: HomingSequence, t: int, x: int, max_phases: int = 64) -> tuple[Done | Failed,
                                                                              list[Phase]]:
    """Run a sequence to its end with exact events (a reference drive)."""
    step = seq.start(t, x)
    phases: list[Phase] = []
    while isinstance(step, Phase):
        phases.append(step)
        if len(phases) > max_phases:
            raise PlcRuntimeError(f"homing method {seq.params.method}: more than {max_phases} "
                                 f"phases")
        t, x, event = step.first_event()
        step = seq.on_event(t, x, event)
    return step, phases
