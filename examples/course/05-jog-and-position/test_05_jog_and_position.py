"""Lesson 5: jogging with SPD_CTRL and a relative move with POS_GOTO_R.

Positions are in pulses, times in simulated seconds (10 ms scans).
``plc.axis()`` is the state of axis 0 of the EM253 in slot 0 at
``plc.time``, between two scans; the block outputs (C_Status, C_Pos) are
written when the block runs, at the start of a scan.

The figures follow from the parameters: a ramp changes the speed linearly
between SpdSs and SpdSet in AccTime / DecTime, so the 200 ms ramps of the
move (1 kHz <-> 10 kHz) take (1000 + 10000) / 2 x 0.2 = 1100 pulses each,
and the 7800 pulses between them take 0.78 s at 10 kHz: 1.18 s in all.
The jog ramps (1 kHz <-> 5 kHz) take 600 pulses each.
"""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.plc("lesson.awl", plant="plant.toml",
                             watch=["I0.0", "I0.1", "M11.0", "VW106", "VW206", "VD208", "VD300"])


@pytest.fixture
def ready(plc):
    """Power-up and one scan: the module is enabled, the axis stands at 0."""
    plc.scan()
    assert plc.axis().position == 0
    return plc


def press_go(plc):
    plc.pulse("I0.2")


def test_go_moves_exactly_10000_pulses_in_1_18_s(ready):
    """Go pressed in the scan at 0.01 s sets Run (M11.0) after the CALL; the
    block sees the edge in the scan at 0.02 s and the last pulse goes out at
    1.20 s.  axis_done_within runs one scan more, in which the block reports:
    C_Status is 8, C_Pos and the counter read 10000, and Run is released."""
    press_go(ready)
    assert ready["M11.0"] == 1
    assert ready.axis_done_within("2s") == pytest.approx(1.18)
    assert ready.time == pytest.approx(1.21)
    axis = ready.axis()
    assert (axis.position, axis.mechanical, axis.speed) == (10000, 10000, 0)
    assert ready.values("VW206", "VD208", "VD300", "M11.0", "Q0.0") == {
        "VW206": 8, "VD208": 10000, "VD300": 10000, "M11.0": 0, "Q0.0": 0}


@pytest.mark.parametrize("after, speed", [
    (0.01, 1450),    # one scan after the start: 1000 Hz + 45 kHz/s x 0.01 s
    (0.1, 5500),     # half way up the ramp
    (0.2, 10000),    # SpdSet reached
    (0.9, 10000),    # cruising
    (1.08, 5500),    # half way down
    (1.17, 1450),    # 10 ms before the last pulse
])
def test_speed_profile_of_the_move(ready, after, speed):
    """The speed (Hz) of the trapezoid ``after`` seconds after the move
    started (at 0.02 s): the ramps change it by 9000 Hz in 0.2 s."""
    press_go(ready)
    ready.run(after)
    assert ready.time == pytest.approx(0.02 + after)
    assert ready.axis().speed == speed


def test_each_go_moves_another_10000_pulses(ready):
    """POS_GOTO_R is relative: three presses, 30000 pulses from the origin."""
    for n in (1, 2, 3):
        press_go(ready)
        ready.axis_done_within("2s")
        assert ready["VD300"] == 10000 * n


def test_jog_forward_and_back(ready):
    """Jog forward held 1 s: 600 pulses of ramp and 0.8 s at 5 kHz, so 4600
    pulses; released, the ramp down adds 600: 5200.  Jog reverse for the
    same time brings the axis back to 0."""
    ready["I0.0"] = 1
    ready.run("1s")
    assert ready.axis().position == 4600
    assert ready["VD108"] == 5000           # C_Spd, signed
    ready["I0.0"] = 0
    ready.wait_axis_stopped(timeout="1s")
    assert ready.axis().position == 5200
    ready["I0.1"] = 1
    ready.run("1s")
    assert ready["VD108"] == -5000
    ready["I0.1"] = 0
    ready.wait_axis_stopped(timeout="1s")
    assert ready.axis().position == 0


def test_both_jog_buttons_together_do_not_move(ready):
    """Jog forward and reverse together: M10.0 (exclusive OR) stays off."""
    with ready.forced({"I0.0": 1, "I0.1": 1}):
        ready.stays(lambda h: not h.axis().moving, "1s")
    assert ready["M10.0"] == 0


def test_go_is_refused_while_jogging(ready):
    """Only one instruction may move an axis: go pressed during a jog is
    ignored (with a warning) and Run is released, so the next go after the
    jog works."""
    ready["I0.0"] = 1
    ready.run("0.5s")
    press_go(ready)
    ready.scan()
    assert ready.warnings("already moved by another instruction")
    assert ready["M11.0"] == 0
    ready["I0.0"] = 0
    ready.wait_axis_stopped(timeout="1s")
    start = ready.axis().position
    press_go(ready)
    ready.axis_done_within("2s")
    assert ready.axis().position == start + 10000


def test_stop_during_the_move_stops_at_once(ready):
    """Stop (E_Stop) at 0.52 s: the pulses stop at that scan start, without
    a ramp.  C_Status becomes 8, C_Pos keeps the pulses sent, and a new go
    (stop released) starts a whole new 10000-pulse move."""
    press_go(ready)
    ready.run("0.5s")
    ready["I0.3"] = 1
    ready.scan()
    axis = ready.axis()
    assert axis.speed == 0 and not axis.moving
    assert ready["VW206"] == 8
    stopped_at = axis.position
    assert stopped_at == ready["VD208"] == 4100    # 1100 of ramp + 0.3 s x 10 kHz
    ready["I0.3"] = 0
    ready.scan()
    press_go(ready)
    ready.axis_done_within("2s")
    assert ready.axis().position == stopped_at + 10000


def test_jog_into_the_hard_limit(ready):
    """Holding jog forward, the slide runs into L0+ at 60000 pulses and stops
    on the pulse that reaches it (a hard stop, with a warning); jog forward
    is then refused, jog reverse moves away."""
    ready["I0.0"] = 1
    ready.wait_axis_stopped(timeout="20s")
    assert ready.axis().position == 60000
    assert ready.warnings("hard limit reached at position 60000")
    ready["I0.0"] = 0
    ready.scan()
    ready["I0.0"] = 1
    ready.run("0.5s")
    assert ready.axis().position == 60000
    ready["I0.0"] = 0
    ready.scan()                 # Run must be seen at 0 before a new edge
    ready["I0.1"] = 1
    ready.run("0.5s")
    assert ready.axis().position == 60000 - 2100   # 600 of ramp + 0.3 s x 5 kHz
