"""Micro/WIN V3 projects (``.mwp``, ``R03.10``) against the corpus
(shared/corpus/mwp beside the checkout; ``PLCRT_CORPUS`` names another
corpus folder).  Skipped where the corpus or a file is absent.

* each V3 project of the corpus loads, compiles, and its ``plcrt export``
  re-loads to the same IR and runs to the same memory image;
* ``Proyecto Esdras`` is its own export (published beside it): the same IR
  network by network and the same memory image after 300 scans of the same
  stimuli;
* the other two projects published with an export are other revisions of
  the program: the networks that differ are named, the others compared;
* the decoded code and the ladder cells are two readings of a network: a
  project whose code was altered is refused, with its network and offset.
"""

from __future__ import annotations

import struct
import sys
import zlib
from pathlib import Path

import pytest

import plcrt
from plcrt.cli import main
from plcrt.errors import PlcConfigError, PlcSyntaxError
from plcrt.lang.stl import parse_program
from plcrt.project import read_project

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_project_corpus import _file  # noqa: E402
from test_project_load import ir_of, same_run  # noqa: E402

PAIR = "santiagoesdras__Practica_1_taller__"
ESDRAS = f"{PAIR}Proyecto Esdras__Practica 1.mwp"
FINAL = f"{PAIR}Proyecto Final__PT1_IIIB_SDL.mwp"
FIRST = f"{PAIR}Practica 1.mwp"
BELITA = "Belita-Lili__PracticasPLC_cecyt3__Proyecto1.mwp"
#: the V3 projects of the corpus that load
V3 = (BELITA, ESDRAS, FINAL, FIRST)
#: the CPU SOURCES.md names for each
CPUS = {BELITA: "CPU 221", ESDRAS: "CPU 216", FINAL: "CPU 216", FIRST: "CPU 216"}
#: project -> its export, as SOURCES.md pairs them
EXPORTS = {ESDRAS: f"{PAIR}Proyecto Esdras__practica 1.awl",
           FINAL: f"{PAIR}Proyecto Final__practica 1.awl",
           FIRST: f"{PAIR}practica 1.awl"}
#: where the pair is two revisions of the program: the networks of OB1
#: whose code differs, and why the pair is not one revision
REVISIONS = {
    FINAL: ((9, 10, 11), "the export is byte for byte the export of Proyecto Esdras; this "
                         "project adds network titles and starts the level lamps of "
                         "networks 9 to 11 with LDN I0.2"),
    FIRST: (tuple(range(1, 14)), "the project (13 networks, TON T37 +5) and the export (9 "
                                 "networks, TON T37 +20) were published in different "
                                 "commits and hold other programs"),
}
def _export_text(name: str) -> str:
    """The export as published: a V3 export sets a box's operands apart by a
    blank (``TON T37 +5``), which plcrt reads as V4's comma."""
    return _file(name).read_bytes().decode("cp1252")


def _export(name: str):
    return parse_program(_export_text(name), name)


def _stream(path: Path) -> tuple[bytes, bytes]:
    """(header up to the length, inflated stream) of a V3 project."""
    data = path.read_bytes()
    return data[:0x10], zlib.decompress(data[0x14:])


def _pack(head: bytes, stream: bytes) -> bytes:
    return head + struct.pack("<I", len(stream)) + zlib.compress(stream)


@pytest.mark.parametrize("name", V3)
def test_v3_project_loads_and_exports_to_itself(name: str, tmp_path: Path) -> None:
    path = _file(name)
    project = read_project(path.read_bytes(), str(path))
    assert project.format == "Micro/WIN V3" and project.version == "R03.10"
    assert project.cpu == CPUS[name]
    assert any("Micro/WIN V3" in note for note in project.notes)
    plc = plcrt.load(path)
    out, table = tmp_path / "o.awl", tmp_path / "o.txt"
    assert main(["export", str(path), "--awl", str(out), "--symbols", str(table)]) == 0
    again = plcrt.load(out, symbols=table if project.symbols else None,
                       cpu=plc.model.name)                  # the project's CPU
    assert ir_of(again.program) == ir_of(plc.program)
    for line in project.symbols.splitlines():
        name, address = line.split("\t")[:2]
        assert again.symbols.lookup(name).address == plc.symbols.lookup(name).address == address
    same_run(plc, again, 300)


