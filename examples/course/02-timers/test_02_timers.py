"""Lesson 2: TON, TOF, TONR and the timer resolutions, to the scan.

All times are simulated seconds with the default 10 ms scan.  A value read
after ``run_until`` is the state at the end of the scan in which the
condition first held; ``run_until`` returns the time that took.
"""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.plc("lesson.awl", watch=["I0.0", "T37", "Q0.0", "Q0.1", "T38", "Q0.2"])


def test_delayed_start_after_exactly_five_seconds(plc):
    """Run switch on before the first scan: the horn sounds at once, and
    TON T37 (+50 x 100 ms) turns the motor on at the end of the scan that
    starts at 5.00 s, i.e. at 5.01 s; the horn stops in the same scan."""
    plc["I0.0"] = 1
    plc.scan()
    assert plc.values("Q0.0", "Q0.1") == {"Q0.0": 0, "Q0.1": 1}
    assert plc.run_until("Q0.0", timeout="6s") == pytest.approx(5.0)
    assert plc.time == pytest.approx(5.01)
    assert plc["T37"] == 50
    assert plc["Q0.1"] == 0


def test_a_100ms_timer_can_be_up_to_one_tick_short(plc):
    """A 100 ms timer counts the ticks of a 100 ms clock, not the time since
    its input came on: switched on at 0.05 s, T37 still reaches 50 ticks at
    the scan starting at 5.00 s, so the motor comes on 4.96 s after the
    switch (the manual's advice: add 1 to the preset when it matters)."""
    plc.run("50ms")
    plc["I0.0"] = 1
    assert plc.run_until("Q0.0", timeout="6s") == pytest.approx(4.96)
    assert plc.time == pytest.approx(5.01)


def test_ton_starts_again_from_zero_after_a_short_interruption(plc):
    """Switched off after 3 s, the TON forgets its count: switched on again
    at 3.5 s, the motor comes on only 5 s later, at the end of the scan
    starting at 8.50 s."""
    plc.stimulus([(0, "I0.0", 1), (3.0, "I0.0", 0), (3.5, "I0.0", 1)])
    assert plc["T37"] == 0
    plc.run_until("Q0.0", timeout="6s")
    assert plc.time == pytest.approx(8.51)


def test_fan_runs_on_for_ten_seconds(plc):
    """TOF T38 (+100): the fan comes on with the motor and stops exactly
    10.00 s after the motor stops."""
    plc["I0.0"] = 1
    plc.run("20s")
    assert plc.values("Q0.0", "Q0.2") == {"Q0.0": 1, "Q0.2": 1}
    plc["I0.0"] = 0
    plc.run_until("not Q0.0", timeout="1s")
    assert plc.time == pytest.approx(20.01)
    assert plc.run_while("Q0.2", timeout="11s") == pytest.approx(10.0)
    assert plc["T38"] == 100


def test_fan_keeps_running_when_the_motor_restarts_in_time(plc):
    """Motor off for 6 s (switch off, on again; the start delay adds 5 s):
    the TOF is re-triggered before its 10 s are over, so the fan never stops."""
    plc["I0.0"] = 1
    plc.run("10s")
    plc["I0.0"] = 0
    plc.run("1s")
    plc["I0.0"] = 1
    plc.stays("Q0.2", "8s")
    assert plc["Q0.0"] == 1


def test_tonr_adds_up_running_time_across_a_pause(plc):
    """TONR T5 keeps its count while the motor is off.  The motor runs from
    the scan at 5.00 s to the one at 35.00 s: 299 ticks (the tick at 35.0
    is dropped, the box sees the motor off).  After a 20 s pause it runs
    again from 60.00 s and T5 reaches 600 at the scan starting at 90.10 s:
    the first run minute is counted in VW10 at 90.11 s, and T5 restarts."""
    plc["I0.0"] = 1
    plc.run("35s")
    plc["I0.0"] = 0
    plc.run("20s")
    assert plc["Q0.0"] == 0
    assert plc["T5"] == 299
    plc["I0.0"] = 1
    plc.run_until("VW10 == 1", timeout="60s")
    assert plc.time == pytest.approx(90.11)
    assert plc["T5"] == 0


def test_service_lamp_after_three_run_minutes_and_reset(plc):
    """Start from 2 run minutes and 55 s (VW10 = 2, T5 = 550): the motor
    starts at 5.00 s, the third minute is complete 50 ticks later, at the
    scan starting at 10.00 s, and the service lamp comes on at 10.01 s.  T5
    goes on counting the next minute (20 ticks in the next 2 s); the
    service button clears both the minutes and the part-minute."""
    plc["VW10"] = 2
    plc["T5"] = 550
    plc["I0.0"] = 1
    plc.run_until("Q0.3", timeout="20s")
    assert plc.time == pytest.approx(10.01)
    plc.run("2s")
    assert plc["T5"] == 20
    plc.pulse("I0.3")
    assert plc.values("VW10", "T5", "Q0.3") == {"VW10": 0, "T5": 0, "Q0.3": 0}


@pytest.mark.parametrize(
    "switch_on, on_times",
    [
        # input on before the first scan: all three timers agree
        (0.0, {"Q0.4": 0.31, "Q0.5": 0.31, "Q0.6": 0.31}),
        # input on at 0.05 s: the 1 ms and 10 ms timers time 300 ms from
        # there, the 100 ms timer counts the clock ticks at 0.1, 0.2, 0.3 s
        (0.05, {"Q0.4": 0.36, "Q0.5": 0.36, "Q0.6": 0.31}),
    ],
)
def test_three_resolutions_of_the_same_300ms(plc, switch_on, on_times):
    """T32 (1 ms, +300), T33 (10 ms, +30) and T39 (100 ms, +3) all mean
    300 ms; the times (end of scan) at which each bit comes on."""
    plc.run(switch_on)
    plc["I0.4"] = 1
    for output, expected in on_times.items():
        branch = plc.fork()
        branch.run_until(output, timeout="1s")
        assert branch.time == pytest.approx(expected), output
