"""The members of a Micro/WIN SMART V3 project: program blocks, data
pages, symbol tables, the device.

A SMART V3 project keeps each block (POU) in a member of its own, in the
layout of a SMART V2 block with these differences (docs/project-files.md,
"SMART V3 projects"): the block layout word is 0x82, 0x83 or 0x84 (V3.0,
V3.1, V3.2), its protection holds two more counted fields, no local
variable table follows the networks (it is an XML document at the end),
and each network says layout 7, where an address operand ends with 2
more bytes.  The networks are read by :func:`.program.read_network`, so
the statements go through the same code tables as a V2 project's.  The
symbol tables are an XML document, the data pages members of their own
in the V2 page layout.

The XML is untrusted: it is refused with a document type or entity
declaration (no entity is ever expanded) or a NUL byte (no UTF-16 that
would hide one), and bounded in size before :mod:`xml.etree` parses it.
It does not open the archive (:mod:`.smartv3`).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

from ..errors import PlcConfigError, PlcError
from .datapage import read_data_page
from .program import MAX_BLOCKS, Block, read_network, skip_dependencies
from .smartv3 import SmartV3Archive, member_label
from .stream import Cursor, binary_error

__all__ = ["SmartV3Content", "read_smartv3_content", "recode_variables", "parse_xml",
           "MAX_XML"]

#: largest XML document parsed (a symbol table of 2000 rows is ~400 KB)
MAX_XML = 4 * 1024 * 1024
MAX_VARIABLES = 4096
MAX_SYMBOLS = 65535
#: block layouts of SMART V3.0, V3.1 and V3.2
_LAYOUTS = {0x82: "V3.0", 0x83: "V3.1", 0x84: "V3.2"}
_KINDS = {0x3E8: "OB", 0x3E9: "SBR", 0x3EA: "INT", 0x3EB: "FB"}
_PROTECTED = 0x600
_FORBIDDEN = re.compile(rb"<!\s*(?:DOCTYPE|ENTITY)|\x00", re.I)
#: the local variable types a V3 block declares that the STL export writes
_VAR_TYPES = frozenset(("BOOL", "BYTE", "WORD", "INT", "DWORD", "DINT", "REAL"))
_SECTIONS = {"0": "IN", "1": "IN_OUT", "2": "OUT", "3": "TEMP"}
_ZIP_SECTION = "zip archive"
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")
#: a symbol's address as the symbol table writes it
_ADDRESS = re.compile(r"(?:(?:I|Q|M|SM|S|V|L)(?:\d{1,5}\.[0-7]|[BWD]\d{1,5})"
                      r"|(?:T|C|HC|AC)\d{1,3}|A[IQ]W\d{1,5})\Z")


class _MemberCursor(Cursor):
    """A cursor whose errors count offsets in one member of the archive."""

    __slots__ = ("space",)

    def __init__(self, data: bytes, file: str, section: str) -> None:
        super().__init__(data, file, section)
        self.space = "member"

    def error(self, message: str, at: int | None = None) -> PlcError:
        return binary_error(self.file, self.section, self.pos if at is None else at,
                            message, space=self.space)


class SmartV3Content:
    """The blocks, the data block text, the symbols and the CPU of a V3
    project; ``notes`` says what was left out."""

    def __init__(self) -> None:
        self.blocks: list[Block] = []
        self.data = ""
        self.symbols: list[tuple[str, str, str]] = []
        self.cpu = ""
        self.notes: list[str] = []


def read_smartv3_content(archive: SmartV3Archive) -> SmartV3Content:
    """Read the members of ``archive``."""
    out = SmartV3Content()
    pages: list[tuple[int, list[str]]] = []
    seen: set[tuple[str, int]] = set()
    for kind, name, body in archive.members:
        label = member_label(name)
        if kind == "program":
            block = _pou(body, archive.file, label, out.notes)
            if block is None:
                continue
            if (block.kind, block.number) in seen:
                raise binary_error(archive.file, f"program block {label}", 0,
                                   f"a second block {block.ident}", space="member")
            seen.add((block.kind, block.number))
            out.blocks.append(block)
            if len(out.blocks) > MAX_BLOCKS:
                raise binary_error(archive.file, f"program block {label}", 0, "more than "
                                   f"{MAX_BLOCKS} blocks", space="member")
        elif kind == "data":
            pages.append(_page(body, archive.file, label))
        elif kind == "symbols":
            _symbols(body, archive.file, label, out)
        elif kind == "device":
            root = parse_xml(body, archive.file, f"device {label}")
            out.cpu = " ".join(_CONTROL.sub(" ", root.get("DeviceType", "")).split())[:40]
    if not any(b.kind == "OB" for b in out.blocks):
        raise binary_error(archive.file, _ZIP_SECTION, 0, "no program block MAIN in the "
                           "archive", space="decrypted zip archive")
    pages.sort(key=lambda page: page[0])
    out.data = "".join(line + "\r\n" for _, lines in pages for line in lines)
    return out


def parse_xml(raw: bytes, file: str, section: str) -> ET.Element:
    """The root element of the XML document ``raw`` (a member of the
    archive), refused past :data:`MAX_XML` or with a document type or
    entity declaration."""
    space = "member"
    if len(raw) > MAX_XML:
        raise binary_error(file, section, MAX_XML, f"the XML document is {len(raw)} bytes, "
                           f"more than the {MAX_XML} this reader parses", space=space)
    bad = _FORBIDDEN.search(raw)
    if bad is not None:
        raise binary_error(file, section, bad.start(), "the XML document declares a "
                           "document type or entity, or holds a NUL byte: not read",
                           PlcConfigError, space)
    try:
        # UTF-8 whatever the document declares: no codec is looked up by a
        # name read from the file
        return ET.fromstring(raw, parser=ET.XMLParser(encoding="utf-8"))
    except ET.ParseError as e:
        line, column = e.position
        at = sum(len(x) + 1 for x in raw.split(b"\n")[:max(line - 1, 0)]) + column
        raise binary_error(file, section, at, f"the XML document is damaged (line {line}, "
                           f"column {column})", space=space) from None


def _pou(body: bytes, file: str, label: str, notes: list[str]) -> Block | None:
    c = _MemberCursor(body, file, f"program block {label}")
    c.expect(8, 1, "block version")
    at = c.pos
    kind = _KINDS.get(c.u2())
    if kind is None:
        raise c.error("block type is not MAIN, a subroutine, an interrupt routine or a "
                      "function block", at)
    c.skip(2)
    number = c.u2()
    flags = c.u4()
    c.skip(16 + 4)                             # origin, whether the editor was open
    at = c.pos
    layout = c.u2()
    if layout not in _LAYOUTS:
        raise c.error(f"block layout 0x{layout:x} is not one this reader knows "
                      "(SMART V3: 0x82, 0x83, 0x84)", at)
    name = c.text()
    block = Block(kind, 1 if kind == "OB" else number, name, "")
    c.expect(0, 1, "block header")
    block.comment = c.text()
    c.expect(0, 1, "block header")
    c.text()                                   # author
    c.skip(2 + 20)                             # salt
    hashed = any(c.take(64))                   # SHA-512 of a password
    c.skip(c.count(4, 1 << 20, "password field"))
    sealed = c.count(4, len(body), "protected code")
    c.skip(sealed + 3)
    block.protected = bool(flags & _PROTECTED) or hashed or sealed > 0
    c.skip(32)                                 # created, modified
    c.expect(0, 1, "block header")
    count = c.count(2, 65535, "number of networks")
    for index in range(count):
        block.networks.append(read_network(c, block, index))
    _trailer(c, count, block, records=layout != 0x82)
    if kind == "FB":
        return _function_block(block, c, notes)
    if block.protected:
        notes.append(f"{block.ident} ({block.name}) is protected by a password: it is "
                     "loaded as a protected block, its interface without its code")
    return block


def _function_block(block: Block, c: Cursor, notes: list[str]) -> None:
    """A V3 function block: left out if it holds no code, else refused."""
    if any(net.statements for net in block.networks):
        raise binary_error(c.file, c.section, 0, f"function block {block.name!r} holds "
                           "code: function blocks (SMART V3) are not run by plcrt",
                           PlcConfigError, "member")
    notes.append(f"function block {block.name} is empty and left out")
    return None


def _trailer(c: Cursor, networks: int, block: Block, records: bool) -> None:
    """What follows the networks: dependencies, the local variable table
    (XML) and (from V3.1 on) a record of cell labels per network, to the
    member's end."""
    skip_dependencies(c)
    c.skip(4 + 4)
    c.expect(8, 1, "block trailer")
    c.skip(2 + 4 + 2 + 22)
    size = c.count(4, MAX_XML, "length of the local variable table")
    at = c.pos
    root = parse_xml(c.take(size), c.file, c.section)
    if root.tag != "LocVarTable":
        raise c.error(f"the local variable table is a {member_label(root.tag)!r}, not a "
                      "LocVarTable", at)
    if block.kind != "FB":                     # an FB's interface is not read
        block.variables = _variables(root, c, at, block)
    if records:
        c.expect(0x101, 2, "block trailer")
        c.expect(networks, 4, "number of network records")
        for _ in range(networks):
            c.expect(2, 1, "network record")
            for _ in range(c.count(4, 65535, "number of cell records")):
                c.expect(4, 1, "cell record")
                for _ in range(c.count(4, 64, "number of cell labels")):
                    c.expect(1, 1, "cell label")
                    c.text()
                    c.text()
    if c.pos != len(c.data):
        raise c.error(f"{len(c.data) - c.pos} bytes follow the block's last record")


