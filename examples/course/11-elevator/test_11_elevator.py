"""Exercise 11's requirements: the elevator serves the calls of three
floors, opens its door at each, and moves only with the door closed.

Each test is one requirement, its docstring the requirement as the page
lists it; a failure says what the car did (floors, times).  Time is
simulated (10 ms scans); car and door are the machine's
(``plc.machine("elevator").state()``): floors 3 m apart, the car at
0.5 m/s (6 s a floor), the door opens in 2 s.
``PLCRT_EXERCISE_PROGRAM`` grades another program than ``lesson.awl``.
"""

from __future__ import annotations

import os

import pytest

pytestmark = pytest.mark.plc(os.environ.get("PLCRT_EXERCISE_PROGRAM") or "lesson.awl",
                             plant="plant.toml",
                             watch=["I0.0", "I0.1", "I0.2", "I0.3", "I0.4", "I0.5", "I0.6", "I0.7",
                                    "Q0.0", "Q0.1", "Q0.2", "Q0.3"])


@pytest.fixture
def car(plc):
    return plc.machine("elevator")


def ride(plc, car, calls, seconds):
    """Press ``calls`` ({seconds: floor}) at their times and run
    ``seconds`` scan by scan; returns the visits, ``(t, floor)`` each time
    the door is fully open at a floor (once a stop), and when the door
    closed after each visit."""
    visits, closed, was_open = [], [], False
    pending = sorted(calls.items())
    while plc.time < seconds - 1e-9:
        while pending and pending[0][0] <= plc.time + 1e-9:
            car.press(f"call_{pending.pop(0)[1]}")
        plc.run(scans=1)
        st = car.state()
        is_open = st["door"] >= 1 and st["floor"] > 0
        if is_open and not was_open:
            visits.append((round(plc.time, 2), st["floor"]))
        if was_open and st["door"] == 0:
            closed.append(round(plc.time, 2))
        if st["door"] == 0 or is_open:
            was_open = is_open
    return visits, closed


def shown(visits):
    return ", ".join(f"floor {f} at {t:.2f} s" for t, f in visits) or "none"


CALLS = {0.0: 3, 2.0: 1, 4.0: 2}


def test_a_call_brings_the_car_and_opens_the_door(plc, car):
    """A call from floor 3 brings the car there and opens its door within 20 s."""
    visits, _ = ride(plc, car, {0.0: 3}, 20)
    st = car.state()
    assert any(f == 3 for _, f in visits), (
        f"20 s after the call from floor 3 the car was at {st['car']:.0f} mm "
        f"(floor {st['floor'] or 'none'}) with its door {st['door']:.0%} open; "
        f"doors opened at: {shown(visits)}")


def test_the_door_closes_again(plc, car):
    """After a stop the door closes again within 10 s of opening."""
    visits, closed = ride(plc, car, {0.0: 3}, 35)
    assert visits, "the door never opened at a floor in 35 s"
    t = visits[0][0]
    assert any(t < c <= t + 10 for c in closed), (
        f"the door opened at {t:.2f} s (floor {visits[0][1]}) and was "
        f"{car.state()['door']:.0%} open at {plc.time:.2f} s")


def test_every_call_is_served(plc, car):
    """Calls from floors 3, 1 and 2 are each served: the car stops at each floor with its door open within 60 s."""
    visits, _ = ride(plc, car, CALLS, 60)
    missing = {1, 2, 3} - {f for _, f in visits}
    assert not missing, (
        f"calls at {', '.join(f'{t:g} s from floor {f}' for t, f in CALLS.items())}: "
        f"floor(s) {sorted(missing)} never served in 60 s; doors opened at: {shown(visits)}")


def test_the_car_never_moves_with_its_door_open(plc, car):
    """The car never moves while its door is not closed."""
    ride(plc, car, CALLS, 60)
    st = car.state()
    moves = [n for n in car.notes() if "door" in n[1]]
    assert st["unsafe_moves"] == 0, (
        f"the car moved {st['unsafe_moves']} time(s) with its door open: "
        f"{', '.join(f'{t:.2f} s: {n}' for t, n in moves[:3])}")


def test_the_car_never_hits_the_buffers(plc, car):
    """The car never runs past floor 1 or floor 3 into the buffers."""
    ride(plc, car, CALLS, 60)
    st = car.state()
    assert st["crashes"] == 0, (
        f"the car hit the buffers {st['crashes']} time(s): "
        f"{', '.join(f'{t:.2f} s: {n}' for t, n in car.notes()[:3])}")


def test_without_calls_the_car_stands(plc, car):
    """Without calls the car stands at floor 1 with its door closed."""
    plc.run(seconds=10)
    st = car.state()
    assert st["car"] == 0 and st["door"] == 0, (
        f"with no call, after 10 s the car was at {st['car']:.0f} mm with its door "
        f"{st['door']:.0%} open")


def test_a_jammed_door_keeps_the_car_at_its_floor(plc, car):
    """With its door jammed open at floor 3 the car stays there, whatever is called."""
    visits, _ = ride(plc, car, {0.0: 3}, 30)
    if not any(f == 3 for _, f in visits):
        pytest.fail(f"the door never opened at floor 3 in 30 s (doors opened at: {shown(visits)}), "
                    f"so it could not jam there")
    # open the door again at floor 3 and jam it while it is open
    ride(plc, car, {plc.time: 3}, plc.time + 0.5)
    for _ in range(1000):
        if car.state()["door"] > 0.5:
            break
        plc.run(scans=1)
    car.fault("door_jam")
    at, height = plc.time, car.state()["car"]
    ride(plc, car, {plc.time: 1, plc.time + 5: 2}, plc.time + 30)
    st = car.state()
    assert st["car"] == height and st["unsafe_moves"] == 0, (
        f"the door jammed {st['door']:.0%} open at {at:.2f} s with the car at {height:.0f} mm "
        f"(floor 3); at {plc.time:.2f} s the car was at {st['car']:.0f} mm after "
        f"{st['unsafe_moves']} move(s) with the door open")
