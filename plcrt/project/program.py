"""The program block of a Micro/WIN V4 or SMART V2 project: blocks, their
networks and the STL Micro/WIN compiled each network to.

Every network of the program block holds, whatever editor it was written
in, the list of STL statements Micro/WIN compiled it to (instruction code
and operands); this reader takes that list, not the ladder or FBD cells,
which it reads only to step over them.  A statement's operands are written
as the STL export writes them (``I0.0``, ``VW100``, ``T37``, ``+100``), so
the text handed to the STL parser is an export's text and produces the
same IR.

It does not read the container (:mod:`.container`) nor the tables
(:mod:`.tables`), and it does not parse STL (:mod:`plcrt.lang` does).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .codes import AREAS, CLASSES, OPCODES, VAR_SECTIONS, VAR_TYPES, WIDTH_LETTER
from .stream import Cursor

__all__ = ["Block", "Net", "read_program_block", "read_network", "MAX_BLOCKS", "MAX_OPERANDS"]

#: most blocks read (MAIN, 128 subroutines and 128 interrupt routines)
MAX_BLOCKS = 512
#: most operands of one statement (a CALL passes at most 16 parameters)
MAX_OPERANDS = 32
#: most labels of a ladder or FBD cell
MAX_LABELS = 16

_KINDS = {0x3E8: "OB", 0x3E9: "SBR", 0x3EA: "INT"}
_NETWORK_KINDS = {0x101: "FBD", 0x102: "LAD", 0x106: "STL"}
#: cell kinds that draw no instruction: an empty cell (or arrow), a wire
_WIRES = frozenset((0x0, 0x1))
#: a block's protection flags: 0x200/0x400 mark a block with a password
_PROTECTED = 0x600
#: the network layout of Micro/WIN SMART V3 (V2 and V1 write 4): an
#: address operand is followed by 2 bytes (1)
_V3_NETWORK = 7


@dataclass
class Net:
    """One network: its title, comment, editor and compiled statements."""

    title: str
    comment: str
    editor: str
    statements: list[tuple[str, tuple[str, ...]]] = field(default_factory=list)


@dataclass
class Block:
    """One program block (MAIN, a subroutine or an interrupt routine)."""

    kind: str
    number: int
    name: str
    comment: str
    networks: list[Net] = field(default_factory=list)
    #: (section, name, type, comment) of the local variable table
    variables: list[tuple[str, str, str, str]] = field(default_factory=list)
    protected: bool = False
    #: the block's comment, the lines the export writes after ``TITLE=``
    remarks: str = ""

    @property
    def ident(self) -> str:
        return f"{self.kind}{self.number}"


def read_program_block(c: Cursor) -> list[Block]:
    """The blocks of the program block starting at the cursor."""
    c.section = "program block"
    c.expect(2, 1, "program block version")
    count = c.count(2, MAX_BLOCKS, "number of program blocks")
    return [_block(c) for _ in range(count)]


def _block(c: Cursor) -> Block:
    start = c.pos
    version = c.u1()
    if version not in (7, 8):
        raise c.error(f"block version {version} is not one this reader knows (7 or 8)", start)
    at = c.pos
    kind = _KINDS.get(c.u2())
    if kind is None:
        raise c.error("block type is not MAIN, a subroutine or an interrupt routine", at)
    c.skip(2)
    number = c.u2()
    flags = c.u4()
    c.skip(16)
    if version == 8:
        c.skip(4)          # whether the block's editor was open
    at = c.pos
    layout = c.u2()
    name = c.text()
    block = Block(kind, 1 if kind == "OB" else number, name, "")
    if not name:
        c.skip(4)
        return block
    c.expect(0, 1, "block header")
    block.comment = c.text()
    c.expect(0, 1, "block header")
    c.text()                                   # author
    if layout == 0x0A:                         # Micro/WIN V4
        c.skip(c.u1())
        c.skip(4)
    elif layout in (0x0B, 0x0D):               # SMART V1, V2: salt, hashes
        c.skip(25 if layout == 0x0B else 89)
    else:
        raise c.error(f"block layout 0x{layout:x} is not one this reader knows "
                      "(Micro/WIN V4 0xa, SMART 0xb and 0xd)", at)
    block.protected = bool(flags & _PROTECTED)
    c.skip(32)                                 # created, modified
    c.expect(0, 1, "block header")
    for index in range(c.count(2, 65535, "number of networks")):
        block.networks.append(_network(c, block, index))
    c.expect(0, 1, "block trailer")
    for _ in range(c.count(2, 4096, "number of local variables")):
        var = _variable(c)
        if var is not None:
            block.variables.append(var)
    skip_dependencies(c)
    c.skip(8)
    return block


def skip_dependencies(c: Cursor) -> None:
    """The list of blocks and libraries a block calls: names and stamps the
    reader has no use for (the calls are in the code)."""
    deps = c.count(4, 4096, "number of dependencies")
    if deps:
        c.expect(0, 1, "dependency list")
        for _ in range(deps):
            c.text()
            c.skip(1 + 2 + 8 + 16 + 4)


def read_network(c: Cursor, block: Block, index: int) -> Net:
    """The network at the cursor (of a V4, SMART V2 or SMART V3 block)."""
    return _network(c, block, index)


def _network(c: Cursor, block: Block, index: int) -> Net:
    start = c.pos
    c.u2()
    at = c.pos
    editor = _NETWORK_KINDS.get(c.u2())
    if editor is None:
        raise c.error(f"network {index + 1} of {block.ident}: editor code is not "
                      "LAD, FBD or STL", at)
    v3 = c.u2() == _V3_NETWORK
    net = Net(c.text(), "", editor)
    c.expect(0, 1, "network header")
    net.comment = c.text()
    wide = c.u1() == 2
    width = 4 if wide else 2
    for _ in range(c.count(width, 65535, "number of STL line states")):
        if (c.u4() if wide else c.u2()) != 0xFFFF:
            c.skip(1)
            c.text()
    c.skip(1)
    for _ in range(c.count(width, 65535, "number of STL line comments")):
        if (c.u4() if wide else c.u2()) != 0xFFFF:
            c.skip(7)
            c.text()
    c.skip(1 + 4)
    c.expect(0, 2, "network header")
    for _ in range(c.count(2, 65535, "number of statements")):
        at = c.pos
        if c.u2() == 0xFFFF:
            continue
        c.expect(0, 2, "statement")
        code_at = c.pos
        code = c.u2()
        c.expect(0x101, 2, "statement")
        operands = _operands(c, compiled=True, v3=v3)
        mnemonic = OPCODES.get(code)
        if mnemonic is None:
            raise c.error(f"network {index + 1} of {block.ident}: instruction code "
                          f"0x{code:x} is not one this reader knows", code_at)
        net.statements.append((mnemonic, tuple(operands)))
    c.expect(1, 1, "network body")
    drawn = 0                  # STL lines, or cells other than empty and wire
    if editor == "STL":
        for _ in range(c.count(2, 65535, "number of STL lines")):
            if c.u2() != 0xFFFF:
                drawn += 1
                c.skip(2 + 2 + 2 + 4)
                c.expect(0x101, 2, "STL line")
                _operands(c, compiled=False, v3=v3)
    else:
        for _ in range(c.count(2, 65535, "number of cells")):
            drawn += _cell(c, v3) not in _WIRES
    if drawn and not net.statements:
        # the editor holds a program the CPU would not get: never run it as empty
        raise c.error(f"network {index + 1} of {block.ident} has {editor} content but no "
                      "compiled code (an incomplete network Micro/WIN did not compile): "
                      "compile the project in Micro/WIN and save it", start)
    return net


def _cell(c: Cursor, v3: bool = False) -> int:
    """Step over one ladder or FBD cell (position, kind, labels, operands);
    returns its kind."""
    c.expect(0, 1, "cell")
    c.skip(2)
    c.expect(0x103, 2, "cell")
    kind = c.u2()
    c.skip(1 + 1 + 1 + 2)
    c.skip(53 * c.count(1, MAX_LABELS, "number of cell labels"))
    c.expect(0x101, 2, "cell")
    _operands(c, compiled=True, v3=v3, cell=True)
    return kind


def _operands(c: Cursor, *, compiled: bool, v3: bool = False, cell: bool = False
              ) -> list[str]:
    out = []
    for _ in range(c.count(2, MAX_OPERANDS, "number of operands")):
        if c.u2() == 0xFFFF:
            out.append("")
            continue
        out.append(_operand(c, compiled, v3, cell))
    return out


def _operand(c: Cursor, compiled: bool, v3: bool = False, cell: bool = False) -> str:
    c.skip(1 if compiled else 2)
    layout = c.u1()                           # 3, or 4 (a V3 cell's address: 2 more bytes)
    c.skip(1 + 4 + 1 + 4)                     # kind, 0, 1, column
    at = c.pos
    form = c.u1()
    if form == 2:
        text = _address(c)
        # SMART V3: an address in a statement, or in a cell of layout 4,
        # ends with 2 bytes (1) (docs/project-files.md, SMART V3)
        if v3 and (layout == 4 or not cell):
            c.expect(1, 2, "address operand")
        return text
    if form != 1:
        raise c.error(f"operand form {form} is neither a constant nor an address", at)
    kind, width, _area = c.u1(), c.u1(), c.u1()
    if kind == 0:                              # a symbolic constant
        return c.text(1)
    if kind == 7:
        value = c.f4()
        c.skip(1)
        return _real(value)
    if kind == 8:
        c.skip(4)
        return '"' + c.text(1) + '"'
    value = c.u4()
    c.skip(1)
    return _integer(kind, width, value, c, at)


def _integer(kind: int, width: int, value: int, c: Cursor, at: int) -> str:
    if kind == 1:
        return str(value)
    if kind == 2:
        return f"{value - (1 << 32) if value >= 1 << 31 else value:+d}"
    if kind == 4:
        return f"16#{value:X}"
    if kind == 5:
        return f"2#{value:b}"
    raise c.error(f"constant kind {kind} is not one this reader knows", at)


def _real(value: float) -> str:
    text = repr(value)
    if text in ("inf", "-inf", "nan"):
        return "0.0"
    return text if "e" not in text else f"{value:.7E}"


def _address(c: Cursor) -> str:
    at = c.pos
    pointer, width, area, klass = c.u1(), c.u1(), c.u1(), c.u1()
    group = c.u2()
    offset = c.u4()
    prefix = AREAS.get(area) if area else CLASSES.get(klass)
    if prefix is None:
        if area == klass == 0 and group == 2:  # a subroutine, by its number
            return f"SBR{offset}"
        raise c.error(f"memory area code 0x{area:x}/0x{klass:x} is not one this "
                      "reader knows", at)
    if prefix in ("T", "C", "HC", "AC"):
        text = f"{prefix}{offset}"
    elif width == 1:
        text = f"{prefix}{offset >> 3}.{offset & 7}"
    else:
        letter = WIDTH_LETTER.get(width)
        if letter is None:
            raise c.error(f"operand width {width} is not a bit, byte, word or double word", at)
        text = f"{prefix}{letter}{offset}"
    return {0: text, 1: "&" + text, 2: "*" + text}.get(pointer, text)


def _variable(c: Cursor) -> tuple[str, str, str, str] | None:
    c.skip(2)
    name = c.text()
    c.skip(1)
    complete = c.u2() != 3
    c.skip(1)
    if complete:
        c.skip(3)
    c.skip(2)
    if complete:
        c.skip(8)
    kind = c.u4()
    c.skip(1)
    comment = c.text()
    c.skip(1)
    section = VAR_SECTIONS.get(c.u1(), "TEMP")
    c.skip(2 + 2 + 1 + 1 + 1)
    vtype = VAR_TYPES.get(kind)
    if not name or vtype is None:              # EN (power flow), empty rows
        return None
    return section, name, vtype, comment