def _variables(root: ET.Element, c: Cursor, at: int, block: Block
               ) -> list[tuple[str, str, str, str]]:
    rows = root.findall("Member")
    if len(rows) > MAX_VARIABLES:
        raise c.error(f"{len(rows)} local variables, more than {MAX_VARIABLES}", at)
    out = []
    for row in rows:
        name = row.get("Name", "")
        if not name or (name == "EN" and row.get("varType") == "0"):
            continue                           # empty rows; EN is the power flow
        section = _SECTIONS.get(row.get("varType", ""))
        vtype = row.get("DataType", "").upper()
        if section is None or vtype not in _VAR_TYPES:
            raise c.error(f"local variable {member_label(name)!r} of {block.ident}: type "
                          f"{member_label(vtype)!r} or section "
                          f"{member_label(row.get('varType', ''))!r} is not one this reader "
                          "writes", at)
        # Unicode (the XML is UTF-8); recode_variables() puts them in the
        # code page of the block's other strings
        out.append((section, name, vtype, row.get("Commt", "")))
    return out


def recode_variables(blocks: list[Block], codec: str) -> None:
    """Hold the local variables' names and comments (read as Unicode from
    the XML) as the blocks' other strings are held, one character a byte of
    the project's code page ``codec``; a character outside it becomes ``?``."""
    for block in blocks:
        block.variables = [(section, _bytes_of(name, codec), vtype, _bytes_of(note, codec))
                           for section, name, vtype, note in block.variables]


