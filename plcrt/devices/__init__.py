"""Simulated devices attached to the CPU (expansion modules and their plant).

A device implements the :class:`Device` protocol: after the program has run
in a scan, the engine calls ``step(plc, t_from, t_to)`` so the device
advances its own world from the scan start to the next scan start (exactly,
event by event) and writes its input terminals into the physical input
image (PI) and its output terminals into Q.  Devices and the program meet
only in memory and in the library blocks' calls, as on real hardware.
"""

from __future__ import annotations

from typing import Any, Protocol


class Device(Protocol):
    """What the scan engine needs from a simulated device."""

    slot: int

    def step(self, plc: Any, t_from: int, t_to: int) -> None:
        """Advance from ``t_from`` to ``t_to`` (µs) and update terminals."""

    def snapshot(self, t: int) -> list[dict[str, Any]]:
        """Per-axis (or per-channel) state for status displays and JSON."""


def build_devices(plc: Any, plant: Any) -> list[Any]:
    """Create the devices a plant describes (table of module kinds)."""
    from .em253.module import EM253Module
    kinds = {"EM253": EM253Module}
    return [kinds[m.kind](plc, m) for _, m in sorted(plant.modules.items())]
