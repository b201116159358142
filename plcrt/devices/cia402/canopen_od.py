"""A drive model's object dictionary as the ``canopen`` package sees it.

What it is: :func:`object_dictionary` (a ``canopen.ObjectDictionary`` built
from the model's data file, ``library/cia402/<model>.toml``, read by
:mod:`.od`), :func:`eds_text` (the same as an EDS file) and :func:`models`.
The public facade :mod:`plcrt.cia402` re-exports them; the CANopen port
(:mod:`.canopen_node`) and the ``plcrt cia402`` command (:mod:`.cli`) use
them from here.

What it is not: the CAN view of a drive on a bus (1017h and the PDOs a
master expects: :func:`.canopen_node.can_view`), and no drive.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

from .od import Entry, ObjectDictionary

if TYPE_CHECKING:  # pragma: no cover
    import canopen.objectdictionary

__all__ = ["eds_text", "models", "object_dictionary"]

#: plcrt dtype -> CANopen data type code (CiA 301 Table 44).
_CANOPEN_TYPES = {"BOOL": 0x01, "I8": 0x02, "I16": 0x03, "I32": 0x04, "U8": 0x05, "U16": 0x06,
                  "U32": 0x07, "STR": 0x09, "I64": 0x15, "U64": 0x1B}


def models() -> list[str]:
    """Names of the available drive models (``hcfa-am0520b``, ``kinco-servo``)."""
    return ObjectDictionary.models()


def object_dictionary(model: str = "hcfa-am0520b") -> canopen.objectdictionary.ObjectDictionary:
    """The canopen object dictionary of a drive model: one ``ODVariable`` per
    single-entry object, one ``ODRecord`` per object with subindexes, with
    data type, access, default, limits, PDO mappability and unit of the data
    file (the entry's manual section becomes the description).

    Raises:
        PlcConfigError: unknown model or malformed data file.
    """
    # perf: canopen (about 0.2 s to import) is imported when a dictionary is
    # built, not with this module (the plcrt command line imports .cli)
    from canopen.objectdictionary import ObjectDictionary as CoOD
    from canopen.objectdictionary import ODRecord

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
    return od


def eds_text(model: str = "hcfa-am0520b") -> str:
    """The EDS file of a drive model (canopen's EDS writer, fixed dates from
    the data file so that the text is reproducible).

    Raises:
        PlcConfigError: unknown model or malformed data file.
    """
    from canopen.objectdictionary.eds import export_eds   # perf: see object_dictionary

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
    from canopen.objectdictionary import ODVariable   # perf: see object_dictionary

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
