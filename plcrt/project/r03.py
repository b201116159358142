"""The program block of a Micro/WIN V3 project (``.mwp``, header ``R03.xx``).

A V3 project keeps, per network, the code Micro/WIN compiled the network
to for the CPU (a compact machine code: one or two bytes for a bit
instruction, more for a box) and the grid of ladder cells it was drawn
with; it has no statement list like a V4 project.  This module reads the
blocks, their networks, titles and comments, decodes the compiled code
into STL statements with the table of :mod:`.r03codes`, and steps over
the ladder cells and the local variable table, checking every length.
The statements become the same :class:`~.program.Block` the V4 reader
produces, so :mod:`.awl` writes them as an export and :mod:`plcrt.lang`
parses that text into the same IR as the project's own export.

What is not understood is refused, never guessed: an instruction the code
table does not hold, a cell or variable row of another layout, a network
editor other than ladder.  Each refusal is a
:class:`~plcrt.errors.PlcSyntaxError` naming the file, the section and the
byte offset in the decompressed project (docs/project-files.md,
"Micro/WIN V3 projects").

It does not read the container (:mod:`.container`), the symbol table
(:mod:`.r03tables`), the data block or the system block of a V3 project.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from ..errors import PlcConfigError
from .codes import AREAS
from .program import Block, Net
from .r03codes import decode_network
from .stream import Cursor, binary_error

__all__ = ["V3Program", "read_v3_program", "find_v3_main", "MAX_NETWORKS", "MAX_CELLS"]

#: most networks of one block (the editor keeps 100; Micro/WIN V3 allows 255)
MAX_NETWORKS = 1000
#: most ladder cells of one network (32 columns by 32 rows)
MAX_CELLS = 1024
#: most comment lines of a network or a block
MAX_LINES = 1024
#: most local variables of a block
MAX_VARIABLES = 256
#: most operands of one ladder cell (a box has at most 16 inputs and outputs)
MAX_CELL_OPERANDS = 32
#: most compiled bytes of one network
MAX_CODE = 4096

_KINDS = {0x3E8: "OB", 0x3E9: "SBR", 0x3EA: "INT"}
#: the main program block: number 0, type 1000, one byte (4), a name of 1 to
#: 64 characters (a two-byte length)
_MAIN = re.compile(rb"\x00\x00\xe8\x03\x04[\x01-\x40]\x00", re.S)
#: ladder cell kind -> the statements it compiles to, counted against the
#: code (a contact: LD, A or O; a negated contact: LDN, AN or ON; a coil: =;
#: a box: its instruction); empty cells and wires compile to nothing
_CELL_STATEMENTS = {0x14: ("LD", "A", "O"), 0x15: ("LDN", "AN", "ON"), 0x1B: ("=",),
                    0x136: ("CTU",), 0x1F4: ("TON",)}
_WIRES = (0x0, 0x1)
#: the fixed part of a ladder cell, up to its operand count
_CELL_HEAD = 0xAD
#: operand records of a ladder cell, after their index: a constant (a box's
#: +5), an address (a contact's I0.0, a box's C0) or a symbol (its name
#: follows, with a one-byte length), told apart by their
#: first byte -> the bytes that follow the index
_CELL_OPERAND_SIZES = {0: 13, 1: 17, 2: 10}
#: a row of the local variable table: a flag, the name's length, the name,
#: then 25 bytes (its section, type and comment: not decoded)
_ROW = 25
#: the one named row read: EN, the power flow input every subroutine has
_EN = b"EN"


@dataclass
class V3Program:
    """The blocks of a V3 program block, where the section ends, and the
    networks whose cells name symbols: (network, offset of its code,
    the names, the addresses its code uses), checked once the symbol table
    is read."""

    blocks: list[Block]
    end: int
    symbolic: list[tuple[str, int, set[str], set[str]]] = field(default_factory=list)


def find_v3_main(stream: bytes) -> int:
    """The offset of the main program block's header (its number, 0), or -1."""
    match = _MAIN.search(stream)
    return match.start() if match else -1


