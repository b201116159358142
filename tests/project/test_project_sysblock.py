"""The system block of a project file (plcrt.project.sysblock): read back
as written, applied to the PLC, refused where a value is not known, and
plausible in the public projects of the corpus.

The projects are written by the tests' writer (tests/project_writer.py
with tests/sysblock_writer.py); the corpus is read where it is present.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

import plcrt
from plcrt.errors import PlcConfigError, PlcError
from plcrt.lang.stl import parse_program
from plcrt.project import read_project
from plcrt.project.container import open_container
from plcrt.project.reader import _program_cursor
from plcrt.project.sysblock import read_system_block

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from project_writer import project_bytes  # noqa: E402
from sysblock_writer import smart_block, v4_block  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT.parent / "shared" / "corpus" / "mwp"
PROGRAM = parse_program((ROOT / "programs" / "seal_in.awl").read_text(), "seal_in.awl")
DATA = [("VW100", [1500], "set point"), ("VW200", [42], "")]


def _write(tmp_path: Path, smart: bool, system: bytes, name: str = "p") -> Path:
    path = tmp_path / (name + (".smart" if smart else ".mwp"))
    path.write_bytes(project_bytes(PROGRAM, smart=smart, data=DATA, system=system))
    return path


def test_v4_settings_are_read_back(tmp_path: Path) -> None:
    ranges = (("V", 100, 4), ("M", 0, 14), ("T", 0, 32), ("C", 10, 5))
    system = read_project(_write(tmp_path, False, v4_block(
        ranges, addresses=(3, 7), baud=(4, 0), pulse_catch=(1, 9))).read_bytes(), "p.mwp").system
    assert system is not None and system.version == 0x010E
    assert [str(r) for r in system.settings.ranges] == ["VB100:4", "MB0:14", "T0:32", "C10:5"]
    assert system.settings.startup is None           # an S7-200 starts by its mode switch
    assert system.settings.addresses == {0: 3, 1: 7}
    assert system.baud == {0: 187500, 1: 9600}
    assert system.pulse_catch == [1, 9]
    assert system.filters[0] == "I0.0-I0.3: 6.4 ms" and len(system.filters) == 6
    assert "pulse catch: I0.1, I1.1" in system.lines()


@pytest.mark.parametrize("startup", ["RUN", "STOP", "LAST"])
def test_smart_settings_are_read_back(tmp_path: Path, startup: str) -> None:
    data = _write(tmp_path, True, smart_block(
        [("V", 0, 100), ("M", 2, 3)], startup=startup, address=5, baud=2, cpu=(0x01, 0x06),
        firmware="V02.07.00_00.00.01.00", inputs=36, filter_code=9, pulse_catch=(0, 35))
    ).read_bytes()
    project = read_project(data, "p.smart")
    system = project.system
    assert system is not None and system.version == 0x060F
    assert [str(r) for r in system.settings.ranges] == ["VB0:100", "MB2:3"]
    assert system.settings.startup == startup and system.settings.addresses == {0: 5}
    assert system.baud == {0: 19200}
    assert (system.cpu, system.firmware) == ("CPU SR60", "V02.07.00_00.00.01.00")
    assert system.filters[0] == "I0.0: 12.8 ms" and len(system.filters) == 36
    assert system.pulse_catch == [0, 35]
    assert project.notes == []


def test_project_settings_change_what_a_power_cycle_keeps(tmp_path: Path) -> None:
    """A retentive VW survives, a non-retentive one comes back from the
    data block or is cleared, port addresses reach GPA's table."""
    path = _write(tmp_path, False, v4_block((("V", 100, 2), ("M", 0, 1)), addresses=(4, 2)))
    plc = plcrt.load(path)
    assert [str(r) for r in plc.retentive] == ["VB100:2", "MB0:1"]
    assert plc.station.addresses[0] == 4
    assert (plc["VW100"], plc["VW200"]) == (1500, 42)
    plc["VW100"], plc["VW200"], plc["VW300"], plc["MB0"], plc["MB1"] = 1, 2, 3, 4, 5
    plc.power_cycle()
    assert (plc["VW100"], plc["VW200"], plc["VW300"]) == (1, 42, 0)
    assert (plc["MB0"], plc["MB1"]) == (4, 0)


@pytest.mark.parametrize("startup, mode", [("STOP", "STOP"), ("RUN", "RUN")])
def test_a_smart_startup_mode_applies_at_power_up(tmp_path: Path, startup: str,
                                                  mode: str) -> None:
    plc = plcrt.load(_write(tmp_path, True, smart_block(startup=startup)))
    assert plc.mode == "RUN" and plc.startup == startup and plc.retentive == ()
    plc["VW300"] = 3
    plc.set_mode("STOP" if mode == "RUN" else "RUN")
    plc.power_cycle()
    assert plc.mode == mode and plc["VW300"] == 0


