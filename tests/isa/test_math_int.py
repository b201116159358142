"""Table tests for plcrt.isa.math_int: +I -I *I /I, D forms, MUL, DIV, INC/DEC."""

from __future__ import annotations

import pytest

import plcrt


def _program(lines: list[str]) -> str:
    body = "\n".join(["LD SM0.0"] + lines)
    return f"ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\n{body}\nEND_ORGANIZATION_BLOCK\n"


def _math(lines: list[str], preset: dict | None = None) -> plcrt.Plc:
    """Run one scan of ``LD SM0.0`` + lines + ``AENO / = Q0.0`` (Q0.0 = ENO)."""
    p = plcrt.load(_program(lines + ["AENO", "= Q0.0"]))
    for addr, value in (preset or {}).items():
        p[addr] = value
    p.scan()
    return p


def _flags(zero: int = 0, ovf: int = 0, neg: int = 0, div0: int = 0) -> int:
    return zero | ovf << 1 | neg << 2 | div0 << 3


# (id, lines, preset, expected signed reads; "ENO" = Q0.0, "SMB1" = the flags byte)
CASES = [
    # +I / -I / *I / /I: OUT := OUT op IN1 (destructive STL form)
    ("+I", ["+I VW0, VW2"], {"VW0": 23, "VW2": 100}, {"VW2": 123, "SMB1": 0, "ENO": 1}),
    ("+I negative", ["+I +3, VW2"], {"VW2": -5}, {"VW2": -2, "SMB1": _flags(neg=1)}),
    ("+I zero", ["+I -5, VW2"], {"VW2": 5}, {"VW2": 0, "SMB1": _flags(zero=1)}),
    ("+I overflow keeps OUT", ["+I VW0, VW2"], {"VW0": 1, "VW2": 32767, "SMB1": 0x05},
     {"VW2": 32767, "SMB1": _flags(ovf=1), "ENO": 0}),
    ("+I hex const is -1", ["+I 16#FFFF, VW2"], {"VW2": 10}, {"VW2": 9}),
    ("+I binary const", ["+I 2#0000_0000_0000_0101, VW2"], {"VW2": 10}, {"VW2": 15}),
    ("+I keeps SM1.3", ["+I 1, VW2"], {"VW2": 1, "SMB1": 0x08}, {"SMB1": 0x08}),
    ("-I is OUT - IN1", ["-I +3, VW2"], {"VW2": 10}, {"VW2": 7}),
    ("-I underflow", ["-I +1, VW2"], {"VW2": -32768},
     {"VW2": -32768, "SMB1": _flags(ovf=1), "ENO": 0}),
    ("*I", ["*I -4, VW2"], {"VW2": 8}, {"VW2": -32, "SMB1": _flags(neg=1)}),
    ("*I overflow", ["*I +300, VW2"], {"VW2": 200}, {"VW2": 200, "SM1.1": 1, "ENO": 0}),
    ("/I truncates", ["/I +2, VW2"], {"VW2": 7}, {"VW2": 3, "ENO": 1}),
    ("/I truncates toward zero", ["/I +2, VW2"], {"VW2": -7}, {"VW2": -3, "SM1.2": 1}),
    ("/I by zero", ["/I VW0, VW2"], {"VW0": 0, "VW2": 7, "SMB1": 0x05},
     {"VW2": 7, "SMB1": 0x0D, "ENO": 0}),
    ("/I clears SM1.3", ["/I +1, VW2"], {"VW2": 7, "SMB1": 0x08}, {"SMB1": 0}),
    ("/I -32768 / -1 overflows", ["/I -1, VW2"], {"VW2": -32768},
     {"VW2": -32768, "SM1.1": 1, "ENO": 0}),
    ("+I in AC", ["MOVW +1000, AC0", "+I +234, AC0"], {}, {"AC0": 1234}),
    ("+I indirect", ["MOVD &VB200, AC1", "+I +5, *AC1"], {"VW200": 10}, {"VW200": 15}),
    ("+I from timer value", ["+I T37, VW2"], {"T37": 12, "VW2": 1}, {"VW2": 13}),
    ("+I big-endian bytes", ["+I +1, VW100"], {"VW100": 0x00FF}, {"VB100": 1, "VB101": 0}),
    ("+D", ["+D VD0, VD4"], {"VD0": 100000, "VD4": 23}, {"VD4": 100023, "SMB1": 0}),
    ("+D overflow", ["+D +1, VD4"], {"VD4": 2**31 - 1},
     {"VD4": 2**31 - 1, "SMB1": _flags(ovf=1), "ENO": 0}),
    ("-D", ["-D +100000, VD4"], {"VD4": 1}, {"VD4": -99999, "SM1.2": 1}),
    ("-D underflow", ["-D +1, VD4"], {"VD4": -2**31}, {"VD4": -2**31, "SM1.1": 1}),
    ("*D", ["*D +65536, VD4"], {"VD4": -3}, {"VD4": -196608}),
    ("*D overflow", ["*D +65536, VD4"], {"VD4": 65536}, {"VD4": 65536, "SM1.1": 1, "ENO": 0}),
    ("/D", ["/D +1000, VD4"], {"VD4": -1234567}, {"VD4": -1234}),
    ("/D by zero", ["/D VD0, VD4"], {"VD0": 0, "VD4": 5}, {"VD4": 5, "SM1.3": 1, "ENO": 0}),
    ("/D min / -1", ["/D -1, VD4"], {"VD4": -2**31}, {"VD4": -2**31, "SM1.1": 1}),
    ("+D hex const", ["+D 16#FFFFFFFF, VD4"], {"VD4": 0}, {"VD4": -1, "SM1.2": 1}),
    # MUL: low word of OUT * IN1 -> 32-bit OUT; DIV: low word / IN1 ->
    # remainder in the high word, quotient in the low word.
    ("MUL ignores high word", ["MUL +300, VD0"], {"VW0": 0x7BCD, "VW2": 1000},
     {"VD0": 300000, "SMB1": 0}),
    ("MUL negative", ["MUL -2, VD0"], {"VW2": 30000}, {"VD0": -60000, "SM1.2": 1}),
    ("MUL zero", ["MUL VW10, VD0"], {"VW10": 0, "VW2": 5}, {"VD0": 0, "SM1.0": 1}),
    ("MUL largest", ["MUL -32768, VD0"], {"VW2": -32768}, {"VD0": 2**30}),
    ("MUL in AC", ["MOVD +0, AC0", "MOVW +7, AC0", "MUL +6, AC0"], {}, {"AC0": 42}),
    ("MUL indirect", ["MOVD &VB200, AC1", "MUL +3, *AC1"], {"VD200": 0x00010005},
     {"VD200": 15}),
    ("DIV", ["DIV +2, VD0"], {"VW2": 7}, {"VW0": 1, "VW2": 3, "ENO": 1}),
    ("DIV negative dividend", ["DIV +2, VD0"], {"VW2": -7}, {"VW0": -1, "VW2": -3}),
    ("DIV negative divisor", ["DIV -2, VD0"], {"VW2": 7}, {"VW0": 1, "VW2": -3}),
    ("DIV ignores high word", ["DIV +10, VD0"], {"VW0": 999, "VW2": 100}, {"VD0": 10}),
    ("DIV by zero", ["DIV VW10, VD0"], {"VW10": 0, "VD0": 0x00030007},
     {"VD0": 0x00030007, "SM1.3": 1, "ENO": 0}),
    ("DIV -32768 / -1 overflows", ["DIV -1, VD0"], {"VW2": -32768},
     {"VW2": -32768, "SM1.1": 1, "ENO": 0}),
    ("DIV indirect", ["MOVD &VB200, AC2", "DIV +4, *AC2"], {"VW202": 9},
     {"VW200": 1, "VW202": 2}),
    # INC/DEC wrap around with SM1.1 (ENO 0); INCB/DECB are unsigned
    ("INCB", ["INCB VB0"], {"VB0": 5}, {"VB0": 6, "SMB1": 0, "ENO": 1}),
    ("INCB wraps", ["INCB VB0"], {"VB0": 255}, {"VB0": 0, "SMB1": _flags(zero=1, ovf=1),
                                                 "ENO": 0}),
    ("INCB 127 is unsigned", ["INCB VB0"], {"VB0": 127}, {"VB0": 128, "SMB1": 0}),
    ("DECB wraps", ["DECB VB0"], {"VB0": 0}, {"VB0": 255, "SMB1": _flags(ovf=1), "ENO": 0}),
    ("DECB to zero", ["DECB VB0"], {"VB0": 1}, {"VB0": 0, "SMB1": _flags(zero=1)}),
    ("INCW", ["INCW VW0"], {"VW0": -1}, {"VW0": 0, "SMB1": _flags(zero=1)}),
    ("INCW wraps", ["INCW VW0"], {"VW0": 32767},
     {"VW0": -32768, "SMB1": _flags(ovf=1, neg=1), "ENO": 0}),
    ("DECW wraps", ["DECW VW0"], {"VW0": -32768}, {"VW0": 32767, "SMB1": _flags(ovf=1)}),
    ("DECW negative", ["DECW VW0"], {"VW0": 0}, {"VW0": -1, "SMB1": _flags(neg=1)}),
    ("INCD wraps", ["INCD VD0"], {"VD0": 2**31 - 1}, {"VD0": -2**31, "SM1.1": 1}),
    ("DECD wraps", ["DECD VD0"], {"VD0": -2**31}, {"VD0": 2**31 - 1, "SM1.1": 1}),
    ("INCD in AC", ["MOVD +41, AC3", "INCD AC3"], {}, {"AC3": 42}),
    ("INCW indirect", ["MOVD &VB200, AC1", "INCW *AC1"], {"VW200": 9}, {"VW200": 10}),
]


@pytest.mark.parametrize("lines,preset,expect", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_math_int(lines, preset, expect):
    """Integer math gives the documented result, SMB1 flags and ENO."""
    p = _math(lines, preset)
    got = {a: p["Q0.0" if a == "ENO" else a] for a in expect}
    assert got == expect


def test_aeno_after_overflow_clears_output():
    """`LD SM0.0 / +I VW0, VW2 / AENO / = Q0.0`: Q0.0 = 0 after an overflow, 1 otherwise."""
    p = plcrt.load(_program(["+I VW0, VW2", "AENO", "= Q0.0"]))
    p["VW0"], p["VW2"] = 1, 32767
    p.scan()
    assert p["Q0.0"] == 0
    p["VW2"] = 0
    p.scan()
    assert (p["Q0.0"], p["VW2"]) == (1, 1)


def test_math_skipped_when_top_is_zero():
    """A math box does not run when the top of the stack is 0 (no flags change)."""
    p = plcrt.load(_program(["LDN SM0.0", "/I VW0, VW2"]))
    p["VW2"] = 5
    p.scan()
    assert (p["VW2"], p["SMB1"]) == (5, 0)
