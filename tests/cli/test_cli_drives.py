"""Bus drives in the tools: ``plcrt run`` (table and JSON), ``plcrt trace``
(drive signals), ``plcrt debug`` (the ``drives`` command), and the test
harness (``drive()``, drive signals in the watch history and conditions).

A small program powers drive 1 (HCFA) through the fieldbus module's image
at VB1000 (controlword at VW1000, statusword at VW1032); drive 2 (Kinco)
stays as it powers up.  The expected values are the HCFA statuswords of
§7.2/§7.3 in PP (mode 1): 0x0631 ready to switch on, 0x0633 switched on,
0x8637 operation enabled and idle.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

from plcrt.cli import main
from plcrt.debug.session import Session
from plcrt.devices import DriveState
from plcrt.loader import load
from plcrt.errors import PlcAddressError, PlcConfigError
from plcrt.testing.harness import Harness

PLANT = """
[module.0]
kind = "FIELDBUS"
v = 1000
[module.0.drive.1]
model = "hcfa-am0520b"
[module.0.drive.2]
model = "kinco-servo"
"""

# Network 1 sets PP on the first scan; network 2 follows HCFA §7.2: 0x06,
# then 0x07 when ready to switch on, then 0x0F when switched on.
PROGRAM = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.1
MOVB   1, VB1002
MOVW   16#0006, VW1000
Network 2
LDW=   VW1032, 16#0631
MOVW   16#0007, VW1000
Network 3
LDW=   VW1032, 16#0633
MOVW   16#000F, VW1000
END_ORGANIZATION_BLOCK
"""


@pytest.fixture()
def files(tmp_path: Path) -> tuple[str, str]:
    prog = tmp_path / "power.awl"
    prog.write_text(PROGRAM, encoding="utf-8")
    plant = tmp_path / "bus.toml"
    plant.write_text(PLANT, encoding="utf-8")
    return str(prog), str(plant)


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def test_run_prints_a_table_of_the_drives_with_the_statusword_decoded(files, capsys):
    prog, plant = files
    code, out, _ = run_cli(capsys, "run", prog, "--plant", plant, "--scans", "5")
    assert code == 0
    lines = out.splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith("slot  node"))
    assert lines[head].split() == ["slot", "node", "model", "mode", "position", "velocity",
                                   "statusword", "state"]
    hcfa, kinco = lines[head + 1].split(None, 7), lines[head + 2].split(None, 7)
    assert hcfa == ["0", "1", "hcfa-am0520b", "PP", "0", "0", "0x8637",
                    "OPERATION ENABLED (target reached)"]
    assert kinco == ["0", "2", "kinco-servo", "none", "0", "0", "0x0250", "SWITCH ON DISABLED"]
    assert "axes: none" not in out


def test_run_json_has_the_drives(files, capsys):
    prog, plant = files
    code, out, _ = run_cli(capsys, "run", prog, "--plant", plant, "--scans", "5", "--json")
    assert code == 0
    obj = json.loads(out)
    d1, d2 = obj["drives"]
    assert d1 == {"slot": 0, "node": 1, "model": "hcfa-am0520b",
                  "state": "OPERATION ENABLED", "statusword": 0x8637, "controlword": 0x0F,
                  "mode": 1, "position": 0, "velocity": 0, "following_error": 0,
                  "error_code": 0, "online": True, "flags": ["target reached"]}
    assert d2["state"] == "SWITCH ON DISABLED" and d2["flags"] == []
    assert obj["axes"] == []


def test_trace_records_drive_signals_scan_by_scan(files, capsys, tmp_path):
    prog, plant = files
    csv = tmp_path / "t.csv"
    code, _, _ = run_cli(capsys, "trace", prog, "--plant", plant, "--scans", "4",
                         "--signal", "drive1.statusword", "--signal", "drive0.1.controlword",
                         "--csv", str(csv))
    assert code == 0
    rows = [line.split(",") for line in csv.read_text().splitlines()]
    assert rows[0][1:] == ["drive1.statusword", "drive0.1.controlword"]
    # after scan 1 the drive took 0x06; after scan 2 0x07; after scan 3 0x0F
    assert [int(r[1]) for r in rows[1:]] == [0x0631, 0x0633, 0x8637, 0x8637]
    assert [int(r[2]) for r in rows[1:]] == [0x06, 0x07, 0x0F, 0x0F]


