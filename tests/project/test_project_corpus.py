"""The project reader against the corpus of real project files
(shared/corpus/mwp, beside the checkout; ``PLCRT_CORPUS`` names another
corpus folder).  Skipped where the corpus or a file is absent.

* every Micro/WIN V4 and SMART V2 project of it loads, compiles, and its
  ``plcrt export`` re-loads to the same IR and runs to the same memory image;
* a project published with its own ``.awl`` export has the export's blocks,
  block titles, networks, network titles and comments, and (where the two
  files are the same revision) its code, network by network, and the same
  memory image after 300 scans of the same stimuli;
* what SOURCES.md and the strings of the files say (CPU, symbols) is read.
"""

from __future__ import annotations

import os
import sys
import zlib
from pathlib import Path

import pytest

import plcrt
from plcrt.cli import main
from plcrt.errors import PlcSyntaxError
from plcrt.project import read_project

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_project_load import ir_of, same_run  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
_ENV = os.environ.get("PLCRT_CORPUS")
CORPUS = (Path(_ENV) if _ENV else ROOT.parent / "shared" / "corpus") / "mwp"

TARIQ = "tariqrm__Object-sorting-on-conveyor-belt-S7-200-PLC__EN21435522"
HAMTECH = "hamtech221__Traffic-Light-System-PLC-Ladder-Logic-__Files__TRAFFIC"
ESDRAS = "santiagoesdras__Practica_1_taller__"

#: projects read: file -> the CPU SOURCES.md (or the file's strings) names
READ = {
    f"{TARIQ}.mwp": "CPU 222 REL 02.01",
    f"{HAMTECH}_LIGHT.mwp": "CPU 224 REL 02.00",
    "zcdlab__MCU-PLC-Some-Small-Project__抢答器.mwp": "CPU 221 REL 01.10",
    "Electro-Industrial-Works__PLC-Practical-Projects__Bai_5_Mo_rong_Toggle_1_nut+Chong_doi"
    "+Lockout+Counter__Vol1_Proj05Ex_LAD_05_toggle_debounce.mwp": "CPU 224 REL 02.01",
    "ammardab3an__Step7-Micro-Win__Projects__S7-200 smart__scr.smart": "CPU ST40",
}
#: projects refused, and the words of the refusal
REFUSED = {
    # drawn networks Micro/WIN did not compile (docs/project-files.md); the
    # Micro/WIN V3 projects that load are tests/project/test_project_v3.py's
    "YashviArya12__PLC_Ladder_Logic_Program_.Projects__PLC_PROJECTS__Analog to digital "
    "input__analog.mwp": (PlcSyntaxError, "network 1 of OB1 has LAD content but no compiled "
                                          "code"),
    "Kity23__test__项目 1.smart": (PlcSyntaxError, "network 4 of SBR0 has LAD content but no "
                                                 "compiled code"),
}
#: project -> its export, as SOURCES.md pairs them ("export" quality)
PAIRS = {f"{TARIQ}.mwp": f"{TARIQ}.awl"}
#: pairs whose files are different revisions of the project: why
REVISIONS = {
    f"{TARIQ}.mwp": "the project's ladder cells and compiled code agree with each other and "
                    "not with the export (network 3 holds a TON T38 box and network 5 a TOF "
                    "T39 box; the export has one TON T37): two revisions of the project",
}


def _file(name: str) -> Path:
    path = CORPUS / name
    if not path.is_file():
        pytest.skip(f"corpus file not found: {path}")
    return path


@pytest.mark.parametrize("name", sorted(READ))
def test_corpus_project_loads_and_exports_to_itself(name: str, tmp_path: Path) -> None:
    path = _file(name)
    project = read_project(path.read_bytes(), str(path))
    assert project.cpu == READ[name]
    plc = plcrt.load(path)
    out = [tmp_path / n for n in ("o.awl", "o.txt", "o.db")]
    assert main(["export", str(path), "--awl", str(out[0]), "--symbols", str(out[1]),
                 "--data", str(out[2])]) == 0
    again = plcrt.load(out[0], symbols=out[1] if out[1].stat().st_size else None,
                       data=out[2], cpu=plc.model.name)     # the project's CPU
    assert ir_of(again.program) == ir_of(plc.program)
    same_run(plc, again, 300)


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_corpus_projects_not_read_are_refused_by_name(name: str) -> None:
    path = _file(name)
    kind, words = REFUSED[name]
    with pytest.raises(kind, match=words) as e:
        plcrt.load(path)
    assert e.value.loc.file == str(path) and "byte 0x" in e.value.message


