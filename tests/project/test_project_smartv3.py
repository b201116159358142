"""SMART V3 project files (.smartV3) load into the IR their STL export gives
(plcrt.project.smartv3, plcrt.project.smartv3pou).

The files are written by the tests' writer (tests/smartv3_writer.py): the
blocks in the V3 layout, zipped and encrypted under the published default
key.  Each program must come back network by network and run to the same
memory image; a damaged, protected or hostile file must end in a PlcError
naming the file, the section (the zip member) and the byte offset, within
a time and memory bound.
"""

from __future__ import annotations

import io
import struct
import sys
import time
import tracemalloc
import zipfile
from pathlib import Path

import pytest

import plcrt
from plcrt.cli import main
from plcrt.errors import PlcConfigError, PlcError, PlcSyntaxError
from plcrt.lang.stl import parse_program
from plcrt.project import read_project
from plcrt.project.smartv3 import MAX_DIRECTORY, MAX_MEMBER, MAX_MEMBERS

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import smartv3_writer as w  # noqa: E402
from test_project_load import EVERY_CODE, _programs, export_round_trip, ir_of, same_run  # noqa: E402

SYMBOLS = [("Start", "I0.0", "start button"), ("Level", "VW10", "tank"),
           ("Flag", "SM0.5", ""), ("Count", "C3", "")]
DATA = [("VW100", [10, 20], "batch sizes"), ("VB7", [3], ""), ("VD200", [70000], "")]
#: per hostile file: wall-clock seconds and traced peak memory
TIME_BOUND = 5.0
MEMORY_BOUND = 3 * MAX_MEMBER + (16 << 20)


def _program(text: str = EVERY_CODE):
    return parse_program(text, "x.awl")


def _write(tmp_path: Path, data: bytes, name: str = "p.smartV3") -> Path:
    path = tmp_path / name
    path.write_bytes(data)
    return path


def _refused(data: bytes, kind: type = PlcError, words: str = "") -> PlcError:
    """Reading ``data`` raises ``kind`` matching ``words`` and naming the
    file, within the time and memory bound."""
    tracemalloc.start()
    start = time.perf_counter()
    try:
        with pytest.raises(kind, match=words) as e:
            read_project(data, "h.smartV3")
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert time.perf_counter() - start < TIME_BOUND
    assert peak < MEMORY_BOUND, f"{peak >> 20} MiB"
    assert e.value.loc is not None and e.value.loc.file == "h.smartV3"
    assert "byte 0x" in e.value.message
    return e.value


@pytest.mark.parametrize("text", _programs())
def test_project_is_its_export_network_by_network(tmp_path: Path, text: str) -> None:
    """A V3 project loads to the IR of its export, and runs to the same
    memory image after 200 scans of the same random stimuli."""
    program = _program(text)
    path = _write(tmp_path, w.project_bytes(program))
    awl = tmp_path / "p.awl"
    awl.write_text(text, encoding="utf-8")
    a, b = plcrt.load(path), plcrt.load(awl)
    assert ir_of(a.program) == ir_of(b.program)
    same_run(a, b, 200)


@pytest.mark.parametrize("layout", [0x82, 0x83, 0x84], ids=["V3.0", "V3.1", "V3.2"])
def test_each_v3_block_layout_is_read(layout: int) -> None:
    """V3.0 ends a block with its XML table; V3.1 and V3.2 add a record per
    network after it: all three read to the same IR."""
    program = _program()
    project = read_project(w.project_bytes(program, layout=layout), "p.smartV3")
    assert project.format == "Micro/WIN SMART V3" and project.version == "R03.01.00.00"
    assert ir_of(parse_program(project.awl, "p")) == ir_of(program)


