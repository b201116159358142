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
                     r"_[a-zA-Z]+\d*|n_(OB|SBR|INT)\d+_\d+(_[a-z]\d*)?_\d+|g_(OB|SBR|INT)\d+_\d+_\d+|"
                     r"pou_(OB|SBR|INT)\d+|b(I|Q|M|V|S)\d+_[0-7]|"
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


def test_hostile_text_never_reaches_the_native_backends_ir() -> None:
    """The LLVM IR of the native backend holds only plcrt's own words and
    numbers, and its Python runners pass the checks above."""
    import pytest
    pytest.importorskip("llvmlite")
    from plcrt.compiler import compile_program
    from plcrt.memory.cpu import cpu_model
    from plcrt.lang.sources import read_program
    program, symbols, _ = read_program([HOSTILE], parse_symbols(SYMBOLS, "evil.sdf"), None)
    unit, src, _ = compile_program(program, cpu_model(None), symbols=symbols, native=True)
    ir_text = unit.native.ir
    assert unit.native.pieces >= 1 and "evil" not in ir_text and "import" not in ir_text
    words = set(re.findall(r"[A-Za-z_][A-Za-z_0-9]*",
                           re.sub(r"[%@](v|b|c|seg|p)\d+(_\d+)?|%ctx", " ", ir_text)))
    assert words <= {"define", "declare", "llvm", "bswap", "internal", "void", "ptr", "noinline", "entry", "ret", "call",
                     "getelementptr", "load", "store", "align", "select", "icmp", "true",
                     "false", "to", "trunc", "zext", "sext", "and", "or", "xor", "shl",
                     "lshr", "add", "sub", "mul", "eq", "ne", "slt", "sle", "sgt", "sge",
                     "ult", "ule", "ugt", "uge", "i1", "i8", "i16", "i32", "i64"}, words
    plc = plcrt.load(HOSTILE, symbols=parse_symbols(SYMBOLS, "evil.sdf"), backend="native")
    for node in ast.walk(ast.parse(plc.source)):
        if isinstance(node, (ast.Name, ast.arg)):
            name = node.id if isinstance(node, ast.Name) else node.arg
            assert NAME_OK.match(name), name
    plc["I0.0"] = 1
    plc.scan()
    assert (plc["Q0.0"], plc["VB0"], plc["VW10"]) == (1, ord("A"), 7)


def test_a_native_compile_failure_is_a_clear_error(monkeypatch) -> None:
    """Should llvmlite refuse the IR (a plcrt bug), the load says so and how
    to go on, instead of a traceback."""
    import pytest
    pytest.importorskip("llvmlite")
    from plcrt.compiler.cache import programs
    import plcrt.compiler.native.jit as jit

    def broken(self, modules, names):
        raise RuntimeError("LLVM ERROR: bad IR")
    monkeypatch.setattr(jit.NativeCode, "__init__", broken)
    programs.clear()
    with pytest.raises(plcrt.PlcConfigError, match="backend='python'"):
        plcrt.load("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD I0.3\n= Q0.3\n"
                   "END_ORGANIZATION_BLOCK\n", backend="native")
