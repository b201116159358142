"""Lesson 1: the seal-in circuit, pinned scan by scan.

Run with ``python -m pytest examples/course/01-seal-in``.  Every test gets
a fresh PLC at power-up (the ``plc`` fixture of plcrt's pytest plugin),
loaded from the marker below; the symbol table lets the tests use the
names of the wiring diagram instead of addresses.
"""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.plc("lesson.awl", symbols="symbols.txt",
                             watch=["Start_PB", "Stop_PB_NC", "Overload_OK", "Motor"])


@pytest.fixture
def wired(plc):
    """The machine at rest: the NC stop button is not pressed (its input
    reads 1) and the NC overload relay is healthy (1); one scan has run."""
    plc.set({"Stop_PB_NC": 1, "Overload_OK": 1})
    plc.scan()
    assert plc["Motor"] == 0
    return plc


def test_one_scan_of_start_seals_in(wired):
    """Start pressed for a single 10 ms scan turns the motor and the running
    lamp on in that same scan, and the motor's own contact keeps it on."""
    wired.pulse("Start_PB")
    assert wired["Motor"] == 1
    assert wired["Running_Lamp"] == 1
    wired.stays("Motor", "10s")


def test_stop_breaks_the_seal(wired):
    """Pressing stop (the NC input goes to 0) for one scan stops the motor,
    and it stays off after the button is released."""
    wired.pulse("Start_PB")
    wired.pulse("Stop_PB_NC", value=0)
    assert wired["Motor"] == 0
    assert wired["Running_Lamp"] == 0
    wired.stays("not Motor", "5s")


def test_stop_wins_when_both_buttons_are_held(wired):
    """Start and stop held together: the motor stays off, whether it was
    running or not (the stop contact is in series after the seal)."""
    with wired.forced({"Start_PB": 1, "Stop_PB_NC": 0}):
        wired.stays("not Motor", "1s")
    wired.pulse("Start_PB")
    assert wired["Motor"] == 1
    with wired.forced({"Start_PB": 1, "Stop_PB_NC": 0}):
        wired.scan()
        assert wired["Motor"] == 0


def test_broken_stop_wire_fails_safe(plc):
    """A broken wire to the NC stop button reads like a pressed button: at
    power-up with every input at 0 the start button does nothing."""
    plc["Overload_OK"] = 1
    plc.pulse("Start_PB", scans=5)
    plc.stays("not Motor", "1s")


def test_overload_trips_the_motor_and_lights_its_lamp(wired):
    """The NC overload relay opening stops the running motor and lights the
    overload lamp (an LDN contact); the motor needs a new start afterwards."""
    wired.pulse("Start_PB")
    wired["Overload_OK"] = 0
    wired.scan()
    assert wired.values("Motor", "Overload_Lamp") == {"Motor": 0, "Overload_Lamp": 1}
    wired["Overload_OK"] = 1
    wired.scan()
    assert wired.values("Motor", "Overload_Lamp") == {"Motor": 0, "Overload_Lamp": 0}
    wired.pulse("Start_PB")
    assert wired["Motor"] == 1
