"""Public entry points for plcrt's simulated CiA 402 drives.

* :func:`object_dictionary` gives the ``canopen.ObjectDictionary`` of a drive
  model, for a CANopen master's side (``BaseNode402(node_id, od)``);
* :func:`eds_text` gives the same dictionary as an EDS file;
* :func:`models` lists the drive models;
* :func:`attach` puts a simulated drive on a connected ``canopen.Network``
  (see :mod:`plcrt.devices.cia402.canopen_node`);
* :func:`bus` gives a ``canopen.Network`` on plcrt's in-process CAN bus,
  which delivers each frame synchronously (see
  :mod:`plcrt.devices.cia402.can_bus`).

All three read the model's data file, ``library/cia402/<model>.toml`` (see
:mod:`plcrt.devices.cia402.od`).  ``canopen`` is imported only when a
function needs it.  The drive itself lives in :mod:`plcrt.devices.cia402`,
and so does the work of this facade (:mod:`plcrt.devices.cia402.canopen_od`,
:mod:`plcrt.devices.cia402.canopen_node`); nothing inside plcrt imports it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .devices.cia402 import canopen_od
from .devices.cia402.canopen_od import eds_text, models
from .devices.cia402.plant import plant_of
from .errors import PlcConfigError
from .safetext import printable

if TYPE_CHECKING:  # pragma: no cover
    import canopen.objectdictionary

    from .devices.cia402.can_bus import LocalNetwork
    from .devices.cia402.canopen_node import CanopenDrive, Clock
    from .devices.cia402.plant import DrivePlant

__all__ = ["attach", "bus", "eds_text", "models", "object_dictionary"]


def object_dictionary(model: str = "hcfa-am0520b", node_id: int | None = None
                      ) -> canopen.objectdictionary.ObjectDictionary:
    """The canopen object dictionary of a drive model: one ``ODVariable`` per
    single-entry object, one ``ODRecord`` per object with subindexes, with
    data type, access, default, limits, PDO mappability and unit of the data
    file (the entry's manual section becomes the description).

    With *node_id*, the dictionary also has the CAN view of a drive put on
    the bus by :func:`attach` as that node (1017h, one TPDO and one RPDO):
    a master that wants the drive's PDOs uses it.

    Raises:
        PlcConfigError: unknown model or malformed data file.
    """
    if node_id is not None and (isinstance(node_id, bool) or not isinstance(node_id, int)
                                or not 1 <= node_id <= 127):
        raise PlcConfigError("object_dictionary: node_id is a CANopen node id (1..127, "
                             "CiA 301 §7.5.2.4) or None")
    od = canopen_od.object_dictionary(model)
    if node_id is not None:
        # perf: canopen_node imports canopen (about 0.2 s) when first needed
        from .devices.cia402.canopen_node import can_view
        can_view(od, node_id)
    return od


def attach(network: Any, node_id: int, model: str = "hcfa-am0520b",
           plant: "DrivePlant | dict | str | None" = None, *,
           clock: "Clock" = "wall") -> "CanopenDrive":
    """Put a simulated drive of *model* on the connected ``canopen.Network``
    *network* as node *node_id*; a master drives it with SDOs, PDOs, SYNC,
    NMT, heartbeat and EMCY (``BaseNode402(node_id, object_dictionary(model,
    node_id))`` with ``setup_402_state_machine(read_pdos=True)``).

    *plant*: the machine around the drive: a dict of
    ``plcrt.devices.cia402.plant.PLANT_KEYS`` (limit switches, mechanical
    ends, home switch, index, probe inputs), the path of a TOML file of them,
    or a ``DrivePlant``.

    *clock*: ``"wall"`` (the drive's time follows the wall clock, one bus
    cycle per bus period in a background thread), ``"manual"`` (time moves
    only by ``.advance(seconds)``), ``"step"`` (each SDO read of 6041h
    runs one bus cycle first; ``.advance`` works too) or ``"sync"`` (each
    SYNC received is one bus cycle of 1006h µs).

    Returns an object with ``.drive`` (:class:`~.devices.cia402.drive.Drive`),
    ``.node`` (the ``canopen.LocalNode``: NMT and heartbeat), ``.pdos`` (the
    CAN PDOs), ``.tpdo_no`` / ``.rpdo_no``, ``.advance(seconds)`` and
    ``.close()``.

    Raises:
        PlcConfigError: unknown model, bad node id, a network that is not a
            connected ``canopen.Network``, an unknown clock, a bad plant
            (naming the key).
    """
    from .devices.cia402.canopen_node import CanopenDrive   # perf: as in object_dictionary

    if not isinstance(model, str) or model not in models():
        shown = printable(model)[:40] if isinstance(model, str) else type(model).__name__
        raise PlcConfigError(f"cia402.attach: unknown drive model {shown!r}; models: "
                             + ", ".join(models()))
    return CanopenDrive(network, node_id, model, plant_of(plant, "cia402.attach: plant"),
                        clock=clock)


def bus(channel: str = "plcrt") -> "LocalNetwork":
    """A ``canopen.Network`` connected to in-process CAN channel *channel*.

    Every network connected to the same channel sees the frames the others
    send, delivered in the sender's thread before its send returns (no copy,
    no Notifier thread): a master's ``network.sync.transmit()`` runs the
    SYNC-clocked drives' bus cycles, and their TPDOs have reached the
    master's maps when it returns.  Use one network for the drives
    (:func:`attach`) and one for the master, as with python-can's
    ``virtual`` bus; ``disconnect()`` leaves the channel.  Frames are shared,
    not copied: a receiver copies what it keeps (see
    :mod:`plcrt.devices.cia402.can_bus`).

    Raises:
        PlcConfigError: *channel* is not a text of 1 to 64 printable characters.
    """
    from .devices.cia402.can_bus import MAX_CHANNEL, LocalNetwork   # perf: imports canopen

    if (not isinstance(channel, str) or not 1 <= len(channel) <= MAX_CHANNEL
            or not channel.isprintable()):
        shown = printable(channel)[:40] if isinstance(channel, str) else type(channel).__name__
        raise PlcConfigError(f"cia402.bus: channel {shown!r} is not a text of 1 to "
                             f"{MAX_CHANNEL} printable characters")
    return LocalNetwork().connect(channel)
