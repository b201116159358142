"""How the lark path of :mod:`plcrt.lang.stl` words its syntax errors.

:func:`describe` turns one lark exception into a location (file, line,
column, and the block and network open there) and a short message in the
words of the export ("missing END_SUBROUTINE_BLOCK before end of file",
"unexpected 'X'; expected instruction"); :func:`raise_collected` raises all
errors of a :class:`~plcrt.errors.DiagnosticSink` as one
:class:`~plcrt.errors.PlcSyntaxError`, for the program, symbol table and
data block readers alike.

It is *not* where errors are found: lark finds them, and
:mod:`plcrt.lang.stl` decides how the parse goes on after each.  Nothing
here runs unless a text has an error.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from lark import Token
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from ..errors import DiagnosticSink, PlcSyntaxError, SourceLoc
from ..safetext import EXCERPT_CHARS, excerpt
from .limits import MAX_DIGITS

__all__ = ["describe", "raise_collected"]


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


def describe(exc: UnexpectedInput, text: str, file: str,
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
