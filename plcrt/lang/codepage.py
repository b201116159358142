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

__all__ = ["DEFAULT_CODEPAGE", "MAX_STRING", "program_codepage", "string_bytes",
           "string_codepage"]

#: The code page of string constants when the program text does not name one
#: (a program read as ASCII, UTF-8 or UTF-16, or given as text): the Western
#: Windows code page Micro/WIN uses on an English or German PC.
DEFAULT_CODEPAGE = "cp1252"

#: Longest S7-200 string: a length byte of 0..254 (System Manual, "Data
#: types": a string is a length byte followed by up to 254 characters).
MAX_STRING = 254


def _is_codepage(encoding: str) -> bool:
    """Whether a file read with ``encoding`` was written in a code page
    (``cp1252``, ``gbk``, ...), not as Unicode or ASCII text."""
    e = (encoding or "").lower().replace("_", "-")
    return bool(e) and not e.startswith(("utf", "ascii", "us-ascii"))


def string_codepage(encoding: str) -> str:
    """The code page string constants are stored in, for a program decoded
    with ``encoding``: that code page itself when it is one (``cp1252``,
    ``gbk``, ...), else :data:`DEFAULT_CODEPAGE`."""
    return encoding if _is_codepage(encoding) else DEFAULT_CODEPAGE


#: Code pages tried, in order, for the string constants of a program read as
#: Unicode (UTF-8/16) whose constants CP1252 cannot hold: the ANSI code pages
#: Micro/WIN runs with on Chinese, Japanese, Korean, Taiwanese, Cyrillic,
#: Central European, Greek, Turkish, Hebrew, Arabic, Baltic, Vietnamese and
#: Thai Windows.
UNICODE_FALLBACKS = ("gbk", "cp932", "cp949", "cp950", "cp1251", "cp1250", "cp1253",
                     "cp1254", "cp1255", "cp1256", "cp1257", "cp1258", "cp874")


def program_codepage(encoding: str, constants: list[str]) -> tuple[str, bool]:
    """The code page of a program's string constants, and whether it was
    chosen from their characters.  A program read in a code page keeps it;
    one read as Unicode (it names none) gets CP1252 when its constants fit,
    else the first of :data:`UNICODE_FALLBACKS` that holds them all (a
    Chinese SMART project exported as UTF-8 gets GBK), else CP1252 and an
    error at the constant that does not fit."""
    if _is_codepage(encoding):
        return encoding, False
    text = "".join(constants)
    for candidate in (DEFAULT_CODEPAGE, *UNICODE_FALLBACKS):
        try:
            text.encode(candidate)
        except UnicodeEncodeError:
            continue
        return candidate, candidate != DEFAULT_CODEPAGE
    return DEFAULT_CODEPAGE, False


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
