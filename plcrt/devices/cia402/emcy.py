"""Emergency messages of a simulated CiA 402 drive (CiA 301 §7.2.7).

What it is: the table from a drive's fault code 603Fh to the EMCY error code a
CANopen master sees, and the 8 bytes of one emergency message.  HCFA's alarm
numbers (§4.7, "故障编号 (603F)") are the 603Fh values; five of them (20640,
20704, 12828, 12827, 10256 = 50A0h, 50E0h, 321Ch, 321Bh, 2810h) already lie in
a CiA 301 error class (the high byte: 2xh current, 3xh voltage, 5xh device
hardware) and are sent as they are.  The others (4, 8, 17, 35, 62, 63, 70, 71,
83) lie in 00xxh, which CiA 301 reserves for "error reset or no error": a
master would read them as a reset (canopen's ``EmcyConsumer`` clears its
``active`` list on any code 00xxh).  They are sent in the manufacturer-specific
range, FF00h + the alarm number.  The CiA 402 codes the model raises where HCFA
numbers nothing (8611h following error, 7305h incremental sensor, 5441h E-stop)
are standard and sent as they are.  The manufacturer-specific bytes 3-4 carry
603Fh itself (little-endian), so the alarm number is never lost.

The error register byte is 1001h as the drive holds it (bit 0, generic error,
while a fault is present): CiA 301 makes only bit 0 mandatory, and the byte of
the EMCY equals the object a master reads.

What it is not: no CAN access; the port (``canopen_node.py``) sends the bytes.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from .reactions import FAULT_CODES

__all__ = ["EmcyRow", "EMCY_TABLE", "emcy_code", "emcy_frame", "RESET_CODE"]

RESET_CODE = 0x0000          # CiA 301 §7.2.7.3.1: error reset or no error
MANUFACTURER = 0xFF00        # CiA 301 Table 21: FFxxh device specific (manufacturer)

#: CiA 301 §7.2.7.3.1 Table 21 error classes by the code's high nibble/byte.
_CLASSES = ((0x2000, 0x2FFF, "current"), (0x3000, 0x3FFF, "voltage"),
            (0x4000, 0x4FFF, "temperature"), (0x5000, 0x5FFF, "device hardware"),
            (0x6000, 0x6FFF, "device software"), (0x7000, 0x7FFF, "additional modules"),
            (0x8000, 0x8FFF, "monitoring"), (0x9000, 0x9FFF, "external error"),
            (0xF000, 0xFEFF, "additional functions"), (0xFF00, 0xFFFF, "device specific"))


@dataclass(frozen=True, slots=True)
class EmcyRow:
    """One fault: its 603Fh value, the EMCY code, the CiA 301 class, the name."""

    code_603f: int
    emcy: int
    family: str
    name: str
    source: str


def emcy_code(code_603f: int) -> int:
    """The EMCY error code for 603Fh = *code_603f* (0 -> 0000h, error reset)."""
    if code_603f == 0:
        return RESET_CODE
    if code_603f >= 0x1000:
        return code_603f & 0xFFFF
    return MANUFACTURER | (code_603f & 0xFF)


def _family(code: int) -> str:
    return next(name for lo, hi, name in _CLASSES if lo <= code <= hi)


#: Every fault the model raises, as the master sees it (docs/cia402.md, "EMCY").
EMCY_TABLE: tuple[EmcyRow, ...] = tuple(
    EmcyRow(fc.code, emcy_code(fc.code), _family(emcy_code(fc.code)), fc.name,
            fc.section if fc.code >= 0x1000 else f"{fc.section}; CiA 301 Table 21 (FFxxh)")
    for fc in sorted(FAULT_CODES.values(), key=lambda f: emcy_code(f.code)))

_FRAME = struct.Struct("<HBH3x")


def emcy_frame(code_603f: int, register: int) -> bytes:
    """The 8 data bytes of the EMCY for 603Fh = *code_603f* and 1001h = *register*:
    error code, error register, 603Fh in the manufacturer-specific bytes."""
    return _FRAME.pack(emcy_code(code_603f), register & 0xFF, code_603f & 0xFFFF)
