"""Table tests for plcrt.isa.convert: BTI ITB ITD DTI DTR ROUND TRUNC BCDI IBCD ENCO DECO SEG."""

from __future__ import annotations

import struct

import pytest

import plcrt

#: 7-segment patterns of 0..F from the manual's SEG table (bit 0 = segment a).
SEGMENTS = (0x3F, 0x06, 0x5B, 0x4F, 0x66, 0x6D, 0x7D, 0x07,
            0x7F, 0x6F, 0x77, 0x7C, 0x39, 0x5E, 0x79, 0x71)
NAN_BITS = 0x7FC00000
INF_BITS = 0x7F800000
NEG_INF_BITS = 0xFF800000


def _program(lines: list[str]) -> str:
    body = "\n".join(["LD SM0.0"] + lines)
    return f"ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\n{body}\nEND_ORGANIZATION_BLOCK\n"


def _conv(lines: list[str], preset: dict | None = None) -> plcrt.Plc:
    """Run one scan of ``LD SM0.0`` + lines + ``AENO / = Q0.0`` (Q0.0 = ENO)."""
    p = plcrt.load(_program(lines + ["AENO", "= Q0.0"]))
    for addr, value in (preset or {}).items():
        p[addr] = value
    p.scan()
    return p


def _f32(x: float) -> float:
    return struct.unpack(">f", struct.pack(">f", x))[0]


