"""Lesson 4: the SCR sequence idle -> fill -> heat -> drain -> idle.

The step bits S0.0..S0.3 are the state of the sequence; SB0 is the whole
byte, so ``SB0 == 2`` means "only S0.1 (fill) is active".  An SCRT makes
its target step active at once, and the output networks after the
segments follow in the same scan.
"""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.plc("lesson.awl", watch=["SB0", "QB0", "I0.1", "I0.2", "I0.3", "T37"])

IDLE, FILL, HEAT, DRAIN = 0b0001, 0b0010, 0b0100, 0b1000
INLET, HEATER, OUTLET, IDLE_LAMP = 0b0001, 0b0010, 0b0100, 0b1000


@pytest.fixture
def empty_tank(plc):
    """Power-up with an empty tank (low-level switch I0.3 on): one scan."""
    plc["I0.3"] = 1
    plc.scan()
    return plc


def exactly_one_step(plc):
    """The invariant of a sequence: one and only one step bit is on."""
    return bin(plc["SB0"]).count("1") == 1


def test_power_up_in_idle(plc):
    """The first scan (SM0.1) activates the idle step: only S0.0, only the
    idle lamp."""
    plc.scan()
    assert plc.values("SB0", "QB0") == {"SB0": IDLE, "QB0": IDLE_LAMP}


def test_one_batch_step_by_step(empty_tank):
    """A batch played from a stimulus table (times from 0.01 s, after the
    power-up scan): start at 0.5 s, the tank is no longer empty at 1.0 s and
    full at 3.0 s, the thermostat trips at 5.0 s.  Fill and heat each begin
    in the scan that sees their condition; the 8 s soak counts from the
    scan at 5.01 s on the 100 ms clock (ticks 5.1 ... 13.0), so draining
    starts with the scan at 13.01 s."""
    h = empty_tank
    h.stimulus([
        (0.5, "I0.0", 1), (0.6, "I0.0", 0),
        (1.0, "I0.3", 0),
        (3.0, "I0.1", 1),
        (5.0, "I0.2", 1),
    ], until=5.0)
    assert h.time == pytest.approx(5.01)
    h.scan()
    assert h.values("SB0", "QB0", "T37") == {"SB0": HEAT, "QB0": 0, "T37": 0}
    h.run_until(f"SB0 == {DRAIN}", timeout="10s")
    assert h.time == pytest.approx(13.02)
    assert h.values("QB0", "T37") == {"QB0": OUTLET, "T37": 0}


def test_each_step_switches_its_own_output(empty_tank):
    """Inlet open while filling, heater on while heating below temperature,
    outlet open while draining, idle lamp only when idle."""
    h = empty_tank
    h.pulse("I0.0")
    assert h.values("SB0", "QB0") == {"SB0": FILL, "QB0": INLET}
    h["I0.3"] = 0
    h["I0.1"] = 1
    h.scan()
    assert h.values("SB0", "QB0") == {"SB0": HEAT, "QB0": HEATER}
    h["I0.2"] = 1
    h.scan()
    assert h.values("SB0", "QB0") == {"SB0": HEAT, "QB0": 0}
    h.run_until(f"SB0 == {DRAIN}", timeout="9s")
    assert h["QB0"] == OUTLET
    h.set({"I0.1": 0, "I0.2": 0, "I0.3": 1})
    h.scan()
    assert h.values("SB0", "QB0", "VW0") == {"SB0": IDLE, "QB0": IDLE_LAMP, "VW0": 1}


def test_exactly_one_step_is_active_through_two_batches(empty_tank):
    """Checked after every scan of two complete batches (40 s)."""
    batch = [(0.0, "I0.0", 1), (0.1, "I0.0", 0), (0.2, "I0.3", 0), (2.0, "I0.1", 1),
             (4.0, "I0.2", 1), (12.5, "I0.1", 0), (13.0, "I0.2", 0), (15.0, "I0.3", 1)]
    empty_tank.stimulus(batch + [(t + 20, a, v) for t, a, v in batch], until=40)
    assert exactly_one_step(empty_tank)
    assert empty_tank["VW0"] == 2


def test_no_step_ever_overlaps(empty_tank):
    """The same invariant with ``stays``: it fails at the first scan where
    it breaks, here during one batch with the inputs held."""
    empty_tank.pulse("I0.0")
    empty_tank.set({"I0.3": 0, "I0.1": 1, "I0.2": 1})
    empty_tank.stays(exactly_one_step, "10s")
    assert empty_tank["SB0"] == DRAIN


def test_start_needs_an_empty_tank(empty_tank):
    """With liquid left in the tank (I0.3 off) start does nothing."""
    empty_tank["I0.3"] = 0
    empty_tank.pulse("I0.0")
    empty_tank.stays(f"SB0 == {IDLE}", "1s")


def test_abort_from_any_step_returns_to_idle(empty_tank):
    """Abort (I0.4) while heating: R S0.1, 3 clears the steps, idle is
    active in the same scan, the heater is off."""
    h = empty_tank
    h.pulse("I0.0")
    h.set({"I0.3": 0, "I0.1": 1})
    h.run("1s")
    assert h.values("SB0", "QB0") == {"SB0": HEAT, "QB0": HEATER}
    h.pulse("I0.4")
    assert h.values("SB0", "QB0") == {"SB0": IDLE, "QB0": IDLE_LAMP}


def test_soak_time_is_the_full_8s_in_every_batch(empty_tank):
    """The soak timer is outside the segments, so it is reset when step 2
    ends and the second batch soaks as long as the first.  With the
    thermostat tripping at a whole 0.1 s, T37 reaches 80 ticks at the scan
    8.00 s later, the heat segment sees its bit in the next scan and hands
    over: the drain step is active 8.02 s after the thermostat."""
    h = empty_tank

    def soak_time():
        h.pulse("I0.0")
        h.set({"I0.3": 0, "I0.1": 1})
        h.run_until(f"SB0 == {HEAT}", timeout="1s")
        h.run_until(lambda: round(h.time * 1000) % 100 == 0, timeout="1s")  # a whole 0.1 s
        h["I0.2"] = 1
        t = h.run_until(f"SB0 == {DRAIN}", timeout="10s")
        h.set({"I0.1": 0, "I0.2": 0, "I0.3": 1})
        h.run_until(f"SB0 == {IDLE}", timeout="1s")
        return t

    assert soak_time() == pytest.approx(8.02)
    assert soak_time() == pytest.approx(8.02)