def test_local_variables_come_from_the_xml_table() -> None:
    """A subroutine's IN, IN_OUT, OUT and TEMP rows (names, types, comments
    in the project's code page) are its interface; EN is not a row."""
    text = ("ORGANIZATION_BLOCK MAIN:OB1\nTITLE=主程序\nBEGIN\nNetwork 1 // 启动\n"
            "LD     SM0.0\nCALL   SBR0, I0.0, VW0, VD4\nEND_ORGANIZATION_BLOCK\n"
            "SUBROUTINE_BLOCK 子程序:SBR0\nTITLE=\nVAR_INPUT\n启动:BOOL;\t// 输入\nN:INT;\n"
            "END_VAR\nVAR_IN_OUT\nTotal:DINT;\nEND_VAR\nVAR\nTmp:REAL;\nEND_VAR\nBEGIN\n"
            "Network 1 \nLD     L0.0\n=      L10.0\nEND_SUBROUTINE_BLOCK\n")
    program = _program(text)
    data = w.encrypt(w.zip_bytes(w.members(program, encoding="gbk")))
    project = read_project(data, "p.smartV3")
    assert project.encoding == "gbk"
    again = parse_program(project.awl, "p")
    assert ir_of(again) == ir_of(program)
    sbr = [p for p in again.pous if p.ident == "SBR0"][0]
    assert [(v.section, v.name, v.type, v.comment) for v in sbr.variables] == [
        ("IN", "启动", "BOOL", "输入"), ("IN", "N", "INT", ""), ("IN_OUT", "Total", "DINT", ""),
        ("TEMP", "Tmp", "REAL", "")]


def test_symbols_data_block_and_cpu_of_the_project(tmp_path: Path) -> None:
    """The user's symbol table (the XML's VT tables), the data pages and the
    CPU of the device file come with the project; the I/O table is not the
    user's."""
    data = w.project_bytes(_program(), symbols=SYMBOLS, data=DATA, cpu="CPU SR40")
    project = read_project(data, "p.smartV3")
    assert project.symbols.split("\r\n")[:-1] == ["Start\tI0.0\tstart button",
                                                  "Level\tVW10\ttank", "Flag\tSM0.5",
                                                  "Count\tC3"]
    assert project.data == "VW100\t10, 20\t// batch sizes\r\nVB7\t3\r\nVD200\t70000\r\n"
    assert project.cpu == "CPU SR40"
    plc = plcrt.load(_write(tmp_path, data))
    assert plc.read("VW100") == 10 and plc.read("VW102") == 20 and plc.read("VD200") == 70000


def test_symbols_without_a_plain_address_are_noted_not_exported() -> None:
    extra = ('<VarTable TableType="CONSTVT"><Member Name="Max" IniVal="10"/></VarTable>'
             '<VarTable TableType="VT"><Member Name="Odd" Addr="DB2.DBX0.0"/>'
             '<Member Name="Rec" Addr="VB0"><Member Name="x" Addr="VB0"/></Member></VarTable>')
    entries = w.members(_program(), symbols=SYMBOLS)
    entries = [(n, w.symbols_xml(SYMBOLS, extra) if n.endswith(".xml") and "Glb" in n else b)
               for n, b in entries]
    project = read_project(w.encrypt(w.zip_bytes(entries)), "p.smartV3")
    assert project.symbols.count("\r\n") == len(SYMBOLS)
    assert sum("'Max'" in n and "constant" in n for n in project.notes) == 1
    assert sum("'Odd'" in n and "address" in n for n in project.notes) == 1
    assert sum("'Rec'" in n and "UDT" in n for n in project.notes) == 1


def test_export_reloads_to_the_same_ir(tmp_path: Path) -> None:
    """plcrt export writes an .awl, symbols and data that load to what the
    project loads to."""
    path = _write(tmp_path, w.project_bytes(_program(), symbols=SYMBOLS, data=DATA))
    _project, again = export_round_trip(path, tmp_path)
    assert again.read("VW100") == 10 and again.read("VB7") == 3
    assert main(["check", str(path)]) == 0


def test_a_protected_block_loads_as_its_interface() -> None:
    entries = w.members(_program())
    program = _program()
    sbr = [p for p in program.pous if p.ident == "SBR0"][0]
    entries = [(n, w.pou(sbr, flags=0x401) if n.endswith("SBR_0.poubin") else b)
               for n, b in entries]
    project = read_project(w.encrypt(w.zip_bytes(entries)), "p.smartV3")
    assert any("SBR0" in n and "password" in n for n in project.notes)
    loaded = [p for p in parse_program(project.awl, "p").pous if p.ident == "SBR0"][0]
    assert [n.insns for n in loaded.networks] == [()]