def read_v3_program(stream: bytes, file: str) -> V3Program:
    """The blocks of the V3 program block in the inflated ``stream``."""
    at = find_v3_main(stream)
    c = Cursor(stream, file, "program block", max(at - 2, 0))
    if at < 2:
        raise c.error("no main program block found in the project (type 1000, number 0)")
    count = c.count(2, 512, "number of program blocks")
    if count == 0:
        raise c.error("the program block lists no block", at - 2)
    out = V3Program([], 0)
    out.blocks = [_block(c, out) for _ in range(count)]
    out.end = c.pos
    return out


def _block(c: Cursor, program: V3Program) -> Block:
    start = c.pos
    number = c.u2()
    at = c.pos
    kind = _KINDS.get(c.u2())
    if kind is None:
        raise c.error("block type is not MAIN, a subroutine or an interrupt routine", at)
    c.expect(4, 1, "block header")
    name = c.text()
    if not name:
        raise c.error("a block without a name", start)
    # 8 bytes, zero in every project seen: the place a block password would
    # be kept, so a block with anything there is not read (docs/project-files.md)
    at = c.pos
    if any(c.take(8)):
        raise binary_error(c.file, c.section, at, f"{kind} {name!r}: a field of the block "
                           "header this reader does not know is set (it may hold a "
                           "password); the block is not read", PlcConfigError)
    c.skip(16 + 16)                            # created, last changed (SYSTEMTIMEs)
    block = Block(kind, 1 if kind == "OB" else number, name, "")
    c.expect(0, 1, "block header")
    for index in range(c.count(2, MAX_NETWORKS, "number of networks")):
        block.networks.append(_network(c, block, index, program))
    lines = _lines(c)
    # line 0 is the block's title (TITLE= of the export), the rest its comment
    block.comment = lines[0] if lines else ""
    block.remarks = "\n".join(lines[1:])
    c.expect(0, 1, "local variable table")
    for _ in range(c.count(2, MAX_VARIABLES, "number of local variables")):
        _variable(c, block)
    return block


def _lines(c: Cursor) -> list[str]:
    """A list of numbered text lines (a title and a comment); an absent
    line (number 0xffff) is left out."""
    c.expect(0, 1, "text lines")
    out = []
    for index in range(c.count(2, MAX_LINES, "number of text lines")):
        at = c.pos
        number = c.u2()
        if number == 0xFFFF:
            continue
        if number != index:
            raise c.error(f"text line {index} is numbered {number}", at)
        c.skip(2)
        out.append(c.text())
    return out


def _network(c: Cursor, block: Block, index: int, program: V3Program) -> Net:
    start = c.pos
    where = f"network {index + 1} of {block.ident}"
    number = c.u2()
    if number != index:
        raise c.error(f"{where} is numbered {number + 1}", start)
    c.expect(2, 2, "network header")
    lines = _lines(c)
    net = Net(lines[0] if lines else "", "\n".join(lines[1:]), "LAD")
    at = c.pos
    c.expect(0, 1, "network header")
    if c.u2() != 0:
        raise c.error(f"{where}: a network header field this reader does not know "
                      "(not empty in this project)", at)
    at = c.pos
    if c.u1() != 2:
        raise c.error(f"{where}: not a ladder network (only ladder networks of "
                      "Micro/WIN V3 projects are read)", at)
    size = c.count(2, MAX_CODE, "length of the compiled code")
    code_at = c.pos
    code = c.take(size)
    net.statements = decode_network(code, lambda off, msg: c.error(f"{where}: {msg}",
                                                                   code_at + off))
    c.expect(1, 1, "network cells")
    drawn, kinds, addresses, names, complete = 0, [], set(), set(), True
    for _ in range(c.count(2, MAX_CELLS, "number of ladder cells")):
        kind, cell_addresses, cell_names, cell_complete, head = _cell(c)
        drawn += kind not in _WIRES
        if kind not in _WIRES and head:        # a box counts by its first cell
            kinds.append(kind)
        addresses.update(cell_addresses)
        names.update(cell_names)
        complete = complete and cell_complete
    if drawn and not net.statements:
        raise c.error(f"{where} has LAD content but no compiled code (an incomplete "
                      "network Micro/WIN did not compile): compile the project in "
                      "Micro/WIN and save it", start)
    _check_cells(c, where, net, kinds, code_at)
    used = _check_drawing(c, where, net, addresses, complete, code_at)
    if names:
        program.symbolic.append((where, code_at, names, used))
    return net


