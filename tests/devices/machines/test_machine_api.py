"""What tests and a page use of a machine: the harness and the pytest
marker, forks and snapshots, the JSON state, and the machines as devices
of the one time line: a timed interrupt inside a scan reads the exact
level, and where events cut a scan changes nothing (docs/machines.md)."""

from __future__ import annotations

import json

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

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


#: OB1 runs a 1 ms timer T32 from power-up and copies VB0 to the outputs;
#: INT_0 (I0.0 rising) counts in VW100 and keeps T32 in VW104, INT_1 (I0.0
#: falling) keeps T32 in VW106
EDGE_TIMES = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.1
ATCH   INT_0, 0
ATCH   INT_1, 1
ENI
Network 2
LD     SM0.0
TON    T32, +32000
MOVB   VB0, QB0
END_ORGANIZATION_BLOCK
INTERRUPT_BLOCK INT_0:INT0
BEGIN
Network 1
LD     SM0.0
INCW   VW100
MOVW   T32, VW104
END_INTERRUPT_BLOCK
INTERRUPT_BLOCK INT_1:INT1
BEGIN
Network 1
LD     SM0.0
MOVW   T32, VW106
END_INTERRUPT_BLOCK
"""


def test_an_edge_interrupt_on_an_eye_runs_at_the_edge() -> None:
    plc = plcrt.load(EDGE_TIMES, plant={"machine": {"conveyor": {"interval": 1.0,
                                                                 "speed": 333}}})
    m = plc.machine("conveyor")
    outputs(plc, m, motor=1, gate=1)
    plc.run(seconds=5.005)
    rising = [t for t, s, v in m.edges("eye_entry") if v]
    # arrivals at 0.5 s + k; 150 mm at 333 mm/s is 450451 µs
    assert rising == [(k * 10**6 + 950_451) / 1e6 for k in range(5)]
    assert plc["VW100"] == 5                                # once per part, no scan-start repeat
    assert plc["VW104"] == 4950                             # T32 at 4.950451 s, inside a scan
    # the last tail left the beam at 3.5 s + 250 mm / 333 mm/s = 4.250751 s
    assert m.edges("eye_entry")[-2] == (4.250751, "eye_entry", 0)
    assert plc["VW106"] == 4250


def test_an_edge_interrupt_on_a_button_runs_at_its_press_and_release() -> None:
    plc = plcrt.load(EDGE_TIMES, plant={"machine": {"traffic": {}}})
    m = plc.machine("traffic")
    plc.run(seconds=0.5)
    m.press("button_a", seconds=0.123456)
    plc.run(seconds=0.5)
    assert plc["VW100"] == 1 and plc["VW104"] == 500
    assert plc["VW106"] == 623                              # released at 0.623456 s


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


def test_a_fork_keeps_the_machines_edge_interrupts() -> None:
    plc = plcrt.load(EDGE_TIMES, plant={"machine": {"conveyor": {"interval": 1.0,
                                                                 "speed": 333}}})
    m = plc.machine("conveyor")
    outputs(plc, m, motor=1, gate=1)
    plc.run(seconds=2.0)
    twin = plc.fork()
    for p in (plc, twin):
        p.run(seconds=3.005)
    assert [twin[a] for a in ("VW100", "VW104", "VW106")] == \
        [plc[a] for a in ("VW100", "VW104", "VW106")] == [5, 4950, 4250]
    assert twin.machine("conveyor").edges() == m.edges()


@settings(max_examples=15, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(st.tuples(st.integers(1, 60), st.integers(0, 3)), min_size=1, max_size=8),
       st.integers(101, 499))
def test_edge_interrupts_follow_the_edges_whatever_the_outputs_do(segments, speed):
    plc = plcrt.load(EDGE_TIMES, plant={"machine": {"conveyor": {
        "interval": 0.7, "speed": speed, "pattern": "T"}}}, scan_ms=7)
    m = plc.machine("conveyor")
    for scans, bits in segments:
        plc["VB0"] = bits
        plc.scan(scans)
    rising = [t for t, s, v in m.edges("eye_entry") if v]
    falling = [t for t, s, v in m.edges("eye_entry") if not v]
    assert plc["VW100"] == len(rising)
    if rising:
        assert plc["VW104"] == int(round(rising[-1] * 1e6)) // 1000
    if falling:
        assert plc["VW106"] == int(round(falling[-1] * 1e6)) // 1000
