"""The protocol between a drive in homing mode (6060h = 6) and a homing method.

What it is: the data a drive gives a homing method (:class:`HomingRequest`),
what a method answers (:class:`HomingStep`: a motion, positions to watch, or
an outcome), the :class:`HomingPlan` protocol, the registry of methods per
drive model (:func:`homing_plans`, :func:`register`).  The methods
themselves are :class:`~.homing.HomingSequence` runs, registered for every
method of each model by :mod:`.homing_adapter`.

How a drive runs a plan (``plcrt.devices.cia402.modes.Homing``):

1. On the 0->1 edge of controlword bit 4 in OPERATION ENABLED with mode 6
   (HCFA §7.5.4) the drive looks 6098h up in its registry.  No plan: alarm 62
   (invalid homing method).  Otherwise it calls ``plan.start(request)``.
2. It carries out the step: ``motion`` replaces the axis's plan (None keeps
   it; ``from_rest`` first stops the axis at once); it reports each
   ``watches`` entry the first time the count reaches it moving that way, and the motion's end (the axis at rest, event name
   ``"stopped"``), by ``plan.event(name, t_us, position)``, which returns the
   next step.  The watches of a step replace those of the one before.
3. ``outcome = "attained"``: the axis stops where it is and its count becomes
   ``home_position``; statusword bits 10 and 12 (homing attained).
   ``outcome = "error"``: the axis stops at once; bit 13 (HCFA §7.5.4).
   ``fault``: (603Fh, alarm, why) is raised (e.g. 62, 63).
4. Bit 4 falling, halt (bit 8), leaving OPERATION ENABLED, a mode change or
   the time limit P03.07 end the plan; it is not told (a new start makes a
   new plan).
5. A plan may carry a ``timer`` attribute, ``(t_us, name)`` or None: the
   drive reports ``name`` at ``t_us`` (a standing phase, e.g. the stall of
   Kinco -17 / -18 while the demand pushes on against a mechanical end).
   Mechanical ends (:class:`~.plant.DrivePlant` ``neg_stop`` / ``pos_stop``)
   hold the axis in homing as in every mode (:mod:`.stops`); a plan whose
   ``stop_watch`` attribute is true is told ``"hard_stop"`` at the µs the
   demand reaches one.  Limit switches do not stop the axis while homing (HCFA safety note
   §1: POT/NOT are not limit stops during homing); a plan watches them itself.

Positions in watches, ``"position"`` motions and events are in the plant's
frame (:class:`~.plant.DrivePlant` switch positions), which homing does not
move; ``home_position`` is the count (6064h) the axis takes.  Before the first
homing the two frames agree.  Speeds are P/s, accelerations P/s², times µs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Literal, Optional, Protocol

from .plant import DrivePlant

__all__ = ["HomingRequest", "HomingMotion", "Watch", "HomingStep", "HomingPlan",
           "homing_plans", "register"]


@dataclass(frozen=True, slots=True)
class HomingRequest:
    """What the drive knows when homing starts (HCFA §7.5.4 objects)."""

    model: str
    method: int          #: 6098h
    fast: int            #: 6099h:01, search for switch
    slow: int            #: 6099h:02, search for zero
    accel: int           #: 609Ah
    offset: int          #: 607Ch
    position: int        #: 6064h at the start
    mechanical: int      #: the same place in the plant's frame (switch positions)
    t_us: int
    plant: DrivePlant
    offset_mode: int = 0  #: Kinco 6099h:05 (§2.3-3)
    blind_zone: int = 0   #: Kinco 6099h:06 (§2.4)
    timeout_ms: int = 0   #: HCFA P03.07 (§8.2), 0 = off
    following_error_window: int = 0  #: 6065h (Kinco -17/-18 stall criterion 1, §2.5)
    max_current: int = 0             #: Kinco 6099h:04 (stall criterion 2, §2.5)
    velocity_window: int = 0         #: Kinco 60F9h:0A (stall criterion 3, §2.5)


@dataclass(frozen=True, slots=True)
class HomingMotion:
    """``"velocity"``: run at signed ``value`` P/s until told otherwise;
    ``"position"``: go to count ``value`` at ``speed`` and stop there;
    ``"stop"``: ramp to rest.  Ramps use ``accel`` (0: at once).
    ``from_rest``: the axis first stops at once (a reversal at a limit)."""

    kind: Literal["velocity", "position", "stop"]
    value: int = 0
    speed: int = 0
    accel: int = 0
    from_rest: bool = False


@dataclass(frozen=True, slots=True)
class Watch:
    """Report when the count reaches ``position`` moving in ``direction``
    (+1: count >= position; -1: count <= position)."""

    name: str
    position: int
    direction: int


@dataclass(frozen=True, slots=True)
class HomingStep:
    """A plan's answer."""

    motion: Optional[HomingMotion] = None
    watches: tuple[Watch, ...] = ()
    outcome: Optional[Literal["attained", "error"]] = None
    home_position: Optional[int] = None
    fault: Optional[tuple[int, int, str]] = None
    note: str = ""


class HomingPlan(Protocol):
    """One homing run of one method."""

    def start(self, request: HomingRequest) -> HomingStep: ...

    def event(self, name: str, t_us: int, position: int) -> HomingStep: ...


PlanFactory = Callable[[], HomingPlan]

#: filled by :mod:`.homing_adapter` (imported by :mod:`.drive`)
_REGISTRY: dict[str, dict[int, PlanFactory]] = {"hcfa-am0520b": {}, "kinco-servo": {}}


def homing_plans(model: str) -> dict[int, PlanFactory]:
    """The homing methods simulated for *model*, by 6098h value."""
    return dict(_REGISTRY.get(model, {}))


def register(model: str, method: int, factory: PlanFactory) -> None:
    """Make *factory* the plan for 6098h = *method* on *model*."""
    _REGISTRY.setdefault(model, {})[method] = factory
