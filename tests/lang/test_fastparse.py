"""The line-based fast path against the lark path it stands in for.

:func:`plcrt.lang.fastparse.fast_parse` may decline any text (``None``) but
must never accept one with a program different from the one
:func:`plcrt.lang.stl.parse_program_lark` builds, nor accept a text lark
rejects.  Checked differentially on the sample programs, the shared corpus
(skipped when absent), the inline programs of the test suite, generated
programs and randomly damaged texts; and the fast path must really accept
the sample programs, or it would be no faster.
"""

from __future__ import annotations

import ast
import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from plcrt.errors import PlcSyntaxError
from plcrt.lang import parse_program, read_source
from plcrt.lang.fastparse import fast_parse
from plcrt.lang.ir import Program
from plcrt.lang.stl import parse_program_lark

from stl_helpers import corpus_awl_params

ROOT = Path(__file__).resolve().parents[2]
PROGRAMS = sorted((ROOT / "programs").rglob("*.awl"))
EXAMPLES = int(os.environ.get("PLCRT_PROPERTY_EXAMPLES", "200"))


def lark_or_error(text: str, file: str = "t.awl") -> Program | PlcSyntaxError:
    try:
        return parse_program_lark(text, file)
    except PlcSyntaxError as exc:
        return exc


def assert_declines_or_agrees(text: str, file: str = "t.awl") -> Program | None:
    """The fast path's result is None or lark's program; lark's errors are
    never hidden by an accepted text.  Returns the fast path's result."""
    fast = fast_parse(text, file)
    if fast is None:
        return None
    reference = lark_or_error(text, file)
    assert not isinstance(reference, PlcSyntaxError), (
        f"fast path accepted a text lark rejects: {reference}")
    assert fast == reference
    return fast


# --------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------

@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: str(p.relative_to(ROOT)))
def test_sample_programs_accepted_and_identical(path: Path) -> None:
    """Every sample program is accepted by the fast path, with lark's program."""
    text = read_source(path)
    fast = fast_parse(text, path.name)
    assert fast is not None, "the fast path declined a sample program"
    assert fast == parse_program_lark(text, path.name)


def test_sample_programs_exist() -> None:
    """The parametrised test above is not vacuous."""
    assert len(PROGRAMS) >= 10


@pytest.mark.parametrize("path", corpus_awl_params())
def test_corpus_files_accepted_and_identical(path: Path) -> None:
    """Every real export of the corpus is accepted, with lark's program
    (CRLF, tab-only lines, CJK names, titles on Network lines...)."""
    text = read_source(path)
    fast = fast_parse(text, path.name)
    assert fast is not None, "the fast path declined a corpus file"
    assert fast == parse_program_lark(text, path.name)


# --------------------------------------------------------------------------
# Inline programs of the test suite
# --------------------------------------------------------------------------

def _inline_programs() -> list[str]:
    """String constants of the test modules that look like STL programs
    (valid ones and the deliberately broken ones of the error tests)."""
    found: set[str] = set()
    for path in sorted((ROOT / "tests").rglob("*.py")):
        try:
            tree = ast.parse(path.read_text(encoding="utf-8"))
        except (SyntaxError, UnicodeDecodeError):
            continue
        for node in ast.walk(tree):
            if (isinstance(node, ast.Constant) and isinstance(node.value, str)
                    and "BEGIN" in node.value and "\n" in node.value):
                found.add(node.value)
    return sorted(found)


INLINE = _inline_programs()


def test_inline_programs_decline_or_agree() -> None:
    """No inline program of the suite is read differently by the fast path,
    and nearly all that lark reads without error are accepted (today all;
    a few odd spellings may rightly be declined)."""
    accepted = sum(assert_declines_or_agrees(text) is not None for text in INLINE)
    valid = sum(not isinstance(lark_or_error(text), PlcSyntaxError) for text in INLINE)
    assert len(INLINE) >= 50 and valid >= 30
    assert accepted >= 0.9 * valid


# --------------------------------------------------------------------------
# Hand-picked cases: what is accepted, what is declined
# --------------------------------------------------------------------------

OB = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\n{}\nEND_ORGANIZATION_BLOCK\n"

