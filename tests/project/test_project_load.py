"""Project files load into the IR their STL export gives (plcrt.project).

The project files here are written by the tests' own writer
(tests/project_writer.py) from plcrt's programs, so each has a known
export: the program, the same program through the writer and the reader,
must be the same IR network by network and run to the same memory image.
"""

from __future__ import annotations

import dataclasses
import random
import zlib
import sys
from pathlib import Path

import pytest

import plcrt
from plcrt.cli import main
from plcrt.errors import PlcConfigError, PlcError, PlcSyntaxError
from plcrt.lang.stl import parse_program
from plcrt.project import read_project
from plcrt.project.codes import OPCODES

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from project_writer import container, encodable, project_bytes, stream  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]

#: every instruction the reader's code tables hold that runs on its own,
#: in one program (the writer encodes it, the reader must give it back)
EVERY_CODE = """ORGANIZATION_BLOCK MAIN:OB1
TITLE=All codes
BEGIN
Network 1 // bits
LD     I0.0
A      I0.1
O      M0.0
LDN    I0.2
AN     V10.1
ON     SM0.5
OLD
LPS
AI     I0.3
=      Q0.0
LRD
=      Q0.4
LPP
ANI    I0.4
=I     Q0.1
Network 2 // edges, set, reset
LD     I0.5
EU
S      M1.0, 2
LD     I0.6
ED
R      M1.0, 1
LDN    M1.0
NOT
SI     Q0.2, 1
RI     Q0.3, 1
Network 3 // compares and moves
LDW>=  VW0, +100
AW<    VW0, 200
OD=    VD4, -7
LDB<>  VB8, 16#F
=      M2.0
LD     SM0.0
MOVW   +5, VW20
MOVD   VD4, VD24
MOVR   1.5, VD28
+I     VW20, VW22
+D     +1000, VD24
+R     VD28, VD32
*D     +1000, VD24
Network 4 // timers and counters
LD     I1.0
TON    T37, 10
LD     I1.1
TOF    T38, 5
LD     I1.2
LD     I1.3
CTU    C0, +3
Network 5 // a call
LD     I1.4
CALL   SBR0
END_ORGANIZATION_BLOCK
SUBROUTINE_BLOCK SBR_0:SBR0
TITLE=helper
BEGIN
Network 1 // count
LD     SM0.0
+I     1, VW40
END_SUBROUTINE_BLOCK
"""


def _programs() -> list:
    files = [ROOT / "programs" / "seal_in.awl", ROOT / "examples" / "conveyor" / "conveyor.awl"]
    params = [pytest.param(EVERY_CODE, id="every-code")]
    params += [pytest.param(f.read_text(encoding="utf-8"), id=f.stem) for f in files if f.is_file()]
    return params


def ir_of(program) -> list:
    """A program as comparable values: block, network, title, statements."""
    return [(p.ident, p.name, [(v.section, v.name, v.type) for v in p.variables],
             [(n.number, n.title, n.comment,
               [(i.mnemonic, tuple(o.text for o in i.operands)) for i in n.insns])
              for n in p.networks])
            for p in program.pous]


def same_run(a, b, scans: int) -> None:
    """Two PLCs given the same random inputs scan by scan end with the same
    memory image."""
    rng = random.Random(28)
    for _ in range(scans):
        for bit in range(16):
            value = rng.random() < 0.3
            a.write(f"I{bit // 8}.{bit % 8}", value)
            b.write(f"I{bit // 8}.{bit % 8}", value)
        a.scan()
        b.scan()
    assert a.mem.snapshot().areas == b.mem.snapshot().areas


def export_round_trip(path: Path, tmp_path: Path):
    """(the project loaded, its ``plcrt export`` -- .awl, symbols, data --
    loaded again): the two programs are one IR."""
    out = [tmp_path / n for n in ("o.awl", "o.txt", "o.db")]
    assert main(["export", str(path), "--awl", str(out[0]), "--symbols", str(out[1]),
                 "--data", str(out[2])]) == 0
    project = plcrt.load(path)
    again = plcrt.load(out[0], symbols=out[1], data=out[2])
    assert ir_of(again.program) == ir_of(project.program)
    return project, again


def _write(tmp_path: Path, text: str, smart: bool, **kw) -> Path:
    program = parse_program(text, "x.awl")
    assert encodable(program)
    path = tmp_path / ("p.smart" if smart else "p.mwp")
    path.write_bytes(project_bytes(program, smart=smart, **kw))
    return path


