"""What both STL parsers know of export text: its keywords, block ids,
variable sections and line ends.

:mod:`plcrt.lang.stl` (lark, the reference and the error reporter) and
:mod:`plcrt.lang.fastparse` (the line-based fast path) must read the same
text the same way; the tables they share live here, below both, so that
neither imports the other for them.

It is *not* a parser and holds no grammar: ``grammar/stl.lark`` defines the
language, and these tables only name what both readers of it agree on.
"""

from __future__ import annotations

import re

from .ir import VarSection

__all__ = ["BLOCK_ID", "KEYWORD_TYPES", "SECTION_OF", "prepare"]

# Structural keywords that the generic MNEMONIC / NAME regexes also match.
# The contextual lexer only tries terminals the parser can accept, so inside
# a network "SUBROUTINE_BLOCK" would lex as a mnemonic and a missing
# END_ORGANIZATION_BLOCK would surface only much later.  Re-typing such a
# token makes the parser reject it on the spot with a precise message (and
# the fast path declines any name spelled like one).
KEYWORD_TYPES = {
    "ORGANIZATION_BLOCK": "OB_KW",
    "SUBROUTINE_BLOCK": "SBR_KW",
    "INTERRUPT_BLOCK": "INT_KW",
    "END_ORGANIZATION_BLOCK": "END_OB",
    "END_SUBROUTINE_BLOCK": "END_SBR",
    "END_INTERRUPT_BLOCK": "END_INT",
    "BEGIN": "BEGIN",
    "END_VAR": "END_VAR",
}

#: ``OB1``, ``SBR0``, ``INT3``: the block id after a block keyword
BLOCK_ID = re.compile(r"(OB|SBR|INT)([0-9]+)", re.I)

#: the section of a variable by the keyword of its VAR section
SECTION_OF: dict[str, VarSection] = {
    "VAR_INPUT": "IN", "VAR_IN_OUT": "IN_OUT", "VAR_OUTPUT": "OUT",
    "VAR": "TEMP", "VAR_TEMP": "TEMP"}


def prepare(text: str) -> str:
    """Normalise line ends so that the parsers see LF only, keeping line numbers.

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
