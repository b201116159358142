"""A drive fault and its reset from the panel: homing method 15 is no
method of either model (HCFA §7.5.4: alarm 62, 603Fh = 62), the drive
goes to FAULT; the reset button clears it and the enable switch, still
on, brings the drive back."""

from __future__ import annotations

import pytest
from bus_drive_panel import FILES, PROGRAM, press

pytestmark = pytest.mark.plc(FILES, **PROGRAM,
                             watch=["D1_Ready_L", "D1_Fault_L", "D1_Error_L", "VW1032",
                                    "D2_Ready_L", "D2_Fault_L", "D2_Error_L", "VW1132"])


def test_an_invalid_homing_method_faults_the_drive_and_reset_clears_it(enabled, axis):
    plc = enabled
    plc[axis["HomeMethod"]] = 15
    press(plc, axis["Home_PB"], axis["Error_L"])
    plc.scan()
    d = plc.drive(axis.node)
    assert (d.state, d.error_code) == ("FAULT", 62)
    assert plc[f"VW{axis.image + 44}"] == 62                     # 603Fh in the image
    assert plc.values(axis["Fault_L"], axis["Ready_L"], axis["Homed_L"]) == \
        {axis["Fault_L"]: 1, axis["Ready_L"]: 0, axis["Homed_L"]: 0}
    assert any(f"node {axis.node}:" in m.message and "invalid homing method" in m.message
               for m in plc.diagnostics)
    press(plc, axis["Reset_PB"], axis["Ready_L"], timeout=1)
    d = plc.drive(axis.node)
    assert (d.state, d.error_code) == ("OPERATION ENABLED", 0)
    assert plc.values(axis["Fault_L"], axis["Error_L"]) == {axis["Fault_L"]: 0,
                                                           axis["Error_L"]: 0}
    # the drive works again: homing with the panel's own method
    plc[axis["HomeMethod"]] = 19 if axis.node == 1 else 5
    press(plc, axis["Home_PB"], axis["Homed_L"])
    assert plc.drive(axis.node).position == 0


def test_a_fault_on_one_drive_leaves_the_other_running(enabled):
    """Drive 1 faults while drive 2 jogs: drive 2 keeps its speed."""
    plc = enabled
    plc["D2_Jog_SW"] = 1
    plc.run_until("D2_InVel_L", timeout=2)
    plc["D1_HomeMethod"] = 15
    press(plc, "D1_Home_PB", "D1_Fault_L")
    assert plc.drive(2).velocity == 25000 and plc["D2_InVel_L"] == 1