@pytest.mark.parametrize("signal, fragment", [
    ("drive1.torque", "quantity position|velocity"),
    ("drive9.position", "no drive at node 9"),
    ("drive3.1.position", "no drive at node 1 on the module in slot 3"),
])
def test_trace_rejects_a_bad_drive_signal_clearly(files, capsys, signal, fragment):
    prog, plant = files
    code, out, err = run_cli(capsys, "trace", prog, "--plant", plant, "--scans", "1",
                             "--signal", signal)
    assert code == 1
    assert fragment in err


def test_debugger_drives_command_shows_the_drive_table(files):
    prog, plant = files
    plc = load(prog, plant=plant, instrument=True)
    out = io.StringIO()
    s = Session(plc, out=out)
    assert "2 drive(s)" in s.banner()
    s.execute("run 5")
    s.execute("drives")
    text = out.getvalue()
    assert "0x8637" in text and "OPERATION ENABLED (target reached)" in text
    assert "kinco-servo" in text


def test_debugger_drives_command_without_drives_says_so(tmp_path):
    prog = tmp_path / "p.awl"
    prog.write_text(PROGRAM, encoding="utf-8")
    out = io.StringIO()
    s = Session(load(str(prog), instrument=True), out=out)
    s.execute("drives")
    assert out.getvalue().splitlines()[-1] == "no drives (load a --plant with a FIELDBUS module)"


def test_harness_reads_drives_and_watches_their_signals(files):
    prog, plant = files
    h = Harness.load(prog, plant=plant, watch=["drive1.statusword", "VW1000"])
    h.run_until("drive1.statusword == 16#8637", timeout="1s")
    assert h.scans == 3
    d = h.drive(1)
    assert isinstance(d, DriveState)
    assert (d.state, d.mode_name, d.flags, d.fault) == (
        "OPERATION ENABLED", "PP", ["target reached"], False)
    assert d["statusword"] == 0x8637 and dict(d)["node"] == 1
    assert [row[2] for row in h.history_rows()] == [(0x0631, 6), (0x0633, 7), (0x8637, 15)]
    assert [x.node for x in h.drives()] == [1, 2]


def test_a_fork_carries_its_own_drives(files):
    prog, plant = files
    plc = load(prog, plant=plant)
    plc.scan(1)
    twin = plc.fork()
    twin.scan(2)
    assert twin.drive(1).statusword == 0x8637
    assert plc.drive(1).statusword == 0x0631   # the original did not move on


@pytest.mark.parametrize("args, error", [
    ((True,), PlcAddressError), (("1",), PlcAddressError), ((1, "0"), PlcAddressError),
    ((5,), PlcAddressError),
])
def test_plc_drive_rejects_bad_names(files, args, error):
    prog, plant = files
    with pytest.raises(error):
        load(prog, plant=plant).drive(*args)


def test_a_plant_with_an_unknown_drive_model_is_a_located_error(tmp_path):
    prog = tmp_path / "p.awl"
    prog.write_text(PROGRAM, encoding="utf-8")
    with pytest.raises(PlcConfigError) as e:
        load(str(prog), plant=PLANT.replace("kinco-servo", "acme-9000"))
    assert "module.0.drive.2.model" in e.value.message and "acme-9000" in e.value.message


def test_run_on_a_terminal_draws_the_drive_table_with_rich(files, capsys, monkeypatch):
    import sys
    prog, plant = files
    monkeypatch.setattr(sys.stdout, "isatty", lambda: True)
    monkeypatch.setenv("COLUMNS", "160")       # a wide terminal: no cell is wrapped
    code, out, _ = run_cli(capsys, "run", prog, "--plant", plant, "--scans", "5")
    assert code == 0
    assert "0x8637" in out and "kinco-servo" in out
    assert "│" in out or "┃" in out       # a rich table, not the plain one
