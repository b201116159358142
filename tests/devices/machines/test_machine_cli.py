"""``plcrt run --plant`` with machines: the same model as the harness, the
machines' state in --json and a table, and --press / --hold / --fault."""

from __future__ import annotations

import json

import pytest

import plcrt
from plcrt.cli import main

from machine_helpers import EXAMPLES


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_run_json_holds_the_same_state_as_the_api(capsys) -> None:
    code, out, _ = run_cli(capsys, "run", str(EXAMPLES / "tank.awl"), "--plant",
                           str(EXAMPLES / "tank.toml"), "--seconds", "30",
                           "--press", "tank.start", "--fault", "tank.leak", "--json")
    assert code == 0
    [state] = json.loads(out)["machines"]
    plc = plcrt.load(EXAMPLES / "tank.awl", plant=EXAMPLES / "tank.toml")
    tank = plc.machine("tank")
    tank.fault("leak")
    tank.press("start")
    plc.run(seconds=30)
    assert state == json.loads(json.dumps(tank.state()))
    assert state["faults"] == ["leak"] and state["leaked"] > 0


def test_run_prints_a_line_per_machine(capsys) -> None:
    code, out, _ = run_cli(capsys, "run", str(EXAMPLES / "garage.awl"), "--plant",
                           str(EXAMPLES / "garage.toml"), "--seconds", "3",
                           "--hold", "garage.key", "--press", "garage.button_open")
    assert code == 0
    line = [ln for ln in out.splitlines() if ln.startswith("garage ")][0]
    assert line.split() == ["garage", "garage", "safety_edge", "key", "motor_open", "lamp",
                            "-", "0"]


@pytest.mark.parametrize("args, message", [
    (["--press", "garage.go"], "machine garage has no button 'go'"),
    (["--press", "lift.call_1"], "no machine 'lift' in the plant"),
    (["--fault", "garage"], "--fault 'garage': write MACHINE.FAULT"),
    (["--fault", "garage.melt"], "machine garage has no fault 'melt'"),
])
def test_bad_machine_options_are_errors(capsys, args, message) -> None:
    code, _, err = run_cli(capsys, "run", str(EXAMPLES / "garage.awl"), "--plant",
                           str(EXAMPLES / "garage.toml"), "--seconds", "1", *args)
    assert code == 1 and message in err
