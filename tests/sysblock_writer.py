"""Write the system block of a Micro/WIN V4 or SMART V2 project for the
tests of :mod:`plcrt.project.sysblock` (``project_writer.stream(...,
system=...)`` puts it before the program block).

The layout is the one the reader reads (docs/project-files.md, "System
block"); the values not given are those of Micro/WIN's default system
block.  A test helper, not part of plcrt.
"""

from __future__ import annotations

import struct

#: area letter -> (area code, data width code)
AREA_CODES = {"V": (0x10, 2), "M": (0x20, 2), "T": (0x40, 4), "C": (0x80, 4)}
#: Micro/WIN V4's default ranges (the corpus's CPU 224 projects hold them)
V4_DEFAULT = (("V", 0, 8192), ("V", 0, 0), ("T", 0, 32), ("T", 64, 32), ("C", 0, 256),
              ("M", 14, 18))
STARTUP = {"STOP": 0, "RUN": 1, "LAST": 2}


def u1(v: int) -> bytes: return struct.pack("<B", v)
def u2(v: int) -> bytes: return struct.pack("<H", v)
def u4(v: int) -> bytes: return struct.pack("<I", v & 0xFFFFFFFF)


def ranges_bytes(ranges) -> bytes:
    """Six ranges of (area letter, start, count) or raw (width, code, start,
    count) tuples; missing ones are empty V ranges."""
    rows = list(ranges) + [("V", 0, 0)] * (6 - len(ranges))
    out = b""
    for row in rows[:6]:
        if isinstance(row[0], str):
            code, width = AREA_CODES[row[0]]
            row = (width, code, row[1], row[2])
        out += u4(0) + b"".join(u4(x) for x in row)
    return out


def v4_block(ranges=V4_DEFAULT, *, addresses=(2, 2), baud=(0, 0), filters=(6,) * 6,
             pulse_catch: tuple[int, ...] = ()) -> bytes:
    """A Micro/WIN V4 system block (version 0x010e, 0x4c2 bytes)."""
    out = u2(0x010E) + b"\xa7\x8a\x2d\x00" * 2 + bytes([0, 1, 0, 0, 0, 1])
    out += u4(0) + bytes(128 * 4)                          # outputs in STOP
    out += u1(1) + ranges_bytes(ranges)
    out += u1(1) + b"".join(u4(addresses[p]) + u4(31) + u4(baud[p]) + u4(3) + u4(10)
                            for p in (0, 1))
    out += u1(1) + b"".join(u4(f) for f in filters)
    out += u1(2) + u4(1) * 32 + u4(64) + u4(20)
    out += u1(1) + b"".join(u4(int(b in pulse_catch)) for b in range(24))
    out += u1(1) + (u4(0) + u4(2) + u4(1) + u4(0)) * 7
    out += u1(1) + u4(10) + u1(1) + u4(0) + bytes(128) + u1(1) + u4(0) + u4(0) + u1(1) + u4(0)
    assert len(out) == 0x4C2
    return out


def smart_block(ranges=(), *, startup: str | int = "STOP", address: int = 2, baud: int = 1,
                cpu: tuple[int, int] = (0x00, 0x04), cpu2: tuple[int, int] | None = None,
                firmware: str = "V02.05.00_00.00.07.00", inputs: int = 24,
                filter_code: int = 7, pulse_catch: tuple[int, ...] = (),
                version: int = 0x060F) -> bytes:
    """A Micro/WIN SMART system block (version 0x060f of V2; 0x0613 or
    0x0615 of V3, with the longer password record) up to the digital
    inputs' configuration, then the outputs' (the reader stops before).
    ``startup`` a mode or a raw code; ``cpu2`` the CPU type's second copy
    where it differs."""
    v3 = version != 0x060F
    out = u2(version) + bytes(44) + u1(0) + u1(1)
    out += u1(2) + u4(address) + u4(baud) + bytes(8)
    out += u1(1) + ranges_bytes(ranges)
    out += u1(6 if v3 else 5) + u4(1) + u4(0) + bytes(34 if v3 else 22)   # privileges, password
    out += u1(1) + u4(10) + u1(1) + u1(0) + u1(STARTUP.get(startup, startup))
    out += u2(0) + u4(1) + u4(1)                           # missing hardware, errors allowed
    out += u1(3) + u4(0) + bytes([1, 2, 168, 192]) + bytes([0, 255, 255, 255]) + u4(0)
    out += bytes(64) + bytes(16)
    kind = bytes(cpu)
    out += u1(0) + bytes(12) + kind + u2(0x8000) + u1(7 if v3 else 6) + u2(1) + bytes(10) + u4(0) + bytes(16)
    out += (bytes(cpu2) if cpu2 else kind) + u2(0x8000) + u4(1) + u4(0)
    out += u1(len(firmware)) + firmware.encode()
    out += bytes(24) if v3 else b""                        # record version 7: 24 more bytes
    out += u2(0x0101) + u4(0)
    out += u1(2) + u4(inputs) + b"".join(
        u1(0) + u1(filter_code | (0x40 if b in pulse_catch else 0)) for b in range(inputs))
    out += u1(1) + u4(0) + u1(1) + u4(16) + bytes(16 * 4)   # outputs in STOP
    return out
