"""The CAN view of a drive: the CANopen objects a master expects that the
model's dictionary lacks (CiA 301 §7.5.2).

What it is: :func:`can_view`, which adds them to a canopen
``ObjectDictionary`` (the master's, through ``plcrt.cia402.object_dictionary(
model, node_id)``, and the drive port's): 1005h COB-ID SYNC, 1006h
communication cycle period, 1017h producer heartbeat time, and one TPDO and one
RPDO (communication and mapping records) at the first numbers the model's own
mapping objects leave free (:func:`pdo_slots`; HCFA: TPDO 3, RPDO 5, since
1600h-1603h and 1A00h-1A01h are its EtherCAT maps; Kinco: TPDO 5, RPDO 5);
:func:`view_channels` gives those PDOs to :class:`~.can_pdo.CanPdos`.

What it is not: no behaviour; the port (``canopen_node.py``) answers these
objects and runs the PDOs.
"""

from __future__ import annotations

from typing import Any

from canopen.objectdictionary import ODRecord, ODVariable, datatypes

from .can_pdo import NO_RTR

__all__ = ["can_view", "pdo_slots", "view_channels", "TPDO_OBJECTS", "RPDO_OBJECTS",
           "HEARTBEAT_MS", "TPDO_PERIOD_MS", "SYNC_ID"]

SYNC_ID = 0x80                        # CiA 301 §7.5.2.5: 1005h default

#: The CAN view's PDO contents (CiA 301 §7.5.2.35-38): one TPDO and one RPDO.
TPDO_OBJECTS = ((0x6041, 0, 16), (0x6064, 0, 32), (0x6061, 0, 8))
RPDO_OBJECTS = ((0x6040, 0, 16), (0x607A, 0, 32), (0x6060, 0, 8))
#: 1017h default of the CAN view: a master's NMT learns PRE-OPERATIONAL from
#: the heartbeat, which caveat 1's guard in setup_402_state_machine needs.
HEARTBEAT_MS = 50
TPDO_PERIOD_MS = 2          # digest §7.2 caveat 4: a cyclic TPDO keeps BaseNode402 happy


def pdo_slots(od: Any) -> tuple[int, int]:
    """The CAN view's (TPDO, RPDO) numbers: the first whose communication
    and mapping objects the model's dictionary lacks (HCFA: TPDO 3, RPDO 5;
    the EtherCAT mapping objects 1600h-1603h, 1A00h-1A01h stay the drive's)."""
    def free(com: int, map_: int) -> int:
        return next(n for n in range(512) if com + n not in od and map_ + n not in od)
    return free(0x1800, 0x1A00) + 1, free(0x1400, 0x1600) + 1


def view_channels(od: Any, tpdo: int, rpdo: int) -> list:
    """The port's PDOs as :class:`~.can_pdo.CanPdos` takes them, from the
    CAN view's defaults in *od*."""
    out = []
    for n, tx in ((tpdo, True), (rpdo, False)):
        com, map_ = od[(0x1800 if tx else 0x1400) + n - 1], od[(0x1A00 if tx else 0x1600) + n - 1]
        entries = tuple(map_[k].default for k in range(1, map_[0].default + 1))
        out.append((n, tx, com[1].default & ~NO_RTR, com[2].default, com[5].default, entries))
    return out


def _var(name: str, index: int, sub: int, dtype: int, default: int, access: str = "rw") -> Any:
    var = ODVariable(name, index, sub)
    var.data_type = dtype
    var.access_type = access
    var.default = default
    var.description = "CiA 301 (CAN view of the drive)"
    return var


def can_view(od: Any, node_id: int) -> None:
    """Add the CAN objects a CANopen master expects where the model lacks
    them: 1005h COB-ID SYNC, 1006h communication cycle period (µs, 0 = the
    drive's bus period), 1017h producer heartbeat time (CiA 301 §7.5.2), one
    TPDO (:data:`TPDO_OBJECTS`, COB-ID 180h+id, event-driven) and one RPDO
    (:data:`RPDO_OBJECTS`, COB-ID 200h+id) at the slots of :func:`pdo_slots`,
    each with eight mapping entries."""
    if 0x1017 not in od:
        var = _var("Producer heartbeat time", 0x1017, 0, datatypes.UNSIGNED16,
                   HEARTBEAT_MS)
        var.unit = "ms"
        od.add_object(var)
    if 0x1005 not in od:
        od.add_object(_var("COB-ID SYNC message", 0x1005, 0, datatypes.UNSIGNED32, SYNC_ID))
    if 0x1006 not in od:
        var = _var("Communication cycle period", 0x1006, 0, datatypes.UNSIGNED32, 0)
        var.unit = "us"
        od.add_object(var)
    tpdo, rpdo = pdo_slots(od)
    for com, map_, cob, objects, what in (
            (0x1800 + tpdo - 1, 0x1A00 + tpdo - 1, 0x180 + node_id, TPDO_OBJECTS, f"TPDO {tpdo}"),
            (0x1400 + rpdo - 1, 0x1600 + rpdo - 1, 0x200 + node_id, RPDO_OBJECTS, f"RPDO {rpdo}")):
        rec = ODRecord(f"{what} communication parameter", com)
        rec.add_member(_var("Highest sub-index supported", com, 0, datatypes.UNSIGNED8, 5, "ro"))
        rec.add_member(_var("COB-ID", com, 1, datatypes.UNSIGNED32, cob | NO_RTR))
        rec.add_member(_var("Transmission type", com, 2, datatypes.UNSIGNED8, 0xFE))
        rec.add_member(_var("Inhibit time", com, 3, datatypes.UNSIGNED16, 0))
        rec.add_member(_var("Event timer", com, 5, datatypes.UNSIGNED16,
                            TPDO_PERIOD_MS if com >= 0x1800 else 0))
        od.add_object(rec)
        rec = ODRecord(f"{what} mapping parameter", map_)
        rec.add_member(_var("Number of mapped objects", map_, 0, datatypes.UNSIGNED8,
                            len(objects)))
        for k in range(1, 9):
            index, sub, bits = objects[k - 1] if k <= len(objects) else (0, 0, 0)
            rec.add_member(_var(f"Mapped object {k}", map_, k, datatypes.UNSIGNED32,
                                index << 16 | sub << 8 | bits))
        od.add_object(rec)
