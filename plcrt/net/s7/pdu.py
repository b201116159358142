"""The S7 PDU (S7comm, protocol id 0x32): the header, the job and
user-data parameter sections, and the answers the server builds.

Header (10 bytes for a job or user data, 12 for an answer, which adds
the error class and code): ``32 ROSCTR 00 00 REF(2) PLEN(2) DLEN(2)``.
ROSCTR 1 is a job (setup communication 0xF0, read var 0x04, write var
0x05, PI service 0x28, PLC stop 0x29), 3 its answer with data, 7 user
data (the SZL reads are its group 4).

What it is: byte layouts, every length checked against the frame.  What
it is not: what an item addresses (:mod:`.areas`), the SZL records
(:mod:`.szl`).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from .iso import FrameError

__all__ = ["ERR", "FN", "Header", "Item", "ack", "parse_header", "parse_items",
           "parse_write_data", "userdata_answer"]

#: ROSCTR values
JOB, ACK, ACK_DATA, USERDATA = 0x01, 0x02, 0x03, 0x07
#: job functions
FN = {"setup": 0xF0, "read": 0x04, "write": 0x05, "pi": 0x28, "stop": 0x29}

#: header error words (class << 8 | code) this server answers with
#: (the S7 error classes: 0x81 application, 0x83 resources, 0x84 service
#: processing, 0x85 PDU; the words as libnodave, snap7 and Wireshark's
#: s7comm dissector list them)
ERR = {
    "not_implemented": 0x8104,   # service unknown or not implemented on the module
    "resources": 0x8302,         # too few resources (the request queue is full)
    "state": 0x8402,             # the object's state forbids the service (RUN after a fault)
    "denied": 0x8703,            # access to the object refused (a read-only server)
    "frame": 0x8500,             # wrong frames: malformed parameters, a PDU beyond the size
}

#: longest item list of one read or write (snap7's MaxVars, what S7 CPUs take)
MAX_ITEMS = 20


@dataclass(frozen=True)
class Header:
    rosctr: int
    ref: int
    params: bytes
    data: bytes


def parse_header(pdu: bytes) -> Header:
    """The header of a request and its two sections.

    Raises:
        FrameError: not protocol 0x32, not a job or user data, or section
            lengths that do not add up to the PDU.
    """
    if len(pdu) < 10 or pdu[0] != 0x32:
        raise FrameError("not an S7 PDU (protocol id 0x32)")
    rosctr = pdu[1]
    if rosctr not in (JOB, USERDATA):
        raise FrameError(f"S7 ROSCTR {rosctr} is not a request")
    ref, plen, dlen = struct.unpack_from(">HHH", pdu, 4)
    if 10 + plen + dlen != len(pdu):
        raise FrameError("S7 header lengths do not match the PDU")
    return Header(rosctr, ref, bytes(pdu[10:10 + plen]), bytes(pdu[10 + plen:]))


def ack(ref: int, params: bytes = b"", data: bytes = b"", error: int = 0) -> bytes:
    """An answer with data (ROSCTR 3) to the job ``ref``."""
    return struct.pack(">BBHHHHH", 0x32, ACK_DATA, 0, ref, len(params), len(data),
                       error) + params + data


@dataclass(frozen=True)
class Item:
    """One variable of a read or write (an S7-ANY address)."""

    tsize: int
    count: int
    db: int
    area: int
    address: int          #: bit address, or timer / counter number


def parse_items(params: bytes) -> list[Item]:
    """The item list of a read or write job's parameters
    (``FN COUNT`` then 12 bytes an item: ``12 0A 10 TS COUNT(2) DB(2)
    AREA ADDR(3)``).

    Raises:
        FrameError: a count of 0 or above :data:`MAX_ITEMS`, a length that
            does not fit, or an item that is not an S7-ANY address.
    """
    if len(params) < 2:
        raise FrameError("read/write parameters too short")
    n = params[1]
    if not 1 <= n <= MAX_ITEMS or len(params) != 2 + 12 * n:
        raise FrameError(f"read/write of {n} items in {len(params)} bytes")
    out = []
    for i in range(n):
        spec, length, syntax, ts, count, db, area, a_hi, a_lo = \
            struct.unpack_from(">BBBBHHBBH", params, 2 + 12 * i)
        if spec != 0x12 or length != 0x0A or syntax != 0x10:
            raise FrameError("only S7-ANY item addresses are served")
        out.append(Item(ts, count, db, area, a_hi << 16 | a_lo))
    return out


def parse_write_data(data: bytes, n: int) -> list[tuple[int, bytes]]:
    """The ``n`` data items of a write: ``(transport size, bytes)``; bit
    lengths are turned into bytes (``00 TS LEN(2) DATA [fill]``).

    Raises:
        FrameError: the items do not fit the data section.
    """
    out, i = [], 0
    for k in range(n):
        if i + 4 > len(data):
            raise FrameError("write data truncated")
        ts, length = data[i + 1], data[i + 2] << 8 | data[i + 3]
        nbytes = length if ts in BYTE_LENGTH_TS else (length + 7) // 8
        body = data[i + 4:i + 4 + nbytes]
        if len(body) != nbytes:
            raise FrameError("write data truncated")
        out.append((ts, bytes(body)))
        i += 4 + nbytes + (nbytes & 1 if k < n - 1 else 0)
    if i < len(data) - 1 or i > len(data):
        raise FrameError("write data does not match its items")
    return out


#: data transport sizes whose length is in bytes (bit 0x03 counts bits,
#: but one bit is one byte on the wire; real 0x07, octet string 0x09)
BYTE_LENGTH_TS = frozenset({0x03, 0x07, 0x09})


def userdata_answer(ref: int, group: int, sub: int, data: bytes, *, seq: int = 0,
                    more: bool = False, error: int = 0) -> bytes:
    """A user-data answer: parameters ``00 01 12 08 12 8G SUB SEQ 00 LAST
    ERR(2)`` (type 8 = answer, group G) and ``data`` (already headed)."""
    params = struct.pack(">BBBBBBBBBBH", 0, 1, 0x12, 8, 0x12, 0x80 | group, sub, seq, 0,
                         1 if more else 0, error)
    return struct.pack(">BBHHHH", 0x32, USERDATA, 0, ref, len(params), len(data)) \
        + params + data