# (id, lines, preset, expected reads; "ENO" stands for Q0.0)
CASES = [
    # BTI: unsigned byte, no sign extension; no flags
    ("BTI 200", ["BTI VB0, VW2"], {"VB0": 200}, {"VW2": 200, "ENO": 1}),
    ("BTI 255", ["BTI VB0, VW2"], {"VB0": 0xFF, "VW2": -1}, {"VW2": 255}),
    ("BTI keeps flags", ["BTI VB0, VW2"], {"VB0": 0, "SMB1": 0x46}, {"VW2": 0, "SMB1": 0x46}),
    ("BTI const into AC low word", ["MOVD 16#FFFFFFFF, AC0", "BTI 16#80, AC0"], {},
     {"AC0": 0xFFFF0080 - 2**32}),
    # ITB: 0..255 converted, else SM1.1 and OUT unchanged
    ("ITB 255", ["ITB VW0, VB2"], {"VW0": 255, "SMB1": 0x02}, {"VB2": 255, "SMB1": 0, "ENO": 1}),
    ("ITB 0", ["ITB VW0, VB2"], {"VW0": 0, "VB2": 9}, {"VB2": 0, "ENO": 1}),
    ("ITB 256 overflows", ["ITB VW0, VB2"], {"VW0": 256, "VB2": 7},
     {"VB2": 7, "SM1.1": 1, "ENO": 0}),
    ("ITB -1 overflows", ["ITB VW0, VB2"], {"VW0": -1, "VB2": 7},
     {"VB2": 7, "SM1.1": 1, "ENO": 0}),
    ("ITB overflow keeps SM1.0/SM1.2", ["ITB VW0, VB2"], {"VW0": 300, "SMB1": 0x05},
     {"SMB1": 0x07}),
    # ITD: sign extension
    ("ITD -2", ["ITD VW0, VD2"], {"VW0": -2}, {"VD2": -2, "ENO": 1}),
    ("ITD 32767", ["ITD VW0, VD2"], {"VW0": 32767, "VD2": -1}, {"VD2": 32767}),
    ("ITD hex const", ["ITD 16#8000, VD2"], {}, {"VD2": -32768}),
    # DTI: range -32768..32767
    ("DTI -32768", ["DTI VD0, VW4"], {"VD0": -32768}, {"VW4": -32768, "SM1.1": 0, "ENO": 1}),
    ("DTI 32768 overflows", ["DTI VD0, VW4"], {"VD0": 32768, "VW4": 5},
     {"VW4": 5, "SM1.1": 1, "ENO": 0}),
    ("DTI -32769 overflows", ["DTI VD0, VW4"], {"VD0": -32769, "VW4": 5},
     {"VW4": 5, "SM1.1": 1, "ENO": 0}),
    ("DTI clears SM1.1", ["DTI VD0, VW4"], {"VD0": 1, "SMB1": 0x02}, {"SMB1": 0}),
    # BCDI / IBCD in place; SM1.6 on illegal values
    ("BCDI 1234", ["BCDI VW0"], {"VW0": 0x1234, "SMB1": 0x40},
     {"VW0": 1234, "SMB1": 0, "ENO": 1}),
    ("BCDI 9999", ["BCDI VW0"], {"VW0": 0x9999 - 0x10000}, {"VW0": 9999}),
    ("BCDI 0", ["BCDI VW0"], {"VW0": 0}, {"VW0": 0, "SM1.6": 0}),
    ("BCDI illegal digit", ["BCDI VW0"], {"VW0": 0x12A4},
     {"VW0": 0x12A4, "SM1.6": 1, "ENO": 0}),
    ("BCDI illegal top digit", ["BCDI VW0"], {"VW0": 0xA000 - 0x10000},
     {"VW0": 0xA000 - 0x10000, "SM1.6": 1, "ENO": 0}),
    ("BCDI keeps SM1.1", ["BCDI VW0"], {"VW0": 0x0001, "SMB1": 0x02}, {"SMB1": 0x02}),
    ("IBCD 1234", ["IBCD VW0"], {"VW0": 1234, "SMB1": 0x40},
     {"VW0": 0x1234, "SMB1": 0, "ENO": 1}),
    ("IBCD 9999", ["IBCD VW0"], {"VW0": 9999}, {"VW0": 0x9999 - 0x10000}),
    ("IBCD 10000", ["IBCD VW0"], {"VW0": 10000}, {"VW0": 10000, "SM1.6": 1, "ENO": 0}),
    ("IBCD -1", ["IBCD VW0"], {"VW0": -1}, {"VW0": -1, "SM1.6": 1, "ENO": 0}),
    ("IBCD big-endian bytes", ["IBCD VW0"], {"VW0": 4321}, {"VB0": 0x43, "VB1": 0x21}),
    ("BCDI indirect", ["MOVD &VB200, AC1", "BCDI *AC1"], {"VW200": 0x0042}, {"VW200": 42}),
    # ENCO / DECO / SEG
    ("ENCO bit 8", ["ENCO VW0, VB2"], {"VW0": 0x0100}, {"VB2": 8, "ENO": 1}),
    ("ENCO bit 15", ["ENCO VW0, VB2"], {"VW0": -32768}, {"VB2": 15}),
    ("ENCO lowest of several", ["ENCO VW0, VB2"], {"VW0": 0x8A00 - 0x10000}, {"VB2": 9}),
    ("ENCO 0 gives 0", ["ENCO VW0, VB2"], {"VW0": 0, "VB2": 0xFF}, {"VB2": 0}),
    ("ENCO writes the whole byte", ["ENCO VW0, VB2"], {"VW0": 0x0004, "VB2": 0xF0}, {"VB2": 2}),
    ("ENCO from AC", ["MOVW 16#0800, AC3", "ENCO AC3, VB50"], {}, {"VB50": 11}),
    ("DECO 3", ["DECO VB0, VW2"], {"VB0": 3, "VW2": 0x00F0}, {"VW2": 0x0008, "ENO": 1}),
    ("DECO 15", ["DECO VB0, VW2"], {"VB0": 15}, {"VW2": -32768}),
    ("DECO uses low nibble", ["DECO VB0, VW2"], {"VB0": 0x1F}, {"VW2": -32768}),
    ("DECO const", ["DECO 0, VW2"], {"VW2": 7}, {"VB2": 0, "VB3": 1}),
    ("SEG low nibble", ["SEG VB0, QB0"], {"VB0": 0x1A}, {"QB0": 0x77, "ENO": 1}),
    ("SEG keeps flags", ["SEG 8, VB1"], {"SMB1": 0x03}, {"VB1": 0x7F, "SMB1": 0x03}),
]


