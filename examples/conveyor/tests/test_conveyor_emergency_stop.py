"""R2 emergency stop: the belt stops at once and needs a new start."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.plc("../conveyor.awl", symbols="../conveyor_symbols.txt",
                             data="../conveyor.db",
                             watch=["Start_PB", "EStop_OK", "Motor", "Fault_Lamp"])


def test_emergency_stop_stops_the_belt_in_the_same_scan(running):
    """The emergency-stop chain opening stops the belt in the scan that
    reads it, and the fault lamp lights while it is open."""
    running["EStop_OK"] = 0
    running.scan()
    assert running.values("Motor", "Fault_Lamp") == {"Motor": 0, "Fault_Lamp": 1}


def test_forced_emergency_stop_overrides_the_real_input(running):
    """Forcing the chain input to 0 (as a commissioning engineer forces an
    input from the programming tool) stops the belt although the real
    chain is healthy, and start cannot restart it.  Once the force is
    removed the PLC reads the real input (1) again, and the belt waits for
    a new start."""
    with running.forced({"EStop_OK": 0}):
        running.scan()
        assert running.values("EStop_OK", "Motor", "Fault_Lamp") == {
            "EStop_OK": 0, "Motor": 0, "Fault_Lamp": 1}
        running.pulse("Start_PB")
        running.stays("not Motor", "2s")
    running.scan()
    assert running.values("EStop_OK", "Motor", "Fault_Lamp") == {
        "EStop_OK": 1, "Motor": 0, "Fault_Lamp": 0}
    running.pulse("Start_PB")
    assert running["Motor"] == 1


def test_releasing_the_emergency_stop_does_not_restart(running):
    """Emergency stop pressed for 1 s and released: the belt stays off."""
    running.stimulus([(0, "EStop_OK", 0), (1.0, "EStop_OK", 1)], until=3.0)
    assert running.values("Motor", "Fault_Lamp") == {"Motor": 0, "Fault_Lamp": 0}
