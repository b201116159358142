"""Parse Micro/WIN STL export text into the :mod:`plcrt.lang.ir` program model.

This module turns the text of an ``.awl`` export (STEP 7-Micro/WIN V4 or
Micro/WIN SMART, in any of the dialects seen in real files) into an
:class:`~plcrt.lang.ir.Program`, and decodes such files from disk.  The
grammar lives in ``grammar/stl.lark``; lark builds the parse tree and this
module walks it into immutable IR nodes that all carry a
:class:`~plcrt.errors.SourceLoc`.  The words of the text that the fast path
reads too (keywords, block ids, VAR sections, line ends) are in
:mod:`plcrt.lang.stltext`; how a syntax error is worded is in
:mod:`plcrt.lang.stlerrors`.

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
from functools import cache
from importlib import resources
from pathlib import Path

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from ..errors import DiagnosticSink, PlcSyntaxError, SourceLoc
from ..safetext import excerpt
from .encoding import read_decoded
from .fastparse import fast_parse
from .ir import Insn, Network, Operand, Pou, PouKind, Program, VarDecl
from .limits import too_many_digits
from .stlerrors import describe, raise_collected
from .stltext import BLOCK_ID, KEYWORD_TYPES, SECTION_OF, prepare

# raise_collected is re-exported: its home is plcrt.lang.stlerrors
__all__ = ["parse_program", "parse_program_lark", "raise_collected", "read_source"]

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


# perf: the bound lookup once; the callback runs for every mnemonic and name
# token, and a method called on an imported name is not compiled as a
# method call (CPython 3.11 builds a bound method each time)
_keyword_type = KEYWORD_TYPES.get


def _retype_keyword(token: Token) -> Token:
    """A MNEMONIC or NAME token spelled like a structural keyword becomes
    that keyword's token (``stltext.KEYWORD_TYPES`` says why)."""
    kind = _keyword_type(token.value.upper())
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
    program = fast_parse(text, file)
    if program is not None:
        return program
    return parse_program_lark(text, file)


def parse_program_lark(text: str, file: str = "<string>") -> Program:
    """:func:`parse_program` through lark only: the reference the fast path
    is tested against, and the path that reports syntax errors."""
    prepared = prepare(text)
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
            loc, message = describe(exc, "\n".join(work), file, lines)
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
# Tree -> IR
# --------------------------------------------------------------------------

_KIND_OF_RULE: dict[str, PouKind] = {
    "ob_block": "OB", "sbr_block": "SBR", "int_block": "INT"}
_KEYWORD_OF_KIND = {"OB": "ORGANIZATION_BLOCK", "SBR": "SUBROUTINE_BLOCK",
                    "INT": "INTERRUPT_BLOCK"}


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
        match = BLOCK_ID.fullmatch(str(id_token))
        if match is not None and too_many_digits(match.group(2)):
            self.sink.error(f"block number of {excerpt(str(id_token))!r} is out of range",
                            self.loc(id_token), code="syntax")
            match = BLOCK_ID.fullmatch(f"{match.group(1)}0")
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
        section = SECTION_OF.get(str(head).upper())
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
