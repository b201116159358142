"""Table tests for plcrt.isa.smart: BITIM, CITIM (the 1 ms system timer),
DLED (the diagnostic LED) and GPA, SPA (port station addresses; S7-200
SMART System Manual, "Interval timers", "Diagnostic LED"; S7-200 System
Manual, "Get Port Address and Set Port Address")."""

from __future__ import annotations

import re

import pytest

import plcrt
from plcrt.debug.panels import status_line
from stl_helpers import ob1_text


def _load(*networks: str, scan_ms: float = 10.0) -> plcrt.Plc:
    return plcrt.load(ob1_text(*networks), scan_ms=scan_ms)


def test_bitim_reads_the_millisecond_timer():
    """BITIM stores the milliseconds since power-up at the scan's start."""
    p = _load("LD SM0.0\nBITIM VD0", scan_ms=7.5)
    p.scan(5)
    assert p["VD0"] == 30          # the fifth scan starts at 30 ms


def test_citim_measures_an_interval():
    """CITIM gives the milliseconds since the BITIM that stored IN."""
    p = _load("LD SM0.1\nBITIM VD0", "LD SM0.0\nCITIM VD0, VD4", scan_ms=20)
    p.scan(51)
    assert p["VD4"] == 1000


@pytest.mark.parametrize("start,now_ms,expect", [
    (0xFFFFFFF0, 5, 21),           # the timer wrapped between BITIM and CITIM
    (100, 100, 0),
    (0, 2**32 - 1 + 1, 0),
])
def test_citim_handles_the_wrap(start, now_ms, expect):
    """CITIM is now - IN modulo 2**32 (one wrap of the timer is handled)."""
    p = _load("LD SM0.0\nCITIM VD0, VD4", scan_ms=1)
    p["VD0"] = start - 2**32 if start >= 2**31 else start
    p._t_us = now_ms * 1000
    p.scan()
    assert p["VD4"] & 0xFFFFFFFF == expect


def test_citim_from_a_constant_and_into_ac():
    """IN may be a constant and OUT an accumulator."""
    p = _load("LD SM0.0\nCITIM 1, AC0\nMOVD AC0, VD8", scan_ms=10)
    p.scan(3)
    assert p["VD8"] == 19


def test_dled_on_and_off():
    """DLED with IN > 0 lights the LED, IN = 0 turns it off; the status line says so."""
    p = _load("LD SM0.0\nDLED VB0")
    p["VB0"] = 200
    p.scan()
    assert p.station.led is True
    assert status_line(p).endswith("DLED on")
    p["VB0"] = 0
    p.scan()
    assert p.station.led is False
    assert "DLED" not in status_line(p)


def test_dled_without_power_flow_changes_nothing():
    """A DLED box without power flow leaves the LED as it is."""
    p = _load("LD SM0.1\nDLED 1", "LD I0.0\nDLED 0")
    p.scan(2)
    assert p.station.led is True


def test_gpa_reads_the_default_station_address():
    """Both ports start at station address 2 (the system block's default)."""
    p = _load("LD SM0.0\nGPA VB0, 0\nGPA VB1, 1")
    p.scan()
    assert (p["VB0"], p["VB1"]) == (2, 2)


def test_spa_sets_one_port():
    """SPA changes the address of its port only; GPA reads it back; ENO 1."""
    p = _load("LD SM0.0\nSPA VB10, 1\nAENO\n= Q0.0\nLD SM0.0\nGPA VB0, 0\nGPA VB1, 1")
    p["VB10"] = 126
    p.scan()
    assert (p["VB0"], p["VB1"], p["Q0.0"], p["SM4.3"]) == (2, 126, 1, 0)


def test_spa_out_of_range_is_error_0091():
    """SPA with an address above 126 changes nothing: SM4.3, ENO 0, a warning."""
    p = _load("LD SM0.0\nSPA 127, 0\nAENO\n= Q0.0\nLD SM0.0\nGPA VB0, 0")
    p.scan()
    assert (p["VB0"], p["Q0.0"], p["SM4.3"]) == (2, 0, 1)
    assert any("0091" in d.message for d in p.diagnostics)