def test_a_function_block_is_left_out_when_empty_and_refused_with_code() -> None:
    program = _program()
    main_block = program.pous[0]
    blank = parse_program("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\n"
                          "END_ORGANIZATION_BLOCK\n", "b.awl").pous[0]
    base = w.members(program)
    fb_empty = ("p\\Program Block\\FB_0.poubin", w.pou(blank, kind=0x3EB))
    project = read_project(w.encrypt(w.zip_bytes(base + [fb_empty])), "p.smartV3")
    assert any("function block" in n and "left out" in n for n in project.notes)
    fb_code = ("p\\Program Block\\FB_0.poubin", w.pou(main_block, kind=0x3EB))
    e = _refused(w.encrypt(w.zip_bytes(base + [fb_code])), PlcConfigError, "function block")
    assert "FB_0.poubin" in e.message


def test_a_project_with_a_password_is_refused() -> None:
    """The header's protection flag: refused, naming the flag's offset."""
    e = _refused(w.project_bytes(_program(), protected=True), PlcConfigError, "password")
    assert e.loc.block == "file header" and "byte 0x79 of the file" in e.message


@pytest.mark.parametrize("damage", ["tag", "ciphertext", "key"])
def test_a_tag_that_does_not_verify_is_refused(damage: str) -> None:
    """A flipped bit, or another key (a password the flag does not show):
    the file is damaged or protected, never half read."""
    data = bytearray(w.project_bytes(_program()))
    if damage == "tag":
        data[-1] ^= 1
    elif damage == "ciphertext":
        data[300] ^= 0x80
    else:
        data = bytearray(w.encrypt(w.zip_bytes(w.members(_program())),
                                   key=bytes(32)))
    e = _refused(bytes(data), PlcConfigError, "damaged, or it is protected by a password")
    assert e.loc.block == "encrypted project"


@pytest.mark.parametrize("head, words", [
    (w.header()[:200], "ends inside its header"),
    (w.header()[:121] + b"\0" + w.header()[122:] + bytes(64), "protection flag is 0"),
])
def test_short_or_odd_headers_are_refused(head: bytes, words: str) -> None:
    _refused(head, PlcSyntaxError, words)


def test_a_decrypted_file_that_is_no_zip_is_refused() -> None:
    _refused(w.encrypt(bytes(range(256)) * 4), PlcSyntaxError, "not a zip archive")


def test_an_unknown_code_names_the_member_network_and_offset() -> None:
    program = _program()
    entries = [(n, w.pou(program.pous[0], code=0x7FFF) if n.endswith("MAIN.poubin") else b)
               for n, b in w.members(program)]
    e = _refused(w.encrypt(w.zip_bytes(entries)), PlcSyntaxError,
                 "network 1 of OB1: instruction code 0x7fff")
    assert "MAIN.poubin" in e.loc.block and "of the member" in e.message


def test_an_address_without_its_v3_tail_is_refused() -> None:
    """A V3 network's address operand ends with 2 bytes (1); a block written
    without them does not read as something else."""
    program = _program()
    entries = [(n, w.pou(program.pous[0], tail=False) if n.endswith("MAIN.poubin") else b)
               for n, b in w.members(program)]
    e = _refused(w.encrypt(w.zip_bytes(entries)), PlcSyntaxError, "MAIN.poubin")
    assert "of the member" in e.message


@pytest.mark.parametrize("layout, tail", [(3, False), (4, True)])
def test_cell_operands_of_both_layouts_are_stepped_over(layout: int, tail: bool) -> None:
    """A cell's address operand of layout 4 ends with 2 bytes (1), one of
    layout 3 does not: both are stepped over, the code is the network's."""
    program = _program()
    cells = (("I0.0", layout), ("VW100", layout), ("+5", layout))
    entries = [(n, w.pou(program.pous[0], cells=cells) if n.endswith("MAIN.poubin") else b)
               for n, b in w.members(program)]
    project = read_project(w.encrypt(w.zip_bytes(entries)), "p.smartV3")
    assert ir_of(parse_program(project.awl, "p")) == ir_of(program)


