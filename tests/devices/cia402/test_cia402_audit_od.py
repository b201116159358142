"""The object-dictionary tables of the two drive manuals, transcribed as data
and compared with the models' data files (library/cia402/*.toml).

Each row below is one statement of the manual: an object's index,
subindex, access, type, range, default and unit as the manual prints them
(``None`` where the manual gives nothing).  A field where the data file
departs from the manual must be listed in :data:`DEPARTS` (or the row in
:data:`MOVED`) with a phrase of the decisions log of docs/cia402.md that
says why; a departure not listed, or a listed one that no longer departs,
fails.  docs/cia402.md ("Audit against the manuals") counts these rows.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import pytest

from plcrt.devices.cia402.od import ObjectDictionary

DOCS = Path(__file__).resolve().parents[3] / "docs" / "cia402.md"
U32MAX, I32 = 0xFFFFFFFF, (-2**31, 2**31 - 1)

#: the manual's type names (HCFA, "术语和缩写" and the tables) -> plcrt's
TYPES = {"USINT": "U8", "UINT": "U16", "UINT16": "U16", "Uint16": "U16", "U16": "U16",
         "UINT32": "U32", "UDINT": "U32", "U32": "U32", "INT": "I16", "I16": "I16",
         "DINT": "I32", "I32": "I32", "SINT": "I8", "I8": "I8"}
ACCESS = {"R": "ro", "RO": "ro", "R/W": "rw", "RW": "rw", "rw": "rw", "ro": "ro"}

Row = tuple[str, int, int, str, Optional[str], Optional[int], Optional[int], object,
            Optional[str]]

# (section, index, sub, access, type, min, max, default, unit)
HCFA_8_1: list[Row] = [
    ("§8.1", 0x1000, 0, "R", "UINT32", 0, 32767, 0x20192, None),
    ("§8.1", 0x1001, 0, "R", "USINT", 0, 255, 0, None),
    ("§8.1", 0x1008, 0, "R", None, None, None, None, None),
    ("§8.1", 0x1008, 1, "R", "UINT32", 0, U32MAX, 0xFFFF0000, None),
    ("§8.1", 0x1008, 2, "R", "UINT32", 0, U32MAX, 1, None),
    ("§8.1", 0x1008, 3, "R", "UINT32", 0, U32MAX, 1, None),
    ("§8.1", 0x1008, 4, "R", "UINT32", 0, U32MAX, 0, None),
    ("§8.1", 0x10F1, 0, "R/W", "UINT32", 0, U32MAX, 65536, None),
    ("§8.1", 0x10F1, 1, "R/W", "UINT32", 0, U32MAX, 0, None),
    *[("§8.1", m, 0, "R/W", "USINT", 0, 255, n, None)
      for m, n in ((0x1600, 3), (0x1601, 6), (0x1602, 5), (0x1603, 7), (0x1A00, 7),
                   (0x1A01, 0))],
    *[("§8.1", m, k, "R/W", "UINT32", 0, U32MAX, None, None)
      for m in (0x1600, 0x1601, 0x1602, 0x1603, 0x1A00, 0x1A01) for k in range(1, 9)],
    *[("§8.1", 0x1C00, k, "R", "USINT", 0, 255, v, None) for k, v in enumerate((4, 1, 2, 3, 4))],
    ("§8.1", 0x1C12, 1, "R/W", "UINT32", 0, 32767, 0x1600, None),
    ("§8.1", 0x1C13, 1, "R/W", "UINT32", 0, 32767, 0x1A00, None),
    ("§8.1", 0x1C32, 1, "R", "UINT", 0, 32767, None, None),
    ("§8.1", 0x1C33, 1, "R", "UINT", 0, 32767, None, None),
]

HCFA_8_2: list[Row] = [
    ("§8.2", 0x2000, 1, "R/W", "UINT16", 0, 1, 0, None),
    ("§8.2", 0x2000, 2, "R/W", "UINT16", 200, 51200, 50000, "pulse/rev"),
    ("§8.2", 0x2000, 3, "R/W", "UINT16", 50, 10000, 300, "ms"),
    ("§8.2", 0x2000, 4, "R/W", "UINT16", 0, 100, 50, "%"),
    ("§8.2", 0x2000, 6, "R/W", "UINT16", 0, 1, 0, None),
    ("§8.2", 0x2000, 7, "R/W", "UINT16", 0, 1, 0, None),
    ("§8.2", 0x2000, 8, "R/W", "UINT16", 0, 1, 0, None),
    ("§8.2", 0x2000, 9, "R/W", "UINT16", 0, 1, 0, None),
    ("§8.2", 0x2000, 11, "R/W", "UINT16", 0, 100, 60, "50 us"),      # note "1 代表 50 μs"
    ("§8.2", 0x2000, 13, "R/W", "UINT16", 0, 65535, 4000, "50 us"),  # note "1 代表 50 μs"
    ("§8.2", 0x2000, 14, "R/W", "UINT16", 0, 1, 1, None),
    ("§8.2", 0x2000, 15, "R/W", "UINT16", 0, 1, 1, None),
    ("§8.2", 0x2000, 17, "R/W", "UINT16", 0, 100, 60, "%"),
    ("§8.2", 0x2000, 20, "R/W", "UINT16", 0, 65535, 0xC83, None),
    ("§8.2", 0x2000, 21, "RW", "UINT16", 200, 65535, 1000, None),
    ("§8.2", 0x2000, 24, "RW", "UINT16", 0, 32768, None, None),
    ("§8.2", 0x2001, 1, "RW", "UINT16", 1, 6, 2, None),
    ("§8.2", 0x2001, 10, "R/W", "UINT16", 20, 100, 30, "0.1 A"),
    ("§8.2", 0x2002, 1, "R/W", "UINT16", 0, 65535, 4, None),
    ("§8.2", 0x2002, 2, "R/W", "UINT16", 0, 65535, 2, None),
    ("§8.2", 0x2002, 3, "R/W", "UINT16", 0, 65535, 1, None),
    ("§8.2", 0x2002, 4, "R/W", "UINT16", 0, 65535, 8, None),
    ("§8.2", 0x2000, 5, "R/W", "UINT16", 0, 65535, 16, None),        # DI5, printed at 2000h
    ("§8.2", 0x2002, 10, "R/W", "UINT16", 0, 65535, 0, None),
    *[("§8.2", 0x2002, k, "R/W", "UINT16", 0, 65535, 3, "us") for k in range(15, 20)],
    ("§8.2", 0x2002, 29, "R/W", "UINT16", 1, 4, 1, None),
    ("§8.2", 0x2002, 30, "R/W", "UINT16", 1, 4, 2, None),
    ("§8.2", 0x2002, 31, "R/W", "UINT16", 1, 4, 3, None),
    ("§8.2", 0x2002, 32, "R/W", "UINT16", 1, 4, 3, None),
    ("§8.2", 0x2003, 1, "R/W", "UINT16", 0, 10000, 1000, None),
    ("§8.2", 0x2003, 2, "R/W", "UINT16", 0, 10000, 1000, None),
    ("§8.2", 0x2003, 3, "R/W", "UINT16", 0, 1, 1, None),
    ("§8.2", 0x2003, 4, "R/W", "UINT16", 0, 25600, 12000, None),
    ("§8.2", 0x2003, 7, "R/W", "UINT16", 0, 65535, 0, None),
    ("§8.2", 0x2003, 8, "R/W", "UINT16", 100, 65535, 200, "pulse"),
    ("§8.2", 0x2003, 9, "R/W", "UINT16", 100, 1500, 300, "0.01 A"),
    ("§8.2", 0x2003, 10, "R/W", "UINT16", 100, 65535, 1000, "50 us"),
    ("§8.2", 0x2003, 11, "R/W", "UINT16", 10, 10000, 1000, "50 us"),
    ("§8.2", 0x2003, 13, "R/W", "UINT16", 0, 100, 50, "%"),
    ("§8.2", 0x2004, 3, "R/W", "UINT16", 0, 10000, 100, "ms"),
    ("§8.2", 0x2004, 4, "R/W", "UINT16", 10, 10000, 100, "ms"),
    ("§8.2", 0x2004, 5, "R/W", "UINT16", 0, 100, 1, None),
    # P18 display parameters: RO UINT16; P18.04-06 print their unit in the default column
    *[("§8.2", 0x2012, k, "RO", "UINT16", None, None, None, None)
      for k in (1, 3, 9, 21, 29, 30, 31, 35, 36, 37, 38, 39)],
    ("§8.2", 0x2012, 4, "RO", "UINT16", None, None, None, "0.01 A"),
    ("§8.2", 0x2012, 5, "RO", "UINT16", None, None, None, "0.01 A"),
    ("§8.2", 0x2012, 6, "RO", "UINT16", None, None, None, "0.1 A"),
]

#: §5.1's unit column where it names a unit (1 / 0 / blank are no units)
HCFA_5_1_UNITS = {
    (0x2000, 3): "ms", (0x2000, 11): "%", (0x2000, 13): "50 us",
    (0x2000, 17): "%", (0x2001, 10): "0.1 A", (0x2002, 21): "50 us", (0x2002, 22): "50 us",
    (0x2002, 23): "50 us", (0x2002, 24): "50 us", (0x2002, 25): "50 us", (0x2003, 4): "us",
    (0x2003, 8): "pulse", (0x2003, 9): "0.01 A", (0x2003, 10): "50 us", (0x2003, 11): "50 us",
    (0x2003, 13): "%", (0x2004, 3): "ms", (0x2004, 4): "ms", (0x2012, 1): "rpm",
    (0x2012, 3): "rpm", (0x2012, 4): "0.01 A", (0x2012, 5): "0.01 A", (0x2012, 6): "0.1 V",
    (0x2012, 38): "ns",
}

HCFA_8_3: list[Row] = [
    ("§8.3", 0x603F, 0, "R", "UINT", 0, 65535, 0, None),
    ("§8.3", 0x6040, 0, "R/W", "UINT", 0, 65535, 0, None),
    ("§8.3", 0x6041, 0, "R", "UINT", 0, 65535, 0, None),
    ("§8.3", 0x605A, 0, "R/W", "INT", 0, 65535, 2, None),
    ("§8.3", 0x6060, 0, "R/W", "INT", 0, 255, 8, None),
    ("§8.3", 0x6061, 0, "R", "INT", 0, 255, 8, None),
    ("§8.3", 0x6062, 0, "R", "DINT", *I32, 0, "P"),
    ("§8.3", 0x6064, 0, "R", "DINT", *I32, 0, "P"),
    ("§8.3", 0x606B, 0, "R", "DINT", *I32, 0, "P/s"),
    ("§8.3", 0x606C, 0, "R", "DINT", *I32, 0, "P/s"),
    ("§8.3", 0x607A, 0, "R/W", "DINT", *I32, 0, "P"),
    ("§8.3", 0x60FF, 0, "R/W", "DINT", *I32, 0, "P/s"),
    ("§8.3", 0x607C, 0, "R/W", "DINT", *I32, 0, "P"),
    ("§8.3", 0x6080, 0, "R/W", "UDINT", 0, U32MAX, 833333, None),
    ("§8.3", 0x6081, 0, "R/W", "UDINT", 0, U32MAX, 0, None),
    ("§8.3", 0x6083, 0, "R/W", "UDINT", 0, U32MAX, 0, "P/s2"),
    ("§8.3", 0x6084, 0, "R/W", "UDINT", 0, U32MAX, 0, "P/s2"),
    ("§8.3", 0x6085, 0, "R/W", "UDINT", 0, U32MAX, 0, None),
    ("§8.3", 0x6098, 0, "R/W", "INT", 0, 100, 1, None),
    ("§8.3", 0x6099, 0, "R/W", "UDINT", 0, U32MAX, 83333, "P/s"),
    ("§8.3", 0x6099, 1, "R/W", "UDINT", 0, U32MAX, 41666, "P/s"),
    ("§8.3", 0x609A, 0, "R/W", "UDINT", 0, U32MAX, 833333, "P/s2"),
    ("§8.3", 0x60B8, 0, "R/W", "Uint16", 0, 65535, 0, None),
    ("§8.3", 0x60B9, 0, "RO", "Uint16", None, None, 0, None),
    *[("§8.3", i, 0, "RO", "DINT", None, None, None, "P")       # "指令单位": command units
      for i in (0x60BA, 0x60BB, 0x60BC, 0x60BD)],
    ("§8.3", 0x60FD, 0, "RO", "UDINT", 0, U32MAX, 0, None),
    ("§8.3", 0x60FE, 1, "R/W", "DINT", *I32, 1, None),
    ("§8.3", 0x60FE, 2, "R/W", "DINT", *I32, 0, None),
    ("§8.3", 0x6502, 0, "RO", "UDINT", 0, U32MAX, 165, None),
]

# The mode tables: (section, index, sub, access, pdo direction or None, type or None)
Mode = tuple[str, int, int, str, Optional[str], Optional[str]]
_RX, _TX = "rx", "tx"
HCFA_7: list[Mode] = [
    # §7.5.1 position control, common objects
    *[("§7.5.1", i, 0, "rw", _RX, None) for i in
      (0x6040, 0x607A, 0x6080, 0x6081, 0x6083, 0x6084, 0x60C5, 0x60C6, 0x6065, 0x6066)],
    *[("§7.5.1", i, 0, "ro", _TX, None) for i in (0x6041, 0x6062, 0x6063, 0x6064, 0x606C)],
    # §7.6.1 velocity control, common objects
    *[("§7.6.1", i, 0, "rw", _RX, None) for i in (0x6040, 0x6080, 0x60B1, 0x60FF)],
    *[("§7.6.1", i, 0, "ro", _TX, None) for i in (0x6041, 0x6063, 0x6064)],
    # §7.5.2 CSP: basic (with their PDO direction) and extended objects
    ("§7.5.2", 0x6040, 0, "RW", _RX, "U16"), ("§7.5.2", 0x607A, 0, "RW", _RX, "I32"),
    ("§7.5.2", 0x6041, 0, "RO", _TX, "U16"), ("§7.5.2", 0x603F, 0, "RO", _TX, "U16"),
    ("§7.5.2", 0x6064, 0, "RO", _TX, "I32"), ("§7.5.2", 0x6061, 0, "RO", _TX, "I8"),
    ("§7.5.2", 0x60B9, 0, "RO", _TX, "U32"), ("§7.5.2", 0x60BA, 0, "RO", _TX, "U32"),
    ("§7.5.2", 0x6060, 0, "RW", None, "I8"), ("§7.5.2", 0x6062, 0, "RO", None, "I32"),
    ("§7.5.2", 0x606B, 0, "RO", None, "I32"), ("§7.5.2", 0x605A, 0, "RW", None, "I16"),
    ("§7.5.2", 0x6085, 0, "RW", None, "U32"),
    # §7.5.3 PP
    ("§7.5.3", 0x6040, 0, "RW", _RX, "U16"), ("§7.5.3", 0x607A, 0, "RW", _RX, "I32"),
    ("§7.5.3", 0x6081, 0, "RW", _RX, "U32"), ("§7.5.3", 0x6083, 0, "RW", _RX, "I32"),
    ("§7.5.3", 0x6084, 0, "RW", _RX, "I32"), ("§7.5.3", 0x6041, 0, "RO", _TX, "U16"),
    ("§7.5.3", 0x603F, 0, "RO", _TX, "U16"), ("§7.5.3", 0x6064, 0, "RO", _TX, "I32"),
    ("§7.5.3", 0x606C, 0, "RO", _TX, "I32"), ("§7.5.3", 0x6060, 0, "RW", None, "I8"),
    ("§7.5.3", 0x6061, 0, "RO", None, "I8"), ("§7.5.3", 0x6062, 0, "RO", None, "I32"),
    ("§7.5.3", 0x606B, 0, "RO", None, "I32"), ("§7.5.3", 0x605A, 0, "RW", None, "I16"),
    ("§7.5.3", 0x6085, 0, "RW", None, "U32"),
    # §7.5.4 HM
    ("§7.5.4", 0x6040, 0, "RW", _RX, "U16"), ("§7.5.4", 0x6098, 0, "RW", _RX, "I8"),
    ("§7.5.4", 0x6099, 1, "RW", _RX, "U32"), ("§7.5.4", 0x6099, 2, "RW", _RX, "U32"),
    ("§7.5.4", 0x609A, 0, "RW", _RX, "U32"), ("§7.5.4", 0x607C, 0, "RW", _RX, "I32"),
    ("§7.5.4", 0x6041, 0, "RO", _TX, "U16"), ("§7.5.4", 0x603F, 0, "RO", _TX, "U16"),
    ("§7.5.4", 0x6064, 0, "RO", _TX, "I32"), ("§7.5.4", 0x606C, 0, "RO", _TX, "I32"),
    # §7.6.2 PV
    ("§7.6.2", 0x6040, 0, "RW", _RX, "U16"), ("§7.6.2", 0x60FF, 0, "RW", _RX, "I32"),
    ("§7.6.2", 0x6083, 0, "RW", _RX, "I32"), ("§7.6.2", 0x6041, 0, "RO", _TX, "U16"),
    ("§7.6.2", 0x603F, 0, "RO", _TX, "U16"), ("§7.6.2", 0x6064, 0, "RO", _TX, "I32"),
    ("§7.6.2", 0x606C, 0, "RO", _TX, "I32"), ("§7.6.2", 0x60F4, 0, "RO", _TX, "I32"),
    ("§7.6.2", 0x6084, 0, "RW", None, "U32"), ("§7.6.2", 0x6085, 0, "RW", None, "U32"),
]

#: Kinco §2.1: object -> the values the note gives (None: "user set")
KINCO_2_1: dict[tuple[int, int], Optional[tuple[int, ...]]] = {
    (0x607C, 0): None, (0x6098, 0): None, (0x6099, 2): None, (0x6099, 3): (0, 1, 2),
    (0x609A, 0): None, (0x6099, 1): None, (0x6099, 4): None, (0x6099, 5): (0, 1),
    (0x6099, 6): (0, 1, 2), (0x6060, 0): (6,), (0x6040, 0): (0x0F, 0x1F),
}

#: rows the data file keeps at another place (manual key -> plcrt key), each
#: with the phrase of the decisions log that says why
MOVED: dict[tuple[int, int], tuple[tuple[int, int], str]] = {
    **{(0x1008, k): ((0x1018, k), "Vendor ID, product code, revision, serial listed as "
                     "1008h:01–04") for k in range(1, 5)},
    (0x10F1, 0): ((0x10F1, 1), "10F1h:00/01 as local error reaction / sync error limit"),
    (0x10F1, 1): ((0x10F1, 2), "10F1h:00/01 as local error reaction / sync error limit"),
    (0x6099, 0): ((0x6099, 1), "homing speeds at 6099h:00 / :01"),
    (0x6099, 1): ((0x6099, 2), "homing speeds at 6099h:00 / :01"),
    (0x2000, 5): ((0x2002, 5), "P02.05 at 2000h:05"),
    **{(0x2002, k): ((0x2002, k + 6), "P02.21–25 in 50 µs (§8.2 prints their subindexes as "
                     "15–19") for k in range(15, 20)},
}

_CHAPTERS = "the chapters disagree"
#: (section, index, sub, field) -> phrase of the decisions log
DEPARTS: dict[tuple[str, int, int, str], str] = {
    ("§8.1", 0x1000, 0, "range"): "1000h range 0–32767 below its own default",
    **{("§8.1", m, 0, "range"): '"8 objects, 32 bytes"'
       for m in (0x1600, 0x1601, 0x1602, 0x1603, 0x1A00, 0x1A01)},
    **{("§8.1", m, 1, f): "1C12h/1C13h as UINT32, range 0–32767"
       for m in (0x1C12, 0x1C13) for f in ("type", "range")},
    **{("§8.1", m, 1, f): '1C32h/1C33h "略"'
       for m in (0x1C32, 0x1C33) for f in ("access", "range")},
    ("§8.2", 0x2000, 11, "unit"): 'P00.11 unit "1 = 50 µs"',
    ("§8.2", 0x2000, 24, "range"): _CHAPTERS,
    ("§8.2", 0x2001, 1, "default"): _CHAPTERS,
    **{("§8.2", 0x2002, k, "unit"): _CHAPTERS for k in range(15, 20)},
    ("§8.2", 0x2002, 32, "range"): _CHAPTERS, ("§8.2", 0x2002, 32, "default"): _CHAPTERS,
    ("§8.2", 0x2003, 4, "range"): _CHAPTERS,
    ("§8.2", 0x2003, 8, "default"): _CHAPTERS, ("§8.2", 0x2003, 10, "default"): _CHAPTERS,
    ("§8.2", 0x2012, 6, "unit"): "P18.06 unit 0.1 A",
    ("§8.3", 0x605A, 0, "range"): '605Ah "INT 0–65535"',
    ("§8.3", 0x6060, 0, "type"): '6060h "INT 0–255" and "9: CSV"',
    ("§8.3", 0x6060, 0, "range"): '6060h "INT 0–255" and "9: CSV"',
    ("§8.3", 0x6061, 0, "type"): '6061h INT, 6098h "INT 0–100"',
    ("§8.3", 0x6061, 0, "range"): '6061h INT, 6098h "INT 0–100"',
    ("§8.3", 0x6098, 0, "type"): '6061h INT, 6098h "INT 0–100"',
    ("§8.3", 0x60FE, 1, "type"): "60FEh:01/02 DINT, no :00",
    ("§8.3", 0x60FE, 1, "range"): "60FEh:01/02 DINT, no :00",
    ("§8.3", 0x60FE, 2, "type"): "60FEh:01/02 DINT, no :00",
    ("§8.3", 0x60FE, 2, "range"): "60FEh:01/02 DINT, no :00",
    ("§7.5.2", 0x60B9, 0, "type"): "60B9h U32, 60BAh U32",
    ("§7.5.2", 0x60BA, 0, "type"): "60B9h U32, 60BAh U32",
    **{(s, i, 0, "type"): "6083h/6084h I32 in the mode tables"
       for s, i in (("§7.5.3", 0x6083), ("§7.5.3", 0x6084), ("§7.6.2", 0x6083))},
}


def unit(text: Optional[str]) -> str:
    """A unit as the comparison sees it: case, spaces, µ/μ and ^ ignored."""
    t = (text or "").lower().replace(" ", "").replace("μ", "u").replace("µ", "u")
    return t.replace("^", "").replace("pulse/rev", "p/rev")


def departures(od: ObjectDictionary, rows: list[Row]) -> dict[tuple[str, int, int, str], str]:
    """(section, index, sub, field) -> "manual / plcrt" for each field of
    *rows* where the data file differs from the manual."""
    out = {}
    for section, index, sub, access, dtype, lo, hi, default, u in rows:
        key = MOVED.get((index, sub), ((index, sub), ""))[0]
        e = od.entry(*key)
        got = {"access": e.access, "type": e.dtype, "range": (e.low, e.high),
               "default": e.default, "unit": unit(e.unit)}
        want = {"access": ACCESS[access], "type": TYPES.get(dtype or "", None),
                "range": (lo, hi) if lo is not None else None, "default": default,
                "unit": unit(u) if u else None}
        for field, value in want.items():
            if value is not None and got[field] != value:
                out[(section, index, sub, field)] = f"{value} / {got[field]}"
    return out


def decisions_log() -> str:
    text = DOCS.read_text(encoding="utf-8")
    return text.split("## Decisions log", 1)[1]


@pytest.mark.parametrize("rows", [HCFA_8_1, HCFA_8_2, HCFA_8_3],
                         ids=["8.1 communication", "8.2 vendor", "8.3 profile"])
def test_hcfa_od_tables_are_the_manuals_but_for_logged_decisions(rows: list[Row]) -> None:
    """HCFA §8.1 / §8.2 / §8.3: each row's access, type, range, default and
    unit as printed, unless the decisions log says why not."""
    od = ObjectDictionary.load("hcfa-am0520b")
    found = departures(od, rows)
    section = rows[0][0]
    listed = {k for k in DEPARTS if k[0] == section}
    assert sorted(set(found) - listed) == [], {k: found[k] for k in set(found) - listed}
    assert sorted(listed - set(found)) == []           # a listed departure still departs


def test_every_departure_and_move_names_a_logged_decision() -> None:
    """Each departure of :data:`DEPARTS` and :data:`MOVED` names a phrase of
    docs/cia402.md's decisions log."""
    log = decisions_log()
    phrases = set(DEPARTS.values()) | {why for _, why in MOVED.values()}
    assert sorted(p for p in phrases if p not in log) == []


