"""Modbus RTU frames: the CRC-16, the request and response PDUs of the
functions the Micro/WIN master library uses (1, 2, 3, 4 reads; 5, 6, 15,
16 writes), the bit packing, and the 3.5-character gap that ends a frame.

What it is: pure functions over bytes (Modbus over Serial Line
Specification V1.02, section 2.5.1 "RTU transmission mode" and 6 "CRC";
Modbus Application Protocol V1.1b3, section 6 "Function codes"), and
:func:`serve`, a slave's answer to one request over tables that its caller
supplies (the plant's slave: lists; the slave library: the CPU's memory).
What it is not: no timing of characters (:mod:`plcrt.engine.serial`), no
memory of its own.
"""

from __future__ import annotations

from typing import Protocol

__all__ = ["crc16", "frame", "check_crc", "pack_bits", "unpack_bits", "gap_us",
           "READS", "WRITES", "EXCEPTIONS", "Tables", "ModbusException", "serve"]

#: table kind -> read function (Modbus Application Protocol, section 6)
READS = {"coils": 1, "inputs": 2, "holding": 3, "input_registers": 4}
#: table kind -> (write one, write many)
WRITES = {"coils": (5, 15), "holding": (6, 16)}
#: exception codes (Modbus Application Protocol, section 7)
EXCEPTIONS = {1: "illegal function", 2: "illegal data address", 3: "illegal data value",
              4: "slave device failure"}


def _table() -> tuple[int, ...]:
    out = []
    for n in range(256):
        c = n
        for _ in range(8):
            c = (c >> 1) ^ 0xA001 if c & 1 else c >> 1
        out.append(c)
    return tuple(out)


_CRC = _table()


def crc16(data: bytes) -> int:
    """The Modbus CRC-16 (polynomial 16#A001 reflected, start 16#FFFF)."""
    c = 0xFFFF
    for b in data:
        c = (c >> 8) ^ _CRC[(c ^ b) & 0xFF]
    return c


def frame(body: bytes) -> bytes:
    """*body* (address, function, data) with its CRC, low byte first."""
    c = crc16(body)
    return body + bytes((c & 0xFF, c >> 8))


def check_crc(data: bytes) -> bool:
    """The last two bytes of *data* are the CRC of the others."""
    return len(data) >= 4 and crc16(data[:-2]) == (data[-2] | data[-1] << 8)


def pack_bits(bits: list[int]) -> bytes:
    """Bits into bytes, the first bit the least significant of the first
    byte (Modbus Application Protocol, functions 1, 2 and 15)."""
    out = bytearray((len(bits) + 7) // 8)
    for i, b in enumerate(bits):
        if b:
            out[i // 8] |= 1 << (i % 8)
    return bytes(out)


def unpack_bits(data: bytes, count: int) -> list[int]:
    """The first *count* bits of *data* (inverse of :func:`pack_bits`)."""
    return [data[i // 8] >> (i % 8) & 1 for i in range(count)]


def gap_us(bits: int, baud: int) -> int:
    """The 3.5-character silence that ends a frame, whole µs up: 3.5
    characters of *bits* bits; 1750 µs above 19200 baud (Modbus over
    Serial Line, 2.5.1.1)."""
    if baud > 19200:
        return 1750
    return -(-7 * bits * 1_000_000 // (2 * baud))


#: read function -> (table, is bits, largest count) (Modbus Application
#: Protocol 6.1-6.4)
READ_FN = {1: ("coils", True, 2000), 2: ("inputs", True, 2000),
           3: ("holding", False, 125), 4: ("input_registers", False, 125)}
#: largest count of function 15 and 16 (Modbus Application Protocol 6.11, 6.12)
WRITE_MAX = {15: 1968, 16: 123}


class Tables(Protocol):
    """A slave's four tables by kind ("coils", "inputs", "input_registers",
    "holding"): how many addresses each has, and reading / writing a span."""

    def size(self, kind: str) -> int: ...

    def get(self, kind: str, start: int, count: int) -> list[int]: ...

    def put(self, kind: str, start: int, values: list[int]) -> None: ...


class ModbusException(Exception):
    """An exception response's code (Modbus Application Protocol, section 7)."""

    def __init__(self, code: int) -> None:
        super().__init__(code)
        self.code = code


def serve(fn: int, pdu: bytes, tables: Tables) -> bytes:
    """The response PDU (function and data, or the exception ``fn | 80``
    and its code) of the request *fn* with data *pdu* over *tables*:
    exception 1 for a function not in 1..6, 15, 16; 2 for a span past a
    table; 3 for a bad length, count or coil value.  A request that fails
    writes nothing."""
    try:
        return bytes((fn,)) + _run(fn, pdu, tables)
    except ModbusException as e:
        return bytes((fn | 0x80, e.code))


def _span(tables: Tables, kind: str, start: int, count: int, top: int) -> None:
    if not 1 <= count <= top:
        raise ModbusException(3)
    if start + count > tables.size(kind):
        raise ModbusException(2)


def _run(fn: int, pdu: bytes, tables: Tables) -> bytes:
    if fn in READ_FN:
        if len(pdu) != 4:
            raise ModbusException(3)
        kind, bits, top = READ_FN[fn]
        start, count = pdu[0] << 8 | pdu[1], pdu[2] << 8 | pdu[3]
        _span(tables, kind, start, count, top)
        vals = tables.get(kind, start, count)
        data = pack_bits(vals) if bits else b"".join(v.to_bytes(2, "big") for v in vals)
        return bytes((len(data),)) + data
    if fn in (5, 6):
        if len(pdu) != 4:
            raise ModbusException(3)
        start, value = pdu[0] << 8 | pdu[1], pdu[2] << 8 | pdu[3]
        kind = "coils" if fn == 5 else "holding"
        _span(tables, kind, start, 1, 1)
        if fn == 5 and value not in (0x0000, 0xFF00):
            raise ModbusException(3)
        tables.put(kind, start, [int(value == 0xFF00) if fn == 5 else value])
        return pdu
    if fn in WRITE_MAX:
        if len(pdu) < 5:
            raise ModbusException(3)
        start, count, n = pdu[0] << 8 | pdu[1], pdu[2] << 8 | pdu[3], pdu[4]
        bits = fn == 15
        if n != ((count + 7) // 8 if bits else 2 * count) or len(pdu) != 5 + n:
            raise ModbusException(3)
        kind = "coils" if bits else "holding"
        _span(tables, kind, start, count, WRITE_MAX[fn])
        vals = unpack_bits(pdu[5:], count) if bits else \
            [pdu[5 + 2 * i] << 8 | pdu[6 + 2 * i] for i in range(count)]
        tables.put(kind, start, vals)
        return pdu[:4]
    raise ModbusException(1)
