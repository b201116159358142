"""Operand classification: addresses, constants, pointers, indirect forms."""

from __future__ import annotations

import pytest

from plcrt.compiler.operands import (Addr, Const, Indirect, Name, OperandError, Pointer,
                                     parse_operand)
from plcrt.memory import cpu_model

M = cpu_model("CPU226")


@pytest.mark.parametrize("text,expected", [
    ("I0.0", Addr("I", 0, 0, 0, "I0.0")),
    ("q1.7", Addr("Q", 1, 0, 7, "q1.7")),
    ("SM0.1", Addr("SM", 0, 0, 1, "SM0.1")),
    ("VB100", Addr("V", 100, 1, 0, "VB100")),
    ("VW7", Addr("V", 7, 2, 0, "VW7")),
    ("VD10236", Addr("V", 10236, 4, 0, "VD10236")),
    ("SMB34", Addr("SM", 34, 1, 0, "SMB34")),
    ("LW10", Addr("L", 10, 2, 0, "LW10")),
    ("AIW0", Addr("AI", 0, 2, 0, "AIW0")),
    ("AQW62", Addr("AQ", 62, 2, 0, "AQW62")),
    ("T37", Addr("T", 37, None, 0, "T37")),
    ("C255", Addr("C", 255, None, 0, "C255")),
    ("AC3", Addr("AC", 3, None, 0, "AC3")),
    ("HC5", Addr("HC", 5, 4, 0, "HC5")),
])
def test_addresses(text: str, expected: Addr) -> None:
    """Addresses parse to area, byte offset, width and bit."""
    assert parse_operand(text, M) == expected


@pytest.mark.parametrize("text,value,is_real", [
    ("+50", 50, False), ("-13", -13, False), ("100", 100, False),
    ("16#FFFF0000", 0xFFFF0000, False), ("2#1010_0101", 0xA5, False),
    ("1.5", 1.5, True), ("-1.0", -1.0, True), ("+1.175495E-38", 1.175495e-38, True),
    ("'AB'", b"AB", False),
])
def test_constants(text: str, value, is_real: bool) -> None:
    """Decimal, signed, hex, binary, real and ASCII constants."""
    c = parse_operand(text, M)
    assert isinstance(c, Const) and c.value == value and c.is_real == is_real


def test_pointer_and_indirect() -> None:
    """&VB100 is a pointer value; *AC1/*VD200/*LD10 dereference a dword."""
    p = parse_operand("&VB100", M)
    assert isinstance(p, Pointer) and p.value == 0x08000064
    for t in ("*AC1", "*VD200", "*LD10"):
        assert isinstance(parse_operand(t, M), Indirect)


@pytest.mark.parametrize("text", ["*AC0", "*VW2", "&VB99999", "&AC1", "I0.8", "VW10239",
                                  "AIW1", "T256", "AC4", "1e999"])
def test_invalid(text: str) -> None:
    """Malformed or out-of-range operands raise OperandError with a reason."""
    with pytest.raises(OperandError):
        parse_operand(text, M)


def test_names_are_left_for_symbol_resolution() -> None:
    """Identifiers (symbols, labels, block names) come back as Name."""
    assert parse_operand("电机启动", M) == Name("电机启动", "电机启动")