def test_the_plant_file_overrides_the_system_block(tmp_path: Path) -> None:
    path = _write(tmp_path, True, smart_block([("V", 0, 10)], startup="STOP"))
    plc = plcrt.load(path, plant={"cpu": {"retentive": ["VB300:2"]}})
    assert [str(r) for r in plc.retentive] == ["VB300:2"] and plc.startup == "STOP"


def test_a_project_range_past_the_cpu_is_clipped(tmp_path: Path) -> None:
    """Micro/WIN's default V range of a CPU with more V memory is kept as
    far as the CPU the program runs on has V memory."""
    path = _write(tmp_path, False, v4_block((("V", 0, 10240), ("V", 9000, 100))))
    plc = plcrt.load(path, cpu="CPU 224")
    assert [str(r) for r in plc.retentive] == ["VB0:8192", "VB8192:0"]


def test_without_a_system_block_a_note_says_the_defaults_apply(tmp_path: Path) -> None:
    project = read_project(_write(tmp_path, False, b"").read_bytes(), "p.mwp")
    assert project.system is None
    assert project.notes == ["the system block was not read (a Micro/WIN V4 system block "
                             "(version 0x010e) was not found before the program block): the "
                             "defaults apply (retentive ranges, start-up in RUN)"]
    plc = plcrt.load(_write(tmp_path, False, b""), cpu="CPU 224")
    assert [str(r) for r in plc.retentive][0] == "VB0:8192"


def _v4_with(offset: int, value: bytes) -> bytes:
    block = bytearray(v4_block())
    block[offset:offset + len(value)] = value
    return bytes(block)


#: where the written block starts in the stream (the writer's filler)
START = 65
#: the V4 block's retentive ranges (after the version, the password and
#: the outputs' STOP table, and a marker byte) and port 0's address
RANGES, PORT0 = 0x215, 0x28E


@pytest.mark.parametrize("smart, system, message, offset", [
    (False, _v4_with(RANGES, b"\x00\x00\x00\x00\x02\x00\x00\x00\x11"),
     "retentive range 0: memory area 0x11 with data width 2 is not one this reader knows",
     RANGES),
    (False, _v4_with(RANGES + 8, b"\x40"),
     "retentive range 0: memory area 0x40 with data width 2", RANGES),
    (False, _v4_with(RANGES + 12, b"\x00\x00\x01\x00"),
     "retentive range 0: offset 65536 and count 8192 lie outside any CPU's memory", RANGES),
    (False, _v4_with(RANGES - 1, b"\x07"), "marker before the retentive ranges: expected 0x1, "
     "found 0x7", RANGES - 1),
    (False, _v4_with(PORT0, b"\xc8"), "port 0: station address 200 is outside 0..126", PORT0),
    (True, smart_block(startup=7), "start-up mode 7 is not STOP (0), RUN (1) or LAST (2)",
     None),
    (True, smart_block(cpu=(0x00, 0x09)), "CPU type 0x00 0x09 is not one this reader knows",
     None),
    (True, smart_block(cpu2=(0x01, 0x04)), "the CPU type is given twice, differently", None),
    (True, smart_block(filter_code=0x3F),
     "input filter code 63 of I0.0 is not one this reader knows", None),
])
def test_unknown_values_are_refused_at_their_offset(tmp_path: Path, smart: bool,
                                                    system: bytes, message: str,
                                                    offset: int | None) -> None:
    path = _write(tmp_path, smart, system)
    with pytest.raises(PlcConfigError, match=re.escape(message)) as err:
        plcrt.load(path)
    text = str(err.value)
    assert f"{path.name}" in text and "[system block]" in text
    if offset is not None:
        assert f"(system block, byte 0x{START + offset:x} of the decompressed project)" in text


def _corpus(pattern: str) -> list[Path]:
    if not CORPUS.is_dir():
        return []
    return sorted(CORPUS.glob(pattern))


def _system(path: Path):
    box = open_container(path.read_bytes(), str(path))
    return read_system_block(box.stream, str(path), box.format, _program_cursor(box).pos)


#: V memory of the S7-200 CPUs (S7-200 System Manual, appendix A; the
#: CPU 216 of Micro/WIN V3 projects: 5120 bytes)
V_BYTES = {"CPU 216": 5120, "CPU 221": 2048, "CPU 222": 2048, "CPU 224": 8192,
           "CPU 224XP": 10240, "CPU 226": 10240}


