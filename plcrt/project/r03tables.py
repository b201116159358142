"""The user's symbol table of a Micro/WIN V3 project, and its check against
the ladder cells that name symbols.

The symbol tables follow the program block: a version byte (1), the
number of tables, then each table: 4 bytes (0x20000 for a user's table),
its name (1-byte length), the number of rows and the rows.  A row is its
index (2 bytes), a zero byte, its name (1-byte length) and 20 bytes: an
operand record as in a V4 project (the form 1, the pointer, the width,
the area, the class and group, the offset), 4 bytes of type, and 5 bytes
that are zero in every named row seen (an empty row has no name).

Only what was seen is read: a row whose last 5 bytes are set (a comment,
perhaps), another form, an address this reader does not write, and the
table is not read, with a note; the program does not need it (its code
holds absolute addresses).  What is read is checked: each ladder cell that
names a symbol must name one of the table whose address the network's
code uses, else the network is refused (docs/project-files.md).
"""

from __future__ import annotations

from ..errors import PlcError
from .codes import AREAS, CLASSES
from .r03 import V3Program
from .stream import Cursor
from .tables import address_text

__all__ = ["read_v3_symbols", "check_symbolic_cells"]

MAX_TABLES = 64
MAX_ROWS = 4096
#: the first 4 bytes of a user's symbol table
_USER_TABLE = 0x20000

Row = tuple[str, str, str]


def read_v3_symbols(stream: bytes, file: str, pos: int) -> tuple[list[Row], str]:
    """(the rows of the user's tables, ``""``) of the symbol tables at
    ``pos``, or ``([], why they are not read)``."""
    c = Cursor(stream, file, "symbol table", pos)
    try:
        return _tables(c), ""
    except PlcError as e:
        return [], f"the symbol table is not read: {e.message}"


def _tables(c: Cursor) -> list[Row]:
    c.expect(1, 1, "symbol table section")
    rows: list[Row] = []
    for _ in range(c.count(2, MAX_TABLES, "number of symbol tables")):
        if c.u4() != _USER_TABLE:        # the block names (and what follows)
            break
        c.take(c.u1())                   # the table's name
        for index in range(c.count(2, MAX_ROWS, "number of symbols")):
            row = _row(c, index)
            if row is not None:
                rows.append(row)
    return rows


def _row(c: Cursor, index: int) -> Row | None:
    at = c.pos
    if c.u2() != index:
        raise c.error(f"symbol {index + 1} is numbered otherwise", at)
    c.expect(0, 1, "symbol")
    name = c.take(c.u1()).decode("latin-1")
    at = c.pos
    record = c.take(20)
    if not name:
        return None                      # an empty row
    if record[0] != 1 or record[1] != 0 or any(record[15:20]):
        raise c.error(f"symbol {name!r}: a row of a layout this reader does not know", at)
    address = _address(record[2], record[3], record[4], int.from_bytes(record[7:11], "little"))
    if not address:
        raise c.error(f"symbol {name!r}: an address this reader does not know", at)
    return name, address, ""


def _address(width: int, area: int, klass: int, offset: int) -> str:
    return address_text(AREAS.get(area) if area else CLASSES.get(klass), width, offset)


def check_symbolic_cells(program: V3Program, rows: list[Row], c: Cursor) -> None:
    """Every symbol a network's cells name is in the table, at an address
    the network's code uses; else the network is refused."""
    table = {name: address for name, address, _ in rows}
    for where, at, names, used in program.symbolic:
        wrong = sorted(n for n in names if table.get(n) not in used)
        if wrong:
            raise c.error(f"{where}: the ladder cells name symbols the compiled code "
                          f"does not use at their addresses ({', '.join(wrong)})", at)