def test_a_cell_address_of_layout_4_without_its_tail_is_refused() -> None:
    program = _program()
    main_block = w.pou(program.pous[0], cells=(("I0.0", 4),))
    broken = main_block.replace(w.contact("I0.0", 4), w.contact("I0.0", 4)[:-2] + b"\0\0")
    entries = [(n, broken if n.endswith("MAIN.poubin") else b) for n, b in w.members(program)]
    _refused(w.encrypt(w.zip_bytes(entries)), PlcSyntaxError, "address operand")


def test_an_unknown_block_layout_is_refused() -> None:
    program = _program()
    entries = [(n, w.pou(program.pous[0], layout=0x85) if n.endswith("MAIN.poubin") else b)
               for n, b in w.members(program)]
    _refused(w.encrypt(w.zip_bytes(entries)), PlcSyntaxError, "block layout 0x85")


def test_a_project_without_main_is_refused() -> None:
    entries = [(n, b) for n, b in w.members(_program()) if not n.endswith("MAIN.poubin")]
    _refused(w.encrypt(w.zip_bytes(entries)), PlcSyntaxError, "no program block MAIN")


# -- hostile archives -------------------------------------------------------

#: "billion laughs": ten levels of ten references each
_BOMB = ('<?xml version="1.0"?><!DOCTYPE tables [<!ENTITY e0 "lol">'
         + "".join(f'<!ENTITY e{i} "{f"&e{i - 1};" * 10}">' for i in range(1, 10))
         + "]><tables>&e9;</tables>").encode()


@pytest.mark.parametrize("where", ["symbols", "locals"])
def test_an_xml_entity_bomb_is_refused(where: str) -> None:
    program = _program()
    entries = w.members(program)
    if where == "symbols":
        entries = [(n, _BOMB if "GlbVar" in n else b) for n, b in entries]
    else:
        entries = [(n, w.pou(program.pous[0], xml=_BOMB) if n.endswith("MAIN.poubin") else b)
                   for n, b in entries]
    _refused(w.encrypt(w.zip_bytes(entries)), PlcConfigError, "document type or entity")


def _stream_zip(name: str, size: int) -> bytes:
    """A zip whose one member is ``size`` zero bytes, written in chunks."""
    buffer = io.BytesIO()
    info = zipfile.ZipInfo(name)
    info.compress_type = zipfile.ZIP_DEFLATED
    with zipfile.ZipFile(buffer, "w") as box:
        with box.open(info, "w", force_zip64=False) as out:
            for _ in range(size >> 20):
                out.write(bytes(1 << 20))
    return buffer.getvalue()


def _directory_entry(plain: bytes, name: bytes) -> int:
    """The offset of the central directory entry of the member ``name``."""
    at = plain.find(b"PK\x01\x02")
    while plain[at + 46:at + 46 + len(name)] != name:
        at = plain.find(b"PK\x01\x02", at + 1)
    return at


def _forge_size(plain: bytes, size: int) -> bytes:
    """The zip ``plain`` with its first member's inflated size set to
    ``size`` in the central directory."""
    raw = bytearray(plain)
    struct.pack_into("<I", raw, raw.find(b"PK\x01\x02") + 24, size)
    return bytes(raw)


@pytest.mark.parametrize("declared, words", [
    (1000, "damaged"),                       # inflates past what it declares
    (MAX_MEMBER + 1, "more than"),           # declares past the bound
    (0xFFFFFFF0, "more than"),
])
def test_a_zip_bomb_is_bounded(declared: int, words: str) -> None:
    """64 MiB of zeros in one member (64 KB packed) is never inflated past
    its declared size nor past the bound."""
    plain = _forge_size(_stream_zip("p\\Program Block\\MAIN.poubin", 64 << 20), declared)
    e = _refused(w.encrypt(plain), PlcSyntaxError, words)
    assert "zip member" in e.loc.block and "MAIN.poubin" in e.message


