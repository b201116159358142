"""The Modbus request PDUs of the S7-200 slave library's functions and
their execution on a PLC's memory.

Two halves, so that the scan is held only for the memory access:

- :func:`parse` (in the server's thread) checks a request's function,
  length and quantities and returns a :class:`Request`, or raises
  :class:`~plcrt.devices.modbus.rtu.ModbusException`;
- :func:`execute` (a door job, in the PLC's thread at a scan boundary)
  resolves the span on the address map, checks the write guard, reads or
  writes the memory and returns the response PDU.

The library's rules (S7-200 System Manual, "Modbus slave protocol", the
supported functions; S7-200 SMART System Manual V2.3, 9.3.3): functions 1,
2, 3, 4, 5, 6, 15, 16 and no other (exception 1); at most 120 registers
per request (exception 3 above, as the Modbus Application Protocol
answers a quantity out of range); function 15 of the library map starts
on a byte boundary of Q (exception 2) and writes a multiple of 8 coils
(exception 3); a span past the map's bound is exception 2; a coil value
other than 0000 / FF00, a byte count that does not fit the quantity, or a
wrong length is exception 3.  A request that fails writes nothing.

What it is not: MBAP framing or sockets (:mod:`.server`), the map
(:mod:`.addrmap`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ...devices.modbus.rtu import ModbusException, pack_bits, unpack_bits
from ..options import WriteGuard
from .addrmap import AddressMap, Region

__all__ = ["FUNCTIONS", "MAX_WORDS", "ModbusException", "Refused", "Request", "execute",
           "parse"]

#: registers per request at most (the library: "up to 120 words")
MAX_WORDS = 120
#: function -> (table kind, bits, write, most items) (Modbus Application
#: Protocol 6.1-6.12 for the bit counts; :data:`MAX_WORDS` for registers)
FUNCTIONS = {1: ("coils", True, False, 2000), 2: ("inputs", True, False, 2000),
             3: ("holding", False, False, MAX_WORDS),
             4: ("input_registers", False, False, MAX_WORDS),
             5: ("coils", True, True, 1), 6: ("holding", False, True, 1),
             15: ("coils", True, True, 1968), 16: ("holding", False, True, MAX_WORDS)}
#: the exception a write refused by the server's options is answered with
#: (docs/network.md: "illegal data address", the address is not writable)
REFUSED = 2


class Refused(ModbusException):
    """A write the read-only mode or the allow-list refuses."""

    def __init__(self, what: str) -> None:
        super().__init__(REFUSED)
        self.what = what


@dataclass(frozen=True, slots=True)
class Request:
    """One checked request: ``values`` are the bits or words to write
    (None for a read)."""

    fn: int
    kind: str
    bits: bool
    start: int
    count: int
    values: tuple[int, ...] | None = None


def parse(pdu: bytes) -> Request:
    """The request in ``pdu`` (function code and data).

    Raises:
        ModbusException: 1 for a function the library lacks, 3 for a
            length, quantity, byte count or coil value out of rule.
    """
    if not pdu:
        raise ModbusException(3)
    fn, data = pdu[0], pdu[1:]
    spec = FUNCTIONS.get(fn)
    if spec is None:
        raise ModbusException(1)
    kind, bits, write, top = spec
    if len(data) < 4:
        raise ModbusException(3)
    start, second = data[0] << 8 | data[1], data[2] << 8 | data[3]
    if fn in (5, 6):
        if len(data) != 4 or fn == 5 and second not in (0x0000, 0xFF00):
            raise ModbusException(3)
        return Request(fn, kind, bits, start, 1, (int(second == 0xFF00) if fn == 5 else second,))
    count = second
    if not 1 <= count <= top:
        raise ModbusException(3)
    if not write:
        if len(data) != 4:
            raise ModbusException(3)
        return Request(fn, kind, bits, start, count)
    n = (count + 7) // 8 if bits else 2 * count
    if len(data) != 5 + n or data[4] != n:
        raise ModbusException(3)
    raw = data[5:]
    values = unpack_bits(raw, count) if bits else \
        [raw[2 * i] << 8 | raw[2 * i + 1] for i in range(count)]
    return Request(fn, kind, bits, start, count, tuple(values))


def execute(areas: dict[str, bytearray], amap: AddressMap, req: Request,
            guard: WriteGuard, library: bool) -> bytes:
    """Run ``req`` on the memory ``areas`` (a door job: the PLC's thread at
    a scan boundary); the response PDU.  ``library``: ``amap`` is the
    slave library's map (function 15's byte rule applies).

    Raises:
        ModbusException: 2 for a span the map does not cover (or function
            15 off a byte boundary), 3 for function 15 of a count that is
            not a multiple of 8; :class:`Refused` for a write the guard
            refuses.
    """
    segs = amap.segments(req.kind, req.start, req.count)
    if segs is None:
        raise ModbusException(2)
    if req.values is None:
        vals: list[int] = []
        for r, i, n in segs:
            vals += _get_bits(areas, r, i, n) if req.bits else _get_words(areas, r, i, n)
        data = pack_bits(vals) if req.bits else b"".join(v.to_bytes(2, "big") for v in vals)
        return bytes((req.fn, len(data))) + data
    if req.fn == 15 and library:
        # the library's rule: the first output on a byte boundary of Q, a
        # multiple of 8 outputs (System Manual, Modbus slave functions)
        if req.start & 7:
            raise ModbusException(2)
        if req.count & 7:
            raise ModbusException(3)
    for r, i, n in segs:
        first, nbytes = _bytes_of(r, i, n, req.bits)
        if not guard.allows(r.area, first, nbytes):
            raise Refused(f"{r.area} bytes {first}..{first + nbytes - 1}")
    at = 0
    for r, i, n in segs:
        chunk = req.values[at:at + n]
        if req.bits:
            _put_bits(areas, r, i, chunk)
        else:
            _put_words(areas, r, i, chunk)
        at += n
    if req.fn in (5, 6):
        v = req.values[0]
        return bytes((req.fn,)) + req.start.to_bytes(2, "big") + \
            ((0xFF00 if v else 0) if req.fn == 5 else v).to_bytes(2, "big")
    return bytes((req.fn,)) + req.start.to_bytes(2, "big") + req.count.to_bytes(2, "big")


def _bytes_of(r: Region, i: int, n: int, bits: bool) -> tuple[int, int]:
    """The first byte and the number of bytes of ``n`` items from index
    ``i`` of region ``r``."""
    if bits:
        lo, hi = (r.offset + i) >> 3, (r.offset + i + n - 1) >> 3
        return lo, hi - lo + 1
    return r.offset + 2 * i, 2 * n


def _get_bits(areas: dict[str, bytearray], r: Region, i: int, n: int) -> list[int]:
    buf, b0 = areas[r.area], r.offset + i
    return [buf[b >> 3] >> (b & 7) & 1 for b in range(b0, b0 + n)]


def _get_words(areas: dict[str, bytearray], r: Region, i: int, n: int) -> list[int]:
    buf, o = areas[r.area], r.offset + 2 * i
    return [buf[o + 2 * k] << 8 | buf[o + 2 * k + 1] for k in range(n)]


def _put_bits(areas: dict[str, bytearray], r: Region, i: int, vals: Any) -> None:
    # an input written goes to the physical input too, so the next scan's
    # I := PI keeps it (as plcrt.engine.access's write does)
    bufs = (areas["I"], areas["PI"]) if r.area == "I" else (areas[r.area],)
    b0 = r.offset + i
    for buf in bufs:
        for b, v in enumerate(vals, b0):
            if v:
                buf[b >> 3] |= 1 << (b & 7)
            else:
                buf[b >> 3] &= ~(1 << (b & 7)) & 0xFF


def _put_words(areas: dict[str, bytearray], r: Region, i: int, vals: Any) -> None:
    bufs = (areas["I"], areas["PI"]) if r.area == "I" else (areas[r.area],)
    o = r.offset + 2 * i
    raw = b"".join(v.to_bytes(2, "big") for v in vals)
    for buf in bufs:
        buf[o:o + len(raw)] = raw
