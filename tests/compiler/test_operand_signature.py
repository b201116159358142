"""An operand of a kind its position does not take is a compile error at
the operand (file, line, column, block, network) that says what the
position takes; a constant outside its type's range likewise.  Nothing
but a PlcError leaves ``load`` or ``plcrt check``, also when plcrt itself
has a bug.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt
from plcrt.cli import main
from plcrt.isa.registry import REGISTRY, load_families
from plcrt.lang import parse_program

HEAD = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD     SM0.0\nNetwork 2\nLD     SM0.0\n"
TAIL = "END_ORGANIZATION_BLOCK\n"


def _load_named(text: str) -> plcrt.Plc:
    """Load ``text`` as the file prog.awl."""
    return plcrt.Plc(parse_program(text, "prog.awl"))


def _prog(line: str) -> str:
    """``line`` is line 7, in network 2 of OB1."""
    return HEAD + line + "\n" + TAIL


REFUSED = [
    # (line, where the error points, what it says)
    ("BMB    255, VB10, 4", "prog.awl:7:8: error: BMB operand 1:",
     "not a valid byte in memory (an address or *pointer) (a constant has no address)"),
    ("BMW    255, VW10, 4", "prog.awl:7:8: error: BMW operand 1:", "word in memory"),
    ("BMD    255, VD10, 4", "prog.awl:7:8: error: BMD operand 1:", "double word in memory"),
    ("BMB    VB0, 7, 4", "prog.awl:7:13: error: BMB operand 2:", "a constant cannot be written"),
    ("BMB    AC0, VB10, 4", "prog.awl:7:8: error: BMB operand 1:",
     "an accumulator is a register, not memory"),
    ("BIR    5, VB0", "prog.awl:7:8: error: BIR operand 1:",
     "not a valid input byte (IB) (a constant has no address)"),
    ("BIR    &IB0, VB0", "prog.awl:7:8: error: BIR operand 1:", "input byte (IB)"),
    ("DTR    -1.0E+39, AC0", "prog.awl:7:8: error: DTR operand 1:",
     "outside the REAL range, ±3.402823E+38"),
    ("MOVR   3.5E+38, VD0", "prog.awl:7:8: error: MOVR operand 1:", "outside the REAL range"),
    ("MOVR   " + "9" * 40 + ", VD0", "prog.awl:7:8: error: MOVR operand 1:",
     "outside the REAL range"),
    ("LDR=   VD0, -1.0E+39", "prog.awl:7:13: error: LDR= operand 2:", "outside the REAL range"),
    ("MOVR   'A', VD0", "prog.awl:7:8: error: MOVR operand 1:",
     "a character constant is not a REAL"),
    ("MOVD   'ABCDE', VD0", "prog.awl:7:8: error: MOVD operand 1:",
     "a character constant of 1 to 4 characters"),
    ("ATH    'A', VB0, 1", "prog.awl:7:8: error: ATH operand 1:", "byte in memory"),
    ("FND=   +5, +1, VW0", "prog.awl:7:8: error: FND= operand 1:", "word in memory"),
    ("TODR   +5", "prog.awl:7:8: error: TODR operand 1:", "writable byte in memory"),
    ("FILL   +1, HC0, 2", "prog.awl:7:12: error: FILL operand 2:",
     "a high-speed counter value is a register, not memory"),
]


@pytest.mark.parametrize("line,where,says", REFUSED, ids=[r[0].split()[0] + " " + r[0].split()[1]
                                                        for r in REFUSED])
def test_an_operand_of_the_wrong_kind_is_a_located_error(line: str, where: str,
                                                         says: str) -> None:
    """The first error names the operand's file:line:col, the instruction
    and operand number, what the position takes, and the network."""
    with pytest.raises(plcrt.PlcCompileError) as info:
        _load_named(_prog(line))
    first = str(info.value.diagnostics[0])
    assert first.startswith(where) and says in first and first.endswith("[OB1 network 2]"), first


@pytest.mark.parametrize("backend", ["python", "native"])
def test_character_constants_are_the_numbers_they_stand_for(
        backend: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A character constant is its characters as bytes, from the most
    significant: a count ('A' = 65 shifts a word out entirely), a word
    ('AB' = 16#4142), a byte."""
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))
    plc = plcrt.load(_prog("RLW    VW6, 'A'\nMOVW   16#00FF, VW0\nSLW    VW0, 'A'\n"
                           "MOVW   'AB', VW2\nMOVB   'z', VB4"), backend=backend)
    plc["VW6"] = 0x1234
    plc.scan()
    assert plc["VW0"] == 0 and plc["SM1.0"] == 1       # shifted out: zero
    assert plc["VW2"] == 0x4142 and plc["VB4"] == ord("z")
    assert plc["VW6"] == ((0x1234 << 1) | (0x1234 >> 15)) & 0xFFFF   # 65 mod 16 = 1


