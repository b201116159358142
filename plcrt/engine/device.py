"""What the scan engine and the public API see of a simulated device.

What it is: the :class:`Device` protocol the engine steps, and the frozen
states the API reports: :class:`AxisState` (an axis of a positioning
module) and :class:`DriveState` (a CiA 402 drive on a fieldbus module),
both also read-only mappings.  Re-exported by :mod:`plcrt.devices`.

What it is not: any device.  The devices sit above the engine: the modules
(:mod:`plcrt.devices.em253.module`, :mod:`plcrt.devices.cia402.coupler`)
build on this module and report through it, and the engine steps them
through :class:`Device` without importing them (:mod:`plcrt.parts`).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any, ClassVar, Protocol

from ..errors import PlcKeyError
from ..safetext import shown_value
from .statusword import describe_statusword

__all__ = ["AxisState", "Device", "DriveState"]


class _StateMapping(Mapping[str, Any]):
    """A frozen dataclass of a device's state read as a mapping of its
    fields (``KEYS``, set after the class): equal to any mapping with the
    same keys and values, a plain dict for JSON with :meth:`to_dict`."""

    KEYS: ClassVar[tuple[str, ...]] = ()

    def to_dict(self) -> dict[str, Any]:
        """A plain dict of the fields, for JSON."""
        return asdict(self)  # type: ignore[call-overload]

    def __getitem__(self, key: str) -> Any:
        if not isinstance(key, str) or key not in self.KEYS:
            raise PlcKeyError(f"{type(self).__name__} has no field {shown_value(key)}; "
                              f"the fields are {', '.join(self.KEYS)}")
        return getattr(self, key)

    def __iter__(self) -> Iterator[str]:
        return iter(self.KEYS)

    def __len__(self) -> int:
        return len(self.KEYS)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Mapping):
            return dict(self) == dict(other)
        return NotImplemented

    def __hash__(self) -> int:
        return hash(tuple(self.values()))


@dataclass(frozen=True, eq=False)
class AxisState(_StateMapping):
    """One axis of a positioning module at a moment of simulated time.

    What :meth:`plcrt.Plc.axis` and the test harness's ``axis()`` return:
    read it as an object (``a.position``) or as a read-only mapping
    (``a["position"]``, ``dict(a)``, ``a.to_dict()`` for JSON); it equals
    any mapping with the same keys and values.
    """

    slot: int
    axis: int
    position: int       #: the module's position counter (pulses)
    mechanical: int     #: where the machine really is (pulses from the plant origin)
    speed: int          #: pulse frequency in Hz, signed by direction
    status: str         #: "stopped" or "moving"
    masked: bool = False  #: pulses masked by SevOn (the drive is not enabled)
    stf: bool = False     #: the STF (stop) input is active

    @property
    def moving(self) -> bool:
        """Whether the axis is moving (``status == "moving"``)."""
        return self.status == "moving"


AxisState.KEYS = tuple(f.name for f in fields(AxisState))


@dataclass(frozen=True, eq=False)
class DriveState(_StateMapping):
    """One CiA 402 drive on a fieldbus module at a moment of simulated time.

    What :meth:`plcrt.Plc.drive` and the test harness's ``drive()`` return,
    read as an object (``d.position``) or as a read-only mapping
    (``d["position"]``, ``d.to_dict()`` for JSON), like :class:`AxisState`.
    """

    slot: int
    node: int
    model: str
    state: str          #: the CiA 402 power state, e.g. "OPERATION ENABLED"
    statusword: int     #: 6041h
    controlword: int    #: 6040h as the drive holds it
    mode: int           #: 6061h, the mode shown (1 PP, 3 PV, 6 HM, 8 CSP, 0 none)
    position: int       #: 6064h, counts
    velocity: int       #: 6069h/606Ch, counts per second
    following_error: int  #: 60F4h
    error_code: int     #: 603Fh (0: no fault)
    online: bool        #: the bus exchanges process data with it (EtherCAT OP)

    @property
    def moving(self) -> bool:
        """Whether the drive's axis is moving (velocity not zero)."""
        return self.velocity != 0

    @property
    def fault(self) -> bool:
        """Statusword bit 3, fault."""
        return bool(self.statusword & 0x0008)

    @property
    def flags(self) -> list[str]:
        """The statusword's other set bits in words for the mode shown
        (``["target reached", "homing attained"]``)."""
        return describe_statusword(self.statusword, self.mode, self.model)

    @property
    def mode_name(self) -> str:
        """6061h as its short name: PP, PV, HM, CSP (or the number)."""
        return _MODE_NAMES.get(self.mode, str(self.mode))


DriveState.KEYS = tuple(f.name for f in fields(DriveState))
_MODE_NAMES = {0: "none", 1: "PP", 3: "PV", 6: "HM", 8: "CSP"}


class Device(Protocol):
    """What the scan engine needs from a simulated device."""

    slot: int

    def step(self, plc: Any, t_from: int, t_to: int) -> None:
        """Advance from ``t_from`` to ``t_to`` (µs) and update terminals."""

    def snapshot(self, t: int) -> list[AxisState]:
        """Per-axis state for status displays, tests and JSON."""

    # Optional (perf): a device whose step, to any time before ``quiet_to``
    # (µs), only stores the same bytes again (its terminals) may list them
    # as ``held``: a tuple of (buffer, slice, bytearray) runs, changed in
    # place by the device, replaced only by a restore.  The scan loop then
    # stores two such runs itself instead of calling ``step``.
    #
    #   quiet_to: int
    #   held: tuple[tuple[bytearray, slice, bytearray], ...]
