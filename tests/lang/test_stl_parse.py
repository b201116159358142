"""Unit tests of the STL parser: one small inline program per export quirk,
syntax errors with exact locations, and fuzzing that only PlcSyntaxError
ever escapes."""

from __future__ import annotations

import random
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from plcrt.errors import PlcSyntaxError
from plcrt.lang import parse_program, read_source
from plcrt.lang.ir import Insn, Pou, Program, VarDecl

OB1 = """ORGANIZATION_BLOCK MAIN:OB1
TITLE=PROGRAM COMMENTS
BEGIN
Network 1 // Network Title
// Network Comment
LD     I0.0
=      Q0.0
END_ORGANIZATION_BLOCK
"""


def only_pou(program: Program) -> Pou:
    assert len(program.pous) == 1
    return program.pous[0]


def insns(program: Program) -> list[Insn]:
    return [i for p in program.pous for n in p.networks for i in n.insns]


def wrap(body: str, header: str = "ORGANIZATION_BLOCK MAIN:OB1") -> str:
    """A one-network OB1 around some instruction lines."""
    end = "END_" + header.split()[0]
    return f"{header}\nBEGIN\nNetwork 1\n{body}\n{end}\n"


def syntax_error(text: str) -> PlcSyntaxError:
    with pytest.raises(PlcSyntaxError) as info:
        parse_program(text, "bad.awl")
    return info.value


# --------------------------------------------------------------------------
# Structure and the IR
# --------------------------------------------------------------------------

def test_basic_micro_win_v4_block() -> None:
    """A V4-style OB1 gives kind, number, name, title, network title and comment."""
    program = parse_program(OB1, "p.awl")
    pou = only_pou(program)
    assert (pou.kind, pou.number, pou.name, pou.ident) == ("OB", 1, "MAIN", "OB1")
    assert pou.title == "PROGRAM COMMENTS"
    net = pou.networks[0]
    assert (net.number, net.title, net.comment) == (1, "Network Title", "Network Comment")
    assert [(i.mnemonic, [o.text for o in i.operands]) for i in net.insns] == [
        ("LD", ["I0.0"]), ("=", ["Q0.0"])]
    assert program.file == "p.awl" and program.source == OB1


def test_v3_export_operands_set_apart_by_a_blank() -> None:
    """Micro/WIN V3 exports write a box's operands apart by a blank
    (``TON T37 +5``, ``CTU C0 +2``): they read as V4's comma-separated form."""
    v3 = parse_program(wrap("LD I0.0\nTON T37 +5\nLD I0.1\nLD M5.0\nCTU C0 +2"), "v3.awl")
    v4 = parse_program(wrap("LD I0.0\nTON T37, +5\nLD I0.1\nLD M5.0\nCTU C0, +2"), "v4.awl")
    assert [(i.mnemonic, [o.text for o in i.operands]) for i in insns(v3)] == [
        ("LD", ["I0.0"]), ("TON", ["T37", "+5"]), ("LD", ["I0.1"]), ("LD", ["M5.0"]),
        ("CTU", ["C0", "+2"])]
    assert [(i.mnemonic, [o.text for o in i.operands]) for i in insns(v3)] == \
        [(i.mnemonic, [o.text for o in i.operands]) for i in insns(v4)]


def test_locations_are_one_based_with_block_and_network() -> None:
    """Insn and operand locs give line/column plus block id and network number."""
    pou = only_pou(parse_program(OB1, "p.awl"))
    ld = pou.networks[0].insns[0]
    assert (ld.loc.file, ld.loc.line, ld.loc.column) == ("p.awl", 6, 1)
    assert (ld.loc.block, ld.loc.network) == ("OB1", 1)
    op = ld.operands[0]
    assert (op.loc.line, op.loc.column, op.loc.block, op.loc.network) == (6, 8, "OB1", 1)
    assert (pou.loc.line, pou.loc.column, pou.loc.block, pou.loc.network) == (1, 1, "OB1", None)
    assert (pou.networks[0].loc.line, pou.networks[0].loc.network) == (4, 1)


def test_mnemonics_upper_cased_operands_kept_raw() -> None:
    """Mnemonics are upper-cased; operands keep their spelling."""
    program = parse_program(wrap("ld  i0.0\nmovw +10, vw100"))
    assert [(i.mnemonic, [o.text for o in i.operands]) for i in insns(program)] == [
        ("LD", ["i0.0"]), ("MOVW", ["+10", "vw100"])]