def test_plcrt_check_names_the_line(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """``plcrt check`` of a program with constants where addresses go lists
    each at its line, exits 1, and never says "internal error"."""
    path = tmp_path / "consts.awl"
    path.write_text(_prog("BMB    255, VB10, 4\nBIR    5, VB0\nDTR    -1.0E+39, AC0"),
                    encoding="utf-8")
    assert main(["check", str(path)]) == 1
    err = capsys.readouterr().err
    assert "internal error" not in err
    for n, mn in ((7, "BMB"), (8, "BIR"), (9, "DTR")):
        assert f"consts.awl:{n}:8: error: {mn} operand 1:" in err, err
    assert "3 errors" in err


def test_a_plcrt_bug_in_an_emitter_is_a_located_compile_error(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The last resort: an exception of plcrt's own code while compiling one
    instruction is a PlcCompileError at that instruction, saying it is a
    plcrt bug, and the other instructions are still checked."""
    load_families()
    spec = REGISTRY["INCW"]

    def broken(g, op) -> None:  # noqa: ANN001
        raise ZeroDivisionError("division by zero")

    monkeypatch.setitem(REGISTRY, "INCW", type(spec)(
        spec.mnemonic, spec.roles, broken, spec.family, spec.summary))
    with pytest.raises(plcrt.PlcCompileError) as info:
        _load_named(_prog("INCW   VW0\nMOVB   VW0, VB0"))
    errors = [str(d) for d in info.value.diagnostics if d.severity == "error"]
    assert errors[0].startswith("prog.awl:7:1: error: INCW: plcrt cannot compile this "
                                "(ZeroDivisionError: division by zero); this is a bug in plcrt")
    assert errors[0].endswith("[OB1 network 2]")
    assert errors[1].startswith("prog.awl:8:8: error: MOVB operand 1:")


def test_a_plcrt_bug_in_operand_resolution_is_a_located_compile_error(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The same for an exception while resolving an operand: at the operand."""
    from plcrt.gen import resolve

    def broken(*args, **kwargs):  # noqa: ANN002, ANN003
        raise OverflowError("too big")

    monkeypatch.setattr(resolve, "check_role", broken)
    with pytest.raises(plcrt.PlcCompileError) as info:
        _load_named(_prog("INCW   VW0"))
    at = [str(d) for d in info.value.diagnostics if d.loc.line == 7]
    assert at[0].startswith("prog.awl:7:8: error: INCW operand 1: plcrt cannot compile this "
                            "(OverflowError: too big)"), at


def test_a_plcrt_bug_between_instructions_is_a_located_compile_error(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """The same for an exception of plcrt's code outside one instruction
    (here the native backend's planning of a block): a PlcCompileError at
    the network being compiled, never the bare exception."""
    pytest.importorskip("llvmlite")
    from plcrt.compiler import native

    def broken(*args, **kwargs):  # noqa: ANN002, ANN003
        raise KeyError("segment")

    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(native, "plan_pou", broken)
    with pytest.raises(plcrt.PlcCompileError) as info:
        plcrt.Plc(parse_program(_prog("INCW   VW0"), "prog.awl"), backend="native")
    first = str(info.value.diagnostics[0])
    assert first.startswith("prog.awl:5:1: error: this network: plcrt cannot compile this "
                            "(KeyError: 'segment'); this is a bug in plcrt"), first
    assert first.endswith("[OB1 network 2]"), first
