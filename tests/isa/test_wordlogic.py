"""Table tests for plcrt.isa.wordlogic: AND/OR/XOR/INV, shifts, rotates, SHRB."""

from __future__ import annotations

import re

import pytest

import plcrt
from plcrt.errors import PlcCompileError

_WIDTH = {"B": 1, "W": 2, "D": 4}


def _program(lines: list[str]) -> str:
    if not lines[0].split()[0].upper().startswith("LD"):
        lines = ["LD SM0.0"] + lines
    body = "\n".join(lines)
    return f"ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\n{body}\nEND_ORGANIZATION_BLOCK\n"


def _run(lines: list[str], preset: dict | None = None, scans: int = 1) -> plcrt.Plc:
    """Load a one-network program (``LD SM0.0`` prepended), preset memory, scan."""
    p = plcrt.load(_program(lines))
    for addr, value in (preset or {}).items():
        p[addr] = value
    p.scan(scans)
    return p


def _unsigned(p: plcrt.Plc, addr: str) -> int:
    """Read an address as an unsigned bit pattern (bits as 0/1)."""
    m = re.fullmatch(r"(?:SM|[IQMVSL])([BWD])\d+", addr, re.IGNORECASE)
    width = 4 if addr.upper().startswith("AC") else _WIDTH[m.group(1).upper()] if m else 0
    v = p[addr]
    return v & ((1 << 8 * width) - 1) if width else v


def _check(p: plcrt.Plc, expect: dict) -> None:
    got = {a: _unsigned(p, a) for a in expect}
    assert got == expect


# -- logic: (id, lines, preset, expected unsigned values) ---------------------
LOGIC = [
    ("ANDB", ["ANDB VB0, VB1"], {"VB0": 0xF0, "VB1": 0x3C},
     {"VB1": 0x30, "VB0": 0xF0, "SM1.0": 0}),
    ("ANDB zero", ["ANDB VB0, VB1"], {"VB0": 0x0F, "VB1": 0xF0}, {"VB1": 0, "SM1.0": 1}),
    ("ORB binary const", ["ORB 2#1010_0101, VB1"], {"VB1": 0x0A}, {"VB1": 0xAF}),
    ("XORB to zero", ["XORB VB1, VB1"], {"VB1": 0x5A, "SMB1": 0}, {"VB1": 0, "SM1.0": 1}),
    ("ANDW hex const", ["ANDW 16#FF00, VW2"], {"VW2": 0x1234}, {"VW2": 0x1200}),
    ("ORW", ["ORW 16#00FF, VW2"], {"VW2": 0x1200}, {"VW2": 0x12FF, "SM1.0": 0}),
    ("XORW self", ["XORW VW2, VW2"], {"VW2": -1}, {"VW2": 0, "SM1.0": 1}),
    ("ANDD", ["ANDD 16#0FF00FF0, VD4"], {"VD4": 0x12345678}, {"VD4": 0x02300670}),
    ("ORD", ["ORD VD0, VD4"], {"VD0": 0x80000000, "VD4": 1}, {"VD4": 0x80000001}),
    ("XORD all ones", ["XORD 16#FFFFFFFF, VD4"], {"VD4": 0x12345678}, {"VD4": 0xEDCBA987}),
    ("ANDD in AC", ["MOVD 16#F0F0F0F0, AC0", "ANDD 16#0FF00FF0, AC0"], {},
     {"AC0": 0x00F000F0}),
    ("ANDB into AC low byte", ["MOVD 16#12345678, AC2", "ANDB 16#0F, AC2"], {},
     {"AC2": 0x12345608}),
    ("ORW indirect", ["MOVD &VB200, AC1", "ORW 16#0101, *AC1"], {"VW200": 0x1010},
     {"VW200": 0x1111}),
    ("ANDW big-endian bytes", ["ANDW 16#F00F, VW100"], {"VW100": 0x1234},
     {"VB100": 0x10, "VB101": 0x04}),
    ("INVB", ["INVB VB0"], {"VB0": 0x0F}, {"VB0": 0xF0, "SM1.0": 0}),
    ("INVW to zero", ["INVW VW0"], {"VW0": -1}, {"VW0": 0, "SM1.0": 1}),
    ("INVD", ["INVD VD0"], {"VD0": 0x0000FFFF}, {"VD0": 0xFFFF0000}),
    ("INVW timer value", ["INVW T37"], {"T37": 0}, {"SM1.0": 0}),
    # Logic ops affect SM1.0 only: SM1.1, SM1.2, SM1.3 keep their values.
    ("other flags kept", ["ANDW 16#00FF, VW0"], {"VW0": 0x0101, "SMB1": 0x0E},
     {"SMB1": 0x0E}),
    ("other flags kept, zero", ["ANDW 16#0000, VW0"], {"VW0": 0x0101, "SMB1": 0x0E},
     {"SMB1": 0x0F}),
]


