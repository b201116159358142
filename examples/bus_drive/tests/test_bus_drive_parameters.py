"""Reading and writing a drive parameter by SDO from the panel, and the
abort code of a write the drive refuses, on both drive models."""

from __future__ import annotations

import pytest
from bus_drive_panel import FILES, PROGRAM, press

pytestmark = pytest.mark.plc(FILES, **PROGRAM,
                             watch=["D1_ParDone_L", "D1_Error_L", "D1_ParRead", "D1_ParAbort",
                                    "D2_ParDone_L", "D2_Error_L", "D2_ParRead", "D2_ParAbort"])


def sim(plc, axis):
    return plc.plc.module(0).drive(axis.node)


def test_read_a_parameter_set_by_the_plant_file(enabled, axis):
    """6099h:01, the homing search speed, is 20000 from the plant file's
    params (written by SDO at start-up)."""
    plc = enabled
    plc[axis["ParIndex"]], plc[axis["ParSub"]] = 0x6099, 1
    press(plc, axis["Read_PB"], axis["ParDone_L"])
    assert (plc[axis["ParRead"]], plc[axis["ParAbort"]]) == (20000, 0)


def test_write_then_read_back(enabled, axis):
    """The panel's value 250 to 607Ch:00 (home offset), then read back; the
    drive holds it too."""
    plc = enabled
    press(plc, axis["Write_PB"], axis["ParDone_L"])
    assert sim(plc, axis).read(0x607C) == 250
    plc[axis["ParValue"]] = -1234
    plc.scan(2)
    press(plc, axis["Write_PB"], axis["ParDone_L"])
    press(plc, axis["Read_PB"], axis["ParDone_L"])
    assert plc[axis["ParRead"]] == -1234 and sim(plc, axis).read(0x607C) == -1234


def test_a_refused_write_lights_the_error_lamp_with_the_abort_code(enabled, axis):
    """6041h is read-only: SDO abort 0x06010002 in the panel's abort code,
    the error lamp on, the diagnostics say why; the fault reset button
    puts the lamp out (the drive itself has no fault)."""
    plc = enabled
    plc[axis["ParIndex"]] = 0x6041
    press(plc, axis["Write_PB"], axis["Error_L"])
    assert plc[axis["ParAbort"]] & 0xFFFFFFFF == 0x06010002
    assert plc[axis["ParDone_L"]] == 0
    assert any(f"node {axis.node}: SDO write 6041h:00" in d.message and "read-only" in d.message
               for d in plc.diagnostics)
    assert plc.drive(axis.node).state == "OPERATION ENABLED"
    press(plc, axis["Reset_PB"], f"not {axis['Error_L']}")