def _check_cells(c: Cursor, where: str, net: Net, kinds: list[int], at: int) -> None:
    """As many contacts, negated contacts, coils and boxes of each kind as
    the decoded code has statements for them."""
    for kind in kinds:
        if kind not in _CELL_STATEMENTS:
            raise c.error(f"{where}: a ladder cell of kind 0x{kind:x} this reader does not "
                          "know", at)
    for kind, mnemonics in _CELL_STATEMENTS.items():
        drawn = kinds.count(kind)
        coded = sum(m in mnemonics for m, _ in net.statements)
        if drawn != coded:
            raise c.error(f"{where}: the ladder cells draw {drawn} and the compiled code "
                          f"has {coded} of {'/'.join(mnemonics)}", at)


def _check_drawing(c: Cursor, where: str, net: Net, drawn: set[str], complete: bool,
                   at: int) -> set[str]:
    """The addresses the ladder cells name are those the decoded code uses
    (all of them where every cell operand is an address; a symbol's address
    is not known here): a second reading of the network, so that a code
    read wrongly is refused rather than run."""
    used = {op for _, ops in net.statements for op in ops if op[:1] not in "+-"}
    if not drawn <= used or (complete and drawn != used):
        missing = ", ".join(sorted(drawn ^ used)) if complete else ", ".join(
            sorted(drawn - used))
        raise c.error(f"{where}: the compiled code and the ladder cells name other "
                      f"addresses ({missing})", at)
    return used


def _cell(c: Cursor) -> tuple[int, list[str], list[str], bool, bool]:
    """Read one ladder cell: (its kind: 0 empty, 1 a wire, 0x14 a contact,
    0x1b a coil, a box's code; the addresses it names; the symbols it names;
    whether every operand of it is an address this reader writes; whether it
    has operands: a contact, a coil, a box's first cell)."""
    start = c.pos
    head = c.take(_CELL_HEAD)
    if head[0] != 0 or head[3] != 1:
        raise c.error("a ladder cell of a layout this reader does not know", start)
    addresses, names, complete = [], [], True
    nops = c.count(2, MAX_CELL_OPERANDS, "number of cell operands")
    for _ in range(nops):
        at = c.pos
        if c.u2() == 0xFFFF:
            continue
        c.need(1)
        form = c.data[c.pos]
        size = _CELL_OPERAND_SIZES.get(form)
        if size is None:
            raise c.error("a cell operand that is neither a constant, an address nor a "
                          "symbol", at)
        record = c.take(size)
        if form == 2:
            names.append(c.take(c.u1()).decode("latin-1"))
        if form != 1:
            complete = complete and form == 0
            continue
        address = _cell_address(record)
        if address is None:
            complete = False
        else:
            addresses.append(address)
    return head[4] | head[5] << 8, addresses, names, complete, bool(nops)


def _cell_address(record: bytes) -> str | None:
    """The address of a cell's address record (its area code at byte 9, its
    bit or element number at 13..16), or None for an area not known here."""
    prefix = AREAS.get(record[9]) if not any(record[10:13]) else None
    offset = int.from_bytes(record[13:17], "little")
    if prefix in ("T", "C"):
        return f"{prefix}{offset}"
    if prefix in ("I", "Q", "M"):
        return f"{prefix}{offset >> 3}.{offset & 7}"
    return None


def _variable(c: Cursor, block: Block) -> None:
    at = c.pos
    c.expect(0, 1, "local variable")
    name = c.take(c.u1())
    if name and not (name == _EN and block.kind == "SBR"):
        raise c.error(f"local variable {name.decode('latin-1')!r} of {block.ident}: "
                      "a named local variable of a Micro/WIN V3 project is not read", at)
    c.skip(_ROW)
