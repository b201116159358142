"""Local variable names of a block are case-sensitive, as in Micro/WIN: a
Siemens library block declares ``tmp_b:BOOL`` and ``tmp_B:BYTE`` side by
side (plcrt.compiler.resolve.layout_locals; docs/decisions.md)."""

from __future__ import annotations

import pytest

import plcrt
from plcrt.errors import PlcCompileError

SBR = """SUBROUTINE_BLOCK LIB:SBR0
VAR_INPUT
DataPtr:DWORD;
END_VAR
VAR_OUTPUT
Res:BYTE;
END_VAR
VAR_TEMP
tmp_b:BOOL;
tmp_B:BYTE;
END_VAR
BEGIN
Network 1
LD     SM0.0
MOVB   *#DataPtr, #tmp_B
=      #tmp_b
INCB   {ref}
MOVB   #tmp_B, #Res
END_SUBROUTINE_BLOCK
"""


def program(ref: str = "#tmp_B") -> str:
    return ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD     SM0.0\n"
            "CALL   LIB, &VB100, VB10\nEND_ORGANIZATION_BLOCK\n" + SBR.format(ref=ref))


def test_names_differing_only_in_case_are_two_variables() -> None:
    """tmp_b is the BOOL at L.. and tmp_B the BYTE after it: the whole
    interface is kept and each name reaches its own variable."""
    plc = plcrt.load(program())
    plc.write("VB100", 41)
    plc.scan()
    assert plc.read("VB10") == 42


def test_another_spelling_of_a_unique_name_still_resolves() -> None:
    plc = plcrt.load(program().replace("#Res\n", "#RES\n"))
    plc.write("VB100", 7)
    plc.scan()
    assert plc.read("VB10") == 8


def test_a_spelling_that_fits_two_variables_is_a_located_error() -> None:
    with pytest.raises(PlcCompileError) as info:
        plcrt.load(program("#TMP_B"))
    err = info.value
    assert "could be #tmp_b and #tmp_B" in err.message
    assert err.loc is not None and err.loc.block == "SBR0" and err.loc.network == 1


def test_the_same_name_twice_is_still_an_error() -> None:
    with pytest.raises(PlcCompileError, match="declared twice"):
        plcrt.load(program().replace("tmp_B:BYTE;", "tmp_b:BYTE;").replace("#tmp_B", "#tmp_b"))