ACCEPTED = [
    OB.format("LD I0.0\n= Q0.0"),
    OB.format("=Q0.0"),                        # mnemonic "=Q0", operand ".0"
    OB.format("LD#x"),                         # no blank before the operand
    OB.format("MOVB 'it''s', VB0 ; // c"),
    OB.format('SSCPY "a,b // c", VB0'),
    OB.format("/D VD0, VD4//x"),
    OB.format("LD\u3000I0.0\xa0//\u3000c"),
    OB.format("LD I0.0;"),
    OB.format("TITLE=\nTITLE = second\n// first comment\nLD I0.0\n// dropped"),
    "\ufeff" + OB.format("LD I0.0").replace("\n", "\r\n"),
    OB.format("LD I0.0").replace("\n", "\r"),
    "// file comment\n\n \t\nSUBROUTINE_BLOCK 系统初始化 : sbr03\nTITLE=t\n// a\n"
    "VAR_INPUT\nStart:bool; // s\n// x\nEND_VAR\nVAR\nEND_VAR1:DWORD\nEND_VAR\n"
    "BEGIN\n// b\nNetwork1//title\nTITLE=ignored\nLD #Start\nEND_SUBROUTINE_BLOCK\n",
    "interrupt_block INT5\nbegin\nend_interrupt_block\n",
    # letters that /i matching folds onto ASCII, where lark's keyword
    # patterns (mirrored exactly) read them, and in operands and comments
    "ORGANIZAT\u0131ON_BLOCK MAIN:OB1\nT\u0131TLE=x\nVAR_\u0131NPUT\nEND_VAR\nBEGIN\n"
    "Network 1 // Kap\u0131 a\u00e7\u0131k\nLD Kap\u0131, \u017f\u212a\nEND_ORGANIZATION_BLOCK\n",
    # whitespace lark does not ignore, inside comments, titles and strings
    OB.format("// a\x85b \u2028\nTITLE=\u2000t\x1c\nLD 'a\x85b' //\x85c\x85"),
    "",
    "   \n",
]

DECLINED = [
    # errors: lark reports them
    OB.format("LD 'open"),
    OB.format("LD a b"),
    OB.format("LD , a"),
    "ORGANIZATION_BLOCK MAIN:SBR1\nBEGIN\nEND_ORGANIZATION_BLOCK\n",
    "ORGANIZATION_BLOCK OB" + "9" * 200 + "\nBEGIN\nEND_ORGANIZATION_BLOCK\n",
    OB.format("Network " + "1" * 200),
    "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n",
    "SUBROUTINE_BLOCK S:SBR0\nBEGIN\nEND_ORGANIZATION_BLOCK\n",
    OB.format("(* a comment *)"),
    "ORGANIZATION_BLOCK BEGIN:OB1\nBEGIN\nEND_ORGANIZATION_BLOCK\n",
    "ORGANIZATION_BLOCK MAIN:OB1\nVAR\nx:BEGIN;\nEND_VAR\nBEGIN\nEND_ORGANIZATION_BLOCK\n",
    OB.format("END_VAR"),
    OB.format("LD I0.0\x1c"),                  # whitespace lark does not ignore
    OB.format("LD I0.0\n\x85\n"),              # a "blank" line lark rejects
    "ORGANIZATION_BLOCK OB1\nVAR_\u0130NPUT\nEND_VAR\nBEGIN\nEND_ORGANIZATION_BLOCK\n",
    # valid for lark, but outside what the fast path is sure of
    OB.format("NETWORKS x"),                   # a mnemonic spelled like a keyword
    OB.format("T\u0131TLE=x"),                  # lark: a title; ASCII: "T" "ıTLE=x"
]


@pytest.mark.parametrize("text", ACCEPTED, ids=range(len(ACCEPTED)))
def test_accepted_forms_match_lark(text: str) -> None:
    """Export quirks and odd but valid spellings are accepted with lark's program."""
    fast = fast_parse(text, "t.awl")
    assert fast is not None
    assert fast == parse_program_lark(text, "t.awl")


@pytest.mark.parametrize("text", DECLINED, ids=range(len(DECLINED)))
def test_unsure_texts_are_declined(text: str) -> None:
    """Broken texts, and valid ones outside the fast path's subset, go to lark."""
    assert fast_parse(text, "t.awl") is None


def test_parse_program_still_reports_lark_errors() -> None:
    """A declined broken text gets lark's error, located as before."""
    with pytest.raises(PlcSyntaxError) as info:
        parse_program(OB.format("LD 'open"), "bad.awl")
    assert "unterminated string" in info.value.message
    assert (info.value.loc.line, info.value.loc.column) == (4, 4)


# --------------------------------------------------------------------------
# Generated programs
# --------------------------------------------------------------------------

