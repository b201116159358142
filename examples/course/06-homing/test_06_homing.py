"""Lesson 6: homing mode 2 on a reference switch and the Z pulse.

The plant (plant.toml): reference switch RPS0 active from 30000 to 34000
pulses, a Z pulse every 2000 pulses at 500 + 2000 k, limits at -5000 and
40000, the slide at 12000 at power-up.  Mode 2 leaves the switch in the
negative direction and stops on the next Z pulse: the last Z left of
the switch is 28500.  PosOffset -500 then moves the slide to 28000, where
the position counter is set to 0.
"""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import pytest

HERE = Path(__file__).parent
PLANT = tomllib.loads((HERE / "plant.toml").read_text(encoding="utf-8"))

pytestmark = pytest.mark.plc("lesson.awl", plant="plant.toml",
                             watch=["M20.0", "VW406", "VD408", "VD420", "Q0.0", "Q0.1"])


def plant_with_start(start):
    """The lesson's plant with the slide somewhere else at power-up."""
    plant = copy.deepcopy(PLANT)
    plant["module"]["0"]["axis"]["0"]["start"] = start
    return plant


def home(h):
    """Press home after the power-up scan and wait for the end of the homing
    (C_Status 8); returns the seconds that took."""
    h.scan()
    h.pulse("I0.0")
    return h.run_until("VW406 == 8", timeout="20s")


def test_counter_reads_zero_at_power_up_wherever_the_slide_is(plc):
    """Before homing the counter knows nothing: it reads 0 at power-up, but
    the slide stands at 12000.  This is why a machine homes first."""
    plc.scan()
    axis = plc.axis()
    assert (axis.position, axis.mechanical) == (0, 12000)
    assert plc.values("VD420", "Q0.1") == {"VD420": 0, "Q0.1": 0}


def test_homing_ends_500_pulses_left_of_the_z_pulse_with_counter_zero(plc):
    """From 12000: search forward at 10 kHz, slow down on the switch, creep
    back at 1 kHz to the Z pulse at 28500, move PosOffset -500.  C_Status
    reads 8 in the scan at 4.15 s, the counter is 0 at mechanical 28000,
    and the homed lamp is on."""
    assert home(plc) == pytest.approx(4.14)
    assert plc.time == pytest.approx(4.16)
    axis = plc.axis()
    assert (axis.position, axis.mechanical, axis.speed) == (0, 28000, 0)
    assert plc.values("VW406", "VD408", "VD420", "Q0.0", "Q0.1") == {
        "VW406": 8, "VD408": 0, "VD420": 0, "Q0.0": 0, "Q0.1": 1}


def test_with_no_offset_the_axis_stops_on_the_z_pulse(plc_factory):
    """The same program with PosOffset 0 (loaded from text): home is the Z
    pulse itself, 28500 = 500 + 14 x 2000, the last one left of the
    switch's edge at 30000."""
    text = (HERE / "lesson.awl").read_text(encoding="utf-8")
    call = "CALL   HOMING, 0, 0, +2, +1000, +10000, -500,"
    assert call in text
    h = plc_factory(text.replace(call, call.replace("-500", "+0")), plant=PLANT)
    home(h)
    axis = h.axis()
    assert (axis.position, axis.mechanical) == (0, 28500)


@pytest.mark.parametrize("start, seconds", [
    (-5000, 5.84),   # on the L- limit switch
    (0, 5.34),
    (12000, 4.14),   # the lesson's plant
    (31000, 2.64),   # inside the reference switch: no search
    (38000, 6.08),   # right of the switch: the search hits L+ and reverses
    (40000, 5.84),   # on the L+ limit switch: the search starts reversed
])
def test_home_is_the_same_from_anywhere(plc_factory, start, seconds):
    """Wherever the slide stands at power-up, homing ends at 28000 with the
    counter at 0; only the time it takes differs."""
    h = plc_factory("lesson.awl", plant=plant_with_start(start))
    assert home(h) == pytest.approx(seconds)
    axis = h.axis()
    assert (axis.position, axis.mechanical) == (0, 28000)
    assert h["Q0.1"] == 1


def test_stop_during_homing_leaves_the_axis_unhomed(plc):
    """Stop (E_Stop) 1 s into the search: the slide stops at once, C_Status
    is 8 but the counter was not set, so the homed lamp stays off."""
    plc.scan()
    plc.pulse("I0.0")
    plc.run("1s")
    assert plc["Q0.0"] == 1
    plc["I0.1"] = 1
    plc.scan()
    axis = plc.axis()
    assert axis.speed == 0
    assert axis.mechanical != 28000
    assert axis.position == axis.mechanical - 12000    # pulses counted since power-up
    assert plc.values("VW406", "Q0.0", "Q0.1") == {"VW406": 8, "Q0.0": 0, "Q0.1": 0}


def test_homing_again_clears_the_homed_lamp_until_it_ends(plc):
    """A second homing from home: the lamp goes off while it runs (C_Status
    1) and comes back on at the end, at the same place."""
    home(plc)
    plc.scan()
    plc.pulse("I0.0")
    plc.scan()
    assert plc.values("VW406", "Q0.0", "Q0.1") == {"VW406": 1, "Q0.0": 1, "Q0.1": 0}
    plc.run_until("Q0.1", timeout="20s")
    axis = plc.axis()
    assert (axis.position, axis.mechanical) == (0, 28000)
