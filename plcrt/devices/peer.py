"""What every plant device at the far end of a CPU port shares.

What it is: :class:`PortPeer`, the base of the scripted device, the Modbus
slave and master and the USS drives (becoming the port's peer; no PPI
station), and the checks of the line settings a device may fix for itself
in the plant file (``baud``, ``parity``).  What it is not: a protocol; each
device answers in its own module.
"""

from __future__ import annotations

from typing import Any, Optional

from ..engine.serial import BAUDS as _CODES
from ..errors import PlcConfigError

__all__ = ["PortPeer", "BAUDS", "PARITIES", "baud_key", "parity_key"]

#: the rates a plant device may run at (those of SMB30 / SMB130's freeport)
BAUDS = tuple(sorted(_CODES))
PARITIES = ("none", "even", "odd")


class PortPeer:
    """A plant device at a port: it becomes the port's peer on attach."""

    port: Any = None

    def attach(self, port: Any) -> None:
        self.port = port
        port.peer = self

    def station(self, address: int) -> None:
        """A plant device is no PPI station (no NETR/NETW partner)."""
        return None


def baud_key(raw: dict, where: str) -> Optional[int]:
    """The table's ``baud``, one of :data:`BAUDS`; None when absent."""
    if "baud" not in raw:
        return None
    v = raw["baud"]
    if isinstance(v, bool) or v not in BAUDS:
        raise PlcConfigError(f"{where}.baud must be one of {', '.join(map(str, BAUDS))}, "
                             f"got {v!r:.40}")
    return v


def parity_key(raw: dict, where: str) -> Optional[str]:
    """The table's ``parity``, one of :data:`PARITIES`; None when absent."""
    if "parity" not in raw:
        return None
    v = raw["parity"]
    if v not in PARITIES:
        raise PlcConfigError(f"{where}.parity must be \"none\", \"even\" or \"odd\", "
                             f"got {v!r:.40}")
    return v