def test_v3_project_is_its_own_export() -> None:
    """Proyecto Esdras: blocks, titles, comments, variables and every
    network's statements equal its export's; the same memory image after
    300 scans of the same random inputs."""
    project = plcrt.load(_file(ESDRAS))
    export = _export(EXPORTS[ESDRAS])
    assert [len(p.networks) for p in project.program.pous] == [14, 1, 1]
    assert ir_of(project.program) == ir_of(export)
    assert [p.comment for p in project.program.pous] == [p.comment for p in export.pous]
    same_run(project, plcrt.load(_export_text(EXPORTS[ESDRAS])), 300)


@pytest.mark.parametrize("name", sorted(REVISIONS))
def test_v3_project_of_another_revision_than_its_export(name: str) -> None:
    """The networks REVISIONS names differ in code; every other network of
    both files has the same statements; the blocks and their comments are
    the same."""
    project = plcrt.load(_file(name)).program
    export = _export(EXPORTS[name])
    differing, why = REVISIONS[name]
    assert [(p.ident, p.name, p.comment) for p in project.pous] == [
        (p.ident, p.name, p.comment) for p in export.pous], why
    code = [[[(i.mnemonic, tuple(o.text for o in i.operands)) for i in n.insns]
             for n in p.networks] for p in (project.pous[0], export.pous[0])]
    found = tuple(k + 1 for k in range(max(map(len, code)))
                  if k >= min(map(len, code)) or code[0][k] != code[1][k])
    assert found == differing, why
    for k in range(min(map(len, code))):
        if k + 1 not in found:
            assert code[0][k] == code[1][k]
    assert ir_of(project)[1:] == ir_of(export)[1:]     # SBR0, INT0


#: the first bytes of the compiled code of OB1's networks 1 and 2 of
#: Proyecto Esdras (LD I0.0, O Q0.0, AN I0.3, O T38; LD I0.0, LD M5.0, CTU)
_CODE = {1: b"\x00\x00\x42\x00\x30\xc0\x4b\x84", 2: b"\x00\x00\x04\x05\xa8\x44"}


def _code_offset(stream: bytes, network: int) -> int:
    at = stream.find(_CODE[network])
    assert at > 0 and stream.find(_CODE[network], at + 1) < 0
    return at


def test_code_that_disagrees_with_its_ladder_cells_is_refused() -> None:
    """Network 1 of Proyecto Esdras with AN I0.3 made AN I0.2 in its code
    (its cells still draw I0.3): refused, naming the network, both
    addresses and the code's offset."""
    head, stream = _stream(_file(ESDRAS))
    at = _code_offset(stream, 1)
    assert stream[at + 4:at + 6] == b"\x30\xc0"              # AN I0.3
    forged = stream[:at + 4] + b"\x30\x80" + stream[at + 6:]  # AN I0.2
    with pytest.raises(PlcSyntaxError, match=r"network 1 of OB1: the compiled code and the "
                       r"ladder cells name other addresses \(I0.2, I0.3\)") as e:
        read_project(_pack(head, forged), "x.mwp")
    assert e.value.loc.column - 1 == at


@pytest.mark.parametrize("code, words", [
    (b"\x7f\x00", "compiled instruction 0x7f00 is not one"),    # an op not in the table
    (b"\x06\x00", "compiled instruction 0x0600 is not one"),    # area 3: not known
    (b"\xa6\x45", "compiled instruction 0xa645 is not one"),    # TON's byte, another form
])
def test_unknown_v3_code_names_network_and_offset(code: bytes, words: str) -> None:
    head, stream = _stream(_file(ESDRAS))
    at = _code_offset(stream, 2)
    forged = stream[:at] + code + stream[at + 2:]
    with pytest.raises(PlcSyntaxError, match=f"network 2 of OB1: {words}") as e:
        read_project(_pack(head, forged), "x.mwp")
    assert e.value.loc.column - 1 == at and "byte 0x" in e.value.message


def test_ald_is_read_where_the_cells_draw_a_series_of_a_parallel_pair() -> None:
    """Belita's network 4: its cells draw I0.4 in series with I0.5 parallel
    to Q0.3, then the coil Q1.4; the one-byte 0xdc between them is ALD (OLD
    would OR I0.4 with the pair)."""
    project = plcrt.load(_file(BELITA)).program
    net = project.pous[0].networks[3]
    assert [(i.mnemonic, tuple(o.text for o in i.operands)) for i in net.insns] == [
        ("LD", ("I0.4",)), ("LD", ("I0.5",)), ("O", ("Q0.3",)), ("ALD", ()), ("=", ("Q1.4",))]
    plc = plcrt.load(_file(BELITA))
    for i4, i5, q14 in ((True, True, 1), (True, False, 0), (False, True, 0)):
        plc.write("I0.4", i4)
        plc.write("I0.5", i5)
        plc.scan()
        assert (int(plc.read("Q0.3")), int(plc.read("Q1.4"))) == (0, q14)


