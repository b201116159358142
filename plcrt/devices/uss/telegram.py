"""USS telegrams as the Micro/WIN USS library and a MicroMaster drive
exchange them: the frame, the block check character, the parameter part
(PKW) and the process data (PZD), the control and status word bits and the
speed scaling.

What it is: pure functions and tables over bytes (the USS protocol as the
S7-200 System Manual, "Using the USS protocol library to control a
MicroMaster drive", and the MicroMaster 4 operating instructions, "USS
communication", describe it)::

    STX  LGE  ADR  PKE IND PWE1 PWE2  STW/ZSW HSW/HIW  BCC
    02   0E   a    ---- 4 words ----  --- 2 words ---  XOR of all before

LGE counts the bytes after it (ADR, the 12 net data bytes and BCC: 14);
ADR holds the drive address 0..31 in bits 0..4; every word is sent high
byte first; BCC is the exclusive OR of every byte before it, STX
included.  The library sends a PKW of 4 words and a PZD of 2 words
(drive parameters P2012 = 2, P2013 = 4; docs/uss.md).  PKE holds the
task or response ID in bits 12..15 and the parameter number in bits
0..10; parameters 2000..3999 are sent as number - 2000 with bit 15 of IND
set (the MicroMaster 4 page bit); IND bits 0..7 are the index.

What it is not: no timing (plcrt.engine.serial), no library state
(:mod:`.library`), no drive (:mod:`.drive`).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

__all__ = ["STX", "LGE", "SIZE", "Telegram", "bcc", "encode", "decode", "param_code",
           "param_number", "TASK", "RESPONSE", "STW", "ZSW", "FULL_SCALE",
           "speed_word", "word_speed", "real_bits", "bits_real"]

STX = 0x02
#: bytes after LGE: ADR, PKW (8), PZD (4), BCC
LGE = 14
#: bytes of a whole telegram
SIZE = LGE + 2
#: setpoint and actual value 16#4000 = 100 % of the reference frequency
#: (MicroMaster 4, P2000; System Manual, USS_CTRL Speed_SP)
FULL_SCALE = 16384

#: task IDs (master -> drive, PKE bits 12..15)
TASK = {"none": 0, "read": 1, "write_word": 2, "write_dword": 3, "read_index": 6,
        "write_word_index": 7, "write_dword_index": 8, "write_dword_index_eeprom": 11,
        "write_word_index_eeprom": 12, "write_dword_eeprom": 13, "write_word_eeprom": 14}
#: response IDs (drive -> master)
RESPONSE = {"none": 0, "word": 1, "dword": 2, "word_index": 4, "dword_index": 5, "error": 7}

#: control word STW bits (MicroMaster 4, r0054)
STW = {"on": 0x0001, "no_off2": 0x0002, "no_off3": 0x0004, "pulse_enable": 0x0008,
       "rfg_enable": 0x0010, "rfg_start": 0x0020, "setpoint_enable": 0x0040,
       "fault_ack": 0x0080, "plc_control": 0x0400, "reverse": 0x0800}
#: status word ZSW bits (MicroMaster 4, r0052; 'no_*' bits are 1 when the
#: condition is absent)
ZSW = {"ready_on": 0x0001, "ready_run": 0x0002, "running": 0x0004, "fault": 0x0008,
       "no_off2": 0x0010, "no_off3": 0x0020, "inhibit": 0x0040, "warning": 0x0080,
       "at_setpoint": 0x0100, "pzd_control": 0x0200, "at_max": 0x0400,
       "no_current_limit": 0x0800, "no_motor_overload": 0x2000, "clockwise": 0x4000,
       "no_inverter_overload": 0x8000}


@dataclass(frozen=True, slots=True)
class Telegram:
    """One telegram's content: drive address, PKW words, PZD words."""

    address: int
    pke: int = 0
    ind: int = 0
    pwe: int = 0          #: PWE1 (high word) and PWE2 (low word) as one 32-bit value
    stw: int = 0          #: STW (master) or ZSW (drive)
    hsw: int = 0          #: HSW (master) or HIW (drive)

    @property
    def task(self) -> int:
        """The task or response ID (PKE bits 12..15)."""
        return self.pke >> 12

    @property
    def param(self) -> int:
        """The parameter number (PKE bits 0..10 and the IND page bit)."""
        return param_number(self.pke, self.ind)


def bcc(data: bytes) -> int:
    """The block check character: XOR of *data*."""
    x = 0
    for b in data:
        x ^= b
    return x


def encode(t: Telegram) -> bytes:
    """The 16 bytes of *t*."""
    body = bytes((STX, LGE, t.address & 0x1F)) + struct.pack(
        ">HHIHH", t.pke & 0xFFFF, t.ind & 0xFFFF, t.pwe & 0xFFFFFFFF, t.stw & 0xFFFF,
        t.hsw & 0xFFFF)
    return body + bytes((bcc(body),))


def decode(data: bytes) -> tuple[Telegram | None, str]:
    """(*data* as a telegram, '') or (None, what is wrong: 'stx', 'length',
    'lge' or 'bcc', in the order they are checked)."""
    if not data or data[0] != STX:
        return None, "stx"
    if len(data) < 2 or len(data) != data[1] + 2:
        return None, "length"
    if data[1] != LGE:
        return None, "lge"
    if bcc(data[:-1]) != data[-1]:
        return None, "bcc"
    pke, ind, pwe, stw, hsw = struct.unpack(">HHIHH", data[3:15])
    return Telegram(data[2] & 0x1F, pke, ind, pwe, stw, hsw), ""


def param_code(param: int, index: int) -> tuple[int, int]:
    """(PKE parameter bits, IND) of parameter *param*, index *index*."""
    page = 0x8000 if param >= 2000 else 0
    return (param - 2000 if page else param) & 0x7FF, page | (index & 0xFF)


def param_number(pke: int, ind: int) -> int:
    """The parameter a PKE and IND name (inverse of :func:`param_code`)."""
    return (pke & 0x7FF) + (2000 if ind & 0x8000 else 0)


def speed_word(percent: float, signed: bool) -> int:
    """The setpoint word of *percent* % (16384 = 100 %): two's complement
    when *signed* (MicroMaster 4), else the magnitude (MicroMaster 3, whose
    direction is the control word's reverse bit); at most 16#7FFF."""
    v = round(abs(percent) * FULL_SCALE / 100)
    v = min(v, 0x7FFF)
    return (-v & 0xFFFF) if signed and percent < 0 else v


def word_speed(word: int, signed: bool) -> float:
    """The percent a setpoint or actual value word stands for."""
    if signed and word & 0x8000:
        word -= 0x10000
    return word * 100 / FULL_SCALE


def real_bits(x: float) -> int:
    """The IEEE single bits of *x*."""
    return int.from_bytes(struct.pack(">f", x), "big")


def bits_real(v: int) -> float:
    """The REAL whose bits are *v*."""
    return struct.unpack(">f", (v & 0xFFFFFFFF).to_bytes(4, "big"))[0]
