"""Parse Micro/WIN STL export text into the :mod:`plcrt.lang.ir` program model.

This module turns the text of an ``.awl`` export (STEP 7-Micro/WIN V4 or
Micro/WIN SMART, in any of the dialects seen in real files) into an
:class:`~plcrt.lang.ir.Program`, and decodes such files from disk.  The
grammar lives in ``grammar/stl.lark``; lark builds the parse tree and this
module walks it into immutable IR nodes that all carry a
:class:`~plcrt.errors.SourceLoc`.

It is *not* a checker: mnemonics and operands are kept as written, and
whether ``LDX`` exists or ``MOVW`` got a word operand is the compiler's
business.  The only things rejected here are texts whose structure cannot be
read (a missing ``END_SUBROUTINE_BLOCK``, a stray line between blocks, an
unterminated string, a block id that is not ``OBn``/``SBRn``/``INTn``).
Every such problem is raised as :class:`~plcrt.errors.PlcSyntaxError`; no
lark exception ever leaves this module.

:func:`parse_program` first tries the line-based fast path of
:mod:`plcrt.lang.fastparse`, which builds the same program for the
well-formed texts it accepts; lark reads everything else and is the only
source of syntax errors.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from functools import cache
from importlib import resources
from pathlib import Path

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from ..errors import DiagnosticSink, PlcSyntaxError, SourceLoc
from ..safetext import EXCERPT_CHARS, excerpt
from .encoding import read_decoded
from .limits import MAX_DIGITS, too_many_digits
from .ir import Insn, Network, Operand, Pou, PouKind, Program, VarDecl, VarSection

__all__ = ["parse_program", "read_source"]

# Stop collecting after this many syntax errors: past that point the user is
# better served by fixing the first ones than by reading a long list.
_MAX_SYNTAX_ERRORS = 20


# --------------------------------------------------------------------------
# Reading files
# --------------------------------------------------------------------------

def read_source(path: str | Path, encoding: str | None = None,
                max_bytes: int | None = None) -> str:
    """Read a program, symbol or data-block file and return its text.

    Micro/WIN writes exports in the Windows code page of the PC that made
    them; :mod:`plcrt.lang.encoding` decides which (``encoding`` overrides
    the detection).  At most ``max_bytes`` are read (default: the limit of
    :mod:`plcrt.lang.limits`), and only from a regular file.  Raises
    :class:`PlcSyntaxError` naming the file if it cannot be read or
    decoded, :class:`PlcConfigError` for an unknown ``encoding``.
    """
    return read_decoded(path, encoding, max_bytes).text


# --------------------------------------------------------------------------
# The parser
# --------------------------------------------------------------------------

@cache
def _parser() -> Lark:
    """Build the lark parser once per process (lazily, on first use).

    ``cache=True`` lets lark store the analysed grammar in the temp directory,
    which cuts the build from hundreds of milliseconds to a few for every
    later process (lark falls back silently if the directory is unusable).
    """
    grammar = (resources.files(__package__) / "grammar" / "stl.lark").read_text(
        encoding="utf-8")
    return Lark(grammar, parser="lalr", lexer="contextual",
                propagate_positions=True, maybe_placeholders=False, cache=True,
                lexer_callbacks={"MNEMONIC": _retype_keyword,
                                 "NAME": _retype_keyword})


# Structural keywords that the generic MNEMONIC / NAME regexes also match.
# The contextual lexer only tries terminals the parser can accept, so inside
# a network "SUBROUTINE_BLOCK" would lex as a mnemonic and a missing
# END_ORGANIZATION_BLOCK would surface only much later.  Re-typing such a
# token makes the parser reject it on the spot with a precise message.
_KEYWORD_TYPES = {
    "ORGANIZATION_BLOCK": "OB_KW",
    "SUBROUTINE_BLOCK": "SBR_KW",
    "INTERRUPT_BLOCK": "INT_KW",
    "END_ORGANIZATION_BLOCK": "END_OB",
    "END_SUBROUTINE_BLOCK": "END_SBR",
    "END_INTERRUPT_BLOCK": "END_INT",
    "BEGIN": "BEGIN",
    "END_VAR": "END_VAR",
}


def _retype_keyword(token: Token) -> Token:
    kind = _KEYWORD_TYPES.get(token.value.upper())
    if kind is None:
        return token
    return Token.new_borrow_pos(kind, token.value, token)


def parse_program(text: str, file: str = "<string>") -> Program:
    """Parse the text of an STL export and return its :class:`Program`.

    ``file`` is used only for source locations.  Raises
    :class:`PlcSyntaxError` with every syntax problem found (see
    :func:`_parse_collecting`); its ``partial`` is the program of the blocks
    that parsed without an error, for tools that show what they can.

    A well-formed text is read by the line-based fast path of
    :mod:`plcrt.lang.fastparse`, which gives the same program; anything it
    is not sure of goes to lark (:func:`parse_program_lark`).
    """
    # imported here: fastparse builds on this module's tables
    from .fastparse import fast_parse

    program = fast_parse(text, file)
    if program is not None:
        return program
    return parse_program_lark(text, file)


def parse_program_lark(text: str, file: str = "<string>") -> Program:
    """:func:`parse_program` through lark only: the reference the fast path
    is tested against, and the path that reports syntax errors."""
    prepared = _prepare(text)
    sink = DiagnosticSink()
    tree, broken = _parse_collecting(prepared, file, sink)
    pous: list[Pou] = []
    if tree is not None:
        pous = _Builder(file, sink).program(tree)
    if sink.errors:
        good = tuple(p for p in pous if p.loc.line not in broken)
        try:
            raise_collected(sink)
        except PlcSyntaxError as e:
            e.partial = Program(pous=good, file=file, source=text)
            raise
    return Program(pous=tuple(pous), file=file, source=text)


def raise_collected(sink: DiagnosticSink) -> None:
    """Raise one :class:`PlcSyntaxError` for all errors in ``sink``, if any.

    Unlike ``DiagnosticSink.raise_if_errors`` the exception's ``message`` and
    ``loc`` are those of the first error, so a caller that shows only one line
    still shows something useful; ``str()`` lists every diagnostic.  Shared
    by the symbol-table and data-block readers.
    """
    errors = sink.errors
    if not errors:
        return
    first = errors[0]
    message = first.message
    if len(errors) > 1:
        message += f" (and {len(errors) - 1} more error(s))"
    raise PlcSyntaxError(message, first.loc, sink.items)


def _prepare(text: str) -> str:
    """Normalise line ends so that lark sees LF only, keeping line numbers.

    A lone CR counts as a line end (old Mac files); CRLF becomes one LF, so
    line numbers match what an editor shows.  A final newline is added because
    every grammar line ends in one.  A leading byte-order mark is dropped.
    """
    if text.startswith("\ufeff"):
        text = text[1:]
    if "\r" in text:
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    if not text.endswith("\n"):
        text += "\n"
    return text


_BLOCK_START = re.compile(
    r"[ \t]*(?:ORGANIZATION_BLOCK|SUBROUTINE_BLOCK|INTERRUPT_BLOCK)(?!\w)", re.I)


_BEGIN_LINE = re.compile(r"[ \t]*BEGIN(?!\w)", re.I)
_HEADER_LINE = re.compile(
    r"[ \t]*(?:(?:END_)?(?:ORGANIZATION|SUBROUTINE|INTERRUPT)_BLOCK|NETWORK(?![A-Za-z_])"
    r"|BEGIN(?!\w)|(?:END_)?VAR)", re.I)


def _parse_collecting(text: str, file: str,
                      sink: DiagnosticSink) -> tuple[Tree | None, set[int]]:
    """Parse ``text``, recording every syntax error; returns the tree of
    what remains readable and the header lines of the blocks with errors.

    Lark's LALR error recovery cannot tell where a broken line ends, and
    resuming mid-line produces a cascade of follow-on errors.  Instead a
    broken instruction line inside a block's networks is blanked and the
    parse goes on, so a user fixing a large export sees every broken line of
    a block in one run; an error anywhere else (a block header, a VAR
    section, a missing END_...) blanks the rest of that block.  Blanked
    lines stay as empty lines, so locations are those of the file.  A block
    that had an error is in the returned set (its tree lacks lines); the
    others are whole.
    """
    parser = _parser()
    lines = text.split("\n")
    work = list(lines)
    starts = [i + 1 for i, line in enumerate(lines) if _BLOCK_START.match(line)]
    broken: set[int] = set()
    while True:
        try:
            return parser.parse("\n".join(work)), broken
        except UnexpectedInput as exc:
            loc, message = _describe(exc, "\n".join(work), file, lines)
            sink.error(message, loc, code="syntax")
            if len(sink.errors) >= _MAX_SYNTAX_ERRORS:
                return None, broken
            line = loc.line
            at_header = (isinstance(exc, UnexpectedToken)
                         and exc.token.type in ("OB_KW", "SBR_KW", "INT_KW"))
            at_end = not isinstance(exc, (UnexpectedToken, UnexpectedCharacters)) or (
                isinstance(exc, UnexpectedToken) and exc.token.type == "$END")
            # the block the error is in: a header the parse stopped on ends
            # the block before it (whose END_... is missing)
            owner = [s for s in starts if (s < line if at_header else s <= line)]
            head = owner[-1] if owner else 1
            if owner:
                broken.add(head)
            if (owner and not at_header and not at_end and work[line - 1].strip()
                    and not _HEADER_LINE.match(work[line - 1])
                    and any(_BEGIN_LINE.match(x) for x in work[head:line - 1])):
                work[line - 1] = ""           # an instruction line: skip it
                continue
            # otherwise the block (or the text before the first block) goes
            nxt = [s for s in starts if s > head]
            end = (line - 1 if at_header else nxt[0] - 1) if nxt else len(work)
            if all(not x.strip() for x in work[head - 1:end]):
                return None, broken           # nothing left to blank: give up
            for i in range(head - 1, end):
                work[i] = ""
        except Exception as exc:  # noqa: BLE001 - a lark bug must not escape raw
            sink.error(f"internal parser error: {exc}", SourceLoc(file, 1, 1),
                       code="syntax")
            return None, broken


# --------------------------------------------------------------------------
# Error messages
# --------------------------------------------------------------------------

# How terminals are named in messages.
_TERMINAL_WORDS = {
    "OB_KW": "ORGANIZATION_BLOCK",
    "SBR_KW": "SUBROUTINE_BLOCK",
    "INT_KW": "INTERRUPT_BLOCK",
    "END_OB": "END_ORGANIZATION_BLOCK",
    "END_SBR": "END_SUBROUTINE_BLOCK",
    "END_INT": "END_INTERRUPT_BLOCK",
    "BEGIN": "BEGIN",
    "VAR_KW": "VAR section",
    "END_VAR": "END_VAR",
    "NETWORK": "Network",
    "TITLE": "TITLE=",
    "COMMENT": "comment",
    "MNEMONIC": "instruction",
    "OPERAND": "operand",
    "STRING": "operand",
    "NAME": "name",
    "NET_NUMBER": "network number",
    "COLON": "':'",
    "SEMICOLON": "';'",
    "COMMA": "','",
    "_NL": "end of line",
    "$END": "end of file",
}
_END_OF = {"END_OB": "ORGANIZATION_BLOCK", "END_SBR": "SUBROUTINE_BLOCK",
           "END_INT": "INTERRUPT_BLOCK"}


def _describe(exc: UnexpectedInput, text: str, file: str,
              lines: list[str]) -> tuple[SourceLoc, str]:
    """Turn a lark exception into a location and a short message."""
    expected: set[str]
    if isinstance(exc, UnexpectedToken):
        token = exc.token
        expected = set(exc.expected)
        if token.type == "$END":
            # lark places $END on the last token; point after the last
            # non-blank line instead, where the missing text belongs.
            line, column = _end_position(lines)
            found = "end of file"
        else:
            line, column = token.line or 1, token.column or 1
            found = _describe_found(token)
    elif isinstance(exc, UnexpectedCharacters):
        line, column = exc.line, exc.column
        expected = set(exc.allowed or ())
        pos = exc.pos_in_stream or 0
        char = text[pos] if pos < len(text) else ""
        if char in ("'", '"'):
            _, block, network = _open_block(lines, line)
            loc = SourceLoc(file, line, column, block, network if block else None)
            return loc, f"unterminated string literal (missing closing {char})"
        found = repr(excerpt(_word_at(text, pos)))
    else:  # UnexpectedEOF and future kinds
        line, column = _end_position(lines)
        expected = set(getattr(exc, "expected", ()) or ())
        found = "end of file"
    keyword, block, network = _open_block(lines, line)
    loc = SourceLoc(file, max(line, 1), max(column, 1), block,
                    network if block else None)
    ends = sorted(t for t in expected if t in _END_OF)
    if keyword is not None:
        # LALR merges the states of the three block kinds, so all three END
        # keywords may be "expected"; the open block says which one is meant.
        ends = [t for t in ends if _END_OF[t] == keyword] or ends
        expected = {t for t in expected
                    if t not in _END_OF or _END_OF[t] == keyword}
    if ends and isinstance(exc, UnexpectedToken) and exc.token.type in _END_OF:
        words = " or ".join(_TERMINAL_WORDS[t] for t in ends)
        return loc, f"{found} does not close this block; expected {words}"
    if ends and (found == "end of file" or isinstance(exc, UnexpectedToken)
                 and exc.token.type in ("OB_KW", "SBR_KW", "INT_KW")):
        words = " or ".join(_TERMINAL_WORDS[t] for t in ends)
        return loc, f"missing {words} before {found}"
    if expected & {"OB_KW", "SBR_KW", "INT_KW"}:
        # Between blocks a blank line is always fine; saying so is noise.
        expected.discard("_NL")
    return loc, f"unexpected {found}; expected {_expected_words(expected)}"


def _describe_found(token: Token) -> str:
    if token.type == "_NL":
        return "end of line"
    return repr(excerpt(str(token.value)))


def _word_at(text: str, pos: int) -> str:
    """The run of non-blank characters starting at ``pos`` (for messages)."""
    end = pos
    while end < len(text) and end - pos <= EXCERPT_CHARS and not text[end].isspace():
        end += 1
    return text[pos:end] if end > pos else text[pos:pos + 1]


def _expected_words(expected: Iterable[str]) -> str:
    words = sorted({_TERMINAL_WORDS.get(t, t) for t in expected})
    # A long list helps nobody; the line is usually clear from context.
    if not words:
        return "something else"
    if len(words) > 5:
        return ", ".join(words[:5]) + ", ..."
    if len(words) == 1:
        return words[0]
    return ", ".join(words[:-1]) + " or " + words[-1]


def _end_position(lines: list[str]) -> tuple[int, int]:
    for index in range(len(lines) - 1, -1, -1):
        if lines[index].strip():
            return index + 1, len(lines[index].rstrip()) + 1
    return 1, 1


_CTX_HEADER = re.compile(
    r"[ \t]*(ORGANIZATION_BLOCK|SUBROUTINE_BLOCK|INTERRUPT_BLOCK)[ \t]+"
    r"(?:[^:\s]*:)?[ \t]*(\w+)", re.I)
_CTX_END = re.compile(r"[ \t]*END_(?:ORGANIZATION|SUBROUTINE|INTERRUPT)_BLOCK", re.I)
_CTX_NETWORK = re.compile(r"[ \t]*NETWORK[ \t]*([0-9]{1,%d})(?![0-9])" % MAX_DIGITS, re.I)


def _open_block(lines: list[str], line: int) -> tuple[str | None, str | None, int | None]:
    """Return (header keyword, block id, network) open at ``line``.

    Only computed on the error path, by a plain scan of the lines before the
    error, because no parse tree exists for a broken text.  The error line
    itself counts only when it is a Network line: an error *on* a block header
    or END line belongs to the block that was open before it.
    """
    keyword: str | None = None
    block: str | None = None
    network: int | None = None
    for text in lines[:line - 1]:
        if m := _CTX_HEADER.match(text):
            keyword, block, network = m.group(1).upper(), m.group(2).upper(), None
        elif _CTX_END.match(text):
            keyword, block, network = None, None, None
        elif block is not None and (m := _CTX_NETWORK.match(text)):
            network = int(m.group(1))
    if block is not None and 0 < line <= len(lines):
        if m := _CTX_NETWORK.match(lines[line - 1]):
            network = int(m.group(1))
    return keyword, block, network


# --------------------------------------------------------------------------
# Tree -> IR
# --------------------------------------------------------------------------

_KIND_OF_RULE: dict[str, PouKind] = {
    "ob_block": "OB", "sbr_block": "SBR", "int_block": "INT"}
_KEYWORD_OF_KIND = {"OB": "ORGANIZATION_BLOCK", "SBR": "SUBROUTINE_BLOCK",
                    "INT": "INTERRUPT_BLOCK"}
_BLOCK_ID = re.compile(r"(OB|SBR|INT)([0-9]+)", re.I)
_SECTION_OF: dict[str, VarSection] = {
    "VAR_INPUT": "IN", "VAR_IN_OUT": "IN_OUT", "VAR_OUTPUT": "OUT",
    "VAR": "TEMP", "VAR_TEMP": "TEMP"}


def _comment_text(token: Token) -> str:
    """The text of a ``//`` comment without the slashes and outer blanks."""
    return str(token)[2:].strip()