# blanks the grammar ignores; a "sep" is a blank that must be there
_BLANK = st.sampled_from(["", " ", "  ", "\t", " \t ", "\u3000", "\xa0", "\f"])
_SEP = st.sampled_from([" ", "    ", "\t", "\t\t", " \u3000", "\v"])
# any text but line ends, with a good share of whitespace, quotes, slashes
# and the letters case-insensitive matching folds onto ASCII
_COMMENT_TEXT = st.text(
    alphabet=st.characters(blacklist_categories=("Cs",), blacklist_characters="\n\r")
    | st.sampled_from([" ", "\t", "\u3000", "\xa0", "\x85", "\u2028", "'", '"', "/",
                       ";", ",", "\u0131", "\u0130", "\u017f", "\u212a"]),
    max_size=12)
_MNEMONICS = ["LD", "ld", "A", "AN", "=", "S", "R", "MOVW", "movb", "+I", "/D", "*R",
              "LDW>=", "AB<", "FND=", "CALL", "TON", "NOT", "ALD", "SCRE", "LDS", "EU"]
_OPERANDS = ["I0.0", "q0.1", "VW100", "+10", "-1.0", "16#FF", "2#1010_0101", "&VB0",
             "*VD200", "*AC1", "#Start", "电机启动", "Always_On", "a/b", "T37", "Kapı_Açık",
             "'A'", "'it''s'", "''", '"a,b // c"', '""""', "'//'"]


def _case(word: str, data: st.DataObject) -> str:
    style = data.draw(st.sampled_from(["keep", "upper", "lower", "title"]))
    return {"keep": word, "upper": word.upper(), "lower": word.lower(),
            "title": word.title()}[style]