def test_spa_in_an_interrupt_routine_is_error_0004():
    """SPA executed by an interrupt routine is refused (error 0004)."""
    text = ob1_text("LD SM0.1\nMOVB 10, SMB34\nATCH INT0, 10\nENI") + """INTERRUPT_BLOCK INT0:INT0
BEGIN
Network 1
LD SM0.0
SPA 9, 0
GPA VB0, 0
END_INTERRUPT_BLOCK
"""
    p = plcrt.load(text, scan_ms=10)
    p.scan(3)
    assert p["VB0"] == 2 and p["SM4.3"] == 1
    assert any("0004" in d.message for d in p.diagnostics)


def test_port_must_be_0_or_1():
    """PORT is the constant 0 or 1 (compile error otherwise)."""
    with pytest.raises(plcrt.PlcCompileError, match="PORT must be the constant 0 or 1"):
        _load("LD SM0.0\nGPA VB0, 2")
    with pytest.raises(plcrt.PlcCompileError, match="PORT must be"):
        _load("LD SM0.0\nSPA 3, VB1")


def test_fork_copies_led_and_addresses():
    """A fork has the same LED and port addresses; changing one leaves the other."""
    p = _load("LD SM0.1\nDLED 1\nSPA 7, 0", "LD I0.0\nDLED 0\nSPA 8, 0")
    p.scan()
    twin = p.fork()
    twin["I0.0"] = 1
    twin.scan()
    assert (p.station.led, p.station.addresses[0]) == (True, 7)
    assert (twin.station.led, twin.station.addresses[0]) == (False, 8)


@pytest.mark.parametrize("stl,title,pins", [
    ("ATT VW0, VW200", "AD_T_TBL", ["DATA", "TBL"]),
    ("FIFO VW200, VW0", "FIFO", ["TBL", "DATA"]),
    ("LIFO VW200, VW0", "LIFO", ["TBL", "DATA"]),
    ("FND< VW202, 5, AC1", "TBL_FIND", ["TBL", "PTN", "INDX", "CMD 3"]),
    ("ITA VW0, VB10, 16#0B", "I_A", ["IN", "FMT", "OUT"]),
    ("DTA VD0, VB10, 3", "DI_A", ["IN", "FMT", "OUT"]),
    ("RTA VD0, VB10, 16#A3", "R_A", ["IN", "FMT", "OUT"]),
    ("ATH VB0, VB10, 3", "ATH", ["IN", "LEN", "OUT"]),
    ("HTA VB0, VB10, 3", "HTA", ["IN", "LEN", "OUT"]),
    ("TODR VB0", "READ_RTC", ["T"]),
    ("TODW VB0", "SET_RTC", ["T"]),
    ("TODRX VB0", "READ_RTCX", ["T"]),
    ("TODWX VB0", "SET_RTCX", ["T"]),
    ("BITIM VD0", "BGN_ITIME", ["OUT"]),
    ("CITIM VD0, VD4", "CAL_ITIME", ["IN", "OUT"]),
    ("DLED VB0", "DIAG_LED", ["IN"]),
    ("GPA VB0, 0", "GET_ADDR", ["ADDR", "PORT"]),
    ("SPA VB0, 1", "SET_ADDR", ["ADDR", "PORT"]),
])
def test_new_boxes_draw(stl, title, pins):
    """Every table, ASCII, clock and SMART box draws as Micro/WIN's LAD box,
    with its pins (FND's compare as the CMD input 1..4)."""
    from plcrt.engine.runtime import parse_sources
    from plcrt.view.render import ladder_text
    prog = parse_sources(ob1_text("LD I0.0\n" + stl))
    pou = prog.pous[0]
    text = ladder_text(pou, pou.networks[0], program=prog)
    assert re.search(rf"│\s+{re.escape(title)}\s+│", text.splitlines()[2]), text   # title row
    for pin in pins:
        assert pin in text, (pin, text)
    assert "ENO" in text