def test_crlf_line_endings() -> None:
    """CRLF files parse with the same line numbers as LF files."""
    crlf = parse_program(OB1.replace("\n", "\r\n"))
    lf = parse_program(OB1)
    assert [i.loc.line for i in insns(crlf)] == [i.loc.line for i in insns(lf)] == [6, 7]
    assert only_pou(crlf).title == "PROGRAM COMMENTS"


def test_no_final_newline_and_bom() -> None:
    """A missing final newline and a leading BOM are accepted."""
    program = parse_program("\ufeff" + OB1.rstrip("\n"))
    assert only_pou(program).ident == "OB1"
    assert insns(program)[0].loc.line == 6


def test_tab_indented_and_padded_mnemonics() -> None:
    """TAB indentation, 7-column padding and single spaces all work."""
    text = wrap("\tLD     I0.0\n    A I0.1\nAN\tI0.2\n\t=      Q0.0")
    assert [(i.mnemonic, i.operands[0].text, i.loc.column) for i in insns(parse_program(text))] == [
        ("LD", "I0.0", 2), ("A", "I0.1", 5), ("AN", "I0.2", 1), ("=", "Q0.0", 2)]


def test_tab_only_and_blank_lines_anywhere() -> None:
    """Lines holding only a TAB or blanks are ignored wherever they appear."""
    text = ("\t\n\nSUBROUTINE_BLOCK S:SBR1\n\t\nTITLE=t\n \t \nBEGIN\n\t\n"
            "Network 1 \n//c\n\t\n\t\n\tLD     Always_On\n\n\t\n\tINCW   VW910\n"
            "\t\nEND_SUBROUTINE_BLOCK\n\t\n\n")
    program = parse_program(text)
    pou = only_pou(program)
    assert pou.networks[0].comment == "c"
    assert [(i.mnemonic, i.loc.line) for i in insns(program)] == [("LD", 13), ("INCW", 16)]


def test_uppercase_network_without_title() -> None:
    """``NETWORK 1`` (upper case, no //) opens a network without title."""
    text = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNETWORK 1\nLD SM0.1\nNETWORK 2\nLD I0.0\n"
            "END_ORGANIZATION_BLOCK\n")
    pou = only_pou(parse_program(text))
    assert [(n.number, n.title) for n in pou.networks] == [(1, ""), (2, "")]


def test_network_numbers_as_written() -> None:
    """Network numbers are taken as written, not renumbered."""
    text = wrap("LD I0.0\nNetwork 7\nLD I0.1\nNetwork 3\nLD I0.2")
    assert [n.number for n in only_pou(parse_program(text)).networks] == [1, 7, 3]


def test_title_on_network_line_with_trailing_blanks() -> None:
    """``Network 1 // title`` gives the title; trailing blanks are dropped."""
    text = wrap("LD I0.0").replace("Network 1", "Network 1 // 上电初始化   ")
    net = only_pou(parse_program(text)).networks[0]
    assert (net.title, net.comment) == ("上电初始化", "")


def test_network_title_line_after_network() -> None:
    """A ``TITLE=`` line right after the Network line is the network title."""
    text = wrap("TITLE=Start logic\n// first\nLD I0.0")
    net = only_pou(parse_program(text)).networks[0]
    assert (net.title, net.comment) == ("Start logic", "first")


def test_network_comment_without_space_and_multi_line() -> None:
    """``//text`` lines after the Network line form the network comment."""
    text = wrap("//首次扫描：初始化\n// second line\nLD SM0.1")
    net = only_pou(parse_program(text)).networks[0]
    assert net.comment == "首次扫描：初始化\nsecond line"


def test_comment_lines_between_instructions_are_dropped() -> None:
    """Comment lines after the first instruction do not end the network."""
    text = wrap("LD I0.0\n// between\n//again\n= Q0.0")
    net = only_pou(parse_program(text)).networks[0]
    assert [i.mnemonic for i in net.insns] == ["LD", "="]
    assert net.comment == ""


def test_comments_before_begin_are_block_comment() -> None:
    """``//`` lines between TITLE= and BEGIN become the block comment."""
    text = ("SUBROUTINE_BLOCK PRESSURE_TEST:SBR0\nTITLE=Pressure test\n"
            "// mapping: Q0.4/I2.1\n//         M10.4 sample\nBEGIN\n"
            "Network 1\nLD SM0.1\nEND_SUBROUTINE_BLOCK\n")
    pou = only_pou(parse_program(text))
    assert pou.title == "Pressure test"
    assert pou.comment == "mapping: Q0.4/I2.1\nM10.4 sample"


