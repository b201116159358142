"""A called subroutine with an interface and no code (a protected library or
wizard block as Micro/WIN exports it) loads, and a warning says its calls do
nothing (plcrt.compiler.codegen._empty_library_blocks).  HSC_INIT (code of
the high-speed counter wizard) is such a block; the Modbus library blocks
are emulated (tests/devices/test_modbus.py, test_modbus_slave.py)."""

from __future__ import annotations

import plcrt

SBR = """SUBROUTINE_BLOCK HSC_INIT:SBR1
TITLE=protected
VAR_INPUT
Mode:BOOL;
Baud:DWORD;
END_VAR
VAR_OUTPUT
Done:BOOL;
Error:BYTE;
END_VAR
BEGIN
Network 1
{body}END_SUBROUTINE_BLOCK
"""


def program(body: str = "", call: bool = True) -> str:
    ob1 = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD     SM0.0\n"
           + ("CALL   HSC_INIT, SM0.0, 9600, M0.0, MB1\n" if call else "= Q0.0\n")
           + "END_ORGANIZATION_BLOCK\n")
    return ob1 + SBR.format(body=body)


def warnings(plc: plcrt.Plc) -> list[str]:
    return [d.message for d in plc.diagnostics if d.code == "empty-block"]


def test_a_called_empty_block_with_an_interface_is_named_in_a_warning() -> None:
    plc = plcrt.load(program())
    [message] = warnings(plc)
    assert message.startswith("SBR1 (HSC_INIT) has an interface and no code")
    assert "not simulated" in message
    plc.scan()
    assert plc.read("MB1") == 0 and plc.read("M0.0") == 0   # its outputs stay as they were


def test_a_block_with_code_or_never_called_is_not_reported() -> None:
    assert warnings(plcrt.load(program("LD #Mode\n= #Done\n"))) == []
    assert warnings(plcrt.load(program(call=False))) == []
