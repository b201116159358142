"""POS_RUN with Update while the envelope runs (EM253 manual 3.2.6: the
positions may change in the same direction, the direction may not)."""

from __future__ import annotations

import plcrt

PROG = """ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     SM0.0
CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0
Network 2
LD     SM0.0
CALL   POS_RUN, 0, 0, 0, +5000, &VB1000, 2, VD100, VB104, M3.1, M3.0, VW106, VD108, VD112, VB116
END_ORGANIZATION_BLOCK
"""
TABLE = ("VW1000 1000\nVW1002 1000\nVD1004 20000\nVD1008 100000\n"
         "VW1012 1000\nVW1014 1000\nVD1016 10000\nVD1020 50000\n")
PLANT = {"module": {"0": {"axis": {"0": {}}}}}


def _started() -> plcrt.Plc:
    plc = plcrt.load(PROG, plant=PLANT, data=TABLE, scan_ms=10)
    plc["M3.0"] = 1
    plc.run(seconds=2)
    assert plc.axis(0, 0)["status"] == "moving" and plc["VB116"] == 1
    return plc


def test_update_lengthens_the_current_step_exactly() -> None:
    """A longer PosSet for the running step, applied with Update, moves the
    end of the envelope by exactly the difference; Update is cleared."""
    plc = _started()
    plc["VD1008"] = 200000
    plc["VB104"] = 1
    plc.scan()
    assert plc["VB104"] == 0
    plc.run(seconds=40)
    assert plc.axis(0, 0)["position"] == 250000
    assert (plc["VW106"], plc["VB116"], plc["VD108"]) == (8, 2, 50000)


def test_update_of_a_later_step() -> None:
    """Changing a step that has not started yet takes effect when it runs."""
    plc = _started()
    plc["VD1020"] = 70000
    plc["VB104"] = 1
    plc.run(seconds=40)
    assert plc.axis(0, 0)["position"] == 170000


def test_update_cannot_reverse_the_envelope() -> None:
    """A negative PosSet given with Update is refused with a diagnostic;
    the envelope ends as first planned."""
    plc = _started()
    plc["VD1020"] = -50000
    plc["VB104"] = 1
    plc.run(seconds=40)
    assert plc.axis(0, 0)["position"] == 150000
    assert any("direction" in d.message and "POS_RUN" in d.message
               for d in plc.diagnostics)
