"""Micro/WIN data block text: initial values of V memory.

The data block editor of Micro/WIN is free text, one address and one or more
values per line::

    VB0     255                // byte
    VW2     256, 700, 2        // consecutive words VW2, VW4, VW6
            800                // continues at VW8
    VD10    3.14               // REAL
    VD14    16#FFFF
    VD20    -5                 // DINT
    VB20    'ABC'              // ASCII bytes
    VB30    "string"           // length byte, then the characters
    V100.3  1                  // one bit

This module turns such text into a :class:`DataBlock`: a list of
:class:`DataEntry` records giving the big-endian bytes to store at each V
offset (S7-200 byte order: VW100 is VB100 high byte, VB101 low byte).  It
does not know the size of V memory of any CPU; :meth:`DataBlock.apply`
checks the entries against the buffer it is given.

Choices made where the format is not documented:

* values on a line are separated by commas (blanks alone are an error, so a
  forgotten comma is not silently read as two values); a trailing comma is
  allowed;
* a line that starts with a blank and has no address continues after the
  last value written, with the same width;
* ``VB`` takes 0..255, ``VW`` -32768..65535, ``VD`` -2**31..2**32-1 (the
  negative values stored as two's complement), a REAL only fits ``VD``;
* character literals are stored in the code page of the data block file
  (:mod:`plcrt.lang.codepage`; a character it cannot hold is an error);
  ``'ABC'`` stores its bytes and advances by their count, ``"ABC"`` stores a
  length byte first (at most 254 bytes); inside either a doubled quote
  stands for one;
* a later entry that overlaps an earlier one wins; each overlap is reported
  as a warning in :attr:`DataBlock.warnings`.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass, field

from ..errors import Diagnostic, DiagnosticSink, SourceLoc
from ..safetext import excerpt
from .codepage import DEFAULT_CODEPAGE, MAX_STRING, string_bytes
from .limits import too_many_digits
from .stlerrors import raise_collected

__all__ = ["DataBlock", "DataEntry", "parse_datablock"]


@dataclass(frozen=True, slots=True)
class DataEntry:
    """Bytes to store at V memory ``offset`` (or one bit, if ``bit`` is set).

    For a bit entry ``data`` is ``b"\\x00"`` or ``b"\\x01"``: the value of bit
    ``bit`` of byte ``offset``; the other bits of that byte are untouched.
    """

    offset: int
    data: bytes
    loc: SourceLoc
    bit: int | None = None

    @property
    def end(self) -> int:
        """The first V offset after this entry."""
        return self.offset + (1 if self.bit is not None else len(self.data))


@dataclass
class DataBlock:
    """The parsed data block: entries in file order (later ones win)."""

    entries: list[DataEntry] = field(default_factory=list)
    file: str = "<string>"
    #: non-fatal findings such as overlapping entries
    warnings: list[Diagnostic] = field(default_factory=list)

    @property
    def extent(self) -> int:
        """The number of V bytes needed to hold every entry (0 if empty)."""
        return max((e.end for e in self.entries), default=0)

    def apply(self, buf: bytearray) -> None:
        """Write all entries into ``buf`` (the V memory image, offset 0 = VB0).

        Nothing is written if any entry falls outside ``len(buf)``; a
        :class:`PlcSyntaxError` then names every such entry.
        """
        sink = DiagnosticSink()
        _check_extent(self.entries, len(buf), sink)
        raise_collected(sink)
        for entry in self.entries:
            if entry.bit is None:
                buf[entry.offset:entry.end] = entry.data
            elif entry.data[0]:
                buf[entry.offset] |= 1 << entry.bit
            else:
                buf[entry.offset] &= ~(1 << entry.bit) & 0xFF


# One lexical item of a data line.  Strings first, so that "//" and ","
# inside quotes stay part of the literal.
_ITEM = re.compile(r"""
      (?P<string>'(?:[^']|'')*'|"(?:[^"]|"")*")
    | (?P<comment>//.*)
    | (?P<comma>,)
    | (?P<blank>\s+)
    | (?P<open>['"].*)
    | (?P<word>[^\s,'"/]+(?:/(?!/)[^\s,'"/]*)*)
    | (?P<other>.)
""", re.X)

_ADDRESS = re.compile(r"V([BWD])([0-9]+)|V([0-9]+)\.([0-9]+)", re.I)
_OTHER_AREA = re.compile(r"(?:[IQMSLT]|SM|AI|AQ|AC|HC|C)[BWD]?[0-9]+(?:\.[0-9]+)?",
                         re.I)
_WIDTH = {"B": 1, "W": 2, "D": 4}
_NAME = {1: "VB", 2: "VW", 4: "VD"}
# Signed minimum and unsigned maximum per width: a word may be given as INT
# or as WORD, so both ranges are accepted and stored as two's complement.
_RANGE = {1: (0, 0xFF), 2: (-0x8000, 0xFFFF), 4: (-0x8000_0000, 0xFFFF_FFFF)}
_DECIMAL = re.compile(r"[+-]?[0-9]+")
_BASED = re.compile(r"(16|2)#([0-9A-Fa-f_]+)")
_REAL = re.compile(r"[+-]?(?:[0-9]+\.[0-9]*|\.[0-9]+|[0-9]+(?=[eE]))(?:[eE][+-]?[0-9]+)?")
_REAL_MAX = 3.4028234663852886e38


@dataclass
class _Cursor:
    """Where the next value goes: byte offset, width, or bit position."""

    offset: int
    width: int  # 1, 2 or 4; 0 for bit entries
    bit: int = 0


def _check_extent(entries: list[DataEntry], size: int, sink: DiagnosticSink) -> None:
    """An error for every entry past the end of a V memory of ``size`` bytes."""
    for entry in entries:
        if entry.end > size:
            sink.error(
                f"data block entry at V{entry.offset} needs "
                f"{entry.end - entry.offset} byte(s) but V memory has only "
                f"{size} bytes (VB0..VB{size - 1})",
                entry.loc, code="datablock")


def parse_datablock(text: str, file: str = "<string>", *,
                    v_bytes: int | None = None,
                    codepage: str = DEFAULT_CODEPAGE) -> DataBlock:
    """Parse data block text and return its :class:`DataBlock`.

    With ``v_bytes`` (the V memory size of the CPU) entries past its end
    are reported together with the syntax errors, so one run lists both.
    Character constants are stored in ``codepage`` (the file's code page).

    Raises :class:`PlcSyntaxError` listing every error (bad address, bad or
    out-of-range value, missing comma, entry past the end of V memory)
    with file:line:column.
    """
    if text.startswith("\ufeff"):
        text = text[1:]
    sink = DiagnosticSink()
    block = DataBlock(file=file)
    cursor: _Cursor | None = None
    for number, line in enumerate(text.splitlines(), start=1):
        cursor = _parse_line(line, number, file, cursor, block, sink, codepage)
    if v_bytes is not None:
        _check_extent(block.entries, v_bytes, sink)
    _note_overlaps(block)
    raise_collected(sink)
    return block


def _tokens(line: str) -> list[tuple[str, str, int]]:
    """(kind, text, 1-based column) of each item, blanks and comment dropped."""
    items: list[tuple[str, str, int]] = []
    for match in _ITEM.finditer(line):
        kind = match.lastgroup or "other"
        if kind == "comment":
            break
        if kind != "blank":
            items.append((kind, match.group(), match.start() + 1))
    return items


def _parse_line(line: str, number: int, file: str, cursor: _Cursor | None,
                block: DataBlock, sink: DiagnosticSink,
                codepage: str = DEFAULT_CODEPAGE) -> _Cursor | None:
    """Parse one line, append its entries, return the cursor after it."""
    items = _tokens(line)
    if not items:
        return cursor

    def loc(column: int) -> SourceLoc:
        return SourceLoc(file, number, column)

    kind, text, column = items[0]
    address = _ADDRESS.fullmatch(text) if kind == "word" else None
    if address is not None and too_many_digits(text):
        sink.error(f"address {excerpt(text)} is out of range", loc(column), code="datablock")
        return None
    if address is not None:
        if address.group(1):
            cursor = _Cursor(int(address.group(2)), _WIDTH[address.group(1).upper()])
        else:
            bit = int(address.group(4))
            if bit > 7:
                sink.error(f"bit number {bit} in {excerpt(text)} is not 0..7", loc(column),
                           code="datablock")
                return None
            cursor = _Cursor(int(address.group(3)), 0, bit)
        values = items[1:]
        if not values:
            sink.error(f"missing value after {excerpt(text)}", loc(column + len(text)),
                       code="datablock")
            return cursor
    elif line[:1].isspace() and cursor is not None:
        values = items  # a continuation line
    else:
        if kind == "word" and _OTHER_AREA.fullmatch(text):
            message = (f"{excerpt(text)}: the data block can only initialise V memory "
                       "(VB, VW, VD or V<byte>.<bit>)")
        elif cursor is None and line[:1].isspace():
            message = "values before the first address"
        else:
            message = (f"expected a V memory address (VB, VW, VD or "
                       f"V<byte>.<bit>), found {excerpt(text)!r}")
        sink.error(message, loc(column), code="datablock")
        return cursor

    expect_value = True
    for kind, text, column in values:
        if kind == "comma":
            if expect_value:
                sink.error("missing value before ','", loc(column), code="datablock")
            expect_value = True
            continue
        if not expect_value:
            sink.error(f"expected ',' before {excerpt(text)!r}", loc(column), code="datablock")
            return cursor
        expect_value = False
        if kind == "open":
            sink.error("unterminated string literal", loc(column), code="datablock")
            return cursor
        entries = _value_entries(text, kind, cursor, loc(column), sink, codepage)
        block.entries.extend(entries)
    return cursor


def _value_entries(text: str, kind: str, cursor: _Cursor, loc: SourceLoc,
                   sink: DiagnosticSink, codepage: str = DEFAULT_CODEPAGE) -> list[DataEntry]:
    """Entries for one value at ``cursor``; advances the cursor."""
    if kind == "string":
        return _string_entry(text, cursor, loc, sink, codepage)
    if cursor.width == 0:  # bit form
        value = None if too_many_digits(text) else _integer(text)
        if value not in (0, 1):
            sink.error(f"a bit takes 0 or 1, not {excerpt(text)!r}", loc, code="datablock")
            return []
        entry = DataEntry(cursor.offset, bytes((value,)), loc, cursor.bit)
        cursor.offset += (cursor.bit + 1) // 8
        cursor.bit = (cursor.bit + 1) % 8
        return [entry]

    width = cursor.width
    data: bytes
    if too_many_digits(text):
        sink.error(f"value {excerpt(text)} out of range for {_NAME[width]}", loc,
                   code="datablock")
        cursor.offset += width
        return []
    integer = _integer(text)
    if integer is not None:
        low, high = _RANGE[width]
        if not low <= integer <= high:
            sink.error(f"value {excerpt(text)} out of range for {_NAME[width]} "
                       f"({low}..{high})", loc, code="datablock")
            cursor.offset += width
            return []
        data = (integer & ((1 << (8 * width)) - 1)).to_bytes(width, "big")
    elif _REAL.fullmatch(text):
        real = float(text)
        if width != 4:
            sink.error(f"REAL value {excerpt(text)} needs a VD address, not "
                       f"{_NAME[width]}", loc, code="datablock")
            cursor.offset += width
            return []
        if abs(real) > _REAL_MAX:
            sink.error(f"REAL value {excerpt(text)} out of range", loc, code="datablock")
            cursor.offset += width
            return []
        data = struct.pack(">f", real)
    else:
        sink.error(f"bad constant {excerpt(text)!r}", loc, code="datablock")
        cursor.offset += width
        return []
    entry = DataEntry(cursor.offset, data, loc)
    cursor.offset += width
    return [entry]


def _integer(text: str) -> int | None:
    """The value of a decimal, 16# or 2# integer constant, else None."""
    if _DECIMAL.fullmatch(text):
        return int(text)
    based = _BASED.fullmatch(text)
    if based is None:
        return None
    digits = based.group(2).replace("_", "")
    try:
        return int(digits, int(based.group(1))) if digits else None
    except ValueError:  # e.g. 2#102
        return None


def _string_entry(text: str, cursor: _Cursor, loc: SourceLoc,
                  sink: DiagnosticSink, codepage: str) -> list[DataEntry]:
    quote = text[0]
    body = text[1:-1].replace(quote * 2, quote)
    if cursor.width == 0:
        sink.error("a character constant cannot initialise a bit", loc,
                   code="datablock")
        return []
    try:
        raw = string_bytes(body, codepage, None)
    except ValueError as e:
        sink.error(f"character constant {excerpt(text)}: {e}", loc, code="datablock")
        return []
    if quote == '"':
        if len(raw) > MAX_STRING:
            sink.error(f"string of {len(raw)} characters is longer than {MAX_STRING}",
                       loc, code="datablock")
            return []
        raw = bytes((len(raw),)) + raw
    entry = DataEntry(cursor.offset, raw, loc)
    cursor.offset += len(raw)
    return [entry] if raw else []


def _note_overlaps(block: DataBlock) -> None:
    """Add a warning for every entry that overwrites an earlier one."""
    owner: dict[int, DataEntry] = {}  # byte offset -> whole-byte entry
    bit_owner: dict[tuple[int, int], DataEntry] = {}
    bits_at: dict[int, list[int]] = {}
    for entry in block.entries:
        earlier: DataEntry | None = None
        if entry.bit is not None:
            earlier = bit_owner.get((entry.offset, entry.bit)) or owner.get(entry.offset)
            bit_owner[(entry.offset, entry.bit)] = entry
            bits_at.setdefault(entry.offset, []).append(entry.bit)
        else:
            for offset in range(entry.offset, entry.end):
                earlier = earlier or owner.get(offset)
                if earlier is None and offset in bits_at:
                    earlier = bit_owner[(offset, bits_at[offset][0])]
                owner[offset] = entry
        if earlier is not None:
            block.warnings.append(Diagnostic(
                "warning", f"overwrites V memory already set at {earlier.loc}",
                entry.loc, "datablock-overlap"))
