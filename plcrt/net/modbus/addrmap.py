"""The Modbus address map of a served PLC, as data: which S7-200 memory
each of the four Modbus tables reaches.

Two maps exist:

- the **library map** (:func:`library_map`), the one of the Modbus slave
  library MBUS_INIT / MBUS_SLAVE (S7-200 System Manual, "Modbus slave
  protocol", table "Modbus address mapping"; S7-200 SMART System Manual
  V2.3, 9.2 table 9-1)::

      00001 + n   coil n            Q bit n (Q0.0 ..)        n < MaxIQ
      10001 + n   discrete input n  I bit n (I0.0 ..)        n < MaxIQ
      30001 + n   input register n  AIW(2n)                  n < MaxAI
      40001 + n   holding register  V word at HoldStart+2n   n < MaxHold

  with the program's own MBUS_INIT parameters once it has run, else
  :data:`DEFAULTS` (HoldStart VB0, MaxHold 1000, MaxIQ 256, MaxAI 56),
  each bounded by the CPU's own image;
- a **custom map** (:func:`load_map`: a TOML file or a dict), ranges of
  each table onto any of I, Q, M, V, S (bits) or IW, QW, MW, VW, SW, AIW,
  AQW (words), so that a plant simulator writes its sensors into I (coils
  or holding registers mapped there) and reads Q::

      [[coils]]                 # 00001 ..: the client writes them
      start = 0                 # Modbus data address (00001 is 0)
      count = 16
      to = "I0.0"               # I0.0 .. I1.7: the plant's sensors
      [[discrete_inputs]]       # 10001 ..: the client reads them
      start = 0
      count = 16
      to = "Q0.0"
      [[holding_registers]]     # 40001 ..
      start = 0
      count = 4
      to = "AIW0"

What it is: the map (:class:`AddressMap`, a tuple of :class:`Region` per
table) and where a span of a table lies (:meth:`AddressMap.segments`).
What it is not: reading or writing memory (:mod:`.pdu`), the protocol.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from ...errors import PlcConfigError, PlcError
from ...lang.limits import read_capped
from ...safetext import excerpt, shown_value

__all__ = ["AddressMap", "DEFAULTS", "Region", "TABLES", "library_map", "load_map"]

#: the four tables by map key -> (kind, is bits, the client may write it)
TABLES = {"coils": ("coils", True, True), "discrete_inputs": ("inputs", True, False),
          "input_registers": ("input_registers", False, False),
          "holding_registers": ("holding", False, True)}
#: the library's parameters when the program has not run MBUS_INIT:
#: (MaxIQ bits, MaxAI words, MaxHold words, HoldStart V byte)
DEFAULTS = (256, 56, 1000, 0)
#: most regions one custom map holds, and the longest map file read
MAX_REGIONS = 256
MAX_MAP_BYTES = 1 << 20
#: areas a bit table may reach, areas a register table may reach (S7-200
#: letters; SM and the timers are not mapped: the CPU writes SM each scan)
BIT_AREAS = ("I", "Q", "M", "V", "S")
WORD_AREAS = {"IW": "I", "QW": "Q", "MW": "M", "VW": "V", "SW": "S", "AIW": "AI",
              "AQW": "AQ"}
_BIT = re.compile(r"(I|Q|M|V|S)(\d{1,5})\.([0-7])", re.IGNORECASE)
_WORD = re.compile(r"(AIW|AQW|IW|QW|MW|VW|SW)(\d{1,5})", re.IGNORECASE)


@dataclass(frozen=True)
class Region:
    """Modbus addresses ``first`` .. ``first + count - 1`` of one table
    lie in ``area`` from ``offset`` on: a bit number (byte * 8 + bit) for
    a bit table, a byte offset for a register table (one word per address)."""

    first: int
    count: int
    area: str
    offset: int

    @property
    def end(self) -> int:
        return self.first + self.count


@dataclass(frozen=True)
class AddressMap:
    """Regions per table kind ("coils", "inputs", "input_registers",
    "holding"), sorted by their first address, never overlapping."""

    regions: Mapping[str, tuple[Region, ...]]
    #: where the map came from, for messages and the docs' tables
    source: str = "library"

    def segments(self, kind: str, start: int, count: int
                 ) -> list[tuple[Region, int, int]] | None:
        """``[(region, index in region, n), ...]`` covering ``start`` ..
        ``start + count - 1`` of table ``kind`` in order; None when an
        address of the span is mapped to nothing (exception 2)."""
        out: list[tuple[Region, int, int]] = []
        at, end = start, start + count
        for r in self.regions.get(kind, ()):
            if r.end <= at:
                continue
            if r.first > at:
                return None
            n = min(end, r.end) - at
            out.append((r, at - r.first, n))
            at += n
            if at >= end:
                return out
        return None

    def size(self, kind: str) -> int:
        """One past the highest address of table ``kind`` (0: none)."""
        rs = self.regions.get(kind, ())
        return rs[-1].end if rs else 0


def library_map(areas: Mapping[str, Any], params: tuple[int, int, int, int] = DEFAULTS
                ) -> AddressMap:
    """The slave library's map for MaxIQ, MaxAI, MaxHold and HoldStart
    (a V byte offset), each bounded by the CPU's image (a CPU 226 has 128
    Q and I bits, 32 AIW; a SMART 256 and 56)."""
    max_iq, max_ai, max_hold, hold = params
    iq = min(max_iq, 8 * len(areas["Q"]), 8 * len(areas["I"]))
    ai = min(max_ai, len(areas["AI"]) // 2)
    hold_n = max(0, min(max_hold, (len(areas["V"]) - hold) // 2))
    regions = {"coils": (Region(0, iq, "Q", 0),) if iq else (),
               "inputs": (Region(0, iq, "I", 0),) if iq else (),
               "input_registers": (Region(0, ai, "AI", 0),) if ai else (),
               "holding": (Region(0, hold_n, "V", hold),) if hold_n else ()}
    return AddressMap(regions, "library")


# -- custom maps -------------------------------------------------------------
def _int(v: Any, where: str, lo: int, hi: int) -> int:
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise PlcConfigError(f"{where} must be a whole number {lo}..{hi}, not {shown_value(v)}")
    return v


def _target(text: Any, bits: bool, where: str) -> tuple[str, int]:
    """``("Q", bit number)`` of ``"Q0.0"``, or ``("AI", byte)`` of ``"AIW0"``."""
    if not isinstance(text, str) or len(text) > 20:
        raise PlcConfigError(f"{where}: an S7-200 address such as "
                             f"{'I0.0' if bits else 'VW100'}, not {shown_value(text)}")
    if bits:
        m = _BIT.fullmatch(text.strip())
        if m is None:
            raise PlcConfigError(f"{where}: {excerpt(text)} is not a bit address of "
                                 f"{', '.join(BIT_AREAS)} (I0.0, Q1.0, M2.0 ...)")
        return m.group(1).upper(), int(m.group(2)) * 8 + int(m.group(3))
    m = _WORD.fullmatch(text.strip())
    if m is None:
        raise PlcConfigError(f"{where}: {excerpt(text)} is not a word address "
                             f"({', '.join(WORD_AREAS)}: VW100, AIW0 ...)")
    return WORD_AREAS[m.group(1).upper()], int(m.group(2))


def _read(source: str | Path) -> tuple[dict[str, Any], str]:
    path = Path(source)
    try:
        text = read_capped(path, MAX_MAP_BYTES).decode("utf-8")
    except PlcError as e:
        raise PlcConfigError(f"{excerpt(str(path), 300)}: cannot read the Modbus map: "
                             f"{e.message}") from None
    except UnicodeDecodeError:
        raise PlcConfigError(f"{excerpt(str(path), 300)}: the Modbus map is not UTF-8 text "
                             f"(TOML)") from None
    try:
        return tomllib.loads(text), str(path)
    except tomllib.TOMLDecodeError as e:
        raise PlcConfigError(f"{excerpt(str(path), 300)}: {e}") from None


def load_map(source: Any, areas: Mapping[str, Any] | None = None) -> AddressMap:
    """A custom map from a TOML file (path) or a dict (see the module doc).

    ``areas`` (the PLC's memory areas) bounds every region by its area.

    Raises:
        PlcConfigError: an unknown key, a bad address or count, regions of
            one table that overlap, a region past its area, more than
            :data:`MAX_REGIONS` regions, a file that cannot be read.
    """
    if isinstance(source, AddressMap):
        return source
    if isinstance(source, (str, Path)):
        data, name = _read(source)
    elif isinstance(source, dict):
        data, name = source, "<modbus map>"
    else:
        raise PlcConfigError(f"a Modbus map is a TOML file or a dict, not {shown_value(source)}")
    unknown = set(data) - set(TABLES)
    if unknown:
        raise PlcConfigError(f"{excerpt(name, 300)}: unknown key(s) "
                             f"{excerpt(', '.join(sorted(map(str, unknown))))} (a Modbus map "
                             f"has {', '.join(TABLES)})")
    regions: dict[str, tuple[Region, ...]] = {}
    total = 0
    for key, (kind, bits, _) in TABLES.items():
        rows = data.get(key, [])
        if not isinstance(rows, list):
            raise PlcConfigError(f"{excerpt(name, 300)}: {key} is a list of tables ([[{key}]])")
        total += len(rows)
        if total > MAX_REGIONS:
            raise PlcConfigError(f"{excerpt(name, 300)}: at most {MAX_REGIONS} ranges")
        out = []
        for i, row in enumerate(rows):
            where = f"{excerpt(name, 300)}: {key}[{i}]"
            if not isinstance(row, dict) or set(row) - {"start", "count", "to"} \
                    or not {"start", "count", "to"} <= set(row):
                raise PlcConfigError(f"{where}: a range has start, count and to")
            first = _int(row["start"], f"{where}.start", 0, 65535)
            count = _int(row["count"], f"{where}.count", 1, 65536 - first)
            area, off = _target(row["to"], bits, f"{where}.to")
            if areas is not None:
                room = len(areas[area]) * (8 if bits else 1)
                need = off + (count if bits else 2 * count)
                if need > room:
                    raise PlcConfigError(f"{where}: {count} {'bits' if bits else 'words'} "
                                         f"from {excerpt(row['to'])} run past the end of "
                                         f"{area} on this CPU")
            out.append(Region(first, count, area, off))
        out.sort(key=lambda r: r.first)
        for a, b in zip(out, out[1:]):
            if b.first < a.end:
                raise PlcConfigError(f"{excerpt(name, 300)}: {key}: the ranges from "
                                     f"{a.first} and {b.first} overlap")
        regions[kind] = tuple(out)
    return AddressMap(regions, name)
