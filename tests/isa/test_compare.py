"""Table tests for plcrt.isa.compare: LD/A/O x B/W/D/R x = <> < <= > >=.

S7-200 System Manual, "Compare instructions": bytes compare unsigned, words
(INT) and double words (DINT) signed, reals as IEEE single; the result is
pushed (LD..), ANDed (A..) or ORed (O..) into the top of the stack, and
compares run regardless of power flow.
"""

from __future__ import annotations

import operator

import pytest

import plcrt
from stl_helpers import load_ob1 as _load
from plcrt.errors import PlcRuntimeError


RELATIONS = {"=": operator.eq, "<>": operator.ne, "<": operator.lt, "<=": operator.le,
             ">": operator.gt, ">=": operator.ge}

# (width, address of IN1, address of IN2, pairs of values as the CPU sees them).
# Memory is written with the bit pattern, so a byte of 200 is "200" (unsigned)
# while a word of 16#FFFF is "-1" (signed).
OPERANDS = {
    "B": ("VB0", "VB1", [(1, 200), (200, 1), (0x80, 0x7F), (255, 255), (0, 0), (255, 0)]),
    "W": ("VW0", "VW2", [(-1, 1), (1, -1), (-32768, 32767), (32767, -32768), (7, 7),
                         (0, -1)]),
    "D": ("VD0", "VD4", [(-1, 1), (1, -1), (-2**31, 2**31 - 1), (100000, 99999),
                         (-5, -5), (65536, 65535)]),
    "R": ("VD0", "VD4", [(-1.5, 0.25), (0.25, -1.5), (1e-30, 0.0), (-0.0, 0.0),
                         (3.5, 3.5), (-1e30, 1e30)]),
}


def _cases() -> list:
    out = []
    for width, (a, b, pairs) in OPERANDS.items():
        for rel in RELATIONS:
            for x, y in pairs:
                out.append(pytest.param(width, rel, x, y, id=f"{width}{rel}{x},{y}"))
    return out


def _write(p: plcrt.Plc, addr: str, value: float, width: str) -> None:
    if width == "R":
        p.write(addr, float(value))
    else:
        p[addr] = value


@pytest.mark.parametrize("width,rel,x,y", _cases())
def test_load_compare(width: str, rel: str, x, y) -> None:
    """LDx<rel> pushes IN1 <rel> IN2 with B unsigned, W/D signed, R real."""
    a, b, _ = OPERANDS[width]
    p = _load(f"LD{width}{rel} {a}, {b}\n= Q0.0")
    _write(p, a, x, width)
    _write(p, b, y, width)
    p.scan()
    assert p["Q0.0"] == int(RELATIONS[rel](x, y))


@pytest.mark.parametrize("form", ["A", "O"])
@pytest.mark.parametrize("top", [0, 1])
@pytest.mark.parametrize("width,rel,x,y", [c for c in _cases() if c.values[1] in ("<", ">=")])
def test_and_or_compare(form: str, top: int, width: str, rel: str, x, y) -> None:
    """Ax<rel> ANDs and Ox<rel> ORs the comparison into the top of the stack."""
    a, b, _ = OPERANDS[width]
    p = _load(f"LD I0.0\n{form}{width}{rel} {a}, {b}\n= Q0.0")
    p["I0.0"] = top
    _write(p, a, x, width)
    _write(p, b, y, width)
    p.scan()
    result = int(RELATIONS[rel](x, y))
    assert p["Q0.0"] == (top & result if form == "A" else top | result)


@pytest.mark.parametrize("body,preset,expected", [
    ("LDB= VB0, 16#FF", {"VB0": 255}, 1),
    ("LDB> VB0, 127", {"VB0": 128}, 1),                   # unsigned byte constant
    ("LDW= VW0, 16#FFFF", {"VW0": -1}, 1),                # hex pattern of -1
    ("LDW< VW0, +0", {"VW0": 0x8000}, 1),                 # 16#8000 is negative
    ("LDD= VD0, 16#FFFFFFFF", {"VD0": -1}, 1),
    ("LDD> VD0, +100000", {"VD0": 100001}, 1),
    ("LDR< VD0, 1.0", {"VD0": 0.5}, 1),
    ("LDR>= VD0, -2", {"VD0": -2.0}, 1),                  # integer constant as real
    ("LDW>= T37, +5", {"T37": 5}, 1),                     # timer current value
    ("LDW< C3, +2", {"C3": 2}, 0),                        # counter current value
    ("LDW= AC0, +7", {"AC0": 0x12340007}, 1),             # low word of AC0
    ("LDB= AC1, 16#EE", {"AC1": 0x112233EE}, 1),          # low byte of AC1
    ("LDD= AC2, VD8", {"AC2": -9, "VD8": -9}, 1),
    ("LDW= IW0, QW0", {"IW0": 0x1234, "QW0": 0x1234}, 1),
    ("LDB= SMB28, 0", {}, 1),
])
def test_compare_operand_kinds(body: str, preset: dict, expected: int) -> None:
    """Compares read constants, T/C current values, accumulators and all word areas."""
    p = _load(f"{body}\n= Q0.0")
    for addr, value in preset.items():
        if isinstance(value, float):
            p.write(addr, value)
        else:
            p[addr] = value
    p.scan()
    assert p["Q0.0"] == expected


def test_compare_through_a_pointer() -> None:
    """Compares accept *AC / *VD operands (indirect addressing)."""
    p = _load("LD SM0.0\nMOVD &VW100, AC1\nMOVD &VB200, VD10",
              "LDW= *AC1, +1234\n= Q0.0", "LDB> *VD10, 9\n= Q0.1")
    p["VW100"] = 1234
    p["VB200"] = 10
    p.scan()
    assert (p["Q0.0"], p["Q0.1"]) == (1, 1)


def test_compare_runs_without_power_flow() -> None:
    """O compare with a 0 top still evaluates: the result alone drives the output."""
    p = _load("LDN SM0.0\nOW= VW0, VW2\n= Q0.0")
    p.scan()
    assert p["Q0.0"] == 1


@pytest.mark.parametrize("rel", list(RELATIONS))
def test_real_compare_of_nan_is_a_fatal_error(rel: str) -> None:
    """An illegal REAL (NaN) in a compare stops the CPU with the instruction's location."""
    p = _load("LD SM0.0\n= Q0.1", f"LDR{rel} VD0, VD4\n= Q0.0")
    p.write("VD0", 1.0)
    p.scan()
    p["VD4"] = 0x7FC00000                # a quiet NaN bit pattern
    with pytest.raises(PlcRuntimeError) as exc:
        p.scan()
    assert "<string>:7:" in str(exc.value) and "NaN" in str(exc.value)
    assert p.mode == "STOP"
    assert p.mem.areas["PQ"][0] == 0
