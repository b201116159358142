"""Lesson 3: CTU counts parts, CTUD keeps the car park's count.

A counter counts rising edges of its count input, so a helper ``press``
holds an input for one scan and then leaves it off for one scan: one
complete pulse, the shortest a PLC with 10 ms scans can see.
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytestmark = pytest.mark.plc("lesson.awl", watch=["I0.0", "C0", "Q0.0", "I0.2", "I0.3", "C1"])


def press(plc, address, times=1):
    """``times`` complete pulses on ``address``: one scan on, one scan off."""
    for _ in range(times):
        plc.pulse(address)
        plc.scan()


def test_ten_parts_complete_a_batch(plc):
    """Nine parts: C0 = 9, no batch; the tenth part sets C0 and Q0.0 in the
    scan in which it arrives.  VW0 shows the count for the display."""
    press(plc, "I0.0", 9)
    assert plc.values("C0", "VW0", "Q0.0") == {"C0": 9, "VW0": 9, "Q0.0": 0}
    plc.pulse("I0.0")
    assert plc.values("C0", "VW0", "Q0.0") == {"C0": 10, "VW0": 10, "Q0.0": 1}


def test_a_part_that_stays_in_front_of_the_sensor_counts_once(plc):
    """The sensor on for 2 s is one rising edge: one count."""
    plc["I0.0"] = 1
    plc.run("2s")
    assert plc["C0"] == 1


def test_counting_goes_on_past_the_preset(plc):
    """CTU keeps counting past PV (the bit stays on) until it is reset."""
    press(plc, "I0.0", 12)
    assert plc.values("C0", "Q0.0") == {"C0": 12, "Q0.0": 1}


def test_reset_clears_count_and_batch_and_wins_over_counting(plc):
    """The reset button clears C0 and the batch lamp; while it is held,
    parts are not counted (R is the top of the stack: it wins)."""
    press(plc, "I0.0", 10)
    with plc.forced({"I0.1": 1}):
        press(plc, "I0.0", 3)
        assert plc.values("C0", "Q0.0") == {"C0": 0, "Q0.0": 0}
    press(plc, "I0.0")
    assert plc["C0"] == 1


def test_car_park_counts_in_and_out(plc):
    """Five cars in, two out: three inside, 47 spaces free, FULL off."""
    press(plc, "I0.2", 5)
    press(plc, "I0.3", 2)
    assert plc.values("C1", "VW2", "VW4", "Q0.1", "Q0.2") == {
        "C1": 3, "VW2": 3, "VW4": 47, "Q0.1": 0, "Q0.2": 1}


def test_car_park_full_at_fifty(plc):
    """The 50th car switches FULL on and "spaces free" off; one car leaving
    switches them back."""
    press(plc, "I0.2", 49)
    assert plc.values("Q0.1", "Q0.2") == {"Q0.1": 0, "Q0.2": 1}
    press(plc, "I0.2")
    assert plc.values("C1", "VW4", "Q0.1", "Q0.2") == {"C1": 50, "VW4": 0, "Q0.1": 1, "Q0.2": 0}
    press(plc, "I0.3")
    assert plc.values("C1", "Q0.1", "Q0.2") == {"C1": 49, "Q0.1": 0, "Q0.2": 1}


def test_exit_sensor_with_an_empty_car_park_does_not_count_below_zero(plc):
    """Someone walks out past the exit sensor of the empty car park: the AW>
    guard keeps C1 at 0 (an unguarded CTUD would read -1)."""
    press(plc, "I0.3", 3)
    assert plc.values("C1", "VW4") == {"C1": 0, "VW4": 50}


def test_car_park_reset(plc):
    """The reset button (for example at night, after a count) clears C1."""
    press(plc, "I0.2", 7)
    press(plc, "I0.4")
    assert plc.values("C1", "VW2", "VW4") == {"C1": 0, "VW2": 0, "VW4": 50}


def test_without_the_guard_ctud_goes_negative(plc_factory):
    """The same program without the AW> line (loaded from text with
    ``plc_factory``): the exit sensor of the empty car park makes C1 -1 and
    the free-space display 51.  This is why the guard is there."""
    text = (Path(__file__).parent / "lesson.awl").read_text(encoding="utf-8")
    assert "AW>    C1, +0\n" in text
    unguarded = plc_factory(text.replace("AW>    C1, +0\n", ""))
    press(unguarded, "I0.3")
    assert unguarded.values("C1", "VW4") == {"C1": -1, "VW4": 51}
