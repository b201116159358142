"""Every instruction, with an operand of every kind in every position: it
compiles, or each refused operand is a located compile error (file, line,
block, network) that says what the position takes; what compiles scans and
forks on both backends.

This is the operand-kind matrix the mutation test samples at random
(tests/compiler/test_mutation_fuzz.py): here every mnemonic of the
registry meets every kind once, in a subroutine with locals of every type.
"""

from __future__ import annotations

import pytest

import plcrt
from plcrt.isa.registry import REGISTRY, Role, load_families
from plcrt.lang import parse_symbols

load_families()

#: one operand of every kind: bits, bytes, words and double words of every
#: area, constants of every type and size, pointers, indirect operands,
#: locals, symbols, labels.  The pointers of the indirect ones (VD9000, AC2,
#: #q) are set once and written by nothing else
KINDS = [
    "I0.0", "Q0.0", "M0.0", "V0.0", "SM0.0", "SM30.0", "S0.0", "T37", "C1",
    "IB0", "QB0", "MB0", "VB100", "SMB0", "SMB30", "SB0", "LB20", "AC0", "HC0",
    "IW0", "QW0", "MW0", "VW100", "SMW30", "LW20", "AIW0", "AQW0",
    "ID0", "QD0", "MD0", "VD100", "SMD30", "LD20", "AC1",
    "0", "1", "-1", "255", "256", "65535", "-2147483648", "4294967296", "16#FF", "2#101",
    "1.5", "-1.0E+39", "3.402823E+38", "'A'", "'ABCD'", "'ABCDE'", '"Pump 1"', '""', "TRUE",
    "&VB100", "&IB0", "&T37", "*VD9000", "*AC2", "*#q",
    "#x", "#b", "#w", "#d", "#r", "#p", "Sym_bit", "Sym_word", "Nope", "SBR0",
]

#: an operand that fits each role (the other positions of a line)
TYPICAL = {
    Role.BIT_R: "V0.0", Role.BIT_W: "M0.0", Role.BIT_TC: "M0.1", Role.IBIT: "I0.0",
    Role.QBIT: "Q0.0", Role.B_R: "VB0", Role.W_R: "VW2", Role.D_R: "VD4",
    Role.R_R: "VD8", Role.B_W: "VB12", Role.W_W: "VW14", Role.D_W: "VD16",
    Role.R_W: "VD20", Role.D_PTR: "&VB100", Role.B_IB: "IB0", Role.B_QB: "QB0",
    Role.B_M: "VB24", Role.W_M: "VW26", Role.D_M: "VD28", Role.B_MW: "VB40",
    Role.W_MW: "VW42", Role.D_MW: "VD44", Role.N: "4", Role.TIMER: "T37",
    Role.COUNTER: "C1", Role.LABEL: "1", Role.SBIT: "S0.1", Role.STR_R: '"AB"',
    Role.STR_M: "VB200", Role.STR_W: "VB300",
}
#: operands of the instructions that take theirs as written
VARIADIC = {
    "ATCH": ["INT0", "10"], "DTCH": ["10"], "CEVNT": ["10"], "PLS": ["0"],
    "HDEF": ["0", "1"], "HSC": ["0"], "PID": ["VB100", "0"], "XMT": ["VB100", "0"],
    "RCV": ["VB100", "0"], "NETR": ["VB100", "0"], "NETW": ["VB100", "0"],
    "GET": ["VB100"], "PUT": ["VB100"], "CALL": ["SBR1", "#b"],
}
SYMBOLS = parse_symbols('"Symbol","Address","Comment"\n"Sym_bit","M1.0",""\n'
                        '"Sym_word","VW200",""\n', "kinds.sdf")

HEAD = """ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     SM0.0
CALL   SBR0
END_ORGANIZATION_BLOCK
SUBROUTINE_BLOCK KINDS:SBR0
VAR_TEMP
q:DWORD;
x:BOOL;
b:BYTE;
w:INT;
d:DINT;
r:REAL;
p:DWORD;
END_VAR
BEGIN
Network 1 // the pointers of the indirect operands point into V memory
LD     SM0.0
MOVD   &VB400, VD9000
MOVD   &VB400, AC2
MOVD   &VB400, #q
"""
TAIL = """END_SUBROUTINE_BLOCK
SUBROUTINE_BLOCK ONE:SBR1
VAR_INPUT
IN1:BYTE;
END_VAR
BEGIN
Network 1
LD     SM0.0
MOVB   #IN1, VB500
END_SUBROUTINE_BLOCK
INTERRUPT_BLOCK TICK:INT0
BEGIN
Network 1
LD     SM0.0
INCW   VW502
END_INTERRUPT_BLOCK
"""


