"""A line-based fast path for well-formed STL export text.

:func:`fast_parse` reads the common shape of a Micro/WIN export line by line
with compiled regular expressions (no loop over characters in Python) and
builds exactly the :class:`~plcrt.lang.ir.Program` that the lark path of
:mod:`plcrt.lang.stl` builds for the same text: equal by ``==``, including
every :class:`~plcrt.errors.SourceLoc` line and column, titles, comments and
operand texts.  It exists because lark's LALR parser costs several times more
than the rest of loading for large programs.

What it is not:

* not a second grammar.  ``grammar/stl.lark`` stays the definition of the
  language; every regular expression here mirrors one terminal of it and is
  used in the same order of priority as lark's contextual lexer uses them.
* not an error reporter.  Whenever a text is not plainly well formed (a
  syntax error, a block id that does not fit, a number with too many
  digits, a name or mnemonic spelled like a structural keyword, a blank
  line holding whitespace lark does not ignore, a keyword of a block body
  spelled with a letter that case-insensitive matching folds onto ASCII)
  it returns ``None`` and the caller runs the lark path, which reports the
  problem exactly as before.  Declining is always allowed;
  accepting with a different result never is, and the differential tests in
  ``tests/lang/test_fastparse.py`` hold it to that.

It declines per file: one line it is unsure of sends the whole text to lark.
"""

from __future__ import annotations

import gc
import re

from ..errors import SourceLoc
from .ir import Insn, Network, Operand, Pou, PouKind, Program, VarDecl
from .limits import too_many_digits
from .stltext import BLOCK_ID, KEYWORD_TYPES, SECTION_OF, prepare

__all__ = ["fast_parse"]

# The grammar's WS terminal (what lark ignores between tokens and what a
# blank line may hold).  Other whitespace (NEL, U+2028, U+2000...) is an
# ordinary character to lark: text in comments, titles and strings, a
# lexing error elsewhere, and the regexes below treat it the same way.
_WS_CHARS = " \t\f\v\u3000\xa0"
_WS = r"[ \t\f\v\u3000\xa0]"

# The four non-ASCII letters that Python's case-insensitive matching folds
# onto ASCII ones (İ ı ſ K).  The line-level patterns below use lark's own
# /i keyword patterns, so they agree; only the ASCII MNEMONIC pattern, which
# decides whether an instruction line might be a keyword line, could not
# see "TıTLE=" as lark does.  A line of a block body is declined if one of
# lark's keywords of a block body matches at its first token with such a
# letter in it.
_FOLDED = re.compile("[\u0130\u0131\u017f\u212a]")
_BODY_KEYWORD = re.compile(
    r"NETWORK(?![A-Za-z_])|TITLE[ \t]*=|END_(?:ORGANIZATION|SUBROUTINE|INTERRUPT)_BLOCK(?!\w)",
    re.I)

# ---- the terminals of grammar/stl.lark, as whole-line patterns -------------

_COMMENT_LINE = re.compile(_WS + r"*//(.*)\Z")
_HEADER_LINE = re.compile(
    _WS + r"*(?:(ORGANIZATION_BLOCK)|(SUBROUTINE_BLOCK)|(INTERRUPT_BLOCK))(?!\w)"
    + _WS + r"*(\w+)(?:" + _WS + r"*:" + _WS + r"*(\w+))?" + _WS + r"*\Z", re.I)
_TITLE_LINE = re.compile(_WS + r"*TITLE[ \t]*=(.*)\Z", re.I)
_VAR_LINE = re.compile(
    _WS + r"*(VAR(?:_INPUT|_OUTPUT|_IN_OUT|_TEMP)?)(?!\w)" + _WS + r"*\Z", re.I)
_END_VAR_LINE = re.compile(_WS + r"*END_VAR(?!\w)" + _WS + r"*\Z", re.I)
_DECL_LINE = re.compile(
    _WS + r"*(\w+)" + _WS + r"*:" + _WS + r"*(\w+)" + _WS + r"*;?" + _WS
    + r"*(?://(.*))?\Z")
_BEGIN_LINE = re.compile(_WS + r"*BEGIN(?!\w)" + _WS + r"*\Z", re.I)
_NETWORK_LINE = re.compile(
    _WS + r"*(NETWORK)(?![A-Za-z_])" + _WS + r"*([0-9]+)" + _WS + r"*(?://(.*))?\Z",
    re.I)
_END_LINE = {
    "OB": re.compile(_WS + r"*END_ORGANIZATION_BLOCK(?!\w)" + _WS + r"*\Z", re.I),
    "SBR": re.compile(_WS + r"*END_SUBROUTINE_BLOCK(?!\w)" + _WS + r"*\Z", re.I),
    "INT": re.compile(_WS + r"*END_INTERRUPT_BLOCK(?!\w)" + _WS + r"*\Z", re.I),
}
_KINDS: tuple[PouKind, PouKind, PouKind] = ("OB", "SBR", "INT")

