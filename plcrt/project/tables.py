"""The symbol tables of a project file.

The section right after the program block holds the user's symbol tables
and the table of block names ("POU Symbols", whose comments are the
blocks' titles).  Each entry is a name, an address or a constant, and a
comment; :func:`read_symbol_tables` turns them into the rows of the
tab-separated symbol table Micro/WIN exports (``name<TAB>address<TAB>comment``),
which :func:`plcrt.lang.symbols.parse_symbols` reads.

It reads nothing else; :mod:`.reader` finds the section.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .codes import AREAS, CLASSES, WIDTH_LETTER
from .stream import Cursor

__all__ = ["SymbolTables", "read_symbol_tables"]

MAX_TABLES = 256
MAX_ENTRIES = 65535
_USER_TABLE, _POU_TABLE = 0xBB8, 0xBB9
#: where a symbol's address lies, by the 16-bit location code
_LOCATIONS = {1: "HC", 2: "SM", 4: "S", 0x10: "AC"}


@dataclass
class SymbolTables:
    """The user's symbols (name, address, comment) in table order, and the
    block comments of the block-name table."""

    symbols: list[tuple[str, str, str]] = field(default_factory=list)
    block_comments: dict[str, str] = field(default_factory=dict)
    #: (name, why) of entries not exported: incomplete rows, unknown kinds
    skipped: list[tuple[str, str]] = field(default_factory=list)


def read_symbol_tables(c: Cursor) -> SymbolTables:
    """The symbol-table section starting at the cursor."""
    c.section = "symbol table"
    c.u1()                                           # section version
    out = SymbolTables()
    for _ in range(c.count(2, MAX_TABLES, "number of symbol tables")):
        version = c.u1()
        kind = c.u2()
        c.skip(2 + 2 + 2 + (22 if version >= 8 else 18))
        c.expect(2, 2, "symbol table header")
        c.text()                                     # the table's name
        c.skip(18 + 4)
        for _ in range(c.count(2, MAX_ENTRIES, "number of symbols")):
            name, address, comment = _entry(c)
            if kind == _POU_TABLE:
                out.block_comments[name] = comment
            elif kind == _USER_TABLE and name and address:
                out.symbols.append((name, address, comment))
            elif kind == _USER_TABLE and name:
                out.skipped.append((name, "no valid address or value"))
    return out


def _entry(c: Cursor) -> tuple[str, str, str]:
    c.skip(2)
    c.expect(2, 2, "symbol")
    name = c.text()
    c.expect(0, 1, "symbol")
    form, kind3, value_kind, width = c.u1(), c.u1(), c.u1(), c.u1()
    area = c.u1() if kind3 else 0
    location = 0
    if form == 1:
        location = c.u2()
        c.skip(1)
    value = c.u4()
    text = c.text(1) if value_kind == 8 else ""
    c.skip(1)
    if form == 1:
        c.skip(3)
    elif form == 0:
        c.skip(4)
    if form != 3:
        c.skip(4)
    if value_kind != 8:
        c.skip(1)
    comment = c.text()
    c.expect(2, 2, "symbol")
    c.text()                                         # the row as typed, if invalid
    c.skip(2)
    if form == 1 and value_kind == 0:
        return name, _address(area, location, width, value), comment
    if form == 0:
        return name, _constant(value_kind, value, text), comment
    return name, "", comment


def _address(area: int, location: int, width: int, value: int) -> str:
    prefix = AREAS.get(area) if area else (CLASSES.get(location) or _LOCATIONS.get(location))
    return address_text(prefix, width, value)


def address_text(prefix: str | None, width: int, value: int) -> str:
    """A symbol row's address as the export writes it (``I0.1``, ``VW10``,
    ``T37``) from its area letter, width code and offset (a bit address's
    offset counts bits); "" for an area or width not known."""
    if prefix is None:
        return ""
    if prefix in ("T", "C", "HC", "AC"):
        return f"{prefix}{value}"
    if width == 1:
        return f"{prefix}{value >> 3}.{value & 7}"
    letter = WIDTH_LETTER.get(width)
    return f"{prefix}{letter}{value}" if letter else ""


def _constant(kind: int, value: int, text: str) -> str:
    if kind == 1:
        return str(value)
    if kind == 2:
        return str(value - (1 << 32) if value >= 1 << 31 else value)
    if kind == 4:
        return f"16#{value:X}"
    if kind == 5:
        return f"2#{value:b}"
    if kind == 8:
        return f'"{text}"'
    return ""
