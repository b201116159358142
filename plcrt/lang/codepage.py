"""The code page of string and character constants.

An S7-200 string holds bytes; Micro/WIN stores the characters typed into a
string constant or the data block in the Windows ANSI code page of its PC,
the same code page its exports are written in.  plcrt therefore encodes a
constant in the code page the program file was read with, and in CP1252 when
the file does not have one (ASCII, UTF-8, UTF-16, text given directly).  A
character that code page cannot hold is an error at its constant.

This module encodes; it does not parse literals (the operand parser and the
data block parser do, each with its own quoting rules).
"""

from __future__ import annotations

from ..safetext import excerpt

__all__ = ["DEFAULT_CODEPAGE", "MAX_STRING", "string_bytes", "string_codepage"]

#: The code page of string constants when the program text does not name one
#: (a program read as ASCII, UTF-8 or UTF-16, or given as text): the Western
#: Windows code page Micro/WIN uses on an English or German PC.
DEFAULT_CODEPAGE = "cp1252"

#: Longest S7-200 string: a length byte of 0..254 (System Manual, "Data
#: types": a string is a length byte followed by up to 254 characters).
MAX_STRING = 254


def string_codepage(encoding: str) -> str:
    """The code page string constants are stored in, for a program decoded
    with ``encoding``: that code page itself when it is one (``cp1252``,
    ``gbk``, ...), else :data:`DEFAULT_CODEPAGE`."""
    e = (encoding or "").lower().replace("_", "-")
    if not e or e.startswith(("utf", "ascii", "us-ascii")):
        return DEFAULT_CODEPAGE
    return encoding


def string_bytes(body: str, codepage: str, limit: int | None = MAX_STRING) -> bytes:
    """The characters of a constant in ``codepage``.

    Raises:
        ValueError: a character that code page cannot hold (the message
            names it and its position), or more than ``limit`` bytes.
    """
    try:
        data = body.encode(codepage)
    except UnicodeEncodeError as e:
        ch = body[e.start]
        raise ValueError(f"character {excerpt(ch)!r} (U+{ord(ch):04X}, position "
                         f"{e.start + 1}) is not in code page {codepage.upper()}") from None
    except LookupError:
        raise ValueError(f"unknown code page {excerpt(codepage)!r}") from None
    if limit is not None and len(data) > limit:
        raise ValueError(f"a string holds at most {limit} characters, this one "
                         f"has {len(data)} bytes")
    return data
