"""Table tests for plcrt.isa.math_real: +R -R *R /R SQRT SIN COS TAN LN EXP."""

from __future__ import annotations

import math
import struct

import pytest

import plcrt

NAN_BITS = 0x7FC00000
UNCHANGED = object()  #: expected value: OUT keeps its preset


def _f32(x: float) -> float:
    return struct.unpack(">f", struct.pack(">f", x))[0]


def _program(lines: list[str]) -> str:
    body = "\n".join(["LD SM0.0"] + lines)
    return f"ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\n{body}\nEND_ORGANIZATION_BLOCK\n"


def _real(lines: list[str], preset: dict | None = None) -> plcrt.Plc:
    """Run one scan of ``LD SM0.0`` + lines + ``AENO / = Q0.0`` (Q0.0 = ENO)."""
    p = plcrt.load(_program(lines + ["AENO", "= Q0.0"]))
    for addr, value in (preset or {}).items():
        p[addr] = value
    p.scan()
    return p


# (id, instruction, IN1 (VD0) or None for a constant operand in the text,
#  OUT (VD4) before, expected OUT or UNCHANGED, expected SMB1, ENO)
BINARY = [
    ("+R", "+R VD0, VD4", 1.5, 2.25, 3.75, 0, 1),
    ("+R rounds to single", "+R VD0, VD4", 0.1, 0.2, _f32(_f32(0.2) + _f32(0.1)), 0, 1),
    ("+R zero", "+R VD0, VD4", -1.5, 1.5, 0.0, 0x01, 1),
    ("-R is OUT - IN1", "-R VD0, VD4", 1.0, 3.5, 2.5, 0, 1),
    ("-R negative", "-R VD0, VD4", 4.0, 1.0, -3.0, 0x04, 1),
    ("*R", "*R VD0, VD4", 3.0, -0.5, -1.5, 0x04, 1),
    ("*R overflow", "*R VD0, VD4", 1e38, 1e38, UNCHANGED, 0x02, 0),
    ("/R is OUT / IN1", "/R VD0, VD4", 4.0, 1.0, 0.25, 0, 1),
    ("/R rounds to single", "/R VD0, VD4", 3.0, 1.0, _f32(1 / 3), 0, 1),
    ("/R by zero", "/R VD0, VD4", 0.0, 1.0, UNCHANGED, 0x08, 0),
    ("/R by -0.0", "/R VD0, VD4", -0.0, 1.0, UNCHANGED, 0x08, 0),
    ("/R overflow", "/R VD0, VD4", 1e-30, 1e30, UNCHANGED, 0x02, 0),
    ("+R largest single", "+R VD0, VD4", 0.0, 3.4028234663852886e38,
     3.4028234663852886e38, 0, 1),
    ("+R NaN input", "+R VD0, VD4", NAN_BITS, 1.0, UNCHANGED, 0x02, 0),
    # a REAL constant is single precision, as on the CPU
    ("*R constant rounded", "*R 0.7, VD4", None, _f32(11 / 7),
     _f32(_f32(11 / 7) * _f32(0.7)), 0, 1),
    ("+R integer constant", "+R 5, VD4", None, 0.5, 5.5, 0, 1),
]


@pytest.mark.parametrize("insn,a,o,expect,flags,eno", [c[1:] for c in BINARY],
                         ids=[c[0] for c in BINARY])
def test_binary(insn, a, o, expect, flags, eno):
    """+R -R *R /R compute OUT := OUT op IN1 in single precision with SMB1 flags;
    overflow and divide by zero leave OUT unchanged with ENO 0."""
    preset = {"VD4": o, "SMB1": 0}
    if a is not None:
        preset["VD0"] = a
    p = _real([insn], preset)
    want = _f32(o) if expect is UNCHANGED else expect
    assert (p.read("VD4", "REAL"), p["SMB1"], p["Q0.0"]) == (want, flags, eno)


# (id, mnemonic, IN, expected OUT or UNCHANGED, expected SMB1)
UNARY = [
    ("SQRT 2", "SQRT", 2.0, _f32(math.sqrt(2.0)), 0),
    ("SQRT 0", "SQRT", 0.0, 0.0, 0x01),
    ("SQRT negative", "SQRT", -4.0, UNCHANGED, 0x02),
    ("SIN 0", "SIN", 0.0, 0.0, 0x01),
    ("SIN -pi/2", "SIN", -_f32(math.pi / 2), -1.0, 0x04),
    ("COS 0", "COS", 0.0, 1.0, 0),
    ("TAN pi/4", "TAN", _f32(math.pi / 4), _f32(math.tan(_f32(math.pi / 4))), 0),
    ("LN 1", "LN", 1.0, 0.0, 0x01),
    ("LN e", "LN", _f32(math.e), _f32(math.log(_f32(math.e))), 0),
    ("LN 0", "LN", 0.0, UNCHANGED, 0x02),
    ("LN negative", "LN", -1.0, UNCHANGED, 0x02),
    ("EXP 1", "EXP", 1.0, _f32(math.e), 0),
    ("EXP -200 underflows to 0", "EXP", -200.0, 0.0, 0x01),
    ("EXP 100 overflows", "EXP", 100.0, UNCHANGED, 0x02),
    ("SQRT NaN", "SQRT", NAN_BITS, UNCHANGED, 0x02),
]


@pytest.mark.parametrize("mn,value,expect,flags", [c[1:] for c in UNARY],
                         ids=[c[0] for c in UNARY])
def test_unary(mn, value, expect, flags):
    """SQRT/SIN/COS/TAN/LN/EXP round to single; an illegal input or a result
    out of range sets SM1.1, leaves OUT unchanged and gives ENO 0."""
    p = _real([f"{mn} VD0, VD4"], {"VD0": value, "VD4": 9.5, "SMB1": 0})
    want = 9.5 if expect is UNCHANGED else expect
    eno = 0 if expect is UNCHANGED else 1
    assert (p.read("VD4", "REAL"), p["SMB1"], p["Q0.0"]) == (want, flags, eno)


def test_real_in_accumulators_and_indirect():
    """REAL operands work in AC registers and through a pointer (*AC1)."""
    p = _real(["MOVR 2.5, AC2", "*R 4.0, AC2", "MOVD &VB200, AC1", "+R AC2, *AC1"],
              {"VD200": 0.25})
    assert (p.read("AC2", "REAL"), p.read("VD200", "REAL")) == (10.0, 10.25)


def test_real_big_endian_bytes():
    """A REAL result is stored big-endian: VB100 holds the sign and exponent high bits."""
    p = _real(["MOVR 1.0, VD100", "+R 1.0, VD100"])
    assert [p[f"VB{i}"] for i in range(100, 104)] == [0x40, 0x00, 0x00, 0x00]


def test_div_by_zero_keeps_other_flags():
    """/R by zero sets SM1.3 and leaves SM1.0-SM1.2 as they were."""
    p = _real(["/R 0.0, VD4"], {"VD4": 1.0, "SMB1": 0x05})
    assert p["SMB1"] == 0x0D


def test_real_constant_out_of_range_is_rejected():
    """A REAL constant beyond the single-precision range is a compile error."""
    with pytest.raises(plcrt.PlcCompileError, match="REAL range"):
        plcrt.load(_program(["+R 1.0E39, VD4"]))
