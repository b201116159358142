"""A bounded cursor over the bytes of a project file's sections.

Every read of :class:`Cursor` checks the length against the end of the
buffer first and raises a :class:`~plcrt.errors.PlcSyntaxError` that names
the file, the section being read and the byte offset (in the decompressed
stream, or in the file for the container header) when it does not fit.
Counts read from the file pass :meth:`Cursor.count`, which refuses a count
larger than the caller's bound, so no loop or allocation is driven by an
unchecked number.

It knows nothing of what the bytes mean (that is :mod:`.program`,
:mod:`.tables` and :mod:`.container`).
"""

from __future__ import annotations

import struct

from ..errors import PlcError, PlcSyntaxError, SourceLoc

__all__ = ["Cursor", "binary_error"]

_U2 = struct.Struct("<H")
_U4 = struct.Struct("<I")
_F4 = struct.Struct("<f")


def binary_error(file: str, section: str, offset: int, message: str,
                 kind: type[PlcError] = PlcSyntaxError, space: str = "decompressed project"
                 ) -> PlcError:
    """An error at byte ``offset`` (of ``space``: the file itself or the
    decompressed project) while reading ``section`` of the project ``file``.

    The location's column is the offset plus one (the first byte is column
    1) and its block is the section, so the message reads
    ``file:1:OFFSET+1: error: ... [section]`` and repeats the offset in hex.
    """
    return kind(f"{message} ({section}, byte 0x{offset:x} of the {space})",
                SourceLoc(file, 1, offset + 1, section))


class Cursor:
    """Reads little-endian numbers and counted strings from ``data``."""

    __slots__ = ("data", "pos", "file", "section", "encoding")

    def __init__(self, data: bytes, file: str, section: str, pos: int = 0,
                 encoding: str = "latin-1") -> None:
        self.data = data
        self.pos = pos
        self.file = file
        self.section = section
        self.encoding = encoding

    def error(self, message: str, at: int | None = None) -> PlcError:
        """A :class:`PlcSyntaxError` at ``at`` (default: the cursor)."""
        return binary_error(self.file, self.section, self.pos if at is None else at, message)

    def need(self, n: int) -> int:
        """The current position, after checking ``n`` more bytes exist."""
        pos = self.pos
        if n < 0 or pos + n > len(self.data):
            raise self.error(f"the {self.section} ends inside a field of {n} bytes "
                             f"({len(self.data) - pos} left)")
        return pos

    def take(self, n: int) -> bytes:
        pos = self.need(n)
        self.pos = pos + n
        return self.data[pos:pos + n]

    def skip(self, n: int) -> None:
        self.pos = self.need(n) + n

    def u1(self) -> int:
        pos = self.need(1)
        self.pos = pos + 1
        return self.data[pos]

    def u2(self) -> int:
        pos = self.need(2)
        self.pos = pos + 2
        return int(_U2.unpack_from(self.data, pos)[0])

    def u4(self) -> int:
        pos = self.need(4)
        self.pos = pos + 4
        return int(_U4.unpack_from(self.data, pos)[0])

    def f4(self) -> float:
        pos = self.need(4)
        self.pos = pos + 4
        return float(_F4.unpack_from(self.data, pos)[0])

    def expect(self, value: int, width: int, what: str) -> None:
        """Read a ``width``-byte number that must equal ``value``."""
        at = self.pos
        got = {1: self.u1, 2: self.u2, 4: self.u4}[width]()
        if got != value:
            raise self.error(f"{what}: expected 0x{value:x}, found 0x{got:x}", at)

    def count(self, width: int, limit: int, what: str) -> int:
        """A count of ``width`` bytes, refused above ``limit``."""
        at = self.pos
        n = {1: self.u1, 2: self.u2, 4: self.u4}[width]()
        if n > limit:
            raise self.error(f"{what}: {n} is more than the {limit} this reader accepts", at)
        return n

    def text(self, width: int = 2) -> str:
        """A string with a ``width``-byte length and no terminator, as
        Latin-1 (one character a byte: the project's code page is decided
        once for the whole text, by :mod:`plcrt.lang.encoding`)."""
        n = {1: self.u1, 2: self.u2}[width]()
        return self.take(n).decode(self.encoding, "replace")
