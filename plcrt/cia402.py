"""Public entry points for plcrt's simulated CiA 402 drives.

* :func:`object_dictionary` gives the ``canopen.ObjectDictionary`` of a drive
  model, for a CANopen master's side (``BaseNode402(node_id, od)``);
* :func:`eds_text` gives the same dictionary as an EDS file;
* :func:`models` lists the drive models;
* :func:`attach` puts a simulated drive on a connected ``canopen.Network``
  as a ``canopen.LocalNode`` (see :mod:`plcrt.devices.cia402.canopen_node`).

All three read the model's data file, ``library/cia402/<model>.toml`` (see
:mod:`plcrt.devices.cia402.od`).  ``canopen`` is imported only when a
function needs it.  The drive itself lives in :mod:`plcrt.devices.cia402`.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

from .devices.cia402.od import Entry, ObjectDictionary
from .errors import PlcConfigError
from .safetext import printable

if TYPE_CHECKING:  # pragma: no cover
    import canopen.objectdictionary

__all__ = ["attach", "eds_text", "models", "object_dictionary"]

if TYPE_CHECKING:  # pragma: no cover
    from .devices.cia402.canopen_node import CanopenDrive, Clock
    from .devices.cia402.plant import DrivePlant

#: plcrt dtype -> CANopen data type code (CiA 301 Table 44).
_CANOPEN_TYPES = {"BOOL": 0x01, "I8": 0x02, "I16": 0x03, "I32": 0x04, "U8": 0x05, "U16": 0x06,
                  "U32": 0x07, "STR": 0x09, "I64": 0x15, "U64": 0x1B}


def models() -> list[str]:
    """Names of the available drive models (``hcfa-am0520b``, ``kinco-servo``)."""
    return ObjectDictionary.models()


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
    from canopen.objectdictionary import ObjectDictionary as CoOD
    from canopen.objectdictionary import ODRecord

    if node_id is not None and (isinstance(node_id, bool) or not isinstance(node_id, int)
                                or not 1 <= node_id <= 127):
        raise PlcConfigError("object_dictionary: node_id is a CANopen node id (1..127, "
                             "CiA 301 §7.5.2.4) or None")
    data = ObjectDictionary.load(model)
    od = CoOD()
    info = od.device_information
    info.product_name = str(data.info.get("title", data.model))
    info.vendor_name = str(data.info.get("vendor", ""))
    for attr, key in (("vendor_number", 1), ("product_number", 2), ("revision_number", 3)):
        e = data.find(0x1018, key)
        if e is not None:
            setattr(info, attr, int(e.default))
    rx = sum(1 for i in data.indexes() if 0x1600 <= i <= 0x17FF)
    tx = sum(1 for i in data.indexes() if 0x1A00 <= i <= 0x1BFF)
    info.nr_of_RXPDO, info.nr_of_TXPDO = rx, tx
    for index in data.indexes():
        subs = data.subs(index)
        if len(subs) == 1 and subs[0].sub == 0:
            od.add_object(_variable(subs[0]))
            continue
        record = ODRecord(subs[0].name.split(":")[0], index)
        for e in subs:
            record.add_member(_variable(e))
        od.add_object(record)
    if node_id is not None:
        from .devices.cia402.canopen_node import can_view
        can_view(od, node_id)
    return od


def attach(network: Any, node_id: int, model: str = "hcfa-am0520b",
           plant: "DrivePlant | None" = None, *, clock: "Clock" = "wall") -> "CanopenDrive":
    """Put a simulated drive of *model* on the connected ``canopen.Network``
    *network* as node *node_id*; a master drives it with SDOs, NMT and
    heartbeat (``BaseNode402(node_id, object_dictionary(model))``).

    *clock*: ``"wall"`` (the drive's time follows the wall clock, one bus
    cycle per bus period in a background thread), ``"manual"`` (time moves
    only by ``.advance(seconds)``) or ``"step"`` (each SDO read of 6041h
    runs one bus cycle first; ``.advance`` works too).

    Returns an object with ``.drive`` (:class:`~.devices.cia402.drive.Drive`),
    ``.node`` (the ``canopen.LocalNode``), ``.advance(seconds)`` and
    ``.close()``.

    Raises:
        PlcConfigError: unknown model, bad node id, a network that is not a
            connected ``canopen.Network``, an unknown clock.
    """
    from .devices.cia402.canopen_node import CanopenDrive

    if not isinstance(model, str) or model not in models():
        shown = printable(model)[:40] if isinstance(model, str) else type(model).__name__
        raise PlcConfigError(f"cia402.attach: unknown drive model {shown!r}; models: "
                             + ", ".join(models()))
    return CanopenDrive(network, node_id, model, plant, clock=clock)


def eds_text(model: str = "hcfa-am0520b") -> str:
    """The EDS file of a drive model (canopen's EDS writer, fixed dates from
    the data file so that the text is reproducible).

    Raises:
        PlcConfigError: unknown model or malformed data file.
    """
    from canopen.objectdictionary.eds import export_eds

    data = ObjectDictionary.load(model)
    od = object_dictionary(model)
    date = str(data.info.get("eds_date", "01-01-2026"))
    file_info: dict[str, Any] = {
        "FileName": f"{data.model}.eds", "FileVersion": 1, "FileRevision": 0,
        "EdsVersion": "4.0", "Description": str(data.info.get("title", data.model)),
        "CreationDate": date, "CreationTime": "12:00PM", "CreatedBy": "plcrt",
        "ModificationDate": date, "ModificationTime": "12:00PM", "ModifiedBy": "plcrt",
    }
    out = io.StringIO()
    export_eds(od, out, file_info=file_info)
    return out.getvalue()


def _variable(e: Entry) -> Any:
    from canopen.objectdictionary import ODVariable

    var = ODVariable(e.name, e.index, e.sub)
    var.data_type = _CANOPEN_TYPES[e.dtype]
    var.access_type = e.access
    var.pdo_mappable = bool(e.pdo)
    var.unit = e.unit
    var.description = e.source
    if e.dtype == "STR":
        var.default = str(e.default)
    else:
        var.default = bool(e.default) if e.dtype == "BOOL" else int(e.default)
        var.default_raw = str(int(e.default))
        var.min, var.max = e.min, e.max
    return var
