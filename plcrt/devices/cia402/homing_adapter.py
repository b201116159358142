"""The homing methods of :mod:`.homing` run as a drive's homing plans.

What it is: :class:`SequencePlan`, a :class:`~.homing_plan.HomingPlan` over
:class:`~.homing.HomingSequence`, and :func:`install`, which registers it
for every method of each model's table (:func:`~.homing_methods.method_table`)
in the registry the drive reads (:func:`~.homing_plan.homing_plans`).  The
module registers on import; :mod:`.drive` imports it.

The translation (HCFA §7.5.4, Kinco §2.1):

* the drive's :class:`~.plant.DrivePlant` becomes a
  :class:`~.homing_methods.HomingPlant`, mechanical ends included;
* 6098h, 6099h:01 / :02, 609Ah, 607Ch, Kinco 6099h:05 / :06, HCFA P03.07
  and the stall criteria of Kinco -17 / -18 (6065h, 6099h:04, 60F9h:0A,
  §2.5) become :class:`~.homing.HomingParams`;
* a :class:`~.homing.Phase` becomes a motion and the phase's watches: a
  phase of constant speed or a ramp to a speed is ``"velocity"`` (a phase
  whose first segment cruises starts at that speed at once, the stepper
  start of :meth:`HomingSequence._to_speed`), a ramp to rest is ``"stop"``,
  the Kinco offset move is ``"position"``; a phase that starts from rest
  while the axis moves (reversal at a limit, after leaving the switch) asks
  the drive to stop at once first (``HomingMotion.from_rest``);
* the stall of Kinco -17 / -18 (a standing phase until the first stall
  criterion holds) keeps the demand running into the mechanical end, so
  60F4h grows as on a real drive, and ends by the plan's ``timer``; a
  stall that holds at once (6099h:04, or 60F9h:0A after the ramp) ends at
  once.  A start at the end pushes into it at 6099h:01.  The sequence's
  watch of the end is not a count watch: the drive's :mod:`.stops` reports
  it (``stop_watch``) at the µs the demand reaches the end;
* the drive's ``"stopped"`` event is the phase's ``"end"``, unless the
  motion ends on a watched position it moved to: then it is that watch, as
  in :meth:`Phase.first_event`, where a watch reached at the µs the phase
  ends comes first; a watch reports the watched position itself;
* :class:`~.homing.Done` is ``"attained"`` with ``home_position`` = the
  final mechanical position plus ``position_shift`` (the model's offset
  rule); :class:`~.homing.Failed` is ``"error"`` with its explanation, and a
  fault (603Fh = alarm, the alarm, the explanation) when it names alarm 62
  or 63.

What it is not: it computes no geometry; the sequence does.  Time limits are
the drive's own (P03.07, :class:`~.modes.Homing`).
"""

from __future__ import annotations

from typing import Optional

from .homing import Done, Failed, HomingParams, HomingSequence, Phase, Step
from .homing_methods import MODELS, HomingPlant, method_table
from .homing_plan import HomingMotion, HomingRequest, HomingStep, Watch, register

__all__ = ["SequencePlan", "homing_params", "homing_plant", "install"]

STALL_TIMER = "stall"   #: the timer event that ends a standing phase
STOP_WATCH = "hard_stop"   #: the sequence's watch of a mechanical end (reported by stops.py)


def homing_plant(request: HomingRequest) -> HomingPlant:
    """The drive's plant as the homing sequence sees it."""
    p = request.plant
    return HomingPlant(neg_limit=p.neg_limit, pos_limit=p.pos_limit,
                       home_switch=p.home_switch, index_period=p.index_period,
                       index_phase=p.index_phase, neg_stop=p.neg_stop, pos_stop=p.pos_stop)


def homing_params(request: HomingRequest) -> HomingParams:
    """The drive's homing objects as :class:`HomingParams`."""
    return HomingParams(method=request.method, v_search=request.fast, v_zero=request.slow,
                        accel=request.accel, offset=request.offset,
                        offset_mode=request.offset_mode, blind_zone=request.blind_zone,
                        timeout_ms=request.timeout_ms,
                        following_error_window=request.following_error_window,
                        max_current=request.max_current,
                        velocity_window=request.velocity_window)


