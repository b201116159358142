"""The garage door: limit switches at exact times, the door never past its
ends, the obstacle and the normally closed safety edge, the jam
(docs/machines.md)."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings, strategies as st

from machine_helpers import example, manual, outputs


def test_limit_edges_at_the_exact_microsecond() -> None:
    plc, m = manual("garage", travel=2400, speed=300, band=10)
    outputs(plc, m, motor_open=1)
    plc.run(seconds=9)
    off = (10 * 10**6 // 300 + 1) / 1e6          # first µs above 10 mm
    on = -(-2390 * 10**6 // 300) / 1e6           # first µs at 2390 mm
    assert m.edges("limit_closed") == [(off, "limit_closed", 0)]
    assert m.edges("limit_open") == [(on, "limit_open", 1)]
    assert m.state()["opening"] == 2400 and not m.state()["moving"]


def test_both_directions_on_do_not_move_the_door_and_are_noted() -> None:
    plc, m = manual("garage", start=1000)
    outputs(plc, m, motor_open=1, motor_close=1)
    plc.run(seconds=1)
    assert m.state()["opening"] == 1000
    assert m.notes() == [(0.0, "both motor directions on")]


def test_a_closing_door_stops_on_the_obstacle_and_the_edge_opens() -> None:
    plc, m = manual("garage", start=1000, speed=200, obstacle_at=500, edge=20)
    m.hold("obstacle")
    assert m.state()["inputs"]["safety_edge"] == 1   # clear (normally closed): on
    outputs(plc, m, motor_close=1)
    plc.run(seconds=4)
    assert m.state()["opening"] == 500
    # the edge (NC) opens 20 mm above the obstacle: after 480 mm at 200 mm/s
    assert m.edges("safety_edge") == [(2.4, "safety_edge", 0)]
    assert m.notes()[0] == (2.5, "the door presses on the obstacle")
    m.release("obstacle")
    plc.run(seconds=3)
    assert m.state()["opening"] == 0


def test_the_example_program_reverses_on_the_obstacle() -> None:
    plc, m = example("garage")
    m.hold("key")
    m.press("button_open")
    plc.run(seconds=15)
    assert plc["I0.0"] == 1 and m.state()["opening"] >= 2390
    m.hold("obstacle")
    m.press("button_close")
    plc.run(seconds=25)
    s = m.state()
    assert s["opening"] >= 2390 and not m.notes()   # reversed before pressing on it
    assert min(t for t, sig, v in m.edges("safety_edge") if v == 0) > 15
    m.release("obstacle")
    m.press("button_close")
    plc.run(seconds=15)
    assert m.state()["opening"] <= 10 and plc["I0.1"] == 1


def test_the_example_program_will_not_close_with_a_broken_edge_wire() -> None:
    # normally closed: a broken wire reads as a pressed edge, the safe side
    plc, m = example("garage", start=2400, faults=["broken:safety_edge"])
    m.hold("key")
    m.press("button_close")
    plc.run(seconds=5)
    assert m.state()["opening"] == 2400


def test_the_buttons_include_the_obstacle() -> None:
    _, m = manual("garage")
    assert m.buttons() == ["button_open", "button_close", "button_stop", "key", "obstacle"]


def test_a_jammed_door_does_not_move() -> None:
    plc, m = manual("garage", start=1000, faults=["jam"])
    outputs(plc, m, motor_close=1)
    plc.run(seconds=2)
    assert m.state()["opening"] == 1000
    m.fault("jam", on=False)
    plc.run(seconds=1)
    assert m.state()["opening"] == 800


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(st.tuples(st.integers(1, 40), st.integers(0, 3), st.booleans()),
                min_size=1, max_size=12), st.integers(0, 2400))
def test_the_door_never_moves_past_its_ends_or_through_the_obstacle(segments, start):
    plc, m = manual("garage", scan_ms=50, start=start, speed=500)
    for scans, bits, obstacle in segments:
        plc["VB0"] = bits
        (m.hold if obstacle else m.release)("obstacle")
        under = obstacle and m.state()["opening"] >= 500
        for _ in range(scans):
            plc.scan()
            s = m.state()
            assert 0 <= s["opening"] <= 2400
            if under:
                assert s["opening"] >= 500
            assert s["inputs"]["limit_closed"] == (s["opening"] <= 10)
            assert s["inputs"]["limit_open"] == (s["opening"] >= 2390)