# An instruction line: the MNEMONIC terminal, then operands (STRING or
# OPERAND) separated by commas, an optional ";" and an optional comment.
_MNEMONIC = re.compile(
    _WS + r"*((?:[A-Za-z=<>+\-*]|/(?!/))(?:[A-Za-z0-9_=<>+\-*]|/(?!/))*)")
_OPERAND = re.compile(
    _WS + r"""*('(?:[^'\n]|'')*'|"(?:[^"\n]|"")*"|(?:[^\s,;'"/]|/(?!/))+)""")
_COMMA = re.compile(_WS + r"*,")
_TAIL = re.compile(_WS + r"*;?" + _WS + r"*(?://(.*))?\Z")

# A MNEMONIC token spelled like one of these is either a structural line
# (TITLE=, Network n, END_...) or something lark re-types or rejects; all of
# them leave the instruction path.  MNEMONIC's character class holds every
# letter of the keywords, so a keyword at the start of a line always shows
# up as a prefix of the MNEMONIC match.
_STRUCTURAL = ("NETWORK", "TITLE", "END_", "BEGIN", "VAR", "ORGANIZATION_BLOCK",
               "SUBROUTINE_BLOCK", "INTERRUPT_BLOCK")


def fast_parse(text: str, file: str = "<string>") -> Program | None:
    """Return the :class:`Program` of ``text``, or ``None`` if unsure.

    The result, when there is one, equals what the lark path of
    :func:`plcrt.lang.stl.parse_program` returns for the same arguments.
    ``None`` means "let lark parse it": the text may well be valid.
    """
    # perf: the parse allocates a handful of objects per statement and no
    # reference cycles, yet the cyclic collector's full passes over the
    # growing heap made the time per statement grow with the program
    # (measured: about twice the time for 20k and 100k statements as with
    # the collector paused, the same for 1k).  The collector is paused for
    # the parse only; nothing it would free is made, and it runs as usual
    # afterwards.
    enabled = gc.isenabled()
    gc.disable()
    try:
        return _parse(text, file)
    finally:
        if enabled:
            gc.enable()


def _folded_lines(text: str) -> set[int]:
    """The numbers of the lines holding a folded letter."""
    lines: set[int] = set()
    line, last = 1, 0
    for match in _FOLDED.finditer(text):
        pos = match.start()
        line += text.count("\n", last, pos)
        last = pos
        lines.add(line)
    return lines


def _parse(text: str, file: str) -> Program | None:
    prepared = prepare(text)
    # perf: one scan in C; almost every text has no folded letter at all
    folded = _folded_lines(prepared) if _FOLDED.search(prepared) else set()
    lines = prepared.split("\n")
    count = len(lines)
    pous: list[Pou] = []
    # one string object per distinct mnemonic spelling and operand text: a
    # program names the same few hundred addresses over and over, and the
    # IR of every statement is kept as long as the program is loaded
    shared: dict[str, str] = {}
    index = 0
    while index < count:
        line = lines[index]
        index += 1
        # perf: isspace() first; a blank line of the grammar holds WS only
        if not line or line.isspace():
            if line.strip(_WS_CHARS):
                return None
            continue
        header = _HEADER_LINE.match(line)
        if header is None:
            if _COMMENT_LINE.match(line):
                continue            # file-level comments are dropped
            return None
        block = _block(lines, index, header, file, folded, shared)
        if block is None:
            return None
        pou, index = block
        pous.append(pou)
    return Program(pous=tuple(pous), file=file, source=text)


def _next_line(lines: list[str], index: int) -> tuple[str, int] | None:
    """The first line from ``lines[index]`` on that is not blank, and the
    index after it; None at the end of the text, or at a blank-looking line
    holding whitespace that lark does not ignore (the caller declines)."""
    count = len(lines)
    while index < count:
        line = lines[index]
        index += 1
        # perf: isspace() first; a blank line of the grammar holds WS only
        if line and not line.isspace():
            return line, index
        if line.strip(_WS_CHARS):
            return None
    return None