def test_comments_before_begin_without_title() -> None:
    """A bare ``ORGANIZATION_BLOCK OB1`` with comments and no TITLE= parses."""
    text = ("ORGANIZATION_BLOCK OB1\n// import source\n// one rung per network\n"
            "BEGIN\nNETWORK 1\nLD SM0.1\nMOVB 4, VB100\n\nEND_ORGANIZATION_BLOCK\n")
    pou = only_pou(parse_program(text))
    assert (pou.name, pou.ident, pou.title) == ("OB1", "OB1", "")
    assert pou.comment == "import source\none rung per network"


def test_file_comments_outside_blocks() -> None:
    """``//`` lines before, between and after blocks are accepted."""
    text = "// header\n//x\n" + OB1 + "// between\n\n" + OB1.replace(
        "ORGANIZATION_BLOCK MAIN:OB1", "ORGANIZATION_BLOCK MAIN:OB1") + "// tail\n"
    assert len(parse_program(text).pous) == 2


def test_cjk_block_names_and_kinds() -> None:
    """SBR/INT headers with CJK names give kind, number and name."""
    text = ("SUBROUTINE_BLOCK 系统初始化:SBR0\nTITLE=x\nBEGIN\nNetwork 1 \n"
            "LD First_Scan_On\nEND_SUBROUTINE_BLOCK\n\n"
            "INTERRUPT_BLOCK INT_0:INT0\nBEGIN\nNetwork 1\nEND_INTERRUPT_BLOCK\n"
            "subroutine_block 电机2号_控制:sbr12\nbegin\nend_subroutine_block\n")
    pous = parse_program(text).pous
    assert [(p.kind, p.number, p.name, p.ident) for p in pous] == [
        ("SBR", 0, "系统初始化", "SBR0"), ("INT", 0, "INT_0", "INT0"),
        ("SBR", 12, "电机2号_控制", "SBR12")]


def test_keywords_case_insensitive() -> None:
    """Block keywords, BEGIN, Network, TITLE and VAR are case-insensitive."""
    text = ("organization_block main:ob1\ntitle=x\nvar\nT:bool;\nend_var\nbegin\n"
            "network 1\nld i0.0\nend_organization_block\n")
    pou = only_pou(parse_program(text))
    assert (pou.ident, pou.name, pou.title) == ("OB1", "main", "x")
    assert [(v.section, v.name, v.type) for v in pou.variables] == [("TEMP", "T", "BOOL")]


def test_var_sections() -> None:
    """VAR_INPUT/IN_OUT/OUTPUT/VAR give VarDecls with section, type and comment."""
    text = ("SUBROUTINE_BLOCK SBR_0:SBR0\nTITLE=SUBROUTINE COMMENTS\n"
            "VAR_INPUT\nStart:BOOL;    // start it\nPreset:INT;\nEND_VAR\n"
            "VAR_IN_OUT\nCount:word;\nEND_VAR\n"
            "VAR_OUTPUT\n// outputs\nDone:BOOL;\t// done\nEND_VAR\n"
            "VAR\ntmp:DWORD;\n启动:BOOL;\nEND_VAR\n"
            "BEGIN\nNetwork 1\nLD #Start\n= #Done\nEND_SUBROUTINE_BLOCK\n")
    pou = only_pou(parse_program(text, "s.awl"))
    assert [(v.section, v.name, v.type, v.comment) for v in pou.variables] == [
        ("IN", "Start", "BOOL", "start it"), ("IN", "Preset", "INT", ""),
        ("IN_OUT", "Count", "WORD", ""), ("OUT", "Done", "BOOL", "done"),
        ("TEMP", "tmp", "DWORD", ""), ("TEMP", "启动", "BOOL", "")]
    first = pou.variables[0]
    assert isinstance(first, VarDecl)
    assert (first.loc.line, first.loc.column, first.loc.block) == (4, 1, "SBR0")
    assert [o.text for o in insns(parse_program(text))[0].operands] == ["#Start"]


def test_var_section_in_ob() -> None:
    """OBs may declare temporaries in a VAR section."""
    text = "ORGANIZATION_BLOCK MAIN:OB1\nVAR\nx:REAL;\nEND_VAR\nBEGIN\nEND_ORGANIZATION_BLOCK\n"
    assert [(v.section, v.type) for v in only_pou(parse_program(text)).variables] == [
        ("TEMP", "REAL")]