def test_hcfa_5_1_units() -> None:
    """HCFA §5.1, the unit column (最小单位) where it names a unit; P00.11 is
    "1%" here (§8.2's "1 = 50 µs" is the copy error the log names)."""
    od = ObjectDictionary.load("hcfa-am0520b")
    wrong = {k: (u, od.entry(*k).unit) for k, u in HCFA_5_1_UNITS.items()
             if unit(od.entry(*k).unit) != unit(u)}
    assert wrong == {}


@pytest.mark.parametrize("row", HCFA_7, ids=lambda r: f"{r[0]} {r[1]:04X}h:{r[2]}")
def test_hcfa_mode_tables_access_pdo_and_type(row: Mode) -> None:
    """HCFA §7.5.1–§7.6.2: each object of a mode's table has the access and
    PDO direction printed (an object of the basic tables is mappable in the
    direction given; the extended ones need not be) and its type, unless the
    decisions log says why not."""
    section, index, sub, access, pdo, dtype = row
    e = ObjectDictionary.load("hcfa-am0520b").entry(index, sub)
    assert e.access == ACCESS[access]
    if pdo is not None:
        assert e.pdo == pdo
    if dtype is not None:
        decided = DEPARTS.get((section, index, sub, "type"))
        assert (e.dtype == dtype) is (decided is None), (e.dtype, decided)


