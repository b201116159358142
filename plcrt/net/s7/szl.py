"""The system status list (SZL) the server answers, from a configurable
identity, and the connection resources of that identity.

Records (layouts of the S7 system software manual's SSL chapter, as S7
CPUs send them and snap7, python-snap7 and Wireshark read them):

- 0x0000: the SZL ids served;
- 0x0011: module identification, 28-byte records: index 1 the order
  number (MLFB), 6 the hardware, 7 the firmware (``V`` and three digits);
- 0x001C: component identification, 34-byte records: 1 station name,
  2 module name, 3 plant id, 4 copyright, 5 serial number, 7 module type
  (for both, an index other than 0 asks for that record alone);
- 0x0131 index 1: communication capabilities (max PDU, connections);
- 0x0132 and 0x0232 index 4: protection level and the mode switch;
- 0x0424: the CPU's mode, byte 3 of the record 0x08 RUN or 0x04 STOP (the
  byte snap7's ``Cli_GetPlcStatus`` reads).

Defaults describe a CPU ST40 of the S7-200 SMART (order number
6ES7 288-1ST40-0AA0).  What it is: data and packing.  What it is not:
the user-data framing (:mod:`.pdu`, :mod:`.server`).
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from ...errors import PlcConfigError
from ...safetext import shown_value

__all__ = ["S7Identity", "szl_answer"]

#: the connection resources given for a SMART CPU: one programming device
#: (exclusive: python-snap7#550, #765), eight HMI/OP, eight basic S7
#: (GET/PUT) partners.  The HMI and basic figures are the usual ones for
#: SMART CPUs, not checked against a manual here: configurable
#: (docs/network.md)
SMART_CONNECTIONS = {"PG": 1, "OP": 8, "basic": 8}


@dataclass(frozen=True)
class S7Identity:
    """What the server says it is.  Texts are ASCII, cut to their field."""

    order_number: str = "6ES7 288-1ST40-0AA0"
    firmware: tuple[int, int, int] = (2, 7, 0)
    hardware: int = 1
    station: str = "S7-200 SMART station"
    module_name: str = "CPU ST40"
    plant_id: str = ""
    copyright: str = "Original Siemens Equipment"
    serial: str = "PLCRT-00000001"
    module_type: str = "CPU ST40 DC/DC/DC"
    #: the largest PDU negotiated (240 for a SMART; 480 allowed)
    pdu_size: int = 240
    #: connections per type (PG, OP, basic)
    connections: Mapping[str, int] = field(default_factory=lambda: dict(SMART_CONNECTIONS))

    def __post_init__(self) -> None:
        if self.pdu_size not in (240, 480, 960):
            raise PlcConfigError(f"S7 PDU size is 240, 480 or 960, not "
                                 f"{shown_value(self.pdu_size)}")
        for key in ("PG", "OP", "basic"):
            n = self.connections.get(key)
            if isinstance(n, bool) or not isinstance(n, int) or not 0 <= n <= 64:
                raise PlcConfigError(f"S7 connections of type {key}: 0..64, not {shown_value(n)}")
        fw = self.firmware
        if not (isinstance(fw, tuple) and len(fw) == 3
                and all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 255
                        for v in fw)):
            raise PlcConfigError(f"S7 firmware is three numbers 0..255, not {shown_value(fw)}")
        hw = self.hardware
        if isinstance(hw, bool) or not isinstance(hw, int) or not 0 <= hw <= 0xFFFF:
            raise PlcConfigError(f"S7 hardware version is 0..65535, not {shown_value(hw)}")
        texts = (self.order_number, self.station, self.module_name, self.plant_id,
                 self.copyright, self.serial, self.module_type)
        if not all(isinstance(t, str) and t.isascii() and len(t) <= 32 for t in texts):
            raise PlcConfigError("S7 identity texts are ASCII of at most 32 characters")


def _text(s: str, n: int) -> bytes:
    return s.encode("ascii")[:n].ljust(n, b"\x00")


def _list(ident: S7Identity, index: int, mode: str) -> tuple[int, list[bytes]]:
    return 2, [struct.pack(">H", i) for i in sorted(SZL)]


def _module(ident: S7Identity, index: int, mode: str) -> tuple[int, list[bytes]]:
    v1, v2, v3 = ident.firmware
    mlfb = _text(ident.order_number, 20)
    return 28, [struct.pack(">H", 1) + mlfb + b"\x00\xc0\x00\x00\x00\x00",
                struct.pack(">H", 6) + mlfb + struct.pack(">HHH", 0x00C0, ident.hardware, 0),
                struct.pack(">H", 7) + b"\x20" * 20 + b"\x00\xc0" + bytes([0x56, v1, v2, v3])]


def _component(ident: S7Identity, index: int, mode: str) -> tuple[int, list[bytes]]:
    fields = ((1, ident.station), (2, ident.module_name), (3, ident.plant_id),
              (4, ident.copyright), (5, ident.serial), (7, ident.module_type))
    return 34, [struct.pack(">H", i) + _text(t, 32) for i, t in fields]


def _comm(ident: S7Identity, index: int, mode: str) -> tuple[int, list[bytes]]:
    total = sum(ident.connections.values())
    rec = struct.pack(">HHHII", 1, ident.pdu_size, total, 187500, 12000000)
    return 40, [rec.ljust(40, b"\x00")]


def _protection(ident: S7Identity, index: int, mode: str) -> tuple[int, list[bytes]]:
    switch = 1 if mode == "RUN" else 3          # bart_sch: 1 RUN, 3 STOP
    rec = struct.pack(">HHHHHH", 4, 1, 0, 0, switch, 0)
    return 40, [rec.ljust(40, b"\x00")]


def _mode(ident: S7Identity, index: int, mode: str) -> tuple[int, list[bytes]]:
    state = 0x08 if mode == "RUN" else 0x04
    # ereig 0x5144 (mode transition), ae 0xFF, bzu-id: the mode
    return 20, [struct.pack(">HBB", 0x5144, 0xFF, state) + bytes(16)]


#: SZL id -> the records' length and the records
SZL: dict[int, Callable[[S7Identity, int, str], tuple[int, list[bytes]]]] = {
    0x0000: _list,
    0x0011: _module,
    0x001C: _component,
    0x0131: _comm,
    0x0132: _protection,      # the same record: S7-300 CPUs and H CPUs ask either
    0x0232: _protection,
    0x0424: _mode,
}


#: SZL ids whose records begin with their index (the index asks one)
_INDEXED = frozenset({0x0011, 0x001C})


def szl_answer(ident: S7Identity, szl_id: int, index: int, mode: str) -> bytes | None:
    """The SZL data of ``szl_id`` (``ID(2) INDEX(2) LENTHDR(2) N(2)`` and
    the records), or None when it is not served."""
    make = SZL.get(szl_id)
    if make is None:
        return None
    size, recs = make(ident, index, mode)
    if szl_id in _INDEXED and index:
        # one record asked by its index
        recs = [r for r in recs if r[:2] == struct.pack(">H", index)]
        if not recs:
            return None
    return struct.pack(">HHHH", szl_id, index, size, len(recs)) + b"".join(recs)
