"""What the drive tests share: enabling a simulated drive in a mode."""

from __future__ import annotations

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.statemachine import State


def enable(d: Drive, mode: int, **params: int) -> Drive:
    """Mode *mode*, objects ``x6081=...`` / ``x6099_01=...``, then the
    controlwords 6, 7, 0x0F: the drive is in OPERATION ENABLED."""
    d.write(0x6060, 0, mode)
    for name, value in params.items():
        d.write(int(name[1:5], 16), int(name[6:]) if len(name) > 5 else 0, value)
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
    if d.sm.state is State.SWITCHED_ON:
        d.cycle(d.now)
    assert d.sm.state is State.OPERATION_ENABLED
    return d