def test_kinco_2_1_objects_are_writable_with_the_notes_values() -> None:
    """Kinco §2.1: every object of the table is a writable object of the
    Kinco model and takes the values the note lists (6099h:03 0–2, :05 0–1,
    :06 0–2, 6060h = 6, 6040h 0x0F / 0x1F)."""
    od = ObjectDictionary.load("kinco-servo")
    for (index, sub), values in KINCO_2_1.items():
        e = od.entry(index, sub)
        assert e.access == "rw", e.label
        for v in values or ():
            assert e.low <= v <= e.high and (not e.values or v in e.values), (e.label, v)
    for sub, top in ((3, 2), (5, 1), (6, 2)):
        assert od.entry(0x6099, sub).high == top


def test_the_audit_counts_of_the_od_tables() -> None:
    """docs/cia402.md counts one statement per transcribed row of the
    manual, and the fields that depart by a logged decision."""
    lines_8_1 = {(r[1], min(r[2], 1)) if 0x1600 <= r[1] <= 0x1A01 else (r[1], r[2])
                 for r in HCFA_8_1}                 # a map's "01~08" row is one line
    counts = (len(lines_8_1), len(HCFA_8_2), len(HCFA_8_3), len(HCFA_7), len(HCFA_5_1_UNITS),
              len(KINCO_2_1))
    text = DOCS.read_text(encoding="utf-8")
    assert "OD rows: §8.1 {}, §8.2 {}, §8.3 {}, §7.5–§7.6 mode tables {}, §5.1 units {}, " \
           "Kinco §2.1 {})".format(*counts) in text
    assert f"{len(DEPARTS) + len(MOVED)} fields depart from the print" in text
