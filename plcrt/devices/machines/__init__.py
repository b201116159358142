"""Machines a program controls: a conveyor, a tank, a traffic crossing, a
garage door and an elevator, each a plant device with exact physics in
simulated time (docs/machines.md).

What it is: the table of machine kinds (:data:`KINDS`), the plant file's
reader of ``[machine.NAME]`` (:func:`parse`) and the builder of the devices
(:func:`build`); :class:`Machine` is what ``plc.machine(name)`` and the
harness hand out.  One module per machine over :mod:`.base`.

What it is not: a drawing of the machines (the page animates
``Machine.state()``), nor a second time line: the machines are devices of
the scan's one time line (:mod:`plcrt.engine.events`).
"""

from __future__ import annotations

from typing import Any

from .base import Machine, MachineDevice
from .config import MachineConfig, parse_machines
from .conveyor import Conveyor
from .elevator import Elevator
from .garage import GarageDoor
from .tank import Tank
from .traffic import Traffic

__all__ = ["KINDS", "Machine", "MachineConfig", "MachineDevice", "build", "parse"]

#: machine kind -> its class
KINDS: dict[str, type[MachineDevice]] = {
    cls.KIND: cls for cls in (Conveyor, Tank, Traffic, GarageDoor, Elevator)}


def parse(raw: Any, file: str, taken: dict[tuple[str, int], str] | None = None
          ) -> list[MachineConfig]:
    """The plant's ``[machine]`` table, checked (PlcConfigError naming the
    key); *taken*: the inputs the rest of the plant drives (see
    :func:`~.config.parse_machines`)."""
    return parse_machines(raw, file, KINDS, taken)


def build(plc: Any, cfg: MachineConfig) -> MachineDevice:
    """The device of one machine of the plant, fitted to *plc*."""
    return KINDS[cfg.kind](plc, cfg)
