"""Generated code is built only from validated numbers, never program text.

A program crafted to smuggle Python into the generated module (through
symbol names, comments, block names, titles, string constants and local
variable names) must compile to code whose every name and string literal
comes from plcrt's own vocabulary.
"""

from __future__ import annotations

import ast
import re

import plcrt
from plcrt.lang import parse_symbols

PAYLOAD = "__import__('os').system('echo pwned')"

HOSTILE = f"""ORGANIZATION_BLOCK evil_import_os:OB1
TITLE=");{PAYLOAD}
// ");{PAYLOAD}
BEGIN
Network 1 // ");{PAYLOAD}
// {PAYLOAD}
LD     evil_in    // ");{PAYLOAD}
=      evil_out
MOVB   'A', VB0
Network 2
LD     SM0.0
CALL   evil_sbr, evil_in, VW10
END_ORGANIZATION_BLOCK
SUBROUTINE_BLOCK evil_sbr:SBR0
TITLE={PAYLOAD}
VAR_INPUT
x_in_import_os:BOOL;    // {PAYLOAD}
END_VAR
VAR_OUTPUT
y_out_system:INT;
END_VAR
BEGIN
Network 1
LD     #x_in_import_os
MOVW   +7, #y_out_system
END_SUBROUTINE_BLOCK
"""

SYMBOLS = f'''"Symbol","Address","Comment"
"evil_in","I0.0","{PAYLOAD}"
"evil_out","Q0.0","\\"); {PAYLOAD}"
'''

NAME_OK = re.compile(r"^(s\d|eno|L|I|Q|M|V|SM|S|AI|AQ|AC|HC|PI|PQ|TV|TB|CV|CB|WD|P|C|n|pc|r|"
                     r"_[a-zA-Z]+\d*|n_(OB|SBR|INT)\d+_\d+(_[a-z]\d*)?_\d+|pou_(OB|SBR|INT)\d+|"
                     r"_pieces_pou_\w+|_costs_pou_\w+|range|abs|bytes)$")
STRINGS_OK = {"s", "u", "r", "OB", "SBR", "INT"}


def test_hostile_text_never_reaches_generated_code() -> None:
    """Symbols, comments, titles, names and literals do not appear in the source."""
    plc = plcrt.load(HOSTILE, symbols=parse_symbols(SYMBOLS, "evil.sdf"))
    src = plc.source
    assert "import" not in src and "system" not in src and "evil" not in src
    tree = ast.parse(src)
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            assert NAME_OK.match(node.id), node.id
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            assert node.value in STRINGS_OK, node.value
        elif isinstance(node, ast.arg):
            assert NAME_OK.match(node.arg), node.arg
    plc["I0.0"] = 1
    plc.scan()
    assert plc["Q0.0"] == 1
    assert plc["VB0"] == ord("A")
    assert plc["VW10"] == 7


def test_hostile_symbol_address_is_rejected_cleanly() -> None:
    """A symbol whose address is Python code is a compile error, not code."""
    sym = parse_symbols(f'"Symbol","Address","Comment"\n"bad","{PAYLOAD}",""\n', "s.sdf")
    prog = "ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD     bad\n=      Q0.0\nEND_ORGANIZATION_BLOCK\n"
    try:
        plcrt.load(prog, symbols=sym)
    except plcrt.PlcCompileError as e:
        text = str(e)
        assert "<string>:4:8: error:" in text and "bad" in text
    else:  # pragma: no cover - the assertion above is the point
        raise AssertionError("a symbol standing for code must not compile")
