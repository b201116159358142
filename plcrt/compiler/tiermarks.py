"""Marks of the programs whose machine code an earlier run left on disk.

What it is: the hint that lets a load of ``backend="auto"`` bind the native
build at once (:mod:`plcrt.engine.binding`).  When the background job of a
tiered PLC (:mod:`plcrt.engine.tiering`) has made a program's machine code
and the native disk cache kept it, it writes a *mark* for the program: an
entry of that cache (:mod:`plcrt.compiler.native.diskcache`: atomic,
checksummed, counted in its size limit and trimmed with it, least recently
used first) under a key made of the program's cache key
(:func:`plcrt.compiler.cache.program_key`: its text, file, CPU and every
option that changes the compiled code).  A load
looks for the mark with one ``stat`` and no import of the native backend,
so a program that has no mark loads as fast as on the Python backend.

A mark is only a hint: the load that follows it compiles the native build
as ``backend="native"`` does, and the machine code is taken from the disk
cache only when its own key (the IR, llvmlite, the CPU) matches; a stale
mark (plcrt or llvmlite changed since, the entry trimmed) costs that one
load a native compile, whose machine code the disk cache then keeps.

What it is not: the disk cache itself, or the decision when a PLC
switches builds (:mod:`plcrt.engine.tiering`).
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from typing import Any

__all__ = ["mark", "mark_key", "marked", "touch"]

#: the file ending of the native disk cache's entries (diskcache._SUFFIX)
_SUFFIX = ".native"


def _folder() -> str:
    """The native disk cache's folder (what :func:`plcrt.compiler.native.
    diskcache.cache_dir` says; repeated here so that a load does not import
    the native backend: tests/compiler/test_tiermarks.py keeps them equal).
    perf: strings, not pathlib (a third of the look's cost was pathlib's)."""
    base = os.environ.get("PLCRT_CACHE_DIR")
    if base:
        return os.path.join(base, "native")
    home = os.path.expanduser("~")
    if home == "~":               # no HOME and no password entry
        home = tempfile.gettempdir()
    return os.path.join(home, ".cache", "plcrt", "native")


def mark_key(key: tuple[Any, ...]) -> str | None:
    """The mark's key for a program's cache key, or None when the key holds
    an object known only by its identity in this process (an option that
    cannot be pickled: no other process can find it)."""
    text = repr(key)
    if "_Identity" in text or " at 0x" in text:
        return None
    digest = hashlib.sha256(f"plcrt-tier-mark-1\0{text}".encode(
        "utf-8", "surrogatepass")).hexdigest()
    return digest[:40]


def marked(key: tuple[Any, ...]) -> bool:
    """Whether an earlier run left the machine code of the program with
    cache key ``key`` on disk (one ``stat``; an unreadable folder is no)."""
    name = mark_key(key)
    if name is None or _limit_is_zero():
        return False
    try:
        return os.path.isfile(os.path.join(_folder(), name + _SUFFIX))
    except OSError:
        return False


def mark(key: tuple[Any, ...]) -> bool:
    """Write the mark of ``key`` (in the compile thread, after the machine
    code was kept); False when nothing was written."""
    name = mark_key(key)
    if name is None:
        return False
    from .native import diskcache
    return diskcache.store(name, [b"plcrt tier mark\n"])


def touch(key: tuple[Any, ...]) -> None:
    """Mark the mark as just used (the disk cache trims the least recently
    used entries first)."""
    name = mark_key(key)
    if name is not None:
        try:
            os.utime(os.path.join(_folder(), name + _SUFFIX))
        except OSError:
            pass


def _limit_is_zero() -> bool:
    """``PLCRT_NATIVE_CACHE_MB=0``: the disk cache keeps nothing, so a mark
    left from before means nothing either (read as
    :func:`plcrt.compiler.native.diskcache.limit_bytes` reads it)."""
    raw = os.environ.get("PLCRT_NATIVE_CACHE_MB", "").strip()
    try:
        mb = float(raw) if raw else None
    except ValueError:
        return False
    return mb is not None and 0 <= mb <= 1 << 30 and int(mb * 2**20) == 0
