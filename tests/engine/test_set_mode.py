"""Plc.set_mode: RUN and STOP as the mode switch or a programming device
sets them (System Manual, "Selecting the operating mode"): STOP turns the
outputs off and scans do nothing; RUN from STOP makes the next scan a
first scan (SM0.1 on, SM0.3 off: SM0.3 is for RUN entered from power-up)
and keeps memory; a CPU stopped on a fatal error stays in STOP."""

from __future__ import annotations

import pytest

import plcrt
from plcrt.errors import PlcConfigError

FIRST = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD SM0.1
+I 1, VW0
Network 2
LD SM0.3
+I 1, VW2
Network 3
LD SM0.0
+I 1, VW4
= Q0.0
END_ORGANIZATION_BLOCK
"""


@pytest.mark.parametrize("backend", ["python", "native"])
def test_stop_then_run_is_a_first_scan_without_power_up(backend: str) -> None:
    if backend == "native":
        pytest.importorskip("llvmlite")
    plc = plcrt.load(FIRST, backend=backend)
    plc.scan(3)
    assert (plc["VW0"], plc["VW2"], plc["VW4"], plc["Q0.0"]) == (1, 1, 3, 1)
    plc.set_mode("STOP")
    assert plc.mode == "STOP" and plc.mem.areas["PQ"][0] == 0   # outputs off at once
    t = plc.now_us
    plc.scan(5)
    assert (plc.scans, plc.now_us, plc["VW4"]) == (3, t, 3)
    plc.set_mode("RUN")
    plc.scan(4)
    # SM0.1 once more, SM0.3 not; memory kept (VW4 goes on from 3)
    assert (plc["VW0"], plc["VW2"], plc["VW4"]) == (2, 1, 7)


def test_setting_the_mode_it_is_in_changes_nothing() -> None:
    plc = plcrt.load(FIRST)
    plc.scan(2)
    plc.set_mode("RUN")
    plc.scan(1)
    assert plc["VW0"] == 1


def test_a_stop_instruction_then_run_runs_again() -> None:
    plc = plcrt.load("""ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD SM0.0
+I 1, VW0
Network 2
LDW= VW0, 2
STOP
END_ORGANIZATION_BLOCK
""")
    plc.scan(5)
    assert plc.mode == "STOP" and plc["VW0"] == 2
    plc.set_mode("RUN")
    plc.scan(3)
    assert plc.mode == "RUN" and plc["VW0"] == 5


@pytest.mark.parametrize("bad", ["run", "PAUSE", "", None, 1, ["RUN"],
                                 __import__("numpy").array(["RUN", "STOP"])])
def test_other_modes_are_refused(bad: object) -> None:
    with pytest.raises(PlcConfigError):
        plcrt.load(FIRST).set_mode(bad)  # type: ignore[arg-type]


def test_run_after_a_fatal_error_is_refused() -> None:
    plc = plcrt.load("""ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LBL 1
Network 2
LD SM0.0
JMP 1
END_ORGANIZATION_BLOCK
""")
    with pytest.raises(plcrt.PlcRuntimeError):
        plc.scan(1)
    assert plc.mode == "STOP"
    with pytest.raises(PlcConfigError, match="fatal error"):
        plc.set_mode("RUN")


def test_stop_requested_takes_true_or_false_only() -> None:
    plc = plcrt.load(FIRST)
    with pytest.raises(PlcConfigError):
        plc.stop_requested = __import__("numpy").array([1, 2])  # type: ignore[assignment]
    plc.stop_requested = 1
    plc.scan(2)
    assert plc.mode == "STOP"