def _block(lines: list[str], index: int, header: re.Match[str], file: str,
           folded: set[int], shared: dict[str, str]) -> tuple[Pou, int] | None:
    """Read one block whose header line is ``lines[index - 1]``; return the
    :class:`Pou` and the index of the line after its END line.  ``shared``
    maps each mnemonic as written and each operand text to the one string
    object every statement of the text uses for it."""
    kind_group = 1 if header.group(1) else 2 if header.group(2) else 3
    kind = _KINDS[kind_group - 1]
    first, second = header.group(4), header.group(5)
    for word in (first, second):
        if word is not None and word.upper() in KEYWORD_TYPES:
            return None             # lark re-types it and rejects the header
    id_text = second if second is not None else first
    match = BLOCK_ID.fullmatch(id_text)
    if (match is None or too_many_digits(match.group(2))
            or match.group(1).upper() != kind):
        return None                 # lark's builder reports these
    number = int(match.group(2))
    ident = f"{kind}{number}"
    name = first if second is not None else ident
    loc = SourceLoc(file, index, header.start(kind_group) + 1, ident, None)

    count = len(lines)
    title: str | None = None
    comments: list[str] = []
    variables: list[VarDecl] = []
    # ---- between the header and BEGIN
    while True:
        got = _next_line(lines, index)
        if got is None:
            return None
        line, index = got
        if m := _COMMENT_LINE.match(line):
            comments.append(m.group(1).strip())
        elif m := _TITLE_LINE.match(line):
            # the first TITLE= is the block title, later ones are comment
            if title is None:
                title = m.group(1).strip()
            else:
                comments.append(m.group(1).strip())
        elif m := _VAR_LINE.match(line):
            section = SECTION_OF.get(m.group(1).upper())
            if section is None:
                return None         # "VAR_İNPUT": matched by /i, no such section
            while True:
                got = _next_line(lines, index)
                if got is None:
                    return None
                line, index = got
                if _END_VAR_LINE.match(line):
                    break
                if _COMMENT_LINE.match(line):
                    continue        # comment lines in a VAR section are dropped
                d = _DECL_LINE.match(line)
                if d is None:
                    return None
                var_name, var_type = d.group(1), d.group(2)
                if (var_name.upper() in KEYWORD_TYPES
                        or var_type.upper() in KEYWORD_TYPES):
                    return None
                comment = d.group(3)
                variables.append(VarDecl(
                    section=section, name=var_name, type=var_type.upper(),
                    loc=SourceLoc(file, index, d.start(1) + 1, ident, None),
                    comment=comment.strip() if comment is not None else ""))
        elif _BEGIN_LINE.match(line):
            break
        else:
            return None

    # ---- BEGIN to END_...: comment lines, then networks
    end_line = _END_LINE[kind]
    networks: list[Network] = []
    insns: list[Insn] = []
    net_comments: list[str] = []
    net_title = ""
    net_number = -1                 # -1: no Network line yet
    net_loc: SourceLoc | None = None
    # perf: bound names for the loop that runs once per instruction line
    mnemonic_match = _MNEMONIC.match
    operand_match = _OPERAND.match
    comma_match = _COMMA.match
    tail_match = _TAIL.match
    append_insn = insns.append
    share = shared.setdefault
    upper: dict[str, str] = {}      # mnemonic as written -> its shared upper case
    while True:
        # perf: _next_line inline here, the loop that runs once per statement
        if index >= count:
            return None             # missing END_...
        line = lines[index]
        index += 1
        if not line or line.isspace():
            if line.strip(_WS_CHARS):
                return None
            continue
        m = mnemonic_match(line)
        if m is None:
            c = _COMMENT_LINE.match(line)
            if c is None:
                return None
            if net_number < 0:
                comments.append(c.group(1).strip())     # block comment
            elif not insns:
                net_comments.append(c.group(1).strip())  # network comment
            # comments between instructions are dropped, as by lark's path
            continue
        if (folded and index in folded
                and (k := _BODY_KEYWORD.match(line, m.start(1)))
                and _FOLDED.search(line, k.start(), k.end())):
            return None             # "TıTLE=": a keyword to lark, not to MNEMONIC
        raw = m.group(1)
        mnemonic = upper.get(raw)
        if mnemonic is None:
            mnemonic = upper[raw] = share(raw.upper(), raw.upper())
        if mnemonic.startswith(_STRUCTURAL):
            if net_number >= 0 and (t := _TITLE_LINE.match(line)):
                if not net_title:
                    net_title = t.group(1).strip()
                continue
            new = _NETWORK_LINE.match(line)
            if new is None and not end_line.match(line):
                return None
            if net_loc is not None:
                networks.append(Network(
                    number=net_number, title=net_title, insns=tuple(insns),
                    loc=net_loc, comment="\n".join(net_comments)))
            if new is None:          # the END line of this block
                break
            digits = new.group(2)
            if too_many_digits(digits):
                return None
            net_number = int(digits)
            net_loc = SourceLoc(file, index, new.start(1) + 1, ident, net_number)
            title_comment = new.group(3)
            net_title = title_comment.strip() if title_comment is not None else ""
            net_comments = []
            insns.clear()
            continue
        if net_number < 0:
            return None             # an instruction before the first Network
        # perf: one location per statement; its operands share it and keep
        # their own column (ir.Operand)
        insn_loc = SourceLoc(file, index, m.start(1) + 1, ident, net_number)
        operands: list[Operand] = []
        o = operand_match(line, m.end())
        if o is not None:
            while True:
                text = o.group(1)
                operands.append(Operand(share(text, text), insn_loc, o.start(1) + 1))
                pos = o.end()
                c = comma_match(line, pos)
                if c is None:
                    break
                o = operand_match(line, c.end())
                if o is None:
                    return None
        else:
            pos = m.end()
        tail = tail_match(line, pos)
        if tail is None:
            return None
        comment = tail.group(1)
        # perf: positional arguments; the dataclass __init__ is the largest
        # cost per statement (Insn(mnemonic, operands, loc, comment))
        append_insn(Insn(
            mnemonic, tuple(operands), insn_loc,
            comment.strip() if comment is not None else ""))

    pou = Pou(kind=kind, number=number, name=name, title=title or "",
              variables=tuple(variables), networks=tuple(networks), loc=loc,
              comment="\n".join(comments))
    return pou, index
