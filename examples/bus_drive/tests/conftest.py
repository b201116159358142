"""Shared fixtures of the bus drive example's tests.

Each test module names the program and the library with a module-level
marker (the program file and library/cia402/drive_lib.awl, merged), so every
test starts at power-up.  The fixtures enable the drives and run one test
on both drive models (``bus_drive_panel.AXES``).
"""

from __future__ import annotations

import pytest
from bus_drive_panel import AXES, Axis, press


@pytest.fixture(params=AXES, ids=[a.model for a in AXES])
def axis(request) -> Axis:
    return request.param


@pytest.fixture
def enabled(plc):
    """Both drives switched on and in OPERATION ENABLED (Ready lamps)."""
    plc.scan()
    plc["D1_Enable_SW"] = plc["D2_Enable_SW"] = 1
    plc.run_until(lambda: plc["D1_Ready_L"] and plc["D2_Ready_L"], timeout=1)
    return plc


@pytest.fixture
def homed(enabled, axis):
    """The axis under test homed with its panel's method (607Ch = 0)."""
    press(enabled, axis["Home_PB"], axis["Homed_L"])
    return enabled
