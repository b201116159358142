"""What an S7 item addresses on an S7-200 / S7-200 SMART: the area codes,
the transport sizes and the per-item return codes, as tables; the reads
and writes as door jobs.

V memory is DB1 (area 0x84, DB number 1), as every client library
addresses a SMART (S7NetPlus#433, plc4x#1925, nodeS7#49).  The 200
family's own codes serve SM (0x05), AI (0x06), AQ (0x07), counters (0x1E)
and timers (0x1F) (libnodave's nodave.h, Wireshark's s7comm dissector, a
capture in python-snap7#471); the S7-300 codes for counters (0x1C) and
timers (0x1D) are served as well.  A timer or counter item addresses
elements (its number), two bytes each: the current value, big-endian.

Item return codes (libnodave, nodave.h): 0xFF success; 0x03 the item is
not available, which the 200 family answers for an unknown area, a DB
other than 1 and a bit item longer than one bit (libnodave's
``daveResItemNotAvailable200``), and which is also "access denied" for a
refused write; 0x05 address out of range; 0x06 a transport size the area
does not take; 0x07 write data whose size does not fit the item.

What it is: checking items against the PLC's static sizes (in the
server's thread) and the jobs run at a scan boundary (in the PLC's
thread).  What it is not: the wire format (:mod:`.pdu`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ..options import WriteGuard
from .pdu import Item

__all__ = ["AREAS", "AreaSpec", "Loc", "RC", "TSIZES", "check_write", "locate", "read_job",
           "reply_item", "write_job"]

#: item return codes
RC = {"ok": 0xFF, "na": 0x03, "denied": 0x03, "range": 0x05, "type": 0x06, "size": 0x07}


@dataclass(frozen=True)
class AreaSpec:
    letter: str        #: the S7-200 area (the write allow-list's name)
    buffer: str        #: the memory image's area
    elements: bool     #: timers / counters: addressed by number, 2 bytes each
    db: int | None = None


#: area code -> what it is on the 200 family
AREAS: dict[int, AreaSpec] = {
    0x84: AreaSpec("V", "V", False, db=1),
    0x81: AreaSpec("I", "I", False),
    0x82: AreaSpec("Q", "Q", False),
    0x83: AreaSpec("M", "M", False),
    0x05: AreaSpec("SM", "SM", False),
    0x06: AreaSpec("AI", "AI", False),
    0x07: AreaSpec("AQ", "AQ", False),
    0x1F: AreaSpec("T", "TV", True),
    0x1E: AreaSpec("C", "CV", True),
    0x1D: AreaSpec("T", "TV", True),
    0x1C: AreaSpec("C", "CV", True),
}

#: request transport size -> (bytes an element, answer's transport size,
#: answer's length counted in bits)
TSIZES: dict[int, tuple[int, int, bool]] = {
    0x01: (1, 0x03, True),    # BIT: one bit, sent as one byte
    0x02: (1, 0x04, True),    # BYTE
    0x03: (1, 0x09, False),   # CHAR
    0x04: (2, 0x04, True),    # WORD
    0x05: (2, 0x05, True),    # INT
    0x06: (4, 0x04, True),    # DWORD
    0x07: (4, 0x05, True),    # DINT
    0x08: (4, 0x07, False),   # REAL
    0x1C: (2, 0x09, False),   # COUNTER
    0x1D: (2, 0x09, False),   # TIMER
    0x1E: (2, 0x09, False),   # IEC COUNTER (200 family)
    0x1F: (2, 0x09, False),   # IEC TIMER (200 family)
}
_ELEMENT_TS = frozenset({0x1C, 0x1D, 0x1E, 0x1F})


@dataclass(frozen=True)
class Loc:
    """Where a checked item lives: the image's area, byte offset and byte
    count (``bit`` >= 0 for a bit item), and what the allow-list sees."""

    buffer: str
    offset: int
    nbytes: int
    bit: int
    letter: str
    first: int        #: allow-list start (a byte, or a timer / counter number)
    units: int        #: allow-list length


def locate(item: Item, sizes: Mapping[str, int]) -> Loc | int:
    """The :class:`Loc` of an item, or its return code when it is refused."""
    spec = AREAS.get(item.area)
    if spec is None or (spec.db is not None and item.db != spec.db):
        return RC["na"]
    ts = TSIZES.get(item.tsize)
    if ts is None or (item.tsize in _ELEMENT_TS) != spec.elements:
        return RC["type"]
    if item.count < 1:
        return RC["range"]
    size = sizes[spec.buffer]
    if spec.elements:
        off, n = item.address * 2, item.count * 2
        loc = Loc(spec.buffer, off, n, -1, spec.letter, item.address, item.count)
    elif item.tsize == 0x01:
        if item.count != 1:
            return RC["na"]
        off = item.address >> 3
        loc = Loc(spec.buffer, off, 1, item.address & 7, spec.letter, off, 1)
    else:
        if item.address & 7:
            return RC["range"]
        off, n = item.address >> 3, item.count * ts[0]
        loc = Loc(spec.buffer, off, n, -1, spec.letter, off, n)
    if loc.offset + loc.nbytes > size:
        return RC["range"]
    return loc


def reply_item(tsize: int, rc: int, data: bytes) -> bytes:
    """One item of a read's answer (``RC TS LEN(2) DATA``); fill bytes are
    added by the caller."""
    if rc != RC["ok"]:
        return bytes([rc, 0, 0, 0])
    _, ts, in_bits = TSIZES[tsize]
    length = 1 if tsize == 0x01 else len(data) * 8 if in_bits else len(data)
    return bytes([rc, ts, length >> 8, length & 0xFF]) + data


def read_job(locs: Sequence[Loc]) -> Callable[[Any], list[bytes]]:
    """A door job returning the bytes of each location, all from one
    scan boundary."""
    def job(plc: Any) -> list[bytes]:
        areas = plc.mem.areas
        out = []
        for loc in locs:
            buf = areas[loc.buffer]
            if loc.bit >= 0:
                out.append(bytes([buf[loc.offset] >> loc.bit & 1]))
            else:
                out.append(bytes(buf[loc.offset:loc.offset + loc.nbytes]))
        return out
    return job


def check_write(loc: Loc, data: bytes, guard: WriteGuard, sm_readonly: int) -> int:
    """The return code of writing ``data`` at ``loc``: ok, a size that
    does not fit, or denied (read-only server, outside the allow-list, or
    SMB0..SMB29, which are read-only on the CPU: System Manual, "Special
    memory (SM) bits")."""
    if len(data) != loc.nbytes:
        return RC["size"]
    if loc.buffer == "SM" and loc.offset < sm_readonly:
        return RC["denied"]
    if not guard.allows(loc.letter, loc.first, loc.units):
        return RC["denied"]
    return RC["ok"]


def write_job(writes: Sequence[tuple[Loc, bytes]]) -> Callable[[Any], int]:
    """A door job storing each write; inputs go to the physical inputs
    too (as :meth:`plcrt.engine.access.AddressAccess.write` does), so a
    written input holds over the next scans."""
    def job(plc: Any) -> int:
        areas = plc.mem.areas
        for loc, data in writes:
            targets = (areas["I"], areas["PI"]) if loc.buffer == "I" else (areas[loc.buffer],)
            for buf in targets:
                if loc.bit >= 0:
                    mask = 1 << loc.bit
                    buf[loc.offset] = (buf[loc.offset] | mask) if data[0] & 1 \
                        else (buf[loc.offset] & ~mask & 0xFF)
                else:
                    buf[loc.offset:loc.offset + loc.nbytes] = data
        return len(writes)
    return job