@st.composite
def programs(draw: st.DrawFn) -> str:
    """A well-formed export: 1-3 blocks with titles, comments, VAR sections
    and networks, in random case, blanks and line ends."""
    data = draw(st.data())

    def blank() -> str:
        return draw(_BLANK)

    def sep() -> str:
        return draw(_SEP)

    def comment() -> str:
        return blank() + "//" + draw(_COMMENT_TEXT)

    def title() -> str:
        between = draw(st.sampled_from(["", " ", "\t"]))
        return f"{blank()}{_case('TITLE', data)}{between}={draw(_COMMENT_TEXT)}"

    def var_section() -> list[str]:
        keyword = draw(st.sampled_from(
            ["VAR", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR_TEMP"]))
        lines = [blank() + _case(keyword, data) + blank()]
        for _ in range(draw(st.integers(0, 3))):
            if draw(st.booleans()):
                name = draw(st.sampled_from(["Start", "x", "计数", "END_VAR1", "v_2"]))
                type_ = _case(draw(st.sampled_from(["BOOL", "INT", "DWORD", "REAL"])), data)
                semi = draw(st.sampled_from(["", ";"]))
                tail = draw(st.sampled_from(["", comment()]))
                lines.append(f"{blank()}{name}{blank()}:{blank()}{type_}{blank()}{semi}{tail}")
            else:
                lines.append(draw(st.sampled_from(["", comment()])))
        lines.append(blank() + _case("END_VAR", data) + blank())
        return lines

    def instruction() -> str:
        operands = draw(st.lists(st.sampled_from(_OPERANDS), max_size=4))
        text = sep() + f"{blank()},{blank()}".join(operands) if operands else ""
        semi = draw(st.sampled_from(["", ";", " ;"]))
        tail = draw(st.sampled_from(["", comment()]))
        return f"{blank()}{draw(st.sampled_from(_MNEMONICS))}{text}{blank()}{semi}{tail}"

    def network(number: int) -> list[str]:
        spacing = draw(st.sampled_from([" ", "", "\t"]))
        net_title = draw(st.sampled_from(["", comment()]))
        lines = [f"{blank()}{_case('Network', data)}{spacing}{number}{blank()}{net_title}"]
        for _ in range(draw(st.integers(0, 5))):
            choice = draw(st.integers(0, 9))
            if choice == 0:
                lines.append(comment())
            elif choice == 1:
                lines.append(draw(st.sampled_from(["", "\t", "  "])))
            elif choice == 2:
                lines.append(title())
            else:
                lines.append(instruction())
        return lines

    lines: list[str] = []
    for _ in range(draw(st.integers(0, 2))):
        lines.append(draw(st.sampled_from(["", blank(), comment()])))
    for _ in range(draw(st.integers(1, 3))):
        kind, keyword = draw(st.sampled_from([
            ("OB", "ORGANIZATION_BLOCK"), ("SBR", "SUBROUTINE_BLOCK"),
            ("INT", "INTERRUPT_BLOCK")]))
        ident = _case(kind, data) + draw(st.sampled_from(["0", "1", "07", "12"]))
        name = draw(st.sampled_from(["", "MAIN", "SBR_0", "系统初始化", "x1"]))
        ref = f"{name}{blank()}:{blank()}{ident}" if name else ident
        lines.append(f"{blank()}{_case(keyword, data)}{sep()}{ref}{blank()}")
        for _ in range(draw(st.integers(0, 3))):
            lines.extend(draw(st.sampled_from([
                lambda: [title()], lambda: [comment()], var_section]))())
        lines.append(blank() + _case("BEGIN", data) + blank())
        for _ in range(draw(st.integers(0, 2))):
            lines.append(comment())
        for number in range(draw(st.integers(0, 3))):
            lines.extend(network(number + 1))
        lines.append(blank() + "END_" + _case(keyword, data) + blank())
        if draw(st.booleans()):
            lines.append("")
    newline = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    text = newline.join(lines) + draw(st.sampled_from(["", newline]))
    if draw(st.booleans()):
        text = "\ufeff" + text
    return text


@settings(max_examples=EXAMPLES, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(programs())
def test_generated_programs_accepted_and_identical(text: str) -> None:
    """Generated well-formed programs (any case, blanks, tabs, CRLF, titles,
    quoted strings, local variables, comments) are accepted with lark's program."""
    fast = fast_parse(text, "gen.awl")
    reference = parse_program_lark(text, "gen.awl")
    assert fast is not None
    assert fast == reference


_NOISE = list("'\"/,;:= \t\n\r*()#&.09AZaz_") + ["\u3000", "\xa0", "\x85", "\u0131", "//"]


@st.composite
def damaged(draw: st.DrawFn) -> str:
    """A sample, corpus-like or generated program with a few characters
    deleted, inserted or replaced."""
    source = draw(st.one_of(
        st.sampled_from([read_source(p) for p in PROGRAMS[:6]] + ACCEPTED[:12]),
        programs()))
    text = source
    for _ in range(draw(st.integers(1, 4))):
        pos = draw(st.integers(0, len(text)))
        action = draw(st.sampled_from(["delete", "insert", "replace"]))
        noise = draw(st.sampled_from(_NOISE))
        if action == "delete":
            text = text[:pos] + text[pos + 1:]
        elif action == "insert":
            text = text[:pos] + noise + text[pos:]
        else:
            text = text[:pos] + noise + text[pos + 1:]
    return text


@settings(max_examples=EXAMPLES * 2, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(damaged())
def test_damaged_texts_declined_or_identical(text: str) -> None:
    """A damaged text is either declined or read exactly as lark reads it;
    the fast path never accepts what lark rejects."""
    assert_declines_or_agrees(text, "damaged.awl")


# --------------------------------------------------------------------------
# Operand locations: the instruction's location and a column
# --------------------------------------------------------------------------

def test_an_operand_keeps_its_instructions_location_and_its_own_column() -> None:
    from plcrt.errors import SourceLoc
    from plcrt.lang.ir import Operand
    text = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 3\nLD     SM0.0\n"
            "MOVW   VW16,  VW200 // copy\nEND_ORGANIZATION_BLOCK\n")
    for program in (fast_parse(text, "p.awl"), parse_program_lark(text, "p.awl")):
        assert program is not None
        movw = program.pous[0].networks[0].insns[1]
        first, second = movw.operands
        # no location object per operand: both share the instruction's
        assert first.at is movw.loc and second.at is movw.loc
        assert first.loc == SourceLoc("p.awl", 5, 8, "OB1", 3)
        assert second.loc == SourceLoc("p.awl", 5, 15, "OB1", 3)
        assert repr(second) == f"Operand(text='VW200', loc={second.loc!r})"
    assert fast_parse(text, "p.awl") == parse_program_lark(text, "p.awl")


def test_an_operand_made_from_a_location_has_that_location() -> None:
    from plcrt.errors import SourceLoc
    from plcrt.lang.ir import Operand
    loc = SourceLoc("q.awl", 9, 12, "SBR2", 4)
    op = Operand("+7", loc)
    assert op.loc is loc and op.column == 0
    assert Operand("+7", loc, 12).loc == loc
    assert Operand("+7", loc, 20).loc == SourceLoc("q.awl", 9, 20, "SBR2", 4)
    assert op == Operand("+7", loc) and hash(op) == hash(Operand("+7", loc))