def _bytes_of(text: str, codec: str) -> str:
    return text.encode(codec, "replace").decode("latin-1")


def _page(body: bytes, file: str, label: str) -> tuple[int, list[str]]:
    c = _MemberCursor(body, file, f"data block {label}")
    index = int.from_bytes(body[5:7], "little") if len(body) >= 7 else 0
    lines = read_data_page(c)
    if c.pos != len(body):
        raise c.error(f"{len(body) - c.pos} bytes follow the data page")
    return index, lines


def _symbols(body: bytes, file: str, label: str, out: SmartV3Content) -> None:
    section = f"symbol table {label}"
    root = parse_xml(body, file, section)
    count = 0
    for table in root.iter("VarTable"):
        kind = table.get("TableType", "")
        if kind not in ("VT", "CONSTVT"):
            continue                           # I/O, block, system and instance tables
        for row in table.findall("Member"):
            count += 1
            if count > MAX_SYMBOLS:
                raise binary_error(file, section, 0, f"more than {MAX_SYMBOLS} symbols",
                                   space="member")
            name = row.get("Name", "")
            if not name:
                continue
            address = row.get("Addr", "")
            if kind == "CONSTVT":
                out.notes.append(f"symbol {member_label(name)!r} is not exported: the "
                                 "constant tables of SMART V3 are not read")
            elif row.find("Member") is not None:
                out.notes.append(f"symbol {member_label(name)!r} is not exported: a "
                                 "structure (UDT)")
            elif not _ADDRESS.match(address):
                out.notes.append(f"symbol {member_label(name)!r} is not exported: no "
                                 "address this reader writes")
            else:
                out.symbols.append((name, address, row.get("Commt", "")))