def test_code_comments_and_semicolon() -> None:
    """``// comment`` after operands, with or without ``;``, goes to Insn.comment."""
    text = wrap("LD I0.0 // start\nA I0.1; // guard\nAN I0.2 ;\nLPS//push\n= Q0.0//out")
    got = [(i.mnemonic, [o.text for o in i.operands], i.comment)
           for i in insns(parse_program(text))]
    assert got == [("LD", ["I0.0"], "start"), ("A", ["I0.1"], "guard"),
                   ("AN", ["I0.2"], ""), ("LPS", [], "push"), ("=", ["Q0.0"], "out")]


def test_empty_networks_are_kept() -> None:
    """A Network line without instructions still counts as a network."""
    text = ("INTERRUPT_BLOCK INT_0:INT0\nTITLE=INTERRUPT ROUTINE COMMENTS\nBEGIN\n"
            "Network 1 // Network Title\n// Network Comment\nNetwork 2 \n"
            "END_INTERRUPT_BLOCK\n")
    program = parse_program(text)
    assert program.network_count() == 2 and program.instruction_count() == 0
    assert only_pou(program).networks[0].comment == "Network Comment"


def test_empty_block_and_empty_file() -> None:
    """A block with no networks and a file with no blocks are valid."""
    empty = parse_program("SUBROUTINE_BLOCK A:SBR1\nBEGIN\nEND_SUBROUTINE_BLOCK")
    assert only_pou(empty).networks == ()
    assert parse_program("").pous == ()
    assert parse_program("\n\t\n// only a comment\n").pous == ()


@pytest.mark.parametrize("operand", [
    "I0.0", "VB100", "VW7", "VD10", "SMB34", "SM0.1", "T37", "C5", "AC0", "AIW0",
    "AQW2", "HC0", "L1.0", "LW10", "S0.1", "+50", "-13", "100", "16#FF",
    "2#1010_0101", "1.5", "-1.0", "0.0174533", "+1.175495E-38", "'ABC'",
    '"text"', "&VB100", "*AC1", "*VD200", "*LD10", "#local", "电机启动",
    "Always_On", "INT_0", "'a, b // c'", '"x,y"', "'it''s'",
])
def test_operand_forms(operand: str) -> None:
    """Each operand form is kept verbatim as one operand, with a column."""
    program = parse_program(wrap(f"MOVB   {operand}, VB0 // c"))
    ops = insns(program)[0].operands
    assert [o.text for o in ops] == [operand, "VB0"]
    assert ops[0].loc.column == 8
    assert insns(program)[0].comment == "c"


@pytest.mark.parametrize("mnemonic", [
    "LDW>=", "AB<>", "=I", "+I", "*R", "/D", "FND=", "LDB=", "OW>", "-D", "NOT"])
def test_mnemonic_forms(mnemonic: str) -> None:
    """Comparison and arithmetic mnemonics with symbols are one mnemonic."""
    program = parse_program(wrap(f"{mnemonic}  VW0, +1"))
    assert insns(program)[0].mnemonic == mnemonic


def test_string_operands_with_commas_and_slashes() -> None:
    """Commas and ``//`` inside quotes do not split operands or start comments."""
    program = parse_program(wrap("SSCPY 'A, B', 1, \"x // y, z\", VB0 // real comment"))
    insn = insns(program)[0]
    assert [o.text for o in insn.operands] == ["'A, B'", "1", '"x // y, z"', "VB0"]
    assert insn.comment == "real comment"


def test_operand_separators_tolerate_blanks() -> None:
    """Operands may be separated by ``,`` with any blanks around it."""
    program = parse_program(wrap("FND=   VW560,+100 ,  VW604\t,\tVW610"))
    assert [o.text for o in insns(program)[0].operands] == ["VW560", "+100", "VW604", "VW610"]


def test_unknown_mnemonics_are_not_syntax_errors() -> None:
    """Any mnemonic-shaped word parses; the compiler decides if it exists."""
    program = parse_program(wrap("LDX I0.0\nFOOBAR\nNETR VB0, 1"))
    assert [i.mnemonic for i in insns(program)] == ["LDX", "FOOBAR", "NETR"]


# --------------------------------------------------------------------------
# read_source
# --------------------------------------------------------------------------

