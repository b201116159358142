"""Exercise 10's requirements: the garage door opens and closes with the
key, stops on stop, shows a warning lamp while it moves and reverses when
its safety edge touches an obstacle.

Each test is one requirement, its docstring the requirement as the page
lists it; a failure says what the door did (openings in mm, times).
Time is simulated (10 ms scans); the door is the machine's
(``plc.machine("garage").state()``): 2400 mm of travel at 200 mm/s.
``PLCRT_EXERCISE_PROGRAM`` grades another program than ``lesson.awl``.
"""

from __future__ import annotations

import os

import pytest

pytestmark = pytest.mark.plc(os.environ.get("PLCRT_EXERCISE_PROGRAM") or "lesson.awl",
                             plant="plant.toml",
                             watch=["I0.0", "I0.1", "I0.2", "I0.3", "I0.4", "I0.5", "I0.6",
                                    "Q0.0", "Q0.1", "Q0.2"])

TRAVEL = 2400


@pytest.fixture
def door(plc):
    return plc.machine("garage")


def opened(plc, door):
    """With the key held, press open and run 14 s: the door is open."""
    door.hold("key")
    door.press("button_open")
    plc.run(seconds=14)
    return door.state()


def test_open_with_the_key_opens_the_door_fully(plc, door):
    """With the key switch on, open drives the door up to the open limit, and the motor stops there."""
    st = opened(plc, door)
    assert st["inputs"]["limit_open"], \
        f"14 s after open the door was open {st['opening']:.0f} mm of {TRAVEL} mm"
    assert not st["outputs"]["motor_open"], "the motor still drove the door open at the open limit"


def test_without_the_key_the_door_does_not_move(plc, door):
    """Without the key switch the open and close buttons do nothing."""
    door.press("button_open")
    plc.run(seconds=2)
    door.press("button_close")
    plc.run(seconds=2)
    st = door.state()
    assert st["opening"] == 0 and not st["moving"], \
        f"without the key the door moved: open {st['opening']:.0f} mm at {plc.time:.2f} s"


def test_close_with_the_key_closes_the_door(plc, door):
    """With the key switch on, close drives the open door down to the closed limit, and the motor stops there."""
    opened(plc, door)
    door.press("button_close")
    plc.run(seconds=14)
    st = door.state()
    assert st["inputs"]["limit_closed"], \
        f"14 s after close the door was still open {st['opening']:.0f} mm"
    assert not st["outputs"]["motor_close"], "the motor still drove the door down at the closed limit"


def test_stop_stops_the_door(plc, door):
    """Stop halts a moving door where it is."""
    door.hold("key")
    door.press("button_open")
    plc.run(seconds=4)
    door.press("button_stop")
    plc.run(seconds=0.5)
    at = door.state()["opening"]
    plc.run(seconds=3)
    st = door.state()
    assert not st["moving"] and st["opening"] == at, (
        f"stop pressed at 4.00 s: the door was open {at:.0f} mm at 4.50 s and "
        f"{st['opening']:.0f} mm at {plc.time:.2f} s")


def test_the_lamp_warns_while_the_door_moves(plc, door):
    """The warning lamp is lit while the door moves and dark while it stands."""
    door.hold("key")
    plc.run(seconds=1)
    assert not door.state()["lamp"], "the lamp was lit at 1 s, before the door moved"
    door.press("button_open")
    for _ in range(1400):
        plc.run(scans=1)
        st = door.state()
        assert st["lamp"] == st["moving"], (
            f"at {plc.time:.2f} s the door was {'moving' if st['moving'] else 'standing'} "
            f"(open {st['opening']:.0f} mm) and the lamp {'lit' if st['lamp'] else 'dark'}")


def test_the_safety_edge_reverses_a_closing_door(plc, door):
    """A closing door whose safety edge touches an obstacle reverses and opens fully."""
    opened(plc, door)
    door.hold("obstacle")
    door.press("button_close")
    plc.run(seconds=20)
    st = door.state()
    assert st["inputs"]["limit_open"], (
        f"20 s after close, with an obstacle {st['obstacle_at']} mm high under the door, the "
        f"door was open {st['opening']:.0f} mm, {'moving' if st['moving'] else 'standing'}: "
        f"it should have reversed to the open limit")