@pytest.mark.parametrize("lines,preset,expect", [c[1:] for c in LOGIC],
                         ids=[c[0] for c in LOGIC])
def test_logic(lines, preset, expect):
    """AND/OR/XOR/INV compute OUT := OUT op IN1 (or NOT OUT) and set SM1.0 only."""
    _check(_run(lines, preset), expect)


# -- shifts and rotates -------------------------------------------------------
SHIFT = [
    ("SLB 3", ["SLB VB0, 3"], {"VB0": 0b1011_0001},
     {"VB0": 0b1000_1000, "SM1.1": 1, "SM1.0": 0}),
    ("SRB 1", ["SRB VB0, 1"], {"VB0": 0x81}, {"VB0": 0x40, "SM1.1": 1}),
    ("SRB 8 to zero", ["SRB VB0, 8"], {"VB0": 0x80}, {"VB0": 0, "SM1.1": 1, "SM1.0": 1}),
    ("SRB 255 max shifts", ["SRB VB0, 255"], {"VB0": 0x7F}, {"VB0": 0, "SM1.1": 0, "SM1.0": 1}),
    ("SLW 4", ["SLW VW0, 4"], {"VW0": 0x1234}, {"VW0": 0x2340, "SM1.1": 1}),
    ("SLW 16 last out is bit 0", ["SLW VW0, 16"], {"VW0": 0x0001},
     {"VW0": 0, "SM1.1": 1, "SM1.0": 1}),
    ("SLW 20 same as 16", ["SLW VW0, 20"], {"VW0": 0x0001}, {"VW0": 0, "SM1.1": 1}),
    ("SRW zero fill (not arithmetic)", ["SRW VW0, 4"], {"VW0": -32768},
     {"VW0": 0x0800, "SM1.1": 0}),
    ("SLD 31", ["SLD VD0, 31"], {"VD0": 1}, {"VD0": 0x80000000, "SM1.1": 0}),
    ("SRD 1", ["SRD VD0, 1"], {"VD0": 0x80000001}, {"VD0": 0x40000000, "SM1.1": 1}),
    ("SRD 32", ["SRD VD0, 32"], {"VD0": 0x80000000}, {"VD0": 0, "SM1.1": 1}),
    ("SLB N=0 keeps OUT and SM1.1", ["SLB VB0, 0"], {"VB0": 0x81, "SMB1": 0x02},
     {"VB0": 0x81, "SMB1": 0x02}),
    ("SLW N=0 zero value sets SM1.0", ["SLW VW0, 0"], {"VW0": 0, "SMB1": 0x02},
     {"VW0": 0, "SMB1": 0x03}),
    ("shift keeps SM1.2", ["SLB VB0, 1"], {"VB0": 0x01, "SMB1": 0x04}, {"SMB1": 0x04}),
    ("SLW count in VB", ["MOVB 3, VB10", "SLW VW0, VB10"], {"VW0": 0x2001},
     {"VW0": 0x0008, "SM1.1": 1}),
    ("SRB count in AC, > 8", ["MOVB 200, AC0", "SRB VB0, AC0"], {"VB0": 0xFF},
     {"VB0": 0, "SM1.1": 1, "SM1.0": 1}),
    ("SRW count 0 in VB", ["MOVB 0, VB10", "SRW VW0, VB10"], {"VW0": 0x00FF, "SMB1": 0x02},
     {"VW0": 0x00FF, "SMB1": 0x02}),
    ("SLB indirect", ["MOVD &VB200, AC1", "SLB *AC1, 1"], {"VB200": 0x41}, {"VB200": 0x82}),
    ("RLB 1", ["RLB VB0, 1"], {"VB0": 0x81}, {"VB0": 0x03, "SM1.1": 1}),
    ("RRB 1", ["RRB VB0, 1"], {"VB0": 0x81}, {"VB0": 0xC0, "SM1.1": 1}),
    ("RRB 9 is RRB 1", ["RRB VB0, 9"], {"VB0": 0x02}, {"VB0": 0x01, "SM1.1": 0}),
    ("RLW 4", ["RLW VW0, 4"], {"VW0": 0x1234}, {"VW0": 0x2341, "SM1.1": 1}),
    ("RRW 4", ["RRW VW0, 4"], {"VW0": 0x1234}, {"VW0": 0x4123, "SM1.1": 0}),
    ("RLD 8", ["RLD VD0, 8"], {"VD0": 0x12345678}, {"VD0": 0x34567812, "SM1.1": 0}),
    ("RRD 36 is RRD 4", ["RRD VD0, 36"], {"VD0": 0x12345678}, {"VD0": 0x81234567, "SM1.1": 1}),
    ("RLW 16 does nothing", ["RLW VW0, 16"], {"VW0": 0x1234, "SMB1": 0x02},
     {"VW0": 0x1234, "SMB1": 0x02}),
    ("RLB zero value", ["RLB VB0, 3"], {"VB0": 0, "SMB1": 0x02}, {"VB0": 0, "SMB1": 0x01}),
    ("RRD count in VB", ["MOVB 40, VB10", "RRD VD0, VB10"], {"VD0": 0x000000FF},
     {"VD0": 0xFF000000, "SM1.1": 1}),
    ("RLW count 32 in VB does nothing", ["MOVB 32, VB10", "RLW VW0, VB10"],
     {"VW0": 0x00F0, "SMB1": 0x02}, {"VW0": 0x00F0, "SMB1": 0x02}),
    ("SLW on AC low word", ["MOVD 16#ABCD8001, AC3", "SLW AC3, 1"], {},
     {"AC3": 0xABCD0002, "SM1.1": 1}),
]