@pytest.mark.parametrize("smart", [False, True], ids=["mwp", "smart"])
@pytest.mark.parametrize("text", _programs())
def test_project_is_its_export_network_by_network(tmp_path: Path, text: str, smart: bool) -> None:
    """Loading the project gives the IR of the export, and the same memory
    image after 200 scans of the same random stimuli."""
    path = _write(tmp_path, text, smart)
    awl = tmp_path / "p.awl"
    awl.write_text(text, encoding="utf-8")
    a, b = plcrt.load(path), plcrt.load(awl)
    assert ir_of(a.program) == ir_of(b.program)
    same_run(a, b, 200)


@pytest.mark.parametrize("smart", [False, True], ids=["mwp", "smart"])
def test_export_reloads_to_the_same_ir(tmp_path: Path, smart: bool, capsys) -> None:
    """plcrt export writes an .awl, symbols and data that load to what the
    project loads to."""
    symbols = [("Start", "I0.0", "start button"), ("Lamp", "Q0.0", "")]
    data = [("VW100", [10, 20], "batch sizes"), ("VB7", [3], "")]
    path = _write(tmp_path, EVERY_CODE, smart, symbols=symbols, data=data)
    project, again = export_round_trip(path, tmp_path)
    awl = (tmp_path / "o.awl").read_bytes()
    assert awl.count(b"\r\n") == awl.count(b"\n")
    assert again.read("VW100") == 10 and again.read("VW102") == 20 and again.read("VB7") == 3
    assert project.read("VW100") == 10 and project.read("VB7") == 3


def test_symbols_and_data_block_of_the_project(tmp_path: Path) -> None:
    """The project's symbol table and data block come with it."""
    symbols = [("Start", "I0.0", "start button"), ("Level", "VW10", "tank"),
               ("Flag", "SM0.5", ""), ("Count", "C3", "")]
    path = _write(tmp_path, EVERY_CODE, False, symbols=symbols,
                  data=[("VD200", [70000], "")])
    project = read_project(path.read_bytes(), str(path))
    assert project.symbols.split("\r\n")[:4] == ["Start\tI0.0\tstart button", "Level\tVW10\ttank",
                                                 "Flag\tSM0.5", "Count\tC3"]
    assert project.data == "VD200\t70000\r\n"
    assert project.cpu == "CPU 224 REL 02.01"
    plc = plcrt.load(path)
    assert plc.read("VD200") == 70000


def test_a_protected_block_loads_as_its_interface(tmp_path: Path) -> None:
    """A block with a password keeps its interface and loses its code, with
    a note saying so; the rest of the program loads."""
    program = parse_program(EVERY_CODE, "x.awl")
    data = project_bytes(program, protected=("SBR0",))
    project = read_project(data, "p.mwp")
    assert any("SBR0" in n and "password" in n for n in project.notes)
    loaded = parse_program(project.awl, "p.mwp")
    sbr = [p for p in loaded.pous if p.ident == "SBR0"][0]
    assert [n.insns for n in sbr.networks] == [()]


def test_check_prints_what_the_reader_left_out(tmp_path: Path, capsys) -> None:
    """plcrt check lists the reader's notes (here a protected block and a
    missing system block), so nothing it left out goes unsaid."""
    path = tmp_path / "p.mwp"
    path.write_bytes(project_bytes(parse_program(EVERY_CODE, "x.awl"), protected=("SBR0",)))
    assert main(["check", str(path)]) == 0
    err = capsys.readouterr().err
    assert f"{path}: note: SBR0 (" in err and "is protected by a password" in err
    assert f"{path}: note: the system block was not read" in err


@pytest.mark.parametrize("smart", [False, True], ids=["mwp", "smart"])
def test_a_project_with_a_password_is_refused(smart: bool) -> None:
    program = parse_program(EVERY_CODE, "x.awl")
    data = container(stream(program, smart=smart), smart=smart, password=True)
    with pytest.raises(PlcConfigError, match="password") as e:
        read_project(data, "p.smart")
    assert e.value.loc.file == "p.smart" and e.value.loc.block == "file header"


