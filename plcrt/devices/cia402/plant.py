"""What a simulated CiA 402 drive's axis touches: limit and home switches.

What it is: :class:`DrivePlant`, the positions (in counts) at which the
negative / positive limit switches (NLS / PLS) and the home switch are active,
the index (Z) pulse pattern, and :meth:`DrivePlant.inputs`, the 60FDh
digital-input bits for a count (HCFA §8.3: bit 0 NLS, bit 1 PLS, bit 2 home).

What it is not: it does not move; :class:`~plcrt.devices.cia402.drive.Drive`
asks it where the switches are and finds the crossing times exactly.
Conventions follow ``plcrt.devices.homing_geometry``: a home-switch zone is
the closed range ``[lo, hi]``; NLS is active at counts ``<= neg_limit``, PLS
at counts ``>= pos_limit``.
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

    def __post_init__(self) -> None:
        if (self.neg_limit is not None and self.pos_limit is not None
                and self.neg_limit >= self.pos_limit):
            raise Cia402Error(f"plant: neg_limit = {self.neg_limit} must lie below "
                              f"pos_limit = {self.pos_limit}")
        if self.home_switch is not None and self.home_switch[0] > self.home_switch[1]:
            raise Cia402Error(f"plant: home_switch = {self.home_switch} is no range lo <= hi")
        if self.index_period is not None and self.index_period <= 0:
            raise Cia402Error(f"plant: index_period = {self.index_period} must be positive")

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
