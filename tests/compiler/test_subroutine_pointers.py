"""Pointers into subroutines: ``&VB100`` passed to a DWORD input and
``*#Ptr``, the symbolic form of ``*LDn`` (a pointer held in a DWORD local).

This is how a library subroutine reaches a block of V memory whose address
the caller chooses (``CALL DRV_POWER, I0.0, &VB1000, ...``, library/cia402).
"""

from __future__ import annotations

import pytest

import plcrt
from plcrt.errors import PlcCompileError

SBR = """SUBROUTINE_BLOCK PEEK:SBR0
TITLE=Read the word at Image + 2, add one to the byte at Image + 4
VAR_INPUT
En:BOOL;
Image:{type};
END_VAR
VAR_OUTPUT
Value:WORD;
END_VAR
VAR
P:{ptr};
END_VAR
BEGIN
Network 1
LD     SM0.0
MOVD   #Image, #P
+D     +2, #P
MOVW   *#P, #Value
+D     +2, #P
INCB   *#P
MOVW   *LD1, VW50
END_SUBROUTINE_BLOCK
"""


def program(arg: str = "&VB100", type_: str = "DWORD", ptr: str = "DWORD",
            body: str = "") -> str:
    ob1 = ("ORGANIZATION_BLOCK MAIN:OB1\nTITLE=t\nBEGIN\nNetwork 1\nLD     SM0.0\n"
           f"CALL   PEEK, I0.0, {arg}, VW10\n{body}END_ORGANIZATION_BLOCK\n")
    return ob1 + SBR.format(type=type_, ptr=ptr)


@pytest.mark.parametrize("arg,base", [("&VB100", 100), ("&VB17", 17), ("VD200", 300)])
def test_a_pointer_reaches_the_subroutine_through_a_dword_input(arg: str, base: int) -> None:
    """``&VBn`` (or a pointer already in VD200) is copied into the DWORD
    input; ``*#P`` then reads and writes the bytes it points to, and
    ``*LD1`` (the same input by address) reads the first word."""
    plc = plcrt.load(program(arg))
    plc.write("VD200", 0x08000000 + 300)
    plc.write(f"VW{base}", 0x1234)
    plc.write(f"VW{base + 2}", 0x7EEF)
    plc.write(f"VB{base + 4}", 41)
    plc.scan()
    assert plc.read("VW10") == 0x7EEF
    assert plc.read(f"VB{base + 4}") == 42
    assert plc.read("VW50") == 0x1234


@pytest.mark.parametrize("type_,ptr,arg,message", [
    ("DINT", "DWORD", "&VB100", "only valid as a double-word input"),
    ("REAL", "DWORD", "&VB100", "only valid as a double-word input"),
    ("DWORD", "WORD", "&VB100", "*#P: indirect addressing needs a pointer in a double-word "
                                "local, and #P is WORD"),
])
def test_pointer_forms_that_micro_win_refuses(type_: str, ptr: str, arg: str,
                                              message: str) -> None:
    """An address goes only to a DWORD input; ``*#`` needs a DWORD local."""
    with pytest.raises(PlcCompileError, match=message.replace("*", r"\*")):
        plcrt.load(program(arg, type_, ptr))


def test_an_unknown_local_behind_star_hash_is_named() -> None:
    text = program().replace("MOVW   *#P, #Value", "MOVW   *#Q, #Value")
    with pytest.raises(PlcCompileError, match="unknown local variable '#Q'"):
        plcrt.load(text)


def test_a_pointer_is_still_no_value_for_a_word_input() -> None:
    """A WORD input keeps refusing ``&VB100`` (a pointer is 32 bits)."""
    text = program().replace("Image:DWORD;", "Image:DWORD;\nW:WORD;").replace(
        "CALL   PEEK, I0.0, &VB100, VW10", "CALL   PEEK, I0.0, &VB100, &VB0, VW10")
    with pytest.raises(PlcCompileError, match="parameter #W"):
        plcrt.load(text)
