"""File names a user gives plcrt, checked once before any file is opened.

Every path argument of the public API -- the program, symbol table, data
block and plant files of :func:`plcrt.load`, the harness and the pytest
marker, the CSV and plot files a trace writes -- goes through
:func:`check_path` (reading goes through
:func:`plcrt.lang.limits.read_capped`, which calls it too).  A name no file
system can hold -- one with a NUL character, or with a character the file
system's encoding cannot write (a lone surrogate) -- is a
:class:`~plcrt.errors.PlcConfigError` saying so, not the ``ValueError`` or
``UnicodeEncodeError`` Python's ``open`` raises.

This module opens nothing and does not say whether a file exists.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from .errors import PlcConfigError
from .safetext import excerpt, printable

__all__ = ["check_path"]


def check_path(path: Any, what: str = "the file name") -> Path:
    """``path`` (a str or an ``os.PathLike``) as a :class:`Path`, if a file
    system can hold the name; ``what`` names the argument in messages.

    Raises:
        PlcConfigError: not a str or path, a ``bytes`` path, a NUL
            character in the name, or a character the file system's
            encoding cannot write.
    """
    try:
        name = os.fspath(path)
    except TypeError:
        raise PlcConfigError(f"{what} must be a file path (a str or a pathlib.Path), got "
                             f"{type(path).__name__}") from None
    if not isinstance(name, str):
        raise PlcConfigError(f"{what} must be a file path given as a str or a pathlib.Path, "
                             f"got {type(name).__name__}")
    shown = printable(excerpt(name))
    if "\0" in name:
        raise PlcConfigError(f"{what} '{shown}' holds a NUL character (\\x00), which no file "
                             f"name can hold")
    try:
        os.fsencode(name)
    except UnicodeEncodeError as e:
        raise PlcConfigError(f"{what} '{shown}' cannot be a file name here: its character "
                             f"U+{ord(name[e.start]):04X} at position {e.start + 1} cannot be "
                             f"written in {e.encoding.upper()}, the file system's "
                             f"encoding") from None
    return Path(name)