@pytest.mark.parametrize("lines,preset,expect", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_convert(lines, preset, expect):
    """Integer, BCD and bit-pattern conversions give the manual's results, flags and ENO."""
    p = _conv(lines, preset)
    got = {a: p["Q0.0" if a == "ENO" else a] for a in expect}
    assert got == expect


@pytest.mark.parametrize("digit", range(16))
def test_seg_table(digit):
    """SEG maps each hex digit to the manual's 7-segment pattern (0x3F for 0 ... 0x71 for F)."""
    p = _conv([f"SEG {digit}, VB0"])
    assert p["VB0"] == SEGMENTS[digit]


# REAL -> DINT: (id, mnemonic, input bits or float, expected DINT or None for overflow)
REAL_IN = [
    ("ROUND 2.5", "ROUND", 2.5, 3),
    ("ROUND -2.5", "ROUND", -2.5, -3),
    ("ROUND 0.5", "ROUND", 0.5, 1),
    ("ROUND -0.5", "ROUND", -0.5, -1),
    ("ROUND just below 0.5", "ROUND", _f32(0.49999997), 0),
    ("ROUND 2.4", "ROUND", 2.4, 2),
    ("ROUND -7.6", "ROUND", -7.6, -8),
    ("ROUND largest fitting", "ROUND", 2147483520.0, 2147483520),
    ("ROUND 2**31 overflows", "ROUND", 2147483648.0, None),
    ("ROUND -2**31", "ROUND", -2147483648.0, -2147483648),
    ("ROUND 1e10 overflows", "ROUND", 1e10, None),
    ("ROUND NaN", "ROUND", NAN_BITS, None),
    ("ROUND inf", "ROUND", INF_BITS, None),
    ("TRUNC 2.9", "TRUNC", 2.9, 2),
    ("TRUNC -2.9", "TRUNC", -2.9, -2),
    ("TRUNC -0.7", "TRUNC", -0.7, 0),
    ("TRUNC -2**31", "TRUNC", -2147483648.0, -2147483648),
    ("TRUNC 2**31 overflows", "TRUNC", 2147483648.0, None),
    ("TRUNC -inf", "TRUNC", NEG_INF_BITS, None),
    ("TRUNC NaN", "TRUNC", NAN_BITS, None),
]


@pytest.mark.parametrize("mn,value,expect", [c[1:] for c in REAL_IN],
                         ids=[c[0] for c in REAL_IN])
def test_real_to_dint(mn, value, expect):
    """ROUND rounds half away from zero, TRUNC drops the fraction; out of range or
    NaN sets SM1.1, leaves OUT unchanged and ENO 0."""
    preset = {"VD0": value, "VD4": 77,
              "SMB1": 0x02 if expect is not None else 0}
    p = _conv([f"{mn} VD0, VD4"], preset)
    if expect is None:
        assert (p["VD4"], p["SM1.1"], p["Q0.0"]) == (77, 1, 0)
    else:
        assert (p["VD4"], p["SM1.1"], p["Q0.0"]) == (expect, 0, 1)


def test_round_constant_and_ac():
    """ROUND takes a REAL constant and writes an accumulator."""
    p = _conv(["ROUND 3.7, AC0", "TRUNC -3.7, AC1"])
    assert (p["AC0"], p["AC1"]) == (4, -3)


@pytest.mark.parametrize("value,expect", [
    (-5, -5.0),
    (0, 0.0),
    (16777217, 16777216.0),      # 2**24 + 1 is not a single: ties to even
    (16777219, 16777220.0),
    (2147483647, 2147483648.0),
    (-2147483648, -2147483648.0),
])
def test_dtr(value, expect):
    """DTR converts a DINT to the nearest single-precision REAL; no flags change."""
    p = _conv(["DTR VD0, VD4"], {"VD0": value, "SMB1": 0x02})
    assert (p.read("VD4", "REAL"), p["SMB1"], p["Q0.0"]) == (expect, 0x02, 1)


def test_dtr_indirect_output():
    """DTR writes a REAL through a pointer."""
    p = _conv(["MOVD &VB300, AC2", "DTR +7, *AC2"])
    assert p.read("VD300", "REAL") == 7.0


def test_conversion_skipped_when_top_is_zero():
    """A conversion box does not run (and keeps SM1.1) when the top is 0."""
    p = plcrt.load(_program(["LDN SM0.0", "ITB VW0, VB2"]))
    p["VW0"] = 1000
    p["SMB1"] = 0
    p.scan()
    assert (p["VB2"], p["SMB1"]) == (0, 0)