@pytest.mark.parametrize("lines,preset,expect", [c[1:] for c in SHIFT],
                         ids=[c[0] for c in SHIFT])
def test_shift_rotate(lines, preset, expect):
    """Shifts fill with 0 (count capped at the width), rotates take N mod width;
    SM1.1 = last bit out, SM1.0 = zero; no shift leaves OUT and SM1.1 alone."""
    _check(_run(lines, preset), expect)


def test_shift_skipped_when_top_is_zero():
    """A shift box does nothing when the top of the stack is 0."""
    p = _run(["LDN SM0.0", "SLW VW0, 1"], {"VW0": 3, "SMB1": 0})
    _check(p, {"VW0": 3, "SMB1": 0})


# -- SHRB ---------------------------------------------------------------------
SHRB = [
    ("plus 4, DATA enters at S_BIT", ["SHRB M0.0, V100.0, +4"],
     {"M0.0": 1, "VB100": 0xFA}, {"VB100": 0xF5, "SM1.1": 1}),
    ("minus 4, DATA enters at MSB", ["SHRB M0.0, V100.0, -4"],
     {"M0.0": 1, "VB100": 0xFA}, {"VB100": 0xFD, "SM1.1": 0}),
    ("plus 3 inside a byte", ["SHRB M0.0, V10.2, 3"], {"M0.0": 1, "VB10": 0x93},
     {"VB10": 0x87, "SM1.1": 1}),
    ("minus 3 inside a byte", ["SHRB M0.0, V10.2, -3"], {"M0.0": 0, "VB10": 0x93},
     {"VB10": 0x8B, "SM1.1": 0}),
    ("minus 3, DATA lands on the MSB only", ["SHRB M0.0, V10.2, -3"],
     {"M0.0": 1, "VB10": 0xE3}, {"VB10": 0xF3, "SM1.1": 0}),
    # Manual example: S_BIT V33.4, N = 14 -> MSB V35.1.
    ("plus 14 across bytes", ["SHRB M0.0, V33.4, 14"],
     {"VB33": 0x08, "VB34": 0x00, "VB35": 0x06},
     {"VB33": 0x08, "VB34": 0x00, "VB35": 0x04, "SM1.1": 1}),
    ("minus 14 across bytes", ["SHRB M0.0, V33.4, -14"],
     {"M0.0": 1, "VB33": 0x18, "VB35": 0x04},
     {"VB33": 0x08, "VB34": 0x00, "VB35": 0x06, "SM1.1": 1}),
    ("plus 64", ["SHRB M0.0, V0.0, 64"],
     {"M0.0": 1, "VD0": 0x80000000, "VD4": 0x00000081},
     {"VD0": 0x01010000, "VD4": 0x00000002, "SM1.1": 1}),
    ("hex count is a signed byte", ["SHRB M0.0, V0.0, 16#C0"],
     {"M0.0": 0, "VB0": 0x01}, {"VB0": 0x00, "SM1.1": 1}),
    ("DATA inside the register is read first", ["SHRB V10.1, V10.0, 2"],
     {"VB10": 0x02}, {"VB10": 0x01, "SM1.1": 1}),
    ("only SM1.1 changes", ["SHRB M0.0, V10.0, 1"], {"VB10": 0, "SMB1": 0x0D},
     {"SMB1": 0x0D}),
    ("count from VB", ["MOVB 3, VB20", "SHRB SM0.0, V10.0, VB20"],
     {"VB10": 0x04}, {"VB10": 0x01, "SM1.1": 1}),
    ("negative count from VB", ["MOVB -3, VB20", "SHRB SM0.0, V10.0, VB20"],
     {"VB10": 0x01}, {"VB10": 0x04, "SM1.1": 1}),
    ("DATA from a timer bit", ["SHRB T37, V10.0, 8"], {"VB10": 0x80},
     {"VB10": 0x00, "SM1.1": 1}),
]


