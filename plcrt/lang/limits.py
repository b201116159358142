"""Size limits on the input files, so hostile input ends in a clear error.

Program, symbol table and data block files are untrusted.  Without a
limit, ``/dev/zero`` given as a program is read until memory runs out, and
a 50 MB program that is valid STL takes minutes and gigabytes before
failing.  :func:`read_capped` reads at most ``limit + 1`` bytes of a
*regular* file and refuses anything bigger (or a device, a FIFO, a
socket) with a :class:`~plcrt.errors.PlcSyntaxError` naming the file and
the limit.  :data:`MAX_INSTRUCTIONS` and :data:`MAX_NETWORKS` bound what the compiler
is asked to build, since compiling costs several kilobytes per instruction
and per network.

The limits are far above any real S7-200 program: the largest CPU holds
24 KB of program, a few thousand instructions, and its STL export is
well under a megabyte.  :func:`too_many_digits` keeps a number of
thousands of digits from reaching ``int()``.  ``plcrt.load(..., max_file_mb=...)`` and the
command line's ``--max-file-mb`` raise the file limit.

This module decodes nothing (see :func:`plcrt.lang.read_source`).
"""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

from ..errors import PlcConfigError, PlcSyntaxError, SourceLoc
from ..safetext import shown_value
from ..paths import check_path

#: default largest file read (program, symbol table, data block), in MiB.
#: A real export is well under 1 MB; generated benchmark programs of
#: 100 000 statements are about 1.3 MB
MAX_FILE_MB = 16.0

#: largest number of instructions compiled in one program (a real S7-200
#: program has a few thousand; benchmarks load 100 000)
MAX_INSTRUCTIONS = 131_072

#: largest number of networks compiled in one program (each becomes a
#: generated function, even an empty one)
MAX_NETWORKS = 65_536

#: longest run of digits read as a number.  Python refuses to convert more
#: than 4300 (a ValueError); no S7-200 number needs more than a few dozen
#: (a REAL written out in full).
MAX_DIGITS = 100

_MIB = 1024 * 1024
_LONG_DIGITS = re.compile(r"[0-9]{%d}" % (MAX_DIGITS + 1))


def too_many_digits(text: str) -> bool:
    """Whether ``text`` holds a run of more than :data:`MAX_DIGITS` digits
    (callers refuse it as out of range instead of converting it)."""
    return _LONG_DIGITS.search(text) is not None


def file_limit(max_file_mb: float | None = None) -> int:
    """The byte limit of ``max_file_mb`` (None: :data:`MAX_FILE_MB`).

    Raises:
        PlcConfigError: not a positive finite number.
    """
    if max_file_mb is None:
        max_file_mb = MAX_FILE_MB
    if isinstance(max_file_mb, bool) or not isinstance(max_file_mb, (int, float)) \
            or not 0 < max_file_mb < 1e6:
        raise PlcConfigError(f"the file size limit (--max-file-mb, max_file_mb=) must be a "
                             f"number of MB above 0 and below 1000000, got {shown_value(max_file_mb)}")
    return int(max_file_mb * _MIB)


def describe_limit(limit: int) -> str:
    """``1 MB (1048576 bytes)`` for messages."""
    return f"{limit / _MIB:.4g} MB ({limit} bytes)"


def read_capped(path: str | Path, limit: int) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them.

    Raises:
        PlcSyntaxError: at ``path:1:1``: the file is missing, a directory,
            not a regular file (a device such as ``/dev/zero``, a FIFO),
            unreadable, or longer than ``limit`` bytes (the message names
            the limit and how to raise it).
        PlcConfigError: a name no file can have (a NUL character:
            :func:`plcrt.paths.check_path`).
    """
    name = str(path)

    def fail(reason: str) -> PlcSyntaxError:
        return PlcSyntaxError(f"cannot read file: {reason}", SourceLoc(name, 1, 1))

    if name == "":
        raise fail("no file name given")
    check_path(name)
    try:
        # O_NONBLOCK: opening a FIFO with no writer must not hang; the
        # mode is checked on the open descriptor, so nothing can swap the
        # file between the check and the read.
        fd = os.open(name, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        raise fail("no such file") from None
    except IsADirectoryError:
        raise fail("it is a directory") from None
    except OSError as exc:
        raise fail(exc.strerror or exc.__class__.__name__) from None
    try:
        mode = os.fstat(fd).st_mode
        if stat.S_ISDIR(mode):
            raise fail("it is a directory")
        if not stat.S_ISREG(mode):
            raise fail("it is not a regular file (a device, a pipe or a socket)")
        chunks: list[bytes] = []
        size = 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise fail(exc.strerror or exc.__class__.__name__) from None
    finally:
        os.close(fd)
    if size > limit:
        raise fail(f"it is larger than the limit of {describe_limit(limit)} (raise it "
                   f"with --max-file-mb or load(..., max_file_mb=...) if the file is right)")
    return b"".join(chunks)


def check_text_size(text: str, name: str, limit: int) -> None:
    """Refuse program text given directly that is longer than ``limit``
    characters, as :func:`read_capped` refuses a file.

    Raises:
        PlcSyntaxError: naming the text and the limit.
    """
    if len(text) > limit:
        raise PlcSyntaxError(f"the text is {len(text)} characters long, more than the limit "
                             f"of {describe_limit(limit)} (raise it with "
                             f"load(..., max_file_mb=...))", SourceLoc(name, 1, 1))


__all__ = ["MAX_DIGITS", "MAX_FILE_MB", "MAX_INSTRUCTIONS", "MAX_NETWORKS", "check_text_size",
           "describe_limit", "file_limit", "read_capped", "too_many_digits"]
