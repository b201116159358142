"""The CPU settings a system block holds that change how a program runs.

What it is: the data model of the settings plcrt simulates from the
system block (S7-200 System Manual, chapter 4, "Saving and restoring
data" and "Configuring the retentive ranges"; Micro/WIN's System Block
dialog): the retentive ranges kept through a power cycle, the mode the
CPU starts in, and the station address and PPI baud rate of each port.  They come from a
project's system block (:mod:`plcrt.project.sysblock`) or from the plant
file's ``[cpu]`` table, and the engine applies them
(:mod:`plcrt.engine.power`).  A range is checked here against the CPU's
memory sizes.

What it is not: a reader of either source, or the power cycle itself.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from ..errors import PlcConfigError
from ..safetext import shown_value
from .cpu import CpuModel

__all__ = ["AREAS", "MAX_RANGES", "STARTUP_MODES", "RetentiveRange", "SystemSettings",
           "default_ranges", "parse_ranges", "parse_startup"]

#: the areas a retentive range may name, with the letter(s) of its text
#: form: V and M by bytes, timers and counters by number (only their
#: current values are kept: the bits are not retentive)
AREAS = {"V": "VB", "M": "MB", "T": "T", "C": "C"}
#: the system block holds six ranges
MAX_RANGES = 6
#: start-up modes (S7-200 SMART system block, "Startup"): RUN, STOP, or the
#: mode the CPU was in before it was switched off
STARTUP_MODES = ("RUN", "STOP", "LAST")

_RANGE = re.compile(r"(VB|MB|T|C)(\d{1,6}):(\d{1,6})")


@dataclass(frozen=True)
class RetentiveRange:
    """``count`` bytes (V, M) or timers/counters (T, C) from ``start``."""

    area: str
    start: int
    count: int

    def __str__(self) -> str:
        return f"{AREAS[self.area]}{self.start}:{self.count}"

    def size(self, model: CpuModel) -> int:
        """The number of bytes or elements of this area the CPU has."""
        return {"V": model.v_bytes, "M": model.m_bytes, "T": model.timers,
                "C": model.counters}[self.area]


@dataclass(frozen=True)
class SystemSettings:
    """What the engine takes from a system block or a plant file's
    ``[cpu]`` table; None: not given (the CPU's default)."""

    #: the retentive ranges (None: Micro/WIN's default system block)
    ranges: tuple[RetentiveRange, ...] | None = None
    #: "RUN", "STOP" or "LAST" (None: RUN, as the S7-200's mode switch)
    startup: str | None = None
    #: port number -> station address (a port not named keeps 2)
    addresses: dict[int, int] = field(default_factory=dict)
    #: port number -> PPI baud rate (a port not named keeps 9600)
    bauds: dict[int, int] = field(default_factory=dict)
    #: where they come from, for messages ("the system block of x.mwp")
    source: str = ""


def default_ranges(model: CpuModel) -> tuple[RetentiveRange, ...]:
    """The retentive ranges of Micro/WIN's default system block: all of
    V, MB14 to MB31, the TONR timers T0-T31 and T64-T95, all counters
    (S7-200 System Manual, "Configuring the retentive ranges"; the V4
    projects of the corpus hold exactly these)."""
    return (RetentiveRange("V", 0, model.v_bytes), RetentiveRange("M", 14, 18),
            RetentiveRange("T", 0, 32), RetentiveRange("T", 64, 32),
            RetentiveRange("C", 0, model.counters))


def parse_ranges(value: Any, where: str) -> tuple[RetentiveRange, ...]:
    """``["VB0:100", "MB14:18", "T0:32", "C0:256"]`` (start and count as
    Micro/WIN's dialog has them), checked for form and number; ``where``
    names the key in messages."""
    if not isinstance(value, (list, tuple)):
        raise PlcConfigError(f"{where} must be a list of ranges such as [\"VB0:100\", "
                             f"\"MB14:18\", \"T0:32\", \"C0:256\"], got {shown_value(value)}")
    if len(value) > MAX_RANGES:
        raise PlcConfigError(f"{where}: {len(value)} ranges, the system block holds at most "
                             f"{MAX_RANGES}")
    out = []
    for item in value:
        match = _RANGE.fullmatch(item.replace(" ", "").upper()) if isinstance(item, str) \
            else None
        if match is None:
            raise PlcConfigError(f"{where}: {shown_value(item)} is not a range such as "
                                 f"\"VB0:100\" (VB, MB, T or C, the start, ':', the count)")
        letters, start, count = match.groups()
        out.append(RetentiveRange(letters[0], int(start), int(count)))
    return tuple(out)


def parse_startup(value: Any, where: str) -> str:
    """``"RUN"``, ``"STOP"`` or ``"LAST"`` (any case)."""
    mode = value.strip().upper() if isinstance(value, str) else None
    if mode not in STARTUP_MODES:
        raise PlcConfigError(f"{where} must be \"RUN\", \"STOP\" or \"LAST\", got "
                             f"{shown_value(value)}")
    return mode


def check_range(r: RetentiveRange, model: CpuModel, where: str) -> None:
    """Refuse a range that runs past the CPU's area."""
    if r.start + r.count > r.size(model):
        raise PlcConfigError(f"{where}: the range {r} runs past the end of {model.name}'s "
                             f"{AREAS[r.area][0]} area ({r.size(model)} "
                             f"{'bytes' if r.area in 'VM' else 'elements'})")


def clipped(r: RetentiveRange, model: CpuModel) -> RetentiveRange:
    """The part of ``r`` the CPU has."""
    size = r.size(model)
    start = min(r.start, size)
    return RetentiveRange(r.area, start, min(r.count, size - start))