@pytest.mark.parametrize("head, kind, words", [
    (b"PK\3\4" + bytes(40), PlcConfigError, "SMART V3"),
    (b"GJK\0R03.10" + bytes(6) + b"\x10\0\0\0" + zlib.compress(bytes(16)), PlcSyntaxError,
     "no main program block"),
    (b"GJK\0R05.00" + bytes(60), PlcSyntaxError, "signature"),
    (b"GJK\0R04.00" + bytes(10), PlcSyntaxError, "ends inside its header"),
])
def test_other_files_are_refused_by_name(head: bytes, kind: type, words: str) -> None:
    with pytest.raises(kind, match=words) as e:
        read_project(head, "q.mwp")
    assert e.value.loc.file == "q.mwp" and "byte 0x" in e.value.message


#: codes refused on purpose: 0x7fff is no code; 0x148, 0x157 and 0x3eb are
#: named by the public format description (eq_alt, eq_altp, fbcall) without
#: the STL Micro/WIN writes for them (docs/project-files.md, "Instruction codes")
@pytest.mark.parametrize("unknown", [0x7FFF, 0x148, 0x157, 0x3EB])
def test_unknown_instruction_code_names_block_network_and_offset(unknown: int) -> None:
    assert unknown not in OPCODES
    program = parse_program(EVERY_CODE, "x.awl")
    body = stream(program)
    code = (0x20A).to_bytes(2, "little") + (0x101).to_bytes(2, "little") + b"\0\0"
    at = body.index(code)               # NOT in network 2 of MAIN
    body = body[:at] + unknown.to_bytes(2, "little") + body[at + 2:]
    with pytest.raises(PlcSyntaxError,
                       match=rf"network 2 of OB1: instruction code 0x{unknown:x} ") as e:
        read_project(container(body), "p.mwp")
    assert e.value.loc.column == at + 1 and f"byte 0x{at:x}" in e.value.message


def test_cli_check_and_run_take_a_project(tmp_path: Path, capsys) -> None:
    path = _write(tmp_path, EVERY_CODE, True)
    assert main(["check", str(path)]) == 0
    assert main(["run", str(path), "--scans", "3", "--set", "I1.4=1", "--watch", "VW40"]) == 0
    assert "3" in capsys.readouterr().out


def test_errors_are_plc_errors(tmp_path: Path) -> None:
    bad = tmp_path / "bad.mwp"
    bad.write_bytes(b"GJK\0R04.00" + bytes(60))
    with pytest.raises(PlcError):
        plcrt.load(bad)


def test_a_project_is_loaded_alone(tmp_path: Path) -> None:
    path = _write(tmp_path, EVERY_CODE, False)
    with pytest.raises(PlcConfigError, match="load it alone"):
        plcrt.load([path, ROOT / "programs" / "seal_in.awl"])


def test_show_draws_a_project(tmp_path: Path, capsys) -> None:
    """plcrt show (which parses without loading) reads a project too."""
    path = _write(tmp_path, EVERY_CODE, False)
    assert main(["show", str(path)]) == 0
    out = capsys.readouterr().out
    assert "OB1 (MAIN)" in out and "TON" in out and "T37" in out


def test_export_notes_escape_names_read_from_the_file(tmp_path: Path, capsys) -> None:
    """A block name with a terminal escape is printed escaped."""
    program = parse_program(EVERY_CODE, "x.awl")
    sbr = program.pous[1]
    evil = dataclasses.replace(sbr, name="S\x1b[31mX")
    program = dataclasses.replace(program, pous=(program.pous[0], evil))
    path = tmp_path / "e.mwp"
    path.write_bytes(project_bytes(program, protected=("SBR0",)))
    assert main(["export", str(path), "--awl", str(tmp_path / "e.awl")]) == 0
    err = capsys.readouterr().err
    assert "password" in err and "\x1b" not in err and "\\x1b" in err


def test_a_drawn_network_without_code_is_refused() -> None:
    """Ladder cells without compiled code (a network Micro/WIN did not
    compile) are refused, not run as an empty network; a network with both
    loads."""
    text = EVERY_CODE.replace("Network 5 // a call\nLD     I1.4\nCALL   SBR0\n", "Network 5 // empty\n")
    program = parse_program(text, "x.awl")
    assert not program.pous[0].networks[4].insns
    with pytest.raises(PlcSyntaxError, match="network 5 of OB1 has LAD content but no compiled"):
        read_project(container(stream(program, drawn=(("OB1", 5),))), "p.mwp")
    read_project(container(stream(program, drawn=(("OB1", 4),))), "p.mwp")
