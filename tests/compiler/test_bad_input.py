"""Bad programs give clear, located errors (file:line:col, block, network),
all of them at once, and never a Python traceback."""

from __future__ import annotations

import pytest

import plcrt
from plcrt.lang import parse_program

HEAD = "ORGANIZATION_BLOCK MAIN:OB1\nTITLE=t\nBEGIN\nNetwork 1\n"
TAIL = "END_ORGANIZATION_BLOCK\n"


def _prog(body: str, extra: str = "") -> str:
    return HEAD + body + TAIL + extra


CASES = [
    # (id, program text, expected fragments of the first error line)
    ("unknown mnemonic", _prog("LD     I0.0\nLDX    I0.1\n"),
     ["prog.awl:6:1: error: unknown instruction 'LDX' [OB1 network 1]"]),
    ("unimplemented", _prog("LD     I0.0\nGPA    VB100, 0\n"),
     ["prog.awl:6:1: error: instruction GPA is not implemented yet [OB1 network 1]"]),
    ("wrong operand kind", _prog("LD     VW0\n=      Q0.0\n"),
     ["prog.awl:5:8: error: LD operand 1:", "'VW0' is not a valid bit"]),
    ("word where byte", _prog("LD     SM0.0\nMOVB   VW0, VB2\n"),
     ["prog.awl:6:8: error: MOVB operand 1:", "this is a word"]),
    ("constant output", _prog("LD     SM0.0\nMOVW   VW0, +5\n"),
     ["prog.awl:6:13: error: MOVW operand 2:", "a constant cannot be written"]),
    ("operand count", _prog("LD     SM0.0\nMOVW   VW0\n"),
     ["prog.awl:6:1: error: MOVW takes 2 operand(s), got 1 [OB1 network 1]"]),
    ("out of range V", _prog("LD     SM0.0\nMOVW   +1, VW10239\n"),
     ["prog.awl:6:12: error: MOVW operand 2:", "VW10239 is out of range for the CPU226"]),
    ("bit number", _prog("LD     I0.8\n=      Q0.0\n"),
     ["prog.awl:5:8: error: LD operand 1:", "bit number must be 0..7"]),
    ("timer number", _prog("LD     I0.0\nTON    T256, +10\n"),
     ["prog.awl:6:8: error: TON operand 1:", "timers are T0..T255"]),
    ("read-only SM", _prog("LD     I0.0\n=      SM0.0\n"),
     ["prog.awl:6:8: error: = operand 1:", "read-only"]),
    ("missing label", _prog("LD     I0.0\nJMP    4\n"),
     ["prog.awl:6:1: error: JMP: jump to label 4, which is not defined in OB1"]),
    ("empty stack", _prog("A      I0.0\n=      Q0.0\n"),
     ["prog.awl:5:1: error: A: the logic stack is empty here"]),
    ("missing subroutine", _prog("LD     SM0.0\nCALL   NOPE\n"),
     ["prog.awl:6:1: error: CALL: no subroutine named 'NOPE' in the program [OB1 network 1]"]),
    ("unknown symbol", _prog("LD     Start_Button\n=      Q0.0\n"),
     ["prog.awl:5:8: error: LD operand 1: unknown symbol 'Start_Button'"]),
]


@pytest.mark.parametrize("text,fragments", [(c[1], c[2]) for c in CASES],
                         ids=[c[0] for c in CASES])
def test_compile_errors_are_located(text: str, fragments: list[str]) -> None:
    """The error names file:line:col, the message and the block/network."""
    with pytest.raises(plcrt.PlcCompileError) as info:
        plcrt.Plc(parse_program(text, "prog.awl"))
    first = str(info.value.diagnostics[[d.severity for d in info.value.diagnostics].index("error")])
    for frag in fragments:
        assert frag in first, first


def test_all_errors_reported_together() -> None:
    """Three independent mistakes give three errors in one exception."""
    text = _prog("LD     I0.0\nLDX    I0.1\n=      Q9.9\nMOVB   VW0, VB1\n")
    with pytest.raises(plcrt.PlcCompileError) as info:
        plcrt.Plc(parse_program(text, "prog.awl"))
    lines = [d for d in info.value.diagnostics if d.severity == "error"]
    assert [d.loc.line for d in lines] == [6, 7, 8]


@pytest.mark.parametrize("text", [
    "ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD I0.0\n",          # no END
    "garbage outside any block\n",
    "ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nMOVB 'abc, VB0\nEND_ORGANIZATION_BLOCK\n",
    "\x00\x01\x02",
    "",
])
def test_malformed_files_raise_syntax_errors(text: str) -> None:
    """Malformed text is a PlcSyntaxError with a location (or an empty program)."""
    try:
        plcrt.load(text + "\n")
    except plcrt.PlcSyntaxError as e:
        assert e.loc is not None and e.loc.line >= 1
    except plcrt.PlcError:
        pass
