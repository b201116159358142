"""Simulated devices attached to the CPU (expansion modules and their plant).

A device implements the :class:`Device` protocol: after the program has run
in a scan, the engine calls ``step(plc, t_from, t_to)`` so the device
advances its own world from the scan start to the next scan start (exactly,
event by event) and writes its input terminals into the physical input
image (PI) and its output terminals into Q.  Devices and the program meet
only in memory and in the library blocks' calls, as on real hardware.

The protocol and the states the API reports (:class:`AxisState`,
:class:`DriveState`) are the engine's (:mod:`plcrt.engine.device`),
re-exported here; which device a plant's module kind builds is decided
above the devices, by :mod:`plcrt.loader`.
"""

from __future__ import annotations

from ..engine.device import AxisState, Device, DriveState

__all__ = ["AxisState", "Device", "DriveState"]
