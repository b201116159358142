"""R3 jam: 3 s of blocked jam eye while running latches a fault."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.plc("../conveyor.awl", symbols="../conveyor_symbols.txt",
                             data="../conveyor.db",
                             watch=["Jam_Eye", "Jam_Timer", "Jam_Fault", "Motor", "Reset_PB"])


def test_jam_fault_after_exactly_3_s(running):
    """The jam eye blocked from the scan at 0.10 s (a whole 100 ms): T37
    reaches 30 ticks at the scan starting at 3.10 s, the fault latches at
    the end of that scan and the belt stops one scan later, at 3.12 s."""
    running.run("80ms")
    assert running.time == pytest.approx(0.10)
    running["Jam_Eye"] = 1
    assert running.run_until("Jam_Fault", timeout="4s") == pytest.approx(3.01)
    assert running["Motor"] == 1
    running.scan()
    assert running.time == pytest.approx(3.12)
    assert running.values("Motor", "Fault_Lamp") == {"Motor": 0, "Fault_Lamp": 1}


@pytest.mark.parametrize("blocked_s", [0.5, 1.0, 2.0, 2.8])
def test_short_blockages_are_not_a_jam(running, blocked_s):
    """A part passing the jam eye blocks it for less than 3 s: no fault,
    the belt keeps running, and the timer starts from 0 the next time."""
    running.stimulus([(0, "Jam_Eye", 1), (blocked_s, "Jam_Eye", 0)], until=blocked_s + 1)
    assert running.values("Jam_Fault", "Motor", "Jam_Timer") == {
        "Jam_Fault": 0, "Motor": 1, "Jam_Timer": 0}


def test_fault_latch_survives_the_jam_going_away(running):
    """Once latched, the fault stays when the jam eye clears (an operator
    pulled the part out): the belt stays stopped and the lamp stays on,
    until someone resets."""
    running["Jam_Eye"] = 1
    running.run_until("Jam_Fault", timeout="4s")
    running["Jam_Eye"] = 0
    running.stays("Jam_Fault", "60s")
    assert running.values("Motor", "Fault_Lamp", "Jam_Timer") == {
        "Motor": 0, "Fault_Lamp": 1, "Jam_Timer": 0}
    running.pulse("Start_PB")
    assert running["Motor"] == 0


def test_reset_only_works_once_the_jam_is_cleared(running):
    """Reset with the jam eye still blocked does nothing; with the eye clear
    it clears the fault, and start runs the belt again."""
    running["Jam_Eye"] = 1
    running.run_until("Jam_Fault", timeout="4s")
    running.pulse("Reset_PB")
    assert running["Jam_Fault"] == 1
    running["Jam_Eye"] = 0
    running.pulse("Reset_PB")
    assert running.values("Jam_Fault", "Fault_Lamp") == {"Jam_Fault": 0, "Fault_Lamp": 0}
    running.pulse("Start_PB")
    assert running["Motor"] == 1


def test_a_blocked_eye_is_no_jam_while_the_belt_is_stopped(ready):
    """The jam timer only runs while the belt runs: the eye blocked for 10 s
    at standstill gives no fault."""
    ready["Jam_Eye"] = 1
    ready.stays("not Jam_Fault", "10s")
    assert ready["Jam_Timer"] == 0
