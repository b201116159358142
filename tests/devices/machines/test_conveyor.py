"""The conveyor: parts, photo-eyes at exact times, the stopper gate, the
diverter and bins, the jam and the wire faults (docs/machines.md)."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from plcrt import PlcConfigError
from plcrt.errors import PlcKeyError

from machine_helpers import example, manual, outputs


def ceil_us(mm: int, speed: int) -> int:
    """µs a part needs for *mm* at *speed* mm/s, the first whole µs it is there."""
    return -(-mm * 1_000_000 // speed)


@pytest.mark.parametrize("speed", [250, 333, 7])
def test_eye_edges_are_at_the_exact_microsecond(speed: int) -> None:
    # the belt runs from the first scan; the part arrives at 0.5 s at 0 mm
    # and its nose reaches the entry eye (150 mm) after 150 mm / speed
    plc, m = manual("conveyor", speed=speed, first=0.5, interval=1000)
    outputs(plc, m, motor=1)
    plc.run(seconds=0.5 + 260 / speed)
    on = 500_000 + ceil_us(150, speed)
    off = 500_000 + ceil_us(250, speed)      # its tail (100 mm) leaves the beam
    assert m.edges("eye_entry") == [(on / 1e6, "eye_entry", 1), (off / 1e6, "eye_entry", 0)]


def test_edges_do_not_depend_on_the_scan_time() -> None:
    runs = []
    for scan_ms in (10, 7, 1.5):
        plc, m = manual("conveyor", scan_ms=scan_ms, speed=333, pattern="TS", interval=1.7)
        outputs(plc, m, motor=1, gate=1)
        plc.run(seconds=12)
        runs.append([e for e in m.edges() if e[0] <= 11.9])
    assert runs[0] == runs[1] == runs[2]
    assert len(runs[0]) > 20


def test_the_tall_eye_sees_only_tall_parts() -> None:
    plc, m = manual("conveyor", pattern="ST", first=0.5, interval=2.0)
    outputs(plc, m, motor=1, gate=1)
    plc.run(seconds=5)
    # part 0 (short) at 1.1 s, part 1 (tall) at 3.1 s
    assert [e[0] for e in m.edges("eye_entry") if e[2]] == [1.1, 3.1]
    assert [e[0] for e in m.edges("eye_tall") if e[2]] == [3.1]


def test_a_closed_gate_holds_parts_and_they_queue_nose_to_tail() -> None:
    plc, m = manual("conveyor", first=0.0, interval=1.0, count=3)
    outputs(plc, m, motor=1, gate=0)
    plc.run(seconds=12)
    xs = [p["x"] for p in m.state()["parts"]]
    assert xs == [1000.0, 900.0, 800.0]
    assert plc["I0.2"] == 1                      # the gate eye sees the first
    outputs(plc, m, motor=1, gate=1)
    plc.run(seconds=10)
    s = m.state()
    assert s["parts"] == [] and s["bins"]["straight_short"] + s["bins"]["straight_tall"] == 3


def test_the_diverter_pushes_a_part_whose_nose_reaches_it_while_on() -> None:
    plc, m = manual("conveyor", pattern="T", first=0.0, interval=100, count=1)
    outputs(plc, m, motor=1, gate=1, divert=1)
    plc.run(seconds=8)
    assert m.state()["bins"]["diverted_tall"] == 1
    plc2, m2 = manual("conveyor", pattern="T", first=0.0, interval=100, count=1)
    outputs(plc2, m2, motor=1, gate=1, divert=0)
    plc2.run(seconds=10)
    assert m2.state()["bins"]["straight_tall"] == 1


def test_a_part_waits_in_the_feeder_while_the_start_is_covered() -> None:
    # the belt stands: the first part enters at 0.5 s, the others wait
    plc, m = manual("conveyor", first=0.5, interval=0.5)
    plc.run(seconds=3)
    assert [p["x"] for p in m.state()["parts"]] == [0.0]
    outputs(plc, m, motor=1)
    plc.run(seconds=0.39)
    # the next enters when the first has moved one part length (100 mm, 0.4 s)
    assert len(m.state()["parts"]) == 1
    plc.run(seconds=0.02)
    assert len(m.state()["parts"]) == 2


def test_jam_sticks_the_front_part_and_the_others_queue() -> None:
    plc, m = manual("conveyor", first=0.0, interval=1.0, count=3)
    outputs(plc, m, motor=1, gate=1)
    plc.run(seconds=2.0)       # part 0 at 500 mm, part 1 at 250 mm
    m.fault("jam")
    plc.run(seconds=5)
    xs = [p["x"] for p in m.state()["parts"]]
    assert xs == [500.0, 400.0, 300.0]
    assert m.state()["parts"][0]["jammed"] and "jam" in m.state()["faults"]
    m.fault("jam", on=False)
    plc.run(seconds=20)
    assert m.state()["parts"] == []


def test_faults_in_the_plant_file_and_on_wires() -> None:
    plc, m = manual("conveyor", faults=["stuck_on:eye_exit", "broken:motor"])
    outputs(plc, m, motor=1, gate=1)
    plc.run(seconds=3)
    assert plc["I0.3"] == 1                      # the exit eye is stuck on
    assert [p["x"] for p in m.state()["parts"]] == [0.0]   # the motor gets nothing
    assert m.state()["outputs"]["motor"] == 0
    m.fault("broken:motor", on=False)
    plc.run(seconds=1)
    assert m.state()["parts"][0]["x"] > 0


def test_buttons_and_bad_names() -> None:
    plc, m = example("conveyor")
    with pytest.raises(PlcKeyError, match="no button 'go'"):
        m.press("go")
    with pytest.raises(PlcConfigError, match="no fault 'melt'"):
        m.fault("melt")
    with pytest.raises(PlcConfigError, match="seconds"):
        m.press("start", seconds=-1)
    m.press("start", seconds=0.05)
    plc.run(seconds=0.2)
    assert plc["Q0.0"] == 1 and m.edges("start") == [(0.0, "start", 1), (0.05, "start", 0)]


def test_the_example_program_sorts_tall_parts_into_the_diverted_bin() -> None:
    plc, m = example("conveyor", pattern="STTSS", interval=3.0)
    m.press("start")
    plc.run(seconds=60)
    bins = m.state()["bins"]
    assert bins["diverted_short"] == 0 and bins["straight_tall"] == 0
    assert bins["diverted_tall"] >= 6 and bins["straight_short"] >= 8


_SEGMENTS = st.lists(st.tuples(st.integers(1, 40), st.booleans(), st.booleans(), st.booleans()),
                     min_size=1, max_size=12)


@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
@given(_SEGMENTS, st.sampled_from(["ST", "T", "SST"]), st.integers(100, 400))
def test_no_part_passes_the_closed_gate_and_parts_are_conserved(segments, pattern, speed):
    plc, m = manual("conveyor", scan_ms=50, pattern=pattern, speed=speed, interval=0.7)
    gate_at = m.state()["gate_at"]
    seen: dict[int, float] = {}
    for scans, motor, gate, divert in segments:
        outputs(plc, m, motor=motor, gate=gate, divert=divert)
        for _ in range(scans):
            plc.scan()
            s = m.state()
            parts = s["parts"]
            for p in parts:
                before = seen.get(p["id"], 0.0)
                assert p["x"] >= before                     # never back
                if not gate and before <= gate_at:
                    assert p["x"] <= gate_at                # the closed gate holds it
                seen[p["id"]] = p["x"]
            for a, b in zip(parts, parts[1:]):
                # parts never overlap (positions are whole nm: compare those)
                assert round(a["x"] * 1e6) - round(b["x"] * 1e6) >= s["part"] * 10**6
            assert s["arrived"] == len(parts) + sum(s["bins"].values())