def test_v3_project_without_compiled_code_is_refused_at_its_network() -> None:
    """The refusal's offset is the first network's header (its number, 0,
    and the header version, 2) in the inflated stream."""
    path = _file("YashviArya12__PLC_Ladder_Logic_Program_.Projects__PLC_PROJECTS__Analog to "
                 "digital input__analog.mwp")
    with pytest.raises(PlcSyntaxError, match="no compiled code") as e:
        read_project(path.read_bytes(), str(path))
    at = e.value.loc.column - 1
    stream = zlib.decompress(path.read_bytes()[0x14:])
    assert stream[at:at + 4] == b"\0\0\2\0" and b"\xe8\x03\x04" in stream[at - 64:at]


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_project_is_its_own_export(name: str) -> None:
    """Blocks, titles, networks and comments equal the export's; the code
    too where the two files are one revision."""
    project, export = plcrt.load(_file(name)), plcrt.load(_file(PAIRS[name]))
    shape = [[(p.ident, p.name, p.title)] + [(n.number, n.title, n.comment) for n in p.networks]
             for p in project.program.pous]
    assert shape == [[(p.ident, p.name, p.title)] + [(n.number, n.title, n.comment)
                                                     for n in p.networks]
                     for p in export.program.pous]
    if name in REVISIONS:
        assert ir_of(project.program) != ir_of(export.program)
        pytest.skip(f"code not compared: {REVISIONS[name]}")
    assert ir_of(project.program) == ir_of(export.program)
    same_run(project, export, 300)


def test_symbols_of_a_project() -> None:
    """The symbol table's names, addresses and comments (the names and
    comments are strings of the file; the Chinese ones in GBK)."""
    tariq = read_project(_file(f"{TARIQ}.mwp").read_bytes(), "t.mwp")
    assert tariq.symbols.startswith("START\tI0.0\tstart button\r\nSTOP_\tI0.1\tstop button\r\n")
    zcd = plcrt.load(_file("zcdlab__MCU-PLC-Some-Small-Project__抢答器.mwp"))
    assert zcd.program.encoding == "gbk"
    assert zcd.program.pous[0].name == "主程序"
    assert zcd.symbols is not None and zcd.symbols.lookup("复位按键").address == "I0.3"


def test_smart_code_0x2db_is_the_mul_di_box_of_its_network() -> None:
    """The one SMART statement of the corpus with code 0x2db follows a MOVD
    into the same double word, and its network's only arithmetic box is
    MUL_DI: the code is ``*D`` (MUL_DI compiles to MOVD IN1, OUT and *D IN2,
    OUT), as the code table says."""
    from plcrt.project.codes import OPCODES
    from plcrt.project.container import open_container
    path = _file("Kity23__test__项目 1.smart")
    stream = open_container(path.read_bytes(), str(path)).stream
    statement = b"\0\0\xdb\x02\x01\x01"
    at = stream.find(statement)
    assert at > 0 and stream.find(statement, at + 1) < 0
    before = stream.rfind(b"\0\0\x0e\x03\x01\x01", 0, at)          # MOVD
    assert 0 < before and at - before < 200
    network = stream[before - 400:stream.find(b"Time_Out", at) + 2000]
    boxes = {name for name in (b"MUL_DI", b"MUL_I", b"MUL", b"DIV_DI", b"ADD_DI")
             if b"\x00" + name + b"\x00" in network or bytes([len(name)]) + name in network}
    assert boxes == {b"MUL_DI"}
    assert OPCODES[0x2DB] == "*D"
