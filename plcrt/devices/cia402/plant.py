"""What a simulated CiA 402 drive's axis touches: switches and mechanical ends.

What it is: :class:`DrivePlant`, the positions (in counts) at which the
negative / positive limit switches (NLS / PLS) and the home switch are active,
the index (Z) pulse pattern, the mechanical ends (hard stops) the axis cannot
pass, the touch probe inputs, and :meth:`DrivePlant.inputs`, the 60FDh
digital-input bits for a count (HCFA §8.3: bit 0 NLS, bit 1 PLS, bit 2
home); :func:`plant_of`, a plant from a dict or a TOML file of
:data:`PLANT_KEYS`, every problem a ``PlcConfigError`` naming the key.

What it is not: it does not move; :class:`~plcrt.devices.cia402.drive.Drive`
asks it where the switches are and finds the crossing times exactly.
Conventions follow ``plcrt.devices.homing_geometry``: a home-switch zone is
the closed range ``[lo, hi]``; NLS is active at counts ``<= neg_limit``, PLS
at counts ``>= pos_limit``.  The axis can stand at ``neg_stop`` or
``pos_stop`` but never beyond (:mod:`.stops` blocks it there); the ends lie
at or beyond the limit switches, since a limit switch warns before the end.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

from ...errors import PlcConfigError, PlcError
from ...lang.limits import file_limit, read_capped
from ...safetext import printable, shown_value
from .states import Cia402Error

__all__ = ["DrivePlant", "DI_NLS", "DI_PLS", "DI_HOME", "plant_of", "PLANT_KEYS"]

DI_NLS, DI_PLS, DI_HOME = 0x1, 0x2, 0x4   # 60FDh bits (HCFA §8.3)


@dataclass(frozen=True, slots=True)
class DrivePlant:
    """Switch positions of one axis (None: no such switch)."""

    neg_limit: Optional[int] = None
    pos_limit: Optional[int] = None
    home_switch: Optional[tuple[int, int]] = None
    index_period: Optional[int] = None
    index_phase: int = 0
    neg_stop: Optional[int] = None   #: negative mechanical end (Kinco -17, §2.5)
    pos_stop: Optional[int] = None   #: positive mechanical end (Kinco -18, §2.5)
    probe: Optional[tuple[int, int]] = None    #: touch probe input 1 active in [lo, hi]
    probe2: Optional[tuple[int, int]] = None   #: probe input 2 (HCFA DI5) active in [lo, hi]

    def __post_init__(self) -> None:
        if (self.neg_limit is not None and self.pos_limit is not None
                and self.neg_limit >= self.pos_limit):
            raise Cia402Error(f"plant: neg_limit = {self.neg_limit} must lie below "
                              f"pos_limit = {self.pos_limit}")
        for name in ("home_switch", "probe", "probe2"):
            zone = getattr(self, name)
            if zone is not None and zone[0] > zone[1]:
                raise Cia402Error(f"plant: {name} = {zone} is no range lo <= hi")
        if self.index_period is not None and self.index_period <= 0:
            raise Cia402Error(f"plant: index_period = {self.index_period} must be positive")
        self._check_stops()

    def _check_stops(self) -> None:
        """A mechanical end lies at or beyond the limit switch on its side
        (and beyond the one on the other side), the negative end left of the
        positive one (docs/cia402.md, decisions "Mechanical ends")."""
        neg, pos = self.neg_stop, self.pos_stop
        for name, value in (("neg_stop", neg), ("pos_stop", pos)):
            if value is not None and not isinstance(value, int):
                raise Cia402Error(f"plant: {name} = {shown_value(value)} must be a whole count")
        rules = (
            (neg is not None and pos is not None and neg >= pos,
             f"neg_stop = {neg} must lie below pos_stop = {pos}"),
            (neg is not None and self.neg_limit is not None and neg > self.neg_limit,
             f"neg_stop = {neg} must lie at or below neg_limit = {self.neg_limit} (the "
             "negative limit switch comes before the mechanical end)"),
            (pos is not None and self.pos_limit is not None and pos < self.pos_limit,
             f"pos_stop = {pos} must lie at or above pos_limit = {self.pos_limit} (the "
             "positive limit switch comes before the mechanical end)"),
            (neg is not None and self.pos_limit is not None and neg >= self.pos_limit,
             f"neg_stop = {neg} must lie below pos_limit = {self.pos_limit}"),
            (pos is not None and self.neg_limit is not None and pos <= self.neg_limit,
             f"pos_stop = {pos} must lie above neg_limit = {self.neg_limit}"),
        )
        for broken, why in rules:
            if broken:
                raise Cia402Error(f"plant: {why}")

    def beyond_stop(self, position: int) -> Optional[str]:
        """The name of the mechanical end *position* lies beyond, if any."""
        if self.neg_stop is not None and position < self.neg_stop:
            return "neg_stop"
        if self.pos_stop is not None and position > self.pos_stop:
            return "pos_stop"
        return None

    def nls(self, position: int) -> bool:
        return self.neg_limit is not None and position <= self.neg_limit

    def pls(self, position: int) -> bool:
        return self.pos_limit is not None and position >= self.pos_limit

    def home(self, position: int) -> bool:
        return (self.home_switch is not None
                and self.home_switch[0] <= position <= self.home_switch[1])

    def inputs(self, position: int) -> int:
        """60FDh for the axis at *position*."""
        return ((DI_NLS if self.nls(position) else 0) | (DI_PLS if self.pls(position) else 0)
                | (DI_HOME if self.home(position) else 0))


#: The keys of a plant description (a dict or a TOML file) and what each is.
PLANT_KEYS = {
    "neg_limit": "count: the negative limit switch (NLS) is active at and below it",
    "pos_limit": "count: the positive limit switch (PLS) is active at and above it",
    "home_switch": "[low, high]: the home switch is active in this closed range",
    "index_period": "counts between two index (Z) pulses",
    "index_phase": "count of one index pulse (the others lie a whole period away)",
    "neg_stop": "count: the negative mechanical end (hard stop), at or below neg_limit",
    "pos_stop": "count: the positive mechanical end, at or above pos_limit",
    "probe": "[low, high]: touch probe input 1 is active in this closed range",
    "probe2": "[low, high]: touch probe input 2 (HCFA DI5) is active in this closed range",
}
#: keys a plant of a real machine has that the simulation does not model
_NOT_MODELLED = {"inertia": "load inertia", "load_inertia": "load inertia",
                 "friction": "friction", "backlash": "backlash"}
_ZONES = ("home_switch", "probe", "probe2")
_MAX_COUNT = 2**31 - 1


def _count(value: Any, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) \
            or not -_MAX_COUNT - 1 <= value <= _MAX_COUNT:
        raise PlcConfigError(f"{where} must be a whole count (a 32-bit integer, as 6064h), "
                             f"got {shown_value(value)}")
    return value


def plant_of(value: Any, where: str = "plant") -> DrivePlant:
    """A :class:`DrivePlant` from *value*: None (no switches), a DrivePlant,
    a dict of :data:`PLANT_KEYS`, or the path of a TOML file holding them
    (top-level keys).

    Raises:
        PlcConfigError: naming the file or *where* and the key: an unknown
            key, a value of the wrong kind, an inconsistent plant.
    """
    if value is None:
        return DrivePlant()
    if isinstance(value, DrivePlant):
        return value
    if isinstance(value, (str, Path)):
        where = printable(str(value))[:200]
        try:
            text = read_capped(value, file_limit(1.0)).decode("utf-8")
            value = tomllib.loads(text)
        except PlcError as e:
            raise PlcConfigError(f"{where}: {e.message.removeprefix('error: ')}") from None
        except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
            raise PlcConfigError(f"{where}: not a TOML file: {str(e)[:200]}") from None
    if not isinstance(value, dict):
        raise PlcConfigError(f"{where}: a plant is a dict of {', '.join(PLANT_KEYS)}, the path "
                             f"of a TOML file of them, or a DrivePlant; got "
                             f"{type(value).__name__}")
    kwargs: dict[str, Any] = {}
    for key, v in value.items():
        name = printable(str(key))[:40]
        if key in _NOT_MODELLED:
            raise PlcConfigError(f"{where}.{name}: {_NOT_MODELLED[key]} is not simulated (the "
                                 "axis follows its demand exactly; docs/cia402.md, \"The "
                                 "plant\")")
        if key not in PLANT_KEYS:
            raise PlcConfigError(f"{where}: unknown key {shown_value(name)}; keys: {', '.join(PLANT_KEYS)}")
        if key in _ZONES:
            if not (isinstance(v, (list, tuple)) and len(v) == 2):
                raise PlcConfigError(f"{where}.{key} must be [low, high], got {shown_value(v)}")
            kwargs[key] = (_count(v[0], f"{where}.{key}[0]"), _count(v[1], f"{where}.{key}[1]"))
        else:
            kwargs[key] = _count(v, f"{where}.{key}")
    try:
        return DrivePlant(**kwargs)
    except PlcError as e:
        raise PlcConfigError(f"{where}: {e.message.removeprefix('plant: ')}") from None