def _lines(mnemonic: str) -> list[str]:
    """The instruction with each operand kind in each of its positions."""
    spec = REGISTRY[mnemonic]
    base = VARIADIC[mnemonic] if spec.variadic else [TYPICAL[r] for r in spec.roles]
    out = [f"{mnemonic} {', '.join(base)}".rstrip()]
    for i in range(len(base)):
        for kind in KINDS:
            ops = list(base)
            ops[i] = kind
            out.append(f"{mnemonic} {', '.join(ops)}")
    return out


#: the logic stack before each instruction: three levels, as many as a
#: counter box takes (count, reset, load)
POWER = "LD     SM0.0\nLD     SM0.0\nLD     SM0.0\n"


def _program(lines: list[str]) -> tuple[str, dict[int, int]]:
    """SBR0 with one network per line (from network 2, after :data:`POWER`,
    so boxes have power); and the text line of each instruction -> its
    network."""
    text = HEAD
    where: dict[int, int] = {}
    row = HEAD.count("\n") + 1
    for n, line in enumerate(lines, 2):
        text += f"Network {n}\n{POWER}{line}\n"
        where[row + 1 + POWER.count(chr(10))] = n
        row += 2 + POWER.count(chr(10))
    return text + TAIL, where


def _load(text: str, backend: str = "python") -> plcrt.Plc:
    return plcrt.load(text, symbols=SYMBOLS, backend=backend)


def _refused(mnemonic: str) -> tuple[list[str], set[int]]:
    """The lines of *mnemonic* and the networks the compiler refused, after
    checking that each refusal is located at its line, in block SBR0 and
    its network, and none reports a plcrt bug."""
    lines = _lines(mnemonic)
    text, where = _program(lines)
    refused: set[int] = set()
    try:
        _load(text)
    except plcrt.PlcError as e:
        for d in e.diagnostics:
            if d.severity != "error":
                continue
            assert "bug in plcrt" not in d.message and "internal error" not in d.message, str(d)
            assert d.loc is not None and d.loc.file == "<string>", str(d)
            if d.loc.line in where:
                assert d.loc.block == "SBR0" and d.loc.network == where[d.loc.line], str(d)
                refused.add(where[d.loc.line])
            else:   # about the program as a whole (a CALL cycle, a stack at the end)
                assert d.loc.line >= 1, str(d)
    return lines, refused


def _runs(lines: list[str]) -> bool:
    """The program of *lines* loads on both backends, scans and forks (or
    is refused, never for a plcrt bug); False when it does not load."""
    text, _ = _program(lines)
    for backend in ("python", "native"):
        try:
            plc = _load(text, backend)
        except plcrt.PlcError as e:
            # lines accepted one by one may clash together (labels, SCR
            # segments, FOR/NEXT pairs): located, never a bug
            assert "bug in plcrt" not in str(e) and "internal error" not in str(e), str(e)
            return False
        try:
            plc.run(scans=2)
            plc.fork().run(scans=1)
        except plcrt.PlcError as e:
            assert "bug in plcrt" not in str(e) and "internal error" not in str(e), str(e)
    return True


FAMILIES = sorted({spec.family for spec in REGISTRY.values()})


@pytest.mark.parametrize("family", FAMILIES)
def test_every_operand_kind_compiles_or_is_a_located_error(
        family: str, tmp_path, monkeypatch: pytest.MonkeyPatch) -> None:  # noqa: ANN001
    """Each refused line is reported at its own line, in block SBR0 and its
    network, with no plcrt bug; the lines that compile run and fork on both
    backends (the family's together, else each instruction's)."""
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))
    kept: dict[str, list[str]] = {}
    for mnemonic in sorted(m for m, spec in REGISTRY.items() if spec.family == family):
        lines, refused = _refused(mnemonic)
        kept[mnemonic] = [line for n, line in enumerate(lines, 2) if n not in refused]
    if not _runs([line for lines in kept.values() for line in lines]):
        for lines in kept.values():
            if lines:
                _runs(lines)
