"""Exercise 8's requirements: run the belt, sort tall parts out.

Each test is one requirement, its docstring the requirement as the page
lists it; a failure says what the conveyor did (bins, times).  Time is
simulated (10 ms scans); the belt, the parts and the bins are the
machine's (``plc.machine("conveyor").state()``).
``PLCRT_EXERCISE_PROGRAM`` grades another program than ``lesson.awl``.
"""

from __future__ import annotations

import os

import pytest

pytestmark = pytest.mark.plc(os.environ.get("PLCRT_EXERCISE_PROGRAM") or "lesson.awl",
                             plant="plant.toml",
                             watch=["I0.0", "I0.1", "I0.2", "I0.4", "I0.5", "Q0.0", "Q0.1", "Q0.2"])


@pytest.fixture
def belt(plc):
    return plc.machine("conveyor")


def started(plc, belt, seconds):
    """Press start at power-up and run ``seconds``; the bins then."""
    belt.press("start")
    plc.run(seconds=seconds)
    return belt.state()["bins"]


def test_start_runs_the_belt(plc, belt):
    """Pressing start runs the belt, and it keeps running after start is released."""
    belt.press("start")
    plc.run(seconds=0.1)
    assert belt.state()["outputs"]["motor"], "the belt did not start within 0.1 s of start"
    plc.run(seconds=5)
    assert belt.state()["outputs"]["motor"], (
        f"the belt stopped again: the motor was off at {plc.time:.2f} s, start was "
        f"released at 0.30 s")


def test_stop_stops_the_belt(plc, belt):
    """Pressing stop stops the belt, and it stays stopped."""
    belt.press("start")
    plc.run(seconds=2)
    belt.press("stop")
    plc.run(seconds=0.1)
    assert not belt.state()["outputs"]["motor"], \
        f"the belt still ran 0.1 s after stop was pressed at {plc.time - 0.1:.2f} s"
    plc.run(seconds=3)
    assert not belt.state()["outputs"]["motor"], \
        f"the belt started again by itself: the motor was on at {plc.time:.2f} s"


def test_parts_leave_the_belt(plc, belt):
    """Parts do not pile up: in 30 s at least 6 parts reach a bin."""
    bins = started(plc, belt, 30)
    assert sum(bins.values()) >= 6, (
        f"after 30 s only {sum(bins.values())} part(s) reached a bin ({bins}); "
        f"{len(belt.state()['parts'])} are still on the belt")


def test_a_short_part_goes_straight_on(plc, belt):
    """A short part goes to the straight bin, never to the diverted one."""
    bins = started(plc, belt, 30)
    assert bins["diverted_short"] == 0, \
        f"{bins['diverted_short']} short part(s) went to the diverted bin ({bins})"
    assert bins["straight_short"] >= 1, f"no short part reached the straight bin in 30 s ({bins})"


def test_a_tall_part_goes_to_the_diverted_bin(plc, belt):
    """A tall part goes to the diverted bin, never straight on."""
    bins = started(plc, belt, 30)
    assert bins["straight_tall"] == 0, \
        f"{bins['straight_tall']} tall part(s) went straight on ({bins})"
    assert bins["diverted_tall"] >= 1, f"no tall part reached the diverted bin in 30 s ({bins})"
