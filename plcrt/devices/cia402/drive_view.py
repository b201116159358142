"""What the parts of a simulated CiA 402 drive see of the drive.

What it is: two :class:`~typing.Protocol` classes, the narrow interfaces
the :class:`~.drive.Drive` hands its parts (itself, which has all of it):
:class:`ModeDrive` for the mode engines (:mod:`.modes`) and
:class:`StopsDrive` for the mechanical ends (:mod:`.stops`).  The parts
depend on these, never on :mod:`.drive`, which builds on them.

What it is not: an implementation; nothing here runs.
"""

from __future__ import annotations

from typing import Any, Callable, Mapping, Optional, Protocol

from .axis import Axis
from .homing_plan import HomingPlan
from .plant import DrivePlant
from .statemachine import Drive402

__all__ = ["ModeDrive", "StopsDrive"]


class ModeDrive(Protocol):
    """What a mode engine reads, moves and reports through."""

    model: str
    axis: Axis
    plant: DrivePlant
    sm: Drive402              #: the power state machine (homing sets ``homed``)
    controlword: int          #: 6040h as the drive holds it
    homing_plans: dict[int, Callable[[], HomingPlan]]
    stops: Any                #: the mechanical ends (stops.HardStops) or None
    #: the store's values by (index, sub), read directly on the CSP cycle
    #: (perf: what :meth:`param` does first)
    _live: dict[tuple[int, int], Any]

    def param(self, index: int, sub: int = 0) -> int:
        """The active value of an object the drive acts on."""

    def note(self, t: int, section: str, text: str, source: str = "") -> None:
        """A diagnostic in the drive's log."""

    def fault(self, t: int, code: int, alarm: Optional[int], why: str) -> None:
        """Raise a fault (603Fh *code*, alarm number) with its reason."""

    def limit_toward(self, t: int, direction: int) -> Optional[str]:
        """The active limit switch in *direction*, if any."""

    def limit_active(self, t: int) -> bool:
        """Whether a limit switch is active at *t*."""

    def bus_period_us(self) -> int:
        """The bus cycle in µs."""

    def idle_mode_bits(self) -> int:
        """The mode's statusword bits of the idle statusword (HCFA §7.3)."""


class StopsDrive(ModeDrive, Protocol):
    """What the mechanical ends read besides a mode engine's view: the
    present time, the mode and the engines (the homing engine's plan and
    its watches, 6: HM)."""

    now: int
    mode_number: int
    engines: Mapping[int, Any]
