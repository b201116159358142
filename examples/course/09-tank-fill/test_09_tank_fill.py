"""Exercise 9's requirements: fill to the high switch, pump down to the
low switch, again, and never overflow.

Each test is one requirement, its docstring the requirement as the page
lists it; a failure says what the tank did (volumes in mL, times).  Time
is simulated (10 ms scans); valves, pump and volume are the machine's
(``plc.machine("tank").state()``): 100 L, filled at 2 L/s, pumped out at
1.5 L/s, the low switch at 10 L, the high one at 90 L.
``PLCRT_EXERCISE_PROGRAM`` grades another program than ``lesson.awl``.
"""

from __future__ import annotations

import os

import pytest

pytestmark = pytest.mark.plc(os.environ.get("PLCRT_EXERCISE_PROGRAM") or "lesson.awl",
                             plant="plant.toml",
                             watch=["I0.0", "I0.1", "I0.2", "I0.3", "AIW0", "Q0.0", "Q0.2"])


@pytest.fixture
def tank(plc):
    return plc.machine("tank")


def running(plc, tank, until, seconds):
    """Run scan by scan for at most ``seconds`` until ``until(state)``;
    the state then, or None."""
    end = plc.time + seconds
    while plc.time < end - 1e-9:
        plc.run(scans=1)
        st = tank.state()
        if until(st):
            return st
    return None


def test_start_fills_the_tank(plc, tank):
    """Pressing start opens the inlet of the empty tank, and it stays open after start is released."""
    tank.press("start")
    plc.run(seconds=1)
    st = tank.state()
    assert st["outputs"]["inlet"], f"the inlet was closed 1 s after start (volume {st['volume']:.0f} mL)"
    assert st["volume"] > 0, "the volume did not rise in the first second"


def test_the_inlet_closes_at_the_high_switch(plc, tank):
    """The inlet closes within one scan of the high switch coming on."""
    tank.press("start")
    st = running(plc, tank, lambda s: s["inputs"]["high"], 60)
    assert st is not None, f"the high switch never came on in 60 s (volume {tank.state()['volume']:.0f} mL)"
    high_at = plc.time
    plc.run(scans=2)
    st = tank.state()
    assert not st["outputs"]["inlet"], (
        f"the high switch came on at {high_at:.2f} s but the inlet was still open at "
        f"{plc.time:.2f} s (volume {st['volume']:.0f} mL)")


def test_the_pump_empties_down_to_the_low_switch_then_it_fills_again(plc, tank):
    """After the high switch the pump empties the tank down to the low switch; then the pump stops and the tank fills again."""
    tank.press("start")
    st = running(plc, tank, lambda s: s["outputs"]["pump"], 60)
    assert st is not None, f"the pump never ran in the first 60 s (volume {tank.state()['volume']:.0f} mL)"
    st = running(plc, tank, lambda s: not s["inputs"]["low"], 70)
    assert st is not None, (
        f"the level did not reach the low switch within 70 s of the pump starting "
        f"(volume {tank.state()['volume']:.0f} mL, pump {'on' if tank.state()['outputs']['pump'] else 'off'})")
    low_at = plc.time
    plc.run(seconds=1)
    st = tank.state()
    assert not st["outputs"]["pump"] and st["outputs"]["inlet"], (
        f"1 s after the level fell below the low switch at {low_at:.2f} s the pump was "
        f"{'on' if st['outputs']['pump'] else 'off'} and the inlet "
        f"{'open' if st['outputs']['inlet'] else 'closed'} (volume {st['volume']:.0f} mL)")


def test_stop_closes_the_inlet_and_stops_the_pump(plc, tank):
    """Pressing stop closes the inlet and stops the pump, whatever the level."""
    tank.press("start")
    for stop_at in (20.0, 60.0):
        plc.run(seconds=stop_at - plc.time)
        tank.press("stop")
        plc.run(seconds=0.5)
        st = tank.state()
        assert not st["outputs"]["inlet"] and not st["outputs"]["pump"], (
            f"stop pressed at {stop_at:.2f} s: 0.5 s later the inlet was "
            f"{'open' if st['outputs']['inlet'] else 'closed'} and the pump "
            f"{'on' if st['outputs']['pump'] else 'off'} (volume {st['volume']:.0f} mL)")
        tank.press("start")


def test_the_tank_never_overflows(plc, tank):
    """The tank never overflows in 3 minutes of running."""
    tank.press("start")
    plc.run(seconds=180)
    st = tank.state()
    assert st["spilled"] == 0, f"{st['spilled']:.0f} mL spilled over the rim in 180 s"


def test_the_tank_does_not_overflow_with_the_high_switch_stuck_off(plc, tank):
    """With the high switch stuck off the tank still does not overflow: the analog level (AIW0) guards the inlet."""
    tank.fault("stuck_off:high")
    tank.press("start")
    plc.run(seconds=90)
    st = tank.state()
    assert st["spilled"] == 0, (
        f"with the high switch stuck off, {st['spilled']:.0f} mL spilled over the rim in 90 s "
        f"(the level read {plc['AIW0']} counts of 32000)")