def test_a_block_header_field_that_may_be_a_password_is_not_read() -> None:
    """The 8 bytes after a block's name are zero in every V3 project seen;
    set, they may be a password, and the block is refused, not read."""
    head, stream = _stream(_file(ESDRAS))
    at = stream.find(b"\xe8\x03\x04\x09\x00PRINCIPAL") + 14
    assert stream[at:at + 8] == bytes(8)
    forged = stream[:at] + b"\x01" + stream[at + 1:]
    with pytest.raises(PlcConfigError, match="may hold a password") as e:
        read_project(_pack(head, forged), "x.mwp")
    assert e.value.loc.column - 1 == at


def test_symbols_of_a_v3_project_agree_with_its_cells() -> None:
    """Proyecto Final's symbol table is read; every ladder cell that names a
    symbol sits in a network whose code uses the symbol's address (the
    reader checks it), and the loaded program watches by those names."""
    from plcrt.project.r03 import read_v3_program
    path = _file(FINAL)
    head, stream = _stream(path)
    symbolic = read_v3_program(stream, str(path)).symbolic
    assert sum(len(names) for _, _, names, _ in symbolic) >= 24
    project = read_project(path.read_bytes(), str(path))
    rows = [line.split("\t") for line in project.symbols.splitlines()]
    assert len(rows) == 24 and ["Boton_ON", "I0.0"] in rows and ["Cont1", "C0"] in rows
    plc = plcrt.load(path)
    plc.write("Boton_ON", True)
    plc.scan()
    assert plc.read("B1") == plc.read("Q0.0") == 1


def test_a_symbol_at_another_address_than_the_code_uses_is_refused() -> None:
    """Boton_ON moved from I0.0 to I0.2 in the table: the networks whose
    cells name it use I0.0, so the first of them is refused."""
    head, stream = _stream(_file(FINAL))
    at = stream.find(b"\x08Boton_ON", stream.find(b"USR1")) + 9
    assert stream[at:at + 11] == bytes.fromhex("0100010100000000000000")
    forged = stream[:at + 7] + b"\x02" + stream[at + 8:]
    with pytest.raises(PlcSyntaxError, match=r"network 1 of OB1: the ladder cells name "
                       r"symbols the compiled code does not use at their addresses "
                       r"\(Boton_ON\)"):
        read_project(_pack(head, forged), "x.mwp")


def test_a_symbol_row_of_another_layout_leaves_the_table_unread() -> None:
    """A named row whose last bytes are set (not seen: a comment, perhaps)
    is not guessed: the table is not read, a note says why, the program
    loads."""
    head, stream = _stream(_file(FINAL))
    at = stream.find(b"\x08Boton_ON", stream.find(b"USR1")) + 9 + 19
    forged = stream[:at] + b"\x05" + stream[at + 1:]
    project = read_project(_pack(head, forged), "x.mwp")
    assert project.symbols == ""
    assert any("symbol table is not read" in note and "Boton_ON" in note
               for note in project.notes)
    assert "Network 14" in project.awl


@pytest.mark.parametrize("network, old, new, words", [
    # AN I0.3 made A I0.3: the cells still draw four negated contacts
    (1, b"\x30\xc0", b"\x20\xc0", "the ladder cells draw 3 and the compiled code has 4 of "
                                  "LD/A/O"),
    # TON T37 made CTU C37: the cells still draw a TON box
    (5, b"\xa6\x44\x00\x25", b"\xa8\x44\x00\x25", "the ladder cells draw 0 and the compiled "
                                                   "code has 1 of CTU"),
])
def test_code_that_compiles_other_cells_than_drawn_is_refused(network: int, old: bytes,
                                                              new: bytes, words: str) -> None:
    """A contact, negated contact, coil or box of the drawing is one
    statement of its kind in the code: a code read as another instruction
    on the same address is refused, naming the network."""
    head, stream = _stream(_file(ESDRAS))
    at = stream.find(old)
    assert at > 0 and stream.find(old, at + 1) < 0
    forged = stream[:at] + new + stream[at + len(old):]
    with pytest.raises(PlcSyntaxError, match=f"network {network} of OB1: {words}"):
        read_project(_pack(head, forged), "x.mwp")