def _title_text(token: Token) -> str:
    """The text after ``TITLE=``."""
    return str(token).split("=", 1)[1].strip()


class _Builder:
    """Walks the lark tree of one file and builds IR nodes.

    A hand-written walk rather than a lark ``Transformer``: the tree is
    shallow and mostly tokens, and a direct loop over ``children`` is both
    faster and easier to follow than one callback per rule.
    """

    def __init__(self, file: str, sink: DiagnosticSink) -> None:
        self.file = file
        self.sink = sink

    def loc(self, token: Token, block: str | None = None,
            network: int | None = None) -> SourceLoc:
        return SourceLoc(self.file, token.line or 1, token.column or 1,
                         block, network)

    def program(self, tree: Tree) -> list[Pou]:
        # File-level comment lines (before, between and after blocks) carry
        # no meaning and are dropped.
        return [self.pou(child) for child in tree.children
                if isinstance(child, Tree)]

    def pou(self, tree: Tree) -> Pou:
        kind = _KIND_OF_RULE[tree.data]
        keyword = tree.children[0]
        ref = tree.children[1]
        assert isinstance(keyword, Token) and isinstance(ref, Tree)
        name, ident, number = self.block_ref(kind, ref)
        loc = self.loc(keyword, ident)

        title: str | None = None
        comments: list[str] = []
        variables: list[VarDecl] = []
        networks: list[Network] = []
        for child in tree.children[2:]:
            if isinstance(child, Tree):
                if child.data == "var_section":
                    variables.extend(self.var_section(child, ident))
                else:
                    networks.append(self.network(child, ident))
            elif child.type == "TITLE":
                # The first TITLE= is the block title; a second one (seen in
                # hand-edited files) is kept as comment rather than lost.
                if title is None:
                    title = _title_text(child)
                else:
                    comments.append(_title_text(child))
            elif child.type == "COMMENT":
                comments.append(_comment_text(child))
        return Pou(kind=kind, number=number, name=name, title=title or "",
                   variables=tuple(variables), networks=tuple(networks),
                   loc=loc, comment="\n".join(comments))

    def block_ref(self, kind: PouKind, ref: Tree) -> tuple[str, str, int]:
        """Return (name, ident, number) of ``MAIN:OB1`` or ``OB1``."""
        tokens = [t for t in ref.children if isinstance(t, Token)]
        id_token = tokens[-1]
        match = _BLOCK_ID.fullmatch(str(id_token))
        if match is not None and too_many_digits(match.group(2)):
            self.sink.error(f"block number of {excerpt(str(id_token))!r} is out of range",
                            self.loc(id_token), code="syntax")
            match = _BLOCK_ID.fullmatch(f"{match.group(1)}0")
        if match is None:
            self.sink.error(
                f"block id {excerpt(str(id_token))!r} is not of the form "
                f"{kind}<number> expected after {_KEYWORD_OF_KIND[kind]}",
                self.loc(id_token), code="syntax")
            ident, number = str(id_token), 0
        else:
            written_kind = match.group(1).upper()
            number = int(match.group(2))
            ident = f"{written_kind}{number}"
            if written_kind != kind:
                self.sink.error(
                    f"block id {ident} does not fit {_KEYWORD_OF_KIND[kind]} "
                    f"(expected {kind}<number>)",
                    self.loc(id_token), code="syntax")
            ident = f"{kind}{number}"
        name = str(tokens[0]) if len(tokens) > 1 else ident
        return name, ident, number

    def var_section(self, tree: Tree, block: str) -> list[VarDecl]:
        head = tree.children[0]
        assert isinstance(head, Token)
        section = _SECTION_OF.get(str(head).upper())
        if section is None:
            # VAR_KW is matched case-insensitively, and Python folds "İ" onto
            # "I" there: "VAR_İNPUT" is a VAR_KW token that names no section
            self.sink.error(f"unknown variable section {excerpt(str(head))!r}",
                            self.loc(head, block), code="syntax")
            return []
        decls: list[VarDecl] = []
        for child in tree.children[1:]:
            if isinstance(child, Tree):
                tokens = [t for t in child.children if isinstance(t, Token)]
                name, type_ = tokens[0], tokens[1]
                comment = next((_comment_text(t) for t in tokens[2:]
                                if t.type == "COMMENT"), "")
                decls.append(VarDecl(section=section, name=str(name),
                                     type=str(type_).upper(),
                                     loc=self.loc(name, block), comment=comment))
        return decls

    def network(self, tree: Tree, block: str) -> Network:
        children = tree.children
        keyword, number_token = children[0], children[1]
        assert isinstance(keyword, Token) and isinstance(number_token, Token)
        if too_many_digits(str(number_token)):
            self.sink.error(f"network number {excerpt(str(number_token))!r} is out of range",
                            self.loc(number_token, block), code="syntax")
            number = 0
        else:
            number = int(number_token)
        title = ""
        comments: list[str] = []
        insns: list[Insn] = []
        rest = children[2:]
        # "Network 1 // title": a comment on the Network line itself.  _NL is
        # filtered from the tree, so the line number tells it apart from a
        # network comment on the next line.
        first = rest[0] if rest else None
        if (isinstance(first, Token) and first.type == "COMMENT"
                and first.line == keyword.line):
            title = _comment_text(first)
            rest = rest[1:]
        for child in rest:
            if isinstance(child, Tree):
                insns.append(self.insn(child, block, number))
            elif child.type == "TITLE":
                if not title:
                    title = _title_text(child)
            elif child.type == "COMMENT" and not insns:
                # Comment lines before the first instruction are the network
                # comment.  Comment lines between instructions annotate the
                # code only and are dropped (the IR has no place for them).
                comments.append(_comment_text(child))
        return Network(number=number, title=title, insns=tuple(insns),
                       loc=self.loc(keyword, block, number),
                       comment="\n".join(comments))

    def insn(self, tree: Tree, block: str, network: int) -> Insn:
        children = tree.children
        mnemonic = children[0]
        assert isinstance(mnemonic, Token)
        loc = self.loc(mnemonic, block, network)
        operands: list[Operand] = []
        comment = ""
        for child in children[1:]:
            assert isinstance(child, Token)
            if child.type == "COMMENT":
                comment = _comment_text(child)
            elif (child.line or 1) == loc.line:
                # the instruction's location and the operand's column, as
                # the fast parser gives it (ir.Operand)
                operands.append(Operand(str(child).strip(), loc, child.column or 1))
            else:
                operands.append(Operand(str(child).strip(), self.loc(child, block, network)))
        return Insn(mnemonic=str(mnemonic).upper(), operands=tuple(operands),
                    loc=loc, comment=comment)