class SequencePlan:
    """One homing run of the drive, carried out by a :class:`HomingSequence`."""

    def __init__(self) -> None:
        self.seq: Optional[HomingSequence] = None
        self.phase: Optional[Phase] = None
        self.result: Optional[Done | Failed] = None
        self._watch_at: dict[str, int] = {}
        self.timer: Optional[tuple[int, str]] = None   #: (µs, event) of a standing phase
        self.stop_watch = False    #: the phase waits for the axis to reach a mechanical end

    def start(self, request: HomingRequest) -> HomingStep:
        self.seq = HomingSequence(request.model, homing_params(request), homing_plant(request))
        return self._step(self.seq.start(request.t_us, request.mechanical), moving=False)

    def event(self, name: str, t_us: int, position: int) -> HomingStep:
        assert self.seq is not None
        if name in ("stopped", STALL_TIMER):
            event = self._watch_at_end(position)
            step = self.seq.on_event(t_us, self._watch_at.get(event, position), event)
        else:
            step = self.seq.on_event(t_us, self._watch_at.get(name, position), name)
        return self._step(step, moving=True)

    def _watch_at_end(self, position: int) -> str:
        """The event the sequence sees when the phase's motion ends at ``position``.

        A watched position the motion reaches exactly where it ends is reached at
        the µs it ends: :meth:`Phase.first_event` reports the watch then, not the
        end (the first such watch in the phase's order), so the drive does too -
        a Kinco offset move that ends on a limit switch meets the limit.
        """
        ph = self.phase
        if ph is not None and ph.segs:
            for w in ph.watches:
                if w.position == position and (w.position - ph.x0) * ph.direction > 0:
                    return w.event
        return "end"

    # -- translation ------------------------------------------------------------------
    def _step(self, step: Step, moving: bool) -> HomingStep:
        assert self.seq is not None
        self.timer, self.stop_watch = None, False
        while isinstance(step, Phase) and not step.segs and step.until is not None \
                and step.until <= step.t0:
            step = self.seq.on_event(step.until, step.x0, "end")   # the stall holds at once
        if isinstance(step, Done):
            self.result, self.phase = step, None
            return HomingStep(outcome="attained",
                              home_position=step.position + step.position_shift,
                              note=step.explanation)
        if isinstance(step, Failed):
            self.result, self.phase = step, None
            fault = (step.alarm, step.alarm, step.explanation) if step.alarm else None
            return HomingStep(outcome="error", fault=fault, note=step.explanation)
        self.phase = step
        self._watch_at = {}
        watches = []
        for w in step.watches:
            self._watch_at.setdefault(w.event, w.position)
            if w.event != STOP_WATCH:
                watches.append(Watch(w.event, w.position, step.direction))
        # the drive's mechanical ends report the end itself, at the µs the demand reaches it
        self.stop_watch = STOP_WATCH in self._watch_at
        if not step.segs and step.until is not None:
            self.timer = (step.until, STALL_TIMER)
        return HomingStep(motion=self._motion(step, moving), watches=tuple(watches),
                          note=f"homing phase {step.name} from {step.x0}")

    def _motion(self, ph: Phase, moving: bool) -> Optional[HomingMotion]:
        assert self.seq is not None
        rate = self.seq.params.accel
        if ph.name == "stall":
            # Kinco §2.5: the demand pushes on at 6099h:01 against the end (60F4h grows)
            if moving:
                return None
            m = self.seq.method
            assert m is not None
            return HomingMotion("velocity", m.search * int(self.seq.vh), accel=rate)
        if not ph.segs:
            return HomingMotion("stop", accel=0)
        first, last = ph.segs[0], ph.segs[-1]
        from_rest = first.v0 == 0
        if ph.name == "offset":
            target = ph.x0 + ph.direction * abs(self.seq.params.offset)
            return HomingMotion("position", target, int(self.seq.vh), rate, from_rest=True)
        if last.v1 == 0:
            return HomingMotion("stop", accel=rate)
        speed = last.v1
        accel = rate if first.t1 is not None and first.v0 != first.v1 else 0
        return HomingMotion("velocity", ph.direction * int(speed), accel=accel,
                            from_rest=from_rest)


def install() -> None:
    """Register :class:`SequencePlan` for every method of both models."""
    for model in MODELS:
        for method in method_table(model):
            register(model, method, SequencePlan)


install()
