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


def test_a_variable_of_an_unsupported_type_keeps_the_rest_of_the_interface() -> None:
    """A STRING parameter is reported once at its own declaration line; the
    other variables keep their places, and a CALL says the block cannot be
    called instead of miscounting its parameters."""
    src = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD     SM0.0\n"
           "CALL   SBR_0, \"abc\", VB100\nEND_ORGANIZATION_BLOCK\n"
           "SUBROUTINE_BLOCK SBR_0:SBR0\nVAR_INPUT\nk:BYTE;\ns:STRING;\nEND_VAR\n"
           "VAR_OUTPUT\nn:BYTE;\nEND_VAR\nBEGIN\nNetwork 1\nLD     SM0.0\n"
           "MOVB   #k, #n\nEND_SUBROUTINE_BLOCK\n")
    with pytest.raises(PlcCompileError) as ei:
        plcrt.load(src)
    errors = [d for d in ei.value.diagnostics if d.severity == "error"]
    texts = [d.message for d in errors]
    assert any("'#s': type STRING is not supported" in m for m in texts), texts
    decl = next(d for d in errors if "type STRING" in d.message)
    assert decl.loc.line == 10                     # the line of `s:STRING;`
    assert any("cannot be called" in m and "#s" in m for m in texts), texts
    assert not any("takes" in m and "parameter(s)" in m for m in texts), texts
    # #k and #n were laid out: the body's MOVB resolved
    assert not any("#k" in m or "#n" in m for m in texts), texts
