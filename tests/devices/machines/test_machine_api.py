"""What tests and a page use of a machine: the harness and the pytest
marker, forks and snapshots, the JSON state, and the machines as devices
of the one time line: a timed interrupt inside a scan reads the exact
level, and where events cut a scan changes nothing (docs/machines.md)."""

from __future__ import annotations

import json

import pytest

import plcrt
from plcrt.testing import Harness

from machine_helpers import EXAMPLES, MANUAL, manual, outputs

#: the manual program with a 1 ms timed interrupt that adds AIW0 into VD100
#: and counts its runs in VW104
SAMPLED = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.1
MOVB   1, SMB34
ATCH   INT_0, 10
ENI
Network 2
LD     SM0.0
MOVB   VB0, QB0
END_ORGANIZATION_BLOCK
INTERRUPT_BLOCK INT_0:INT0
BEGIN
Network 1
LD     SM0.0
ITD    AIW0, AC1
+D     AC1, VD100
INCW   VW104
END_INTERRUPT_BLOCK
"""


def test_a_timed_interrupt_reads_the_level_of_its_own_millisecond() -> None:
    # 1 mL per ms into 32000 mL: AIW0 counts the millilitres
    plc = plcrt.load(SAMPLED, plant={"machine": {"tank": {
        "capacity": 32000, "inflow": 1000, "low": 100, "high": 200}}})
    plc["VB0"] = 1
    plc.run(seconds=0.1)
    n = plc["VW104"]
    assert n == 100
    # the routine at k ms read k: the sum of 1..n, not ten steps of a scan
    assert plc["VD100"] == n * (n + 1) // 2


def test_where_events_cut_the_scan_changes_nothing() -> None:
    runs = []
    for program in (MANUAL, SAMPLED):
        plc = plcrt.load(program, plant={"machine": {"conveyor": {"speed": 333,
                                                                  "interval": 1.3}}})
        m = plc.machine("conveyor")
        outputs(plc, m, motor=1, gate=1, divert=1)
        plc.run(seconds=20)
        runs.append((m.edges(), m.state()["bins"], m.state()["parts"]))
    assert runs[0] == runs[1]


def test_harness_machine_presses_and_waits() -> None:
    h = Harness.load(EXAMPLES / "garage.awl", plant={"machine": {"garage": {}}})
    door = h.machine("garage")
    door.hold("key")
    door.press("button_open")
    took = h.run_until(lambda: door.state()["inputs"]["limit_open"], timeout=20)
    assert took == pytest.approx(2390 / 200, abs=0.011)
    assert h["Q0.0"] == 1      # the scan that saw the limit has not run yet
    h.scan()
    assert h["Q0.0"] == 0


@pytest.mark.plc("../../../examples/machines/tank.awl",
                 plant="../../../examples/machines/tank.toml")
def test_the_plc_fixture_hands_out_the_machine(plc) -> None:
    tank = plc.machine("tank")
    tank.press("start")
    plc.run_until("I0.1", timeout=60)          # the high switch
    assert tank.state()["volume"] == pytest.approx(90_000, abs=20)


def test_fork_and_restore_copy_the_machine() -> None:
    plc, m = manual("conveyor")
    outputs(plc, m, motor=1, gate=0)
    plc.run(seconds=3)
    snap = plc.snapshot()
    twin = plc.fork()
    state = m.state()
    plc.run(seconds=5)
    assert m.state() != state
    assert twin.machine("conveyor").state() == state
    plc.restore(snap)
    assert m.state() == state              # the same Machine sees the restored device
    twin.machine("conveyor").fault("jam")
    assert "jam" not in m.state()["faults"]


@pytest.mark.parametrize("kind", ["conveyor", "tank", "traffic", "garage", "elevator"])
def test_the_state_is_plain_json_of_numbers_booleans_and_names(kind: str) -> None:
    plc, m = manual(kind, faults=[m for m in ("jam", "leak", "door_jam")
                                  if m in plcrt.load(MANUAL, plant={"machine": {kind: {}}})
                                  .machine(kind).faults()])
    plc["VB0"] = 0x55
    plc.run(seconds=7)

    def check(x, depth=0):
        assert depth < 5
        if isinstance(x, dict):
            for k, v in x.items():
                assert isinstance(k, str) and k.replace("_", "").isalnum()
                check(v, depth + 1)
        elif isinstance(x, list):
            assert len(x) <= 1000
            for v in x:
                check(v, depth + 1)
        elif isinstance(x, str):
            assert len(x) <= 40 and x.replace("_", "").replace(":", "").isalnum()
        else:
            assert isinstance(x, (bool, int, float))
    s = m.state()
    check(s)
    assert json.loads(json.dumps(s, allow_nan=False)) == s
    assert s["kind"] == kind and s["t"] == 7.0


def test_an_edge_interrupt_on_an_eye_runs_once_per_part() -> None:
    # INT_0 on event 0 (I0.0 rising: the entry eye) counts parts in VW100
    # and keeps the scan count it ran in (SMW22 is no clock: VW102 counts scans)
    program = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.1
ATCH   INT_0, 0
ENI
Network 2
LD     SM0.0
MOVB   VB0, QB0
INCW   VW102
END_ORGANIZATION_BLOCK
INTERRUPT_BLOCK INT_0:INT0
BEGIN
Network 1
LD     SM0.0
INCW   VW100
MOVW   VW102, VW104
END_INTERRUPT_BLOCK
"""
    plc = plcrt.load(program, plant={"machine": {"conveyor": {"interval": 1.0}}})
    m = plc.machine("conveyor")
    outputs(plc, m, motor=1, gate=1)
    plc.run(seconds=5.005)
    rising = [t for t, s, v in m.edges("eye_entry") if v]
    assert rising == [1.1, 2.1, 3.1, 4.1]
    assert plc["VW100"] == 4
    # the last ran at the start of the scan at 4.1 s (after 410 scans, before
    # OB1 counted this one): the first scan start at or after the edge
    assert plc["VW104"] == 410


def test_stuck_and_broken_wires_on_outputs_and_inputs() -> None:
    plc, m = manual("tank", faults=["stuck_on:inlet"])
    plc.run(seconds=1)                       # a welded contact: the inlet runs, Q0.0 is off
    assert m.state()["volume"] == 2000 and m.state()["outputs"]["inlet"] == 1
    assert plc["Q0.0"] == 0
    m.fault("broken:inlet")                  # a broken wire wins over the welded contact
    plc.run(seconds=1)
    assert m.state()["volume"] == 2000
    m.fault("stuck_on:level")                # an analog input stuck at full scale
    m.fault("stuck_off:low")
    plc.run(scans=1)
    assert plc["AIW0"] == 32000 and m.state()["inputs"]["low"] == 0
    assert sorted(m.state()["faults"]) == ["broken:inlet", "stuck_off:low", "stuck_on:inlet",
                                           "stuck_on:level"]