def test_members_past_the_total_bound_are_refused() -> None:
    entries = w.members(_program())
    plain = _stream_zip("p\\Data Block\\big.dbbin", 12 << 20)
    more = zipfile.ZipFile(io.BytesIO(plain))
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as box:
        for name, body in entries:
            box.writestr(name, body)
        for info in more.infolist():
            for k in range(2):
                box.writestr(f"p\\Data Block\\big{k}.dbbin", more.read(info))
    _refused(w.encrypt(buffer.getvalue()), PlcSyntaxError, "in all")


@pytest.mark.parametrize("forge_count", [False, True])
def test_many_members_are_refused(forge_count: bool) -> None:
    """More members than the bound: refused from the end record, or, where
    the record understates them, from the directory."""
    entries = w.members(_program()) + [(f"x{i}.bin", b"") for i in range(MAX_MEMBERS + 50)]
    plain = bytearray(w.zip_bytes(entries, zipfile.ZIP_STORED))
    if forge_count:
        at = plain.rfind(b"PK\x05\x06")
        struct.pack_into("<HH", plain, at + 8, 10, 10)
    _refused(w.encrypt(bytes(plain)), PlcSyntaxError, "members, more than")


def test_a_zip64_record_is_refused() -> None:
    """A zip64 locator before the end record would give zipfile other
    counts than the ones checked: refused."""
    plain = w.zip_bytes(w.members(_program()))
    at = plain.rfind(b"PK\x05\x06")
    locator = b"PK\x06\x07" + struct.pack("<IQI", 0, 0, 1)
    _refused(w.encrypt(plain[:at] + locator + plain[at:]), PlcSyntaxError, "zip64")


def test_a_huge_directory_is_refused() -> None:
    entries = [(f"{i:06d}" + "n" * 2000, b"") for i in range(MAX_DIRECTORY // 2000)]
    _refused(w.encrypt(w.zip_bytes(entries, zipfile.ZIP_STORED)), PlcSyntaxError,
             "directory is")


@pytest.mark.parametrize("method", [zipfile.ZIP_BZIP2, zipfile.ZIP_LZMA])
def test_other_compression_methods_are_refused(method: int) -> None:
    _refused(w.encrypt(w.zip_bytes(w.members(_program()), method)), PlcSyntaxError,
             f"compression method {method}")


def test_an_encrypted_member_is_refused() -> None:
    plain = bytearray(w.zip_bytes(w.members(_program())))
    plain[_directory_entry(plain, b"p\\Program Block\\MAIN") + 8] |= 1   # "encrypted"
    _refused(w.encrypt(bytes(plain)), PlcSyntaxError, "encrypted member")


def test_a_member_name_is_only_compared() -> None:
    """A member named like a path outside the archive is read from memory
    like any other; nothing is written or opened by its name."""
    program = _program()
    entries = [("../../../../tmp/x/MAIN.poubin" if n.endswith("MAIN.poubin") else n, b)
               for n, b in w.members(program)]
    project = read_project(w.encrypt(w.zip_bytes(entries)), "p.smartV3")
    assert ir_of(parse_program(project.awl, "p")) == ir_of(program)


@pytest.mark.parametrize("declared", ["x-no-such-codec", "utf-7", "utf-16"])
def test_the_xml_is_utf8_whatever_it_declares(declared: str) -> None:
    """No codec is looked up by a name read from the file: the symbol table
    reads as UTF-8 under any declaration."""
    xml = w.symbols_xml(SYMBOLS).replace(b'encoding="UTF-8"', f'encoding="{declared}"'.encode())
    entries = [(n, xml if "GlbVar" in n else b) for n, b in w.members(_program())]
    project = read_project(w.encrypt(w.zip_bytes(entries)), "p.smartV3")
    assert project.symbols.startswith("Start\tI0.0\tstart button\r\n")
