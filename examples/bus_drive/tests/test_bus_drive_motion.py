"""Power, homing, absolute and relative moves and a velocity phase, on the
HCFA stepper (node 1) and the Kinco servo (node 2), from the ladder
program: exact counts and statuswords from the drives (``plc.drive``) and
from their images in V memory."""

from __future__ import annotations

import pytest
from bus_drive_panel import FILES, PROGRAM, mechanical, press

pytestmark = pytest.mark.plc(FILES, **PROGRAM,
                             watch=["D1_Ready_L", "D1_Homed_L", "D1_InPos_L", "VD1036",
                                    "D2_Ready_L", "D2_Homed_L", "D2_InPos_L", "VD1136"])


def test_power_up_both_drives_stand_in_switch_on_disabled(plc):
    """The module brings both drives to OP; nothing enables them until the
    switches do.  The first scan chose PP (6060h = 1)."""
    plc.scan()
    for node, image in ((1, 1000), (2, 1100)):
        d = plc.plc.drive(node)
        assert (d.state, d.online, d.mode, d.position) == ("SWITCH ON DISABLED", True, 1, 0)
        assert plc[f"VB{image + 35}"] == 0x01            # online, mailbox idle
    assert plc.values("D1_Ready_L", "D2_Ready_L") == {"D1_Ready_L": 0, "D2_Ready_L": 0}


def test_the_enable_switch_walks_the_drive_to_operation_enabled(plc, axis):
    """06h, 07h, 0Fh one scan each (HCFA §7.2), Ready in the fourth scan;
    switched off: Disable voltage, SWITCH ON DISABLED."""
    plc.scan()
    plc[axis["Enable_SW"]] = 1
    states = []
    for _ in range(4):
        plc.scan()
        states.append((plc.plc.drive(axis.node).state, plc[axis["PowerCmd"]], plc[axis["Ready_L"]]))
    assert states == [("READY TO SWITCH ON", 6, 0), ("SWITCHED ON", 7, 0),
                      ("OPERATION ENABLED", 15, 0), ("OPERATION ENABLED", 15, 1)]
    plc[axis["Enable_SW"]] = 0
    plc.scan(2)
    assert (plc.plc.drive(axis.node).state, plc[axis["Ready_L"]]) == ("SWITCH ON DISABLED", 0)


def test_homing_ends_on_the_method_s_home_point_with_count_zero(enabled, axis):
    plc = enabled
    press(plc, axis["Home_PB"], axis["Homed_L"])
    d = plc.plc.drive(axis.node)
    assert (d.position, d.velocity, d.mode, d.statusword) == (0, 0, 6, axis.homed_word)
    assert mechanical(plc, axis) == axis.home_point
    assert plc[f"VD{axis.image + 36}"] == 0
    assert plc.values(axis["Home_Cmd"], axis["Error_L"]) == {axis["Home_Cmd"]: 0,
                                                             axis["Error_L"]: 0}


def test_homing_with_an_offset_written_from_the_panel(enabled, axis):
    """607Ch = 250 by SDO (the panel's parameter 607Ch:00 and value), then
    homing: HCFA counts +250 at the home point, Kinco -250."""
    plc = enabled
    press(plc, axis["Write_PB"], axis["ParDone_L"])
    press(plc, axis["Home_PB"], axis["Homed_L"])
    assert plc.plc.drive(axis.node).position == axis.offset_sign * 250
    assert mechanical(plc, axis) == axis.home_point


def test_absolute_then_relative_moves_end_exactly_on_target(homed, axis):
    plc = homed
    press(plc, axis["Abs_PB"], axis["InPos_L"])
    d = plc.plc.drive(axis.node)
    assert (d.position, d.velocity, d.mode, d.statusword) == \
        (axis.abs_target, 0, 1, axis.pp_idle_homed)
    assert plc[f"VD{axis.image + 36}"] == axis.abs_target
    assert mechanical(plc, axis) == axis.home_point + axis.abs_target
    press(plc, axis["Rel_PB"], axis["InPos_L"])
    d = plc.plc.drive(axis.node)
    assert d.position == axis.abs_target + axis.rel_distance
    assert d.controlword & 0x0070 == 0x0060        # relative, change at once, bit 4 low
    assert plc[axis["Error_L"]] == 0


def test_the_home_point_lies_where_the_method_says(homed, axis):
    """Count 0 is the home point: the HCFA method homes one count off the
    home switch's edge (mechanical 10000), the Kinco method on the index
    pulse 100 counts right of the switch's edge -4000.  The home switch
    input (60FDh bit 2, image + 52) comes on exactly there."""
    plc = homed
    image_inputs = f"VD{axis.image + 52}"
    assert plc[image_inputs] & 0b100 == 0
    plc[axis["RelDistance"]] = axis.to_switch - (1 if axis.to_switch > 0 else -1)
    press(plc, axis["Rel_PB"], axis["InPos_L"])
    assert plc[image_inputs] & 0b100 == 0
    plc[axis["RelDistance"]] = 1 if axis.to_switch > 0 else -1
    plc.scan(2)
    press(plc, axis["Rel_PB"], axis["InPos_L"])
    assert plc[image_inputs] & 0b100 == 0b100
    assert plc.plc.drive(axis.node).position == axis.to_switch
    assert mechanical(plc, axis) == axis.home_point + axis.to_switch


def test_a_velocity_phase_reaches_the_jog_speed_and_stops_on_the_ramp(homed, axis):
    """Jog switch on: PV (6060h = 3) at the panel's jog velocity, InVel lamp
    once the drive reports the speed (6041h bit 10); off: 60FFh = 0, the
    axis ramps to rest on 6084h (the panel's deceleration)."""
    plc = homed
    plc[axis["Jog_SW"]] = 1
    plc.run_until(axis["InVel_L"], timeout=2)
    d = plc.plc.drive(axis.node)
    assert (d.mode, d.velocity) == (3, axis.jog)
    assert plc[f"VD{axis.image + 40}"] == axis.jog
    plc.run("1s")
    plc[axis["Jog_SW"]] = 0
    plc.scan()
    assert plc[f"VD{axis.image + 8}"] == 0 and plc[axis["InVel_L"]] == 0
    plc.run_until(lambda: plc.plc.drive(axis.node).velocity == 0, timeout=2)
    assert plc.plc.drive(axis.node).state == "OPERATION ENABLED"
    # a move after the velocity phase goes back to PP and ends on target
    press(plc, axis["Abs_PB"], axis["InPos_L"])
    assert (plc.plc.drive(axis.node).mode, plc.plc.drive(axis.node).position) == (1, axis.abs_target)
