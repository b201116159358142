"""The data block of a project file: its pages, rows and comments.

Micro/WIN keeps the data block as the rows its editor shows, each row a
list of tokens (a V address, constants) and, apart, the comment of each
row.  :func:`read_data_block` writes them back as the data block text
Micro/WIN exports (``VB100<TAB>1, 2, 3<TAB>// comment``), which
:func:`plcrt.lang.datablock.parse_datablock` reads.

It reads nothing else; :mod:`.reader` finds the section.
"""

from __future__ import annotations

import re
import struct

from .codes import WIDTH_LETTER
from .stream import Cursor

__all__ = ["read_data_block", "read_data_page"]

_CONTROL = re.compile(r"[\x00-\x1f\x7f]")
MAX_PAGES = 256
MAX_ROWS = 65535
MAX_TOKENS = 4096


def read_data_block(c: Cursor) -> str:
    """The data block starting at the cursor, as export text (CR LF)."""
    c.section = "data block"
    c.expect(2, 1, "data block version")
    lines: list[str] = []
    for _ in range(c.count(2, MAX_PAGES, "number of data pages")):
        lines.extend(_page(c))
    return "".join(line + "\r\n" for line in lines)


def read_data_page(c: Cursor) -> list[str]:
    """The lines of the data page at the cursor (a SMART V3 project keeps
    each page apart, with no data-block header)."""
    return _page(c)


def _page(c: Cursor) -> list[str]:
    version = c.u1()
    c.expect(0x1388, 2, "data page header")
    c.skip(2 + 2 + 2 + (22 if version >= 8 else 18))
    layout = c.u2()
    c.text()                                   # the page's name
    c.skip(4)
    c.text()                                   # author
    if layout == 2:                            # Micro/WIN V4
        c.skip(c.u2())
    else:                                      # SMART: salt, hashes
        c.skip(86 if version >= 8 else 22)
    rows = [_row(c) for _ in range(c.count(2, MAX_ROWS, "number of data rows"))]
    comments: dict[int, str] = {}
    # version 2 (SMART V3): the count and each row's index are 4 bytes wide
    width = 4 if c.u1() == 2 else 2
    for _ in range(c.count(width, MAX_ROWS, "number of data comments")):
        index = c.u4() if width == 4 else c.u2()
        if index in (0xFFFF, 0xFFFFFFFF):
            continue
        c.skip(2 + 2 + 2 + 1)
        comments[index] = c.text()
    c.skip(c.u2())                             # trailing data of the page
    out = []
    for index, row in enumerate(rows):
        note = " ".join(comments.get(index, "").split())
        note = ("// " + note) if note else ""
        out.append("\t".join(x for x in (row, note) if x))
    return out


def _row(c: Cursor) -> str:
    c.skip(2)
    c.expect(2, 1, "data row")
    c.skip(1 + 4)
    c.expect(1, 1, "data row")
    c.skip(4 + 4)
    c.expect(0x101, 2, "data row")
    address, values = "", []
    for _ in range(c.count(2, MAX_TOKENS, "number of data tokens")):
        text, is_address = _token(c)
        if is_address and not address and not values:
            address = text
        elif text:
            values.append(text)
    if not address:
        return ", ".join(values)
    return address + ("\t" + ", ".join(values) if values else "")


def _token(c: Cursor) -> tuple[str, bool]:
    c.skip(2 + 1)
    c.expect(0x103, 2, "data token")
    c.skip(4 + 1 + 4)
    at = c.pos
    kind, sub = c.u2(), c.u2()
    if kind == 0x0001:
        return "", False                       # the comment, kept apart
    if kind == 0x0002:                         # a V address
        c.skip(3)
        offset = c.u4()
        width = sub & 0xFF
        letter = WIDTH_LETTER.get(width)
        if letter is None:
            raise c.error(f"data address width 0x{width:x} is not one this reader knows", at)
        return f"V{letter}{offset}", True
    if kind in (0x0601, 0x0801):               # 'text' and "text"
        c.skip(4)
        quote = "'" if kind == 0x0601 else '"'
        # on one line: a value cannot start a data line of its own
        return quote + _CONTROL.sub(" ", c.text(1)) + quote, False
    value = c.u4()
    c.skip(1)
    if kind == 0x0101:
        return str(value), False
    if kind == 0x0201:
        return f"{value - (1 << 32) if value >= 1 << 31 else value:+d}", False
    if kind == 0x0401:
        return f"16#{value:X}", False
    if kind == 0x0501:
        return f"2#{value:b}", False
    if kind == 0x0701:
        return repr(struct.unpack("<f", struct.pack("<I", value))[0]), False
    raise c.error(f"data token kind 0x{kind:x} is not one this reader knows", at)