@pytest.mark.parametrize("lines,preset,expect", [c[1:] for c in SHRB],
                         ids=[c[0] for c in SHRB])
def test_shrb(lines, preset, expect):
    """SHRB shifts DATA into the |N|-bit register at S_BIT (direction by sign of N)
    and copies the bit shifted out to SM1.1."""
    _check(_run(lines, preset), expect)


def test_shrb_runs_every_scan():
    """SHRB shifts once per execution: three scans shift three times."""
    p = _run(["SHRB SM0.0, V10.0, 8"], {"VB10": 0}, scans=3)
    assert p["VB10"] == 0x07


@pytest.mark.parametrize("count", ["0", "65", "-65", "16#80"])
def test_shrb_bad_constant_count(count):
    """A constant SHRB length outside -64..-1, 1..64 is a compile error."""
    with pytest.raises(PlcCompileError, match="SHRB"):
        plcrt.load(_program([f"SHRB M0.0, V10.0, {count}"]))


def test_shrb_register_past_area_end():
    """A constant-length register that runs past the end of its area is rejected."""
    with pytest.raises(PlcCompileError, match="past the end"):
        plcrt.load(_program(["SHRB M0.0, M31.7, 2"]))


@pytest.mark.parametrize("count", [0, 65, 0xBF])
def test_shrb_bad_runtime_count_sets_eno_0(count):
    """A bad run-time count shifts nothing, keeps SM1.1 and gives ENO 0 (AENO)."""
    p = _run(["SHRB SM0.0, V10.0, VB20", "AENO", "= Q0.0"],
             {"VB20": count, "VB10": 0x55, "SMB1": 0x02})
    _check(p, {"VB10": 0x55, "SM1.1": 1, "Q0.0": 0})


def test_shrb_runtime_register_past_area_end():
    """A run-time length that runs past the area end gives ENO 0, no shift."""
    p = _run(["SHRB SM0.0, M31.0, MB0", "AENO", "= Q0.0"], {"MB0": 9, "MB31": 0x01})
    _check(p, {"MB31": 0x01, "Q0.0": 0})


@pytest.mark.parametrize("lines", [
    ["SHRB SM0.0, V10.0, 4", "AENO", "= Q0.0"],
    ["MOVB 4, VB20", "SHRB SM0.0, V10.0, VB20", "AENO", "= Q0.0"],
    ["ANDW 16#0000, VW0", "AENO", "= Q0.0"],
    ["SLW VW0, 40", "AENO", "= Q0.0"],
])
def test_eno_one_when_no_error(lines):
    """Word logic, shifts and a valid SHRB leave ENO = 1 (AENO keeps the top)."""
    assert _run(lines)["Q0.0"] == 1