def test_read_source_gbk(tmp_path: Path) -> None:
    """A GBK-encoded CRLF export decodes to the right CJK names."""
    text = ("SUBROUTINE_BLOCK 系统初始化:SBR0\r\nTITLE=初始化\r\nBEGIN\r\n"
            "Network 1 \r\n//首次扫描\r\n\tLD     电机启动\r\nEND_SUBROUTINE_BLOCK\r\n")
    path = tmp_path / "gbk.awl"
    path.write_bytes(text.encode("gbk"))
    decoded = read_source(path)
    assert decoded == text
    program = parse_program(decoded, str(path))
    assert only_pou(program).name == "系统初始化"
    assert insns(program)[0].operands[0].text == "电机启动"


def test_read_source_utf8_with_bom(tmp_path: Path) -> None:
    """A UTF-8 BOM is stripped and UTF-8 is preferred over GBK."""
    path = tmp_path / "u.awl"
    path.write_bytes(b"\xef\xbb\xbf" + OB1.replace("MAIN", "主程序").encode("utf-8"))
    assert read_source(path).startswith("ORGANIZATION_BLOCK 主程序:OB1")


def test_read_source_cp1252(tmp_path: Path) -> None:
    """Bytes that are neither UTF-8 nor GBK decode as CP1252."""
    text = OB1.replace("Network Comment", "Zähler Ü")
    path = tmp_path / "w.awl"
    path.write_bytes(text.encode("cp1252"))
    assert read_source(path) == text


def test_read_source_missing_file(tmp_path: Path) -> None:
    """A missing file raises PlcSyntaxError naming it, not OSError."""
    missing = tmp_path / "nope.awl"
    with pytest.raises(PlcSyntaxError) as info:
        read_source(missing)
    assert info.value.loc is not None and info.value.loc.file == str(missing)
    assert "no such file" in str(info.value)


def test_read_source_directory(tmp_path: Path) -> None:
    """Reading a directory raises PlcSyntaxError."""
    with pytest.raises(PlcSyntaxError):
        read_source(tmp_path)


# --------------------------------------------------------------------------
# Syntax errors
# --------------------------------------------------------------------------

def test_missing_end_at_end_of_file() -> None:
    """A block without END_... is reported after its last line, in context."""
    err = syntax_error("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\n\n")
    assert (err.loc.file, err.loc.line, err.loc.column) == ("bad.awl", 5, 7)
    assert (err.loc.block, err.loc.network) == ("OB1", 1)
    assert "missing END_ORGANIZATION_BLOCK" in err.message


def test_missing_end_before_next_block() -> None:
    """A missing END_... is reported at the next block header."""
    err = syntax_error("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n"
                       "SUBROUTINE_BLOCK S:SBR0\nBEGIN\nEND_SUBROUTINE_BLOCK\n")
    assert (err.loc.line, err.loc.column) == (5, 1)
    assert "missing END_ORGANIZATION_BLOCK" in err.message
    assert len(err.diagnostics) == 1  # the SBR itself is fine


def test_wrong_end_keyword() -> None:
    """END_ORGANIZATION_BLOCK cannot close a SUBROUTINE_BLOCK."""
    err = syntax_error(wrap("LD I0.0", "SUBROUTINE_BLOCK S:SBR0").replace(
        "END_SUBROUTINE_BLOCK", "END_ORGANIZATION_BLOCK"))
    assert (err.loc.line, err.loc.column) == (5, 1)
    assert "END_SUBROUTINE_BLOCK" in err.message


def test_garbage_line_outside_block() -> None:
    """A stray line between blocks is an error at its first character."""
    err = syntax_error(OB1 + "   LD I0.0\n" + OB1)
    assert (err.loc.line, err.loc.column) == (9, 4)
    assert "'LD'" in err.message and "ORGANIZATION_BLOCK" in err.message
    assert err.loc.block is None


def test_unterminated_string() -> None:
    """An unterminated quote is reported at the quote."""
    err = syntax_error(wrap("MOVB   'ABC, VB0"))
    assert (err.loc.line, err.loc.column, err.loc.network) == (4, 8, 1)
    assert "unterminated string" in err.message


def test_instruction_before_first_network() -> None:
    """Instructions need a Network line first."""
    err = syntax_error("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n  LD I0.0\nEND_ORGANIZATION_BLOCK\n")
    assert (err.loc.line, err.loc.column) == (3, 3)
    assert "Network" in err.message


