"""``plcrt run/check --plant``: simulated EM253 modules from the command line.

The plant file attaches modules to the CPU; ``run`` then reports every
configured axis (a table after the watch values, or ``"axes"`` in the JSON
object) and prints the warnings the library blocks raise while running.
A broken plant file is an input error: exit status 1 and one clear line,
never a traceback.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from plcrt.cli import main

EM253 = Path(__file__).resolve().parents[2] / "programs" / "em253"
POS_GOTO_R = str(EM253 / "pos_goto_r.awl")
PLANT = str(EM253 / "plant.toml")
AXIS_KEYS = {"slot", "axis", "position", "mechanical", "speed", "status"}


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def write(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


# ---------------------------------------------------------------------------
# --json: "axes"
# ---------------------------------------------------------------------------

def test_run_json_has_the_axes(capsys: pytest.CaptureFixture[str]) -> None:
    # the command of the README: the manual's POS_GOTO_R move, 17 s long
    code, out, err = run_cli(capsys, "run", POS_GOTO_R, "--plant", PLANT, "--seconds", "18",
                             "--set", "M2.0=1", "--json")
    assert code == 0 and err == ""
    obj = json.loads(out)
    assert obj["scans"] == 1800 and obj["mode"] == "RUN"
    axes = obj["axes"]
    assert [(a["slot"], a["axis"]) for a in axes] == [(0, 0), (0, 1)]
    assert all(AXIS_KEYS <= set(a) for a in axes)
    assert {k: axes[0][k] for k in AXIS_KEYS} == {
        "slot": 0, "axis": 0, "position": 1_000_000, "mechanical": 1_000_000,
        "speed": 0, "status": "stopped"}
    assert axes[1]["position"] == 0


def test_run_json_while_moving(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(capsys, "run", POS_GOTO_R, "--plant", PLANT, "--seconds", "10",
                           "--set", "M2.0=1", "--watch", "VD108", "--json")
    assert code == 0
    obj = json.loads(out)
    ax = obj["axes"][0]
    # 4.8 s ramp (204 000 pulses) + 5.2 s at 80 kHz; C_Pos is from the
    # last scan start, 10 ms earlier
    assert (ax["position"], ax["speed"], ax["status"]) == (620_000, 80_000, "moving")
    assert obj["values"] == {"VD108": 619_200}


def test_run_json_without_plant_has_no_axes(capsys: pytest.CaptureFixture[str]) -> None:
    seal_in = str(EM253.parent / "seal_in.awl")
    code, out, _ = run_cli(capsys, "run", seal_in, "--scans", "1", "--json")
    assert code == 0
    assert "axes" not in json.loads(out)


def test_run_json_with_data_block(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "run", str(EM253 / "pos_run.awl"),
                             "--data", str(EM253 / "pos_run.db"), "--plant", PLANT,
                             "--seconds", "70", "--set", "M3.0=1",
                             "--watch", "VB316", "--watch", "VW306", "--json")
    assert code == 0
    obj = json.loads(out)
    assert obj["values"] == {"VB316": 7, "VW306": 8}
    assert obj["axes"][1]["position"] == 1_530_000
    # the block's run-time warning goes to stderr, GNU-style with its line
    assert f"{EM253 / 'pos_run.awl'}:" in err
    assert "POS_RUN: SpdSet 500000 Hz is above the single-ended output limit" in err


# ---------------------------------------------------------------------------
# plain output: the axes table after the watch values
# ---------------------------------------------------------------------------

def test_run_prints_an_axes_table(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "run", POS_GOTO_R, "--plant", PLANT, "--seconds", "18",
                             "--set", "M2.0=1", "--watch", "VW106", "--watch", "VD108")
    assert code == 0 and err == ""
    assert out.splitlines() == [
        f"{POS_GOTO_R}: 1800 scan(s), 18 s simulated, mode RUN",
        "address  value",
        "VW106    8",
        "VD108    1000000",
        "slot  axis  position  mechanical  speed  status",
        "   0     0   1000000     1000000      0  stopped",
        "   0     1         0           0      0  stopped",
    ]


def test_run_axes_table_shows_sevon_and_negative_speed(
        capsys: pytest.CaptureFixture[str]) -> None:
    spd_ctrl = str(EM253 / "spd_ctrl.awl")
    # axis 0 in reverse (M1.1 = 0), axis 1 forward but masked by SevOn1 (M0.2)
    code, out, _ = run_cli(capsys, "run", spd_ctrl, "--plant", PLANT, "--seconds", "1.5",
                           "--set", "M1.0=1", "--set", "M1.3=1", "--set", "M1.4=1",
                           "--set", "M0.2=1")
    assert code == 0
    lines = out.splitlines()
    assert lines[1].split() == ["slot", "axis", "position", "mechanical", "speed", "status"]
    assert lines[2].split() == ["0", "0", "-24375", "-24375", "-27500", "moving"]
    # the counter counts, the machine stays put while SevOn masks the pulses
    assert lines[3].split() == ["0", "1", "25312", "0", "28750", "moving", "(SevOn)"]


def test_run_without_axes_in_the_plant(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    plant = write(tmp_path, "empty.toml", "# no modules\n")
    code, out, err = run_cli(capsys, "run", POS_GOTO_R, "--plant", plant, "--scans", "1")
    assert code == 0
    assert out.splitlines()[-1] == "axes: none configured in the plant"
    # without a module the blocks say so while running
    assert "MOTION_EN3: no EM253 module in slot 0" in err


# ---------------------------------------------------------------------------
# broken plant files: exit 1, a clear message, no traceback
# ---------------------------------------------------------------------------

BAD_PLANTS = [
    ("[module.0.axis.0\nstart = 1\n", "bad.toml: "),                          # TOML syntax
    ("[modules.0.axis.0]\nstart = 1\n", "unknown key(s) modules"),
    ("[module.0]\nkinds = 'EM253'\n", "module.0: unknown key(s) kinds"),
    ("[module.0.axis.0]\nstrat = 1\n", "module.0.axis.0: unknown key(s) strat"),
    ("[module.0.axis.2]\n", "an EM253 has axes 0 and 1"),
    ("[module.9]\n", "the slot (EmNo) must be 0..6"),
    ("[module.0]\nkind = 'EM235'\n", "unknown module kind 'EM235'"),
    ("[module.0]\naxis = 3\n", "module.0.axis must be a table"),
    ("[module.0.axis]\n0 = 5\n", "module.0.axis.0 must be a table"),
    ("[module]\n0 = 5\n", "module.0 must be a table"),
    ("[module.0.axis.0]\nstart = 'left'\n", "start must be an integer"),
    ("[module.0.axis.0]\nrps = [20000, 10000]\n", "low 20000 is above high 10000"),
    ("[module.0.axis.0]\nevents = 1\n", "events must be a list"),
    ("[module.0.axis.0]\nevents = [{ at = 1.0 }]\n", "needs at (seconds), input and value"),
    ("[module.0.axis.0]\nevents = [{ at = 1.0, input = 'STF', value = 'false' }]\n",
     "value must be true or false"),
    ("[module.0.axis.0]\nevents = [{ at = nan, input = 'STF', value = true }]\n",
     "at must be a finite number"),
]


@pytest.mark.parametrize("text, message", BAD_PLANTS,
                         ids=[m for _, m in BAD_PLANTS])
def test_run_bad_plant_file(text: str, message: str, tmp_path: Path,
                            capsys: pytest.CaptureFixture[str]) -> None:
    plant = write(tmp_path, "bad.toml", text)
    code, out, err = run_cli(capsys, "run", POS_GOTO_R, "--plant", plant, "--scans", "1")
    assert code == 1 and out == ""
    assert message in err
    assert "internal error" not in err
    assert err.startswith(f"plcrt: error: {plant}: ")


def test_run_bad_plant_file_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    plant = write(tmp_path, "bad.toml", "[module.0.axis.0]\nstrat = 1\n")
    code, out, _ = run_cli(capsys, "run", POS_GOTO_R, "--plant", plant, "--scans", "1",
                           "--json")
    assert code == 1
    obj = json.loads(out)
    assert "unknown key(s) strat" in obj["error"]
    assert "axes" not in obj


def test_run_missing_and_unreadable_plant_file(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    missing = str(tmp_path / "nope.toml")
    code, _, err = run_cli(capsys, "run", POS_GOTO_R, "--plant", missing, "--scans", "1")
    assert code == 1 and f"{missing}: cannot read plant file" in err
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00[module")
    code, _, err = run_cli(capsys, "run", POS_GOTO_R, "--plant", str(binary), "--scans", "1")
    assert code == 1 and "not UTF-8 text" in err
    code, _, err = run_cli(capsys, "run", POS_GOTO_R, "--plant", str(tmp_path), "--scans", "1")
    assert code == 1 and "cannot read plant file" in err


def test_check_validates_the_plant_file(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "check", POS_GOTO_R, "--plant", PLANT)
    assert code == 0 and "0 errors, 0 warnings" in err
    plant = write(tmp_path, "bad.toml", "[module.0.axis.0]\nlimit_neg = 5\nlimit_pos = 5\n")
    code, _, err = run_cli(capsys, "check", POS_GOTO_R, "--plant", plant)
    assert code == 1 and "limit_neg must be below limit_pos" in err


def test_dump_takes_and_validates_the_plant_file(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    """dump reads a program with the options of check and run: a good plant
    file leaves the dump unchanged, a broken one is an input error."""
    code, plain, _ = run_cli(capsys, "dump", POS_GOTO_R)
    assert code == 0
    code, out, err = run_cli(capsys, "dump", POS_GOTO_R, "--plant", PLANT)
    assert (code, out, err) == (0, plain, "")
    plant = write(tmp_path, "bad.toml", "[module.0.axis.0]\nlimit_neg = 5\nlimit_pos = 5\n")
    code, out, err = run_cli(capsys, "dump", POS_GOTO_R, "--plant", plant)
    assert code == 1 and out == "" and "limit_neg must be below limit_pos" in err