@pytest.mark.skipif(not CORPUS.is_dir(), reason="the shared corpus is absent")
@pytest.mark.parametrize("path", _corpus("*.mwp"), ids=lambda p: p.name[:40])
def test_corpus_mwp_system_blocks_are_plausible(path: Path) -> None:
    """Each V4 and V3 project holds Micro/WIN's default retentive ranges for
    its CPU: V over the whole V memory of the CPU the project names,
    MB14..MB31, the TONR timers, all counters.  A V4 block also: both ports
    at address 2, 9.6 kbaud, every filter 6.4 ms, no pulse catch."""
    data = path.read_bytes()
    try:
        project = read_project(data, str(path))
    except PlcError as e:            # the V3 project with an incomplete network
        pytest.skip(f"the project is refused: {e.message[:60]}")
    system = project.system
    assert system is not None, project.notes
    cpu = re.match(r"CPU \d+(XP)?", project.cpu)[0]
    assert sorted(map(str, system.settings.ranges)) == sorted(
        [f"VB0:{V_BYTES[cpu]}", "T0:32", "T64:32", "C0:256", "MB14:18"])
    if data[:8] == b"GJK\0R03.":
        assert system.version == 0 and not system.settings.addresses
        return
    assert system.settings.addresses == {0: 2, 1: 2} and system.baud == {0: 9600, 1: 9600}
    assert set(f.split(": ")[1] for f in system.filters) == {"6.4 ms"}
    assert system.pulse_catch == []


@pytest.mark.skipif(not CORPUS.is_dir(), reason="the shared corpus is absent")
@pytest.mark.parametrize("path", _corpus("*.smart"), ids=lambda p: p.name[:40])
def test_corpus_smart_system_blocks_are_plausible(path: Path) -> None:
    """SMART's default system block: nothing retentive, start-up in STOP,
    port 0 at address 2, 9.6 kbaud; the CPU type agrees with the CPU the
    project names after its data block (CPU ST40, 24 inputs at 6.4 ms),
    and the firmware is a version text."""
    system, note = _system(path)
    assert system is not None, note
    assert system.settings.ranges == () and system.settings.startup == "STOP"
    assert system.settings.addresses == {0: 2} and system.baud == {0: 9600}
    stream = open_container(path.read_bytes(), str(path)).stream
    assert system.cpu == "CPU ST40" and b"\x00\x08\x00CPU ST40" in stream
    assert re.fullmatch(r"V\d\d\.\d\d\.\d\d_\d\d\.\d\d\.\d\d\.\d\d", system.firmware)
    assert len(system.filters) == 24 and set(f.split(": ")[1] for f in system.filters) == {
        "6.4 ms"}


@pytest.mark.skipif(not CORPUS.is_dir(), reason="the shared corpus is absent")
def test_a_corpus_project_loads_with_its_system_block() -> None:
    path = CORPUS / "zcdlab__MCU-PLC-Some-Small-Project__抢答器.mwp"
    if not path.exists():
        pytest.skip("file absent")
    plc = plcrt.load(path, cpu="CPU 221")
    assert [str(r) for r in plc.retentive] == ["VB0:2048", "T0:32", "T64:32", "C0:256",
                                               "MB14:18"]


def test_port_settings_reach_the_ports_unless_the_plant_file_sets_them(tmp_path: Path) -> None:
    """The system block's station address and PPI rate are the port's
    (NETR/NETW, GPA); a [port.N] table of the plant file sets its port."""
    path = _write(tmp_path, False, v4_block(addresses=(4, 9), baud=(4, 0)))
    plc = plcrt.load(path, cpu="CPU226")        # the project's CPU 224 has one port
    assert [(p.address, p.ppi_baud) for p in plc.ports] == [(4, 187500), (9, 9600)]
    assert plc.station.addresses == {0: 4, 1: 9}
    assert [p.address for p in plcrt.load(path).ports] == [4]
    plc = plcrt.load(path, plant={"port": {"0": {"address": 6}}}, cpu="CPU226")
    assert [(p.address, p.ppi_baud) for p in plc.ports] == [(6, 9600), (9, 9600)]
    assert plc.station.addresses[1] == 9
    plc.power_cycle()
    assert [p.address for p in plc.ports] == [6, 9]


