"""What a simulated CiA 402 drive's axis touches: switches and mechanical ends.

What it is: :class:`DrivePlant`, the positions (in counts) at which the
negative / positive limit switches (NLS / PLS) and the home switch are active,
the index (Z) pulse pattern, the mechanical ends (hard stops) the axis cannot
pass, and :meth:`DrivePlant.inputs`, the 60FDh digital-input bits for a count
(HCFA §8.3: bit 0 NLS, bit 1 PLS, bit 2 home).

What it is not: it does not move; :class:`~plcrt.devices.cia402.drive.Drive`
asks it where the switches are and finds the crossing times exactly.
Conventions follow ``plcrt.devices.homing_geometry``: a home-switch zone is
the closed range ``[lo, hi]``; NLS is active at counts ``<= neg_limit``, PLS
at counts ``>= pos_limit``.  The axis can stand at ``neg_stop`` or
``pos_stop`` but never beyond (:mod:`.stops` blocks it there); the ends lie
at or beyond the limit switches, since a limit switch warns before the end.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from .states import Cia402Error

__all__ = ["DrivePlant", "DI_NLS", "DI_PLS", "DI_HOME"]

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

    def __post_init__(self) -> None:
        if (self.neg_limit is not None and self.pos_limit is not None
                and self.neg_limit >= self.pos_limit):
            raise Cia402Error(f"plant: neg_limit = {self.neg_limit} must lie below "
                              f"pos_limit = {self.pos_limit}")
        if self.home_switch is not None and self.home_switch[0] > self.home_switch[1]:
            raise Cia402Error(f"plant: home_switch = {self.home_switch} is no range lo <= hi")
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
                raise Cia402Error(f"plant: {name} = {value!r} must be a whole count")
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
