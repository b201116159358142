"""Modbus RTU frames: the CRC-16, the request and response PDUs of the
functions the Micro/WIN master library uses (1, 2, 3, 4 reads; 5, 6, 15,
16 writes), the bit packing, and the 3.5-character gap that ends a frame.

What it is: pure functions over bytes (Modbus over Serial Line
Specification V1.02, section 2.5.1 "RTU transmission mode" and 6 "CRC";
Modbus Application Protocol V1.1b3, section 6 "Function codes").  What it
is not: no timing of characters (:mod:`plcrt.engine.serial`), no memory.
"""

from __future__ import annotations

__all__ = ["crc16", "frame", "check_crc", "pack_bits", "unpack_bits", "gap_us",
           "READS", "WRITES", "EXCEPTIONS"]

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
