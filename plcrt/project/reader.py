"""Read a project file: the container, then its sections in order.

:func:`read_project` opens the container (:mod:`.container`), finds the
program block in the inflated stream and reads it (:mod:`.program`), then
writes the blocks as STL export text (:mod:`.awl`) whose code page is
detected as an export's is; the wizard sections after the CPU name give
plant tables (:mod:`.wizards`).  The result holds that text, the blocks and
what the header says; :func:`plcrt.project.load_project` parses it.

Micro/WIN V3 projects (``R03.xx``) hold their program blocks in another
layout (compiled CPU code and a grid of ladder cells, no statement list),
read by :mod:`.r03` and :mod:`.r03tables` (with the user's symbol table),
the CPU they are for and their retentive ranges; their data block and the
rest of their system block are not read (docs/project-files.md,
"Micro/WIN V3 projects").  SMART V3 projects
(``.smartV3``, an encrypted zip) are opened by :mod:`.smartv3` and their
members read by :mod:`.smartv3pou`.  The system block (:mod:`.sysblock`) lies before
the program block.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..lang.encoding import decode_bytes
from ..lang.limits import read_capped
from .awl import blocks_text
from .container import Container, open_container
from .datapage import read_data_block
from .program import Block, read_program_block
from .r03 import find_v3_main, read_v3_program
from .r03tables import check_symbolic_cells, read_v3_symbols
from .smartv3 import is_smartv3, open_smartv3
from .smartv3pou import read_smartv3_content, recode_variables
from .stream import Cursor, binary_error
from .sysblock import SystemBlock, read_system_block, read_v3_system_block
from .tables import SymbolTables, read_symbol_tables
from .wizards import SECTION as WIZARDS, Wizard, plant_toml, read_wizards

__all__ = ["Project", "read_project", "read_project_file", "PROJECT_SUFFIXES"]

#: file name endings read as project files (in lower case)
PROJECT_SUFFIXES = (".mwp", ".smart", ".smartv3")

_CONTROL = re.compile(r"[\x00-\x1f\x7f]")
#: the start of the data block: version 2, a page count, a page (version
#: 7 or 8, type 5000)
_DATA_BLOCK = re.compile(rb"\x02..[\x07\x08]\x88\x13", re.S)
#: the CPU named in the project, after the data block: "CPU 224 REL 02.01"
_CPU = re.compile(rb"\x00(.)\x00(CPU [ -~]{1,40})", re.S)

#: the start of the program block: version 2, a block count, then MAIN
#: (block version 7 or 8, type 1000, number 0)
_PROGRAM_BLOCK = re.compile(rb"\x02..[\x07\x08]\xe8\x03\x00\x00\x00\x00", re.S)
#: the CPU a Micro/WIN V3 project is for, at the start of its stream
_V3_CPU = re.compile(rb"\x00(CPU [ -~]{1,40}?)\x00")
#: what a Micro/WIN V3 project holds that the reader does not read
_V3_NOTE = ("a Micro/WIN V3 project: its program block, symbol table, CPU and retentive "
            "ranges are read; its data block and the rest of its system block are not (their "
            "layout is not decoded)")


@dataclass
class Project:
    """A project file, read."""

    file: str
    format: str
    version: str
    blocks: list[Block]
    #: the program as its STL export (the code page's characters)
    awl: str
    #: the code page the project's strings were decoded with
    encoding: str
    #: the user's symbol table as Micro/WIN exports it (tab-separated), or ""
    symbols: str = ""
    #: the data block as Micro/WIN exports it, or ""
    data: str = ""
    #: the CPU the project is for, as Micro/WIN names it ("CPU 224 REL 02.01")
    cpu: str = ""
    notes: list[str] = field(default_factory=list)
    #: the wizard configurations read (docs/project-files.md, "Wizards")
    wizards: list[Wizard] = field(default_factory=list)
    #: the plant tables they give, as a plant file writes them ("" for none)
    plant: str = ""
    #: the system block (None: not read, see notes)
    system: SystemBlock | None = None


def read_project(data: bytes, file: str) -> Project:
    """The project in ``data`` (the bytes of a whole project file)."""
    if is_smartv3(data):
        return _smartv3_project(data, file)
    box = open_container(data, file)
    if box.format == "Micro/WIN V3":
        return _v3_project(box)
    cursor = _program_cursor(box)
    system, not_read = read_system_block(box.stream, file, box.format, cursor.pos)
    blocks = read_program_block(cursor)
    tables = read_symbol_tables(cursor)
    for block in blocks:          # the block's title is its comment in the block-name table
        block.comment = block.comment or tables.block_comments.get(block.name, "")
    data, cpu, end = _data_block(box, cursor.pos)
    wizards = read_wizards(Cursor(box.stream, file, WIZARDS, end),
                           box.format.startswith("Micro/WIN SMART"),
                           {b.name: b.protected for b in blocks})
    program, symbols = blocks_text(blocks), symbols_text(tables)
    # one code page for the program and its tables, detected as an export's
    decoded = decode_bytes((program + symbols + data).encode("latin-1"), file)
    codec = decoded.encoding
    notes = [f"{b.ident} ({b.name}) is protected by a password: it is loaded as a "
             "protected block, its interface without its code" for b in blocks if b.protected]
    notes += [f"symbol {name!r} is not exported: {why}" for name, why in tables.skipped]
    notes += [_recode(note, codec) for note in wizards.notes]
    for wizard in wizards.configs:              # names in the project's code page
        wizard.name = _recode(wizard.name, codec)
    notes += [not_read] if not_read else []
    if system is not None and not system.cpu:      # a V4 block names no CPU
        system.cpu = cpu
    return Project(file, box.format, box.version, blocks, _recode(program, codec), codec,
                   _recode(symbols, codec), _recode(data, codec), cpu, notes,
                   wizards.configs, plant_toml(wizards.plant), system)


def _v3_project(box: Container) -> Project:
    v3 = read_v3_program(box.stream, box.file)
    rows, why = read_v3_symbols(box.stream, box.file, v3.end)
    main = find_v3_main(box.stream)
    system, not_read = read_v3_system_block(box.stream, box.file, max(main, 0))
    notes = [_V3_NOTE] + ([why] if why else []) + ([not_read] if not_read else [])
    if not why:
        check_symbolic_cells(v3, rows, Cursor(box.stream, box.file, "program block"))
    program, symbols = blocks_text(v3.blocks), symbols_text(SymbolTables(rows))
    codec = decode_bytes((program + symbols).encode("latin-1"), box.file).encoding
    cpu = _V3_CPU.search(box.stream, 0, 0x40)
    name = cpu.group(1).decode() if cpu else ""
    if system is not None:
        system.cpu = name
    return Project(box.file, box.format, box.version, v3.blocks, _recode(program, codec),
                   codec, _recode(symbols, codec), cpu=name, notes=notes, system=system)


def _smartv3_project(data: bytes, file: str) -> Project:
    """A SMART V3 project: an encrypted zip of members (:mod:`.smartv3`)."""
    archive = open_smartv3(data, file)
    v3 = read_smartv3_content(archive)
    bare = [dataclasses.replace(b, variables=[]) for b in v3.blocks]
    codec = decode_bytes((blocks_text(bare) + v3.data).encode("latin-1"), file).encoding
    recode_variables(v3.blocks, codec)
    system, not_read = None, "the archive holds no system block: the defaults apply"
    for kind, _name, body in archive.members:
        if kind == "system":            # a SMART system block alone (0x0613/0x0615)
            system, not_read = read_system_block(body, file, "Micro/WIN SMART", len(body))
    if system is not None and not system.cpu:
        system.cpu = v3.cpu
    notes = v3.notes + ([not_read] if not_read else [])
    return Project(file, "Micro/WIN SMART V3", archive.version, v3.blocks,
                   _recode(blocks_text(v3.blocks), codec), codec,
                   symbols_text(SymbolTables(v3.symbols)), _recode(v3.data, codec), v3.cpu,
                   notes, system=system)


def _data_block(box: Container, start: int) -> tuple[str, str, int]:
    """(data block text, CPU name, its offset) of the sections after the
    symbol tables (the status charts between them are stepped over by
    finding the data block's header)."""
    match = _DATA_BLOCK.search(box.stream, start)
    if match is None:
        raise binary_error(box.file, "data block", start, "no data block found after the "
                           "symbol tables")
    cursor = Cursor(box.stream, box.file, "data block", match.start())
    text = read_data_block(cursor)
    cpu = _CPU.match(box.stream, cursor.pos)
    name = ""
    if cpu is not None and cpu.group(1)[0] == len(cpu.group(2)):
        name = cpu.group(2).decode("ascii")
    return text, name, cursor.pos


def _recode(text: str, codec: str) -> str:
    return text.encode("latin-1").decode(codec, "replace")


def symbols_text(tables: SymbolTables) -> str:
    """The user's symbols as Micro/WIN's tab-separated export (CR LF)."""
    rows = []
    for name, address, comment in tables.symbols:
        cells = (" ".join(_CONTROL.sub(" ", x).split()) for x in (name, address, comment))
        rows.append("\t".join(cells).rstrip("\t"))
    return "".join(row + "\r\n" for row in rows)


def _program_cursor(box: Container) -> Cursor:
    match = _PROGRAM_BLOCK.search(box.stream)
    if match is None:
        raise binary_error(box.file, "program block", 0, "no program block found in the "
                           "project (no block MAIN)")
    return Cursor(box.stream, box.file, "program block", match.start())


def read_project_file(path: str | Path, limit: int) -> Project:
    """Read the project file ``path`` (at most ``limit`` bytes)."""
    return read_project(read_capped(path, limit), str(path))