def test_a_comma_without_an_operand() -> None:
    """A comma must be followed by an operand: the error points after it."""
    err = syntax_error(wrap("MOVB 1, ,VB0"))
    assert (err.loc.line, err.loc.column) == (4, 9)
    assert "expected operand" in err.message


def test_missing_end_var() -> None:
    """A VAR section without END_VAR is reported at BEGIN."""
    err = syntax_error("SUBROUTINE_BLOCK S:SBR0\nVAR_INPUT\nA:BOOL;\nBEGIN\nEND_SUBROUTINE_BLOCK\n")
    assert (err.loc.line, err.loc.column, err.loc.block) == (4, 1, "SBR0")
    assert "END_VAR" in err.message


def test_var_section_keyword_with_a_case_folded_letter() -> None:
    """"VAR_İNPUT" (dotted capital I, which case-insensitive matching takes
    for "I") is a syntax error at its line, not an internal KeyError."""
    err = syntax_error("SUBROUTINE_BLOCK S:SBR0\nVAR_\u0130NPUT\nA:BOOL;\nEND_VAR\n"
                       "BEGIN\nEND_SUBROUTINE_BLOCK\n")
    assert (err.loc.line, err.loc.column, err.loc.block) == (2, 1, "SBR0")
    assert "unknown variable section" in err.message


def test_bad_block_ids() -> None:
    """Block ids must be OBn/SBRn/INTn and fit the header keyword."""
    err = syntax_error("ORGANIZATION_BLOCK MAIN:SBR1\nBEGIN\nEND_ORGANIZATION_BLOCK\n"
                       "SUBROUTINE_BLOCK X:FOO\nBEGIN\nEND_SUBROUTINE_BLOCK\n")
    assert [(d.loc.line, d.loc.column) for d in err.diagnostics] == [(1, 25), (4, 20)]


def test_several_errors_one_per_block() -> None:
    """Errors in different blocks are all reported, in file order."""
    good = wrap("LD I0.0", "SUBROUTINE_BLOCK S:SBR0")
    text = (wrap("LD I0.0 ;;") + good.replace("SBR0", "SBR1")
            + wrap("MOVB 'x", "SUBROUTINE_BLOCK T:SBR2"))
    err = syntax_error(text)
    assert [(d.loc.line, d.loc.block) for d in err.diagnostics] == [(4, "OB1"), (14, "SBR2")]
    assert str(err).startswith("bad.awl:4:10: error: ")


def test_every_broken_line_of_a_block_is_reported_in_one_run() -> None:
    """A user fixing a large export sees all broken instruction lines of a
    block at once, not one per run; the lines after them still parse."""
    text = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD     I0.0 ;;\n=      Q0.0\n"
            "Network 2\nLD     I0.2 ,\n=      Q0.1\nNetwork 3\nMOVB   'x\n"
            "END_ORGANIZATION_BLOCK\n")
    err = syntax_error(text)
    assert [(d.loc.line, d.loc.network) for d in err.diagnostics] == [(4, 1), (7, 2), (10, 3)]


def test_the_blocks_without_errors_are_kept_as_a_partial_program() -> None:
    """PlcSyntaxError.partial holds exactly the blocks that parsed whole (a
    viewer draws them); a block with a broken line or a missing END_... is
    left out."""
    text = (wrap("LD I0.0 ;;") + wrap("LD I0.0\n= Q0.0", "SUBROUTINE_BLOCK S:SBR1")
            + "SUBROUTINE_BLOCK T:SBR2\nBEGIN\nNetwork 1\nLD I0.0\n"
            + wrap("LD I0.1\n= Q0.1", "SUBROUTINE_BLOCK U:SBR3"))
    err = syntax_error(text)
    assert [d.loc.block for d in err.diagnostics] == ["OB1", "SBR2"]
    assert err.partial is not None
    assert [p.ident for p in err.partial.pous] == ["SBR1", "SBR3"]
    assert [i.mnemonic for i in err.partial.pous[1].networks[0].insns] == ["LD", "="]


def test_a_missing_end_at_the_end_of_the_file_is_one_error() -> None:
    err = syntax_error("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD     I0.0\n")
    assert len(err.diagnostics) == 1 and "missing END_ORGANIZATION_BLOCK" in err.message


