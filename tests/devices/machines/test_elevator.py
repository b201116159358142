"""The elevator: floor sensors at exact times, the door, the diagnostics of
an unsafe move, and the example program serving random calls without ever
moving the car with its door open (docs/machines.md)."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings, strategies as st

from machine_helpers import example, manual, outputs


def test_floor_sensor_edges_at_the_exact_microsecond() -> None:
    plc, m = manual("elevator", speed=700, floor_height=3000, band=10)
    outputs(plc, m, up=1)
    plc.run(seconds=5)
    def first_at_or_above(mm: int) -> float:
        return -(-mm * 10**6 // 700) / 1e6
    def first_above(mm: int) -> float:
        return (mm * 10**6 // 700 + 1) / 1e6
    assert m.edges("floor_1") == [(first_above(10), "floor_1", 0)]
    assert m.edges("floor_2") == [(first_at_or_above(2990), "floor_2", 1),
                                  (first_above(3010), "floor_2", 0)]


def test_the_car_stops_on_its_buffer_and_the_crash_is_noted() -> None:
    plc, m = manual("elevator", overtravel=300)
    outputs(plc, m, down=1)
    plc.run(seconds=1)
    assert m.state()["car"] == -300 and m.state()["crashes"] == 1
    assert m.notes() == [(0.6, "the car hit a buffer")]


def test_moving_with_the_door_open_is_counted() -> None:
    plc, m = manual("elevator")
    outputs(plc, m, door_open=1)
    plc.run(seconds=3)
    assert plc["I0.3"] == 1 and m.state()["door"] == 1.0
    outputs(plc, m, up=1)
    plc.run(seconds=1)
    assert m.state()["unsafe_moves"] == 1
    assert (3.0, "the car moves with its door open") in m.notes()
    # the car leaves floor 1's band (10 mm) 1 µs after 20 ms at 500 mm/s
    assert (3.020001, "the door opens away from a floor") in m.notes()


def test_a_jammed_door_keeps_the_car_at_the_floor() -> None:
    plc, m = example("elevator", faults=["door_jam"])
    m.press("call_1")
    plc.run(seconds=2)
    m.press("call_3")
    plc.run(seconds=20)
    s = m.state()
    assert s["door"] == 0 and s["floor"] == 1 and s["outputs"]["door_open"] == 1


def test_the_example_program_serves_calls_in_turn() -> None:
    plc, m = example("elevator")
    m.press("call_3")
    plc.run(seconds=20)
    assert m.state()["floor"] == 3 and m.state()["door"] == 0
    m.press("call_2")
    plc.run(seconds=20)
    assert m.state()["floor"] == 2
    opened = [t for t, s, v in m.edges("door_opened") if v]
    assert len(opened) == 2 and not m.notes()


@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(st.tuples(st.integers(1, 400), st.sampled_from([1, 2, 3])),
                min_size=1, max_size=6))
def test_the_car_never_moves_with_its_door_open_and_every_call_is_served(calls):
    plc, m = example("elevator")
    pressed: list[tuple[float, int]] = []
    opened: list[tuple[float, int]] = []
    was_open = 0

    def scan() -> None:
        nonlocal was_open
        plc.scan()
        s = m.state()
        if s["moving"]:
            assert s["door"] == 0 and s["inputs"]["door_closed"] == 1
        if s["inputs"]["door_opened"] and not was_open:
            opened.append((s["t"], s["floor"]))
        was_open = s["inputs"]["door_opened"]

    for scans, floor in calls:
        pressed.append((plc.time, floor))
        m.press(f"call_{floor}")
        for _ in range(scans):
            scan()
    for _ in range(6000):
        scan()
    s = m.state()
    assert s["unsafe_moves"] == 0 and s["crashes"] == 0 and not m.notes()
    assert plc["MB1"] == 0 and s["door"] == 0           # no call left
    for t, floor in pressed:                            # each served after its call
        assert any(t_open >= t and f == floor for t_open, f in opened), (t, floor, opened)
