"""Simulated devices attached to the CPU (expansion modules and their plant).

A device implements the :class:`Device` protocol: after the program has run
in a scan, the engine calls ``step(plc, t_from, t_to)`` so the device
advances its own world from the scan start to the next scan start (exactly,
event by event) and writes its input terminals into the physical input
image (PI) and its output terminals into Q.  Devices and the program meet
only in memory and in the library blocks' calls, as on real hardware.
"""

from __future__ import annotations

from typing import Any

from .state import AxisState, Device, DriveState

__all__ = ["AxisState", "Device", "DriveState", "build_devices"]


def build_devices(plc: Any, plant: Any) -> list[Any]:
    """Create the devices a plant describes (table of module kinds)."""
    # perf: the modules' simulations are imported when a plant is built, not
    # with plcrt.devices (which the plant reader and the API's states need)
    from .cia402.coupler import FieldbusModule
    from .em253.module import EM253Module
    from .process import FirstOrderProcess
    kinds = {"EM253": EM253Module, "FIELDBUS": FieldbusModule}
    devices = [kinds[m.kind](plc, m) for _, m in sorted(plant.modules.items())]
    return devices + [FirstOrderProcess(plc, p) for p in plant.processes]
