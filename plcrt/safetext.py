"""Making untrusted text safe to show on a terminal.

Program files, symbol tables and command scripts are untrusted: a network
title or an operand may hold an ANSI escape sequence (``\\x1b[2J`` clears
the screen, ``\\x1b]8;;...`` makes a hyperlink), a bell, a backspace that
hides what precedes it, or a Unicode bidirectional override that shows text
in another order than it is stored.  :func:`printable` turns every such
character into a visible escape (``\\x1b``, ``\\u202e``) before the text
reaches a terminal, a transcript or a log; everything else, letters of any
script included, is kept.  A tab becomes one space, so columns stay
aligned.

:func:`excerpt` shortens program text quoted in a message (an operand,
a symbol, a value) to :data:`EXCERPT_CHARS` characters and an ellipsis:
a 200 000-character operand must not be echoed in full.  Every message
that quotes program text goes through it.

Escaping only concerns control characters.  Rich markup (``[bold]``) is the
presentation layer's business: it must build ``rich.text.Text`` objects
from program text, never markup strings.  This module has no dependency.
"""

from __future__ import annotations

import re
from typing import Any

#: bidirectional formatting characters (Unicode TR9): embeddings,
#: overrides and isolates, which reorder how the text around them is shown
_BIDI = "\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069"

#: C0 and C1 controls, DEL, the line/paragraph separators, the bidi
#: controls and lone surrogates (undecodable input bytes)
_UNSAFE = re.compile(f"[\x00-\x1f\x7f-\x9f\u2028\u2029{_BIDI}\ud800-\udfff]")


def _escape(m: re.Match[str]) -> str:
    ch = m.group()
    if ch == "\t":
        return " "
    code = ord(ch)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def printable(text: str) -> str:
    """``text`` with control characters shown as escapes (``\\x1b``) and
    tabs as spaces; unchanged when it has none (the usual case)."""
    if _UNSAFE.search(text) is None:
        return text
    return _UNSAFE.sub(_escape, text)


#: longest piece of program text a message quotes (see :func:`excerpt`)
EXCERPT_CHARS = 40


def excerpt(text: str, limit: int = EXCERPT_CHARS) -> str:
    """``text`` as a message quotes it: at most ``limit`` characters, a cut
    marked with ``…`` (so ``'VW1234…'`` shows both what it was and that
    there was more)."""
    if len(text) <= limit:
        return text
    return text[:limit] + "\u2026"


def shown_value(value: Any) -> str:
    """``repr(value)`` short enough for one line of a message."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 200:
        # str() of a huge int is slow, and refused above 4300 digits
        return f"{'-' if value < 0 else ''}a {value.bit_length()}-bit integer"
    try:
        text = printable(repr(value))
    except ValueError:
        # a huge int inside a list or tuple: its repr() is refused too
        return f"a {type(value).__name__} holding a huge integer"
    return text if len(text) <= 60 else text[:57] + "..."


__all__ = ["EXCERPT_CHARS", "excerpt", "printable", "shown_value"]