def test_network_without_number() -> None:
    """``Network`` without a number is an error at the line end."""
    err = syntax_error(wrap("LD I0.0").replace("Network 1", "Network"))
    assert (err.loc.line, err.loc.column) == (3, 8)
    assert "network number" in err.message


# --------------------------------------------------------------------------
# Grammar health and fuzzing
# --------------------------------------------------------------------------

def test_grammar_is_conflict_free_in_strict_mode() -> None:
    """The grammar has no LALR conflicts and no equal-priority regex collisions."""
    pytest.importorskip("interegular")
    from importlib import resources

    from lark import Lark

    grammar = (resources.files("plcrt.lang") / "grammar" / "stl.lark").read_text(
        encoding="utf-8")
    Lark(grammar, parser="lalr", propagate_positions=True,
         maybe_placeholders=False, strict=True)


def _parse_or_syntax_error(text: str) -> None:
    try:
        parse_program(text, "fuzz.awl")
    except PlcSyntaxError as err:
        assert err.diagnostics
        for diag in err.diagnostics:
            assert diag.loc is not None and diag.loc.line >= 1 and diag.loc.column >= 1


_FRAGMENTS = ["ORGANIZATION_BLOCK", "SUBROUTINE_BLOCK", "INTERRUPT_BLOCK",
              "END_ORGANIZATION_BLOCK", "END_SUBROUTINE_BLOCK", "BEGIN", "VAR",
              "VAR_INPUT", "END_VAR", "Network", "TITLE=", "//", "MAIN:OB1",
              "S:SBR0", "LD", "I0.0", ",", ";", ":", "'", '"', "\n", "\r\n",
              "\t", " ", "1", "電", "#x", "BOOL"]


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.text(max_size=200))
def test_random_text_only_raises_syntax_errors(text: str) -> None:
    """Arbitrary text either parses or raises PlcSyntaxError with locations."""
    _parse_or_syntax_error(text)


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.sampled_from(_FRAGMENTS), max_size=60))
def test_random_token_soup_only_raises_syntax_errors(parts: list[str]) -> None:
    """Sequences of grammar fragments parse or raise PlcSyntaxError only."""
    _parse_or_syntax_error(" ".join(parts))


_VALID = (
    "// file\nSUBROUTINE_BLOCK 电机:SBR1\nTITLE=t\n// c\nVAR_INPUT\nA:BOOL; // a\n"
    "END_VAR\nBEGIN\nNetwork 1 // n\n//nc\n\tLD     #A\n\tMOVB   'x,y', VB0 ; // z\n"
    "Network 2 \n\nEND_SUBROUTINE_BLOCK\n\nORGANIZATION_BLOCK OB1\nBEGIN\nNETWORK 1\n"
    "LDW>= VW0, +1\n= Q0.0\nEND_ORGANIZATION_BLOCK\n")


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(min_value=0), st.lists(
    st.tuples(st.sampled_from(["insert", "delete", "replace", "dup_line", "drop_line"]),
              st.integers(min_value=0, max_value=10_000),
              st.sampled_from(_FRAGMENTS + ["x", "\x00", "\u3000", "\ufeff"])),
    min_size=1, max_size=6))
def test_mutated_valid_program_only_raises_syntax_errors(seed: int, edits: list) -> None:
    """Random edits of a valid program parse or raise PlcSyntaxError only."""
    text = _VALID
    for op, pos, frag in edits:
        at = pos % (len(text) + 1)
        if op == "insert":
            text = text[:at] + frag + text[at:]
        elif op == "delete":
            text = text[:at] + text[at + 1 + seed % 5:]
        elif op == "replace":
            text = text[:at] + frag + text[at + len(frag):]
        else:
            lines = text.split("\n")
            index = pos % len(lines)
            if op == "dup_line":
                lines.insert(index, lines[index])
            else:
                del lines[index]
            text = "\n".join(lines)
    _parse_or_syntax_error(text)


def test_valid_fuzz_seed_parses() -> None:
    """The fuzzing seed program itself is valid (so mutations start from good)."""
    program = parse_program(_VALID)
    assert [p.ident for p in program.pous] == ["SBR1", "OB1"]
    assert program.instruction_count() == 4


def test_shuffled_lines_only_raise_syntax_errors() -> None:
    """Shuffled lines of a valid program never raise a non-syntax exception."""
    rng = random.Random(1234)
    lines = _VALID.split("\n")
    for _ in range(200):
        rng.shuffle(lines)
        _parse_or_syntax_error("\n".join(lines))
