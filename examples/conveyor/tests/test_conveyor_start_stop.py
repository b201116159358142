"""R1 start/stop: start runs the belt, stop stops it, stop wins."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.plc("../conveyor.awl", symbols="../conveyor_symbols.txt",
                             data="../conveyor.db",
                             watch=["Start_PB", "Stop_PB", "EStop_OK", "Motor", "Jam_Fault"])


def test_start_runs_the_belt_and_lights_the_lamp(ready):
    """A start press of one scan seals in: belt and running lamp on."""
    ready.pulse("Start_PB")
    assert ready.values("Motor", "Run_Lamp") == {"Motor": 1, "Run_Lamp": 1}
    ready.stays("Motor", "30s")


def test_stop_stops_the_belt(running):
    """Stop (the NC input goes to 0) for one scan stops the belt for good."""
    running.pulse("Stop_PB", value=0)
    assert running.values("Motor", "Run_Lamp") == {"Motor": 0, "Run_Lamp": 0}
    running.stays("not Motor", "5s")


def test_stop_wins_over_start(ready):
    """Start and stop held together: the belt does not run."""
    ready.set({"Start_PB": 1, "Stop_PB": 0})
    ready.stays("not Motor", "2s")


def test_no_start_at_power_up_without_the_stop_circuit(plc):
    """All inputs 0 at power-up (stop circuit open, e.g. a broken wire):
    start does nothing."""
    plc.pulse("Start_PB", scans=3)
    plc.stays("not Motor", "1s")