def test_check_reports_the_system_block_and_the_cpu(tmp_path: Path, capsys) -> None:
    from plcrt.cli import main
    path = _write(tmp_path, True, smart_block([("V", 0, 100)], startup="LAST", pulse_catch=(2,)))
    assert main(["check", str(path), "--cpu", "CPU 224"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err[1:] == [f"{path}: system block: {line}" for line in (
        "retentive ranges: VB0:100", "start-up mode: LAST",
        "port 0: station address 2, baud rate 9600",
        "CPU: CPU ST40 firmware V02.05.00_00.00.07.00 (runs as CPU224; --cpu chooses)",
        "pulse catch: I0.2")]
    path = _write(tmp_path, False, v4_block(), "v4")
    assert main(["check", str(path)]) == 0
    assert (f"{path}: system block: CPU: CPU 224 REL 02.01 (runs as CPU224; --cpu chooses)"
            in capsys.readouterr().err)


@pytest.mark.parametrize("version", [0x0613, 0x0615], ids=["V3.0-V3.1", "V3.2"])
def test_a_smart_v3_system_block_member_is_read_and_applied(tmp_path: Path,
                                                           version: int) -> None:
    """A .smartV3 project's m_cSystemBlockData.bin (the SMART layout with
    V3's longer password record and CPU record 7) gives the same settings
    as a V2 system block, and a power cycle keeps its ranges."""
    import smartv3_writer
    system = smart_block([("V", 100, 2)], startup="RUN", address=6, cpu=(0x20, 0x03),
                         firmware="V03.02.00_00.00.00.00", version=version)
    path = tmp_path / "p.smartV3"
    path.write_bytes(smartv3_writer.project_bytes(PROGRAM, data=DATA, system=system))
    project = read_project(path.read_bytes(), str(path))
    assert project.system is not None and project.system.version == version
    assert [str(r) for r in project.system.settings.ranges] == ["VB100:2"]
    assert (project.system.settings.startup, project.system.settings.addresses) == ("RUN",
                                                                                    {0: 6})
    assert project.system.cpu == "CPU ST32" and project.notes == []
    plc = plcrt.load(path)
    plc["VW100"], plc["VW200"] = 7, 8
    plc.power_cycle()
    assert (plc["VW100"], plc["VW200"]) == (7, 42)


def test_a_smart_v3_project_without_its_system_block_says_the_defaults_apply(
        tmp_path: Path) -> None:
    import smartv3_writer
    path = tmp_path / "p.smartV3"
    path.write_bytes(smartv3_writer.project_bytes(PROGRAM, system=bytes(64)))
    project = read_project(path.read_bytes(), str(path))
    assert project.system is None
    assert any("defaults apply" in note for note in project.notes)


def test_a_build_is_shared_only_with_the_same_system_block(tmp_path: Path) -> None:
    """The same program under another system block is another build: a PLC
    made from the second load's compiled program powers up with its own
    ranges, not those of the first build in the cache."""
    path = tmp_path / "p.mwp"
    path.write_bytes(project_bytes(PROGRAM, system=v4_block((("V", 100, 2),))))
    first = plcrt.load(path)
    path.write_bytes(project_bytes(PROGRAM, system=v4_block((("V", 200, 4),))))
    second = plcrt.load(path)
    again = plcrt.Plc.from_program(second.compiled)
    assert [str(r) for r in first.retentive] == ["VB100:2"]
    assert [str(r) for r in again.retentive] == ["VB200:4"]
    assert second.compiled is not first.compiled


@pytest.mark.parametrize("text, model", [
    ("CPU 224 REL 02.01", "CPU224"), ("CPU 224XP REL 02.01", "CPU224XP"),
    ("CPU221", "CPU221"), ("cpu 222 rel 01.22", "CPU222"), ("CPU 226XM", "CPU226"),
    ("CPU 216", None), ("CPU ST40", None), ("", None), ("CPU 2245", None)])
def test_a_project_cpu_names_the_model_it_runs_as(text: str, model: str | None) -> None:
    from plcrt.memory.cpu import model_named
    assert model_named(text) == model


def test_a_project_runs_on_its_cpu_unless_told_otherwise(tmp_path: Path) -> None:
    """The writer's projects are for a CPU 224: 8 KiB of V memory and one
    port; cpu= gives another model; an export of the program runs as the
    default CPU 226."""
    path = _write(tmp_path, False, v4_block())
    plc = plcrt.load(path)
    assert (plc.model.name, len(plc.ports)) == ("CPU224", 1)
    with pytest.raises(PlcError, match="VB8192"):
        plc["VB8192"] = 1
    assert plcrt.load(path, cpu="CPU226").model.name == "CPU226"
    assert plcrt.load(ROOT / "programs" / "seal_in.awl").model.name == "CPU226"
