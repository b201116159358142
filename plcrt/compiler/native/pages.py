"""Hand the llvmlite library's resident code pages back after a compile.

What it is: :func:`release_library_pages`, called by :mod:`.jit` once a
large program's machine code is made.  LLVM is a large library (the
llvmlite wheel's ``libllvmlite.so`` is about 170 MB), and a recent Linux
kernel maps its file pages into the process in large folios: a process
that has compiled with LLVM keeps about 100 MiB of the library resident,
which ``top`` counts in its RSS, though the machine code made needs none
of it.  This hands those mappings back with ``madvise(MADV_DONTNEED)``:
the pages stay in the page cache (shared by every process, reclaimable)
and are mapped again, from that cache, when LLVM next runs.

Only the library's read-only mappings that hold no private page (no page
written since it was mapped: the anonymous count of ``/proc/self/smaps``
is 0) are handed back, so nothing is lost: a page comes back with the
file's contents, which are the contents it had.  Elsewhere than Linux
(no ``/proc/self/smaps``) it does nothing.

What it is not: the C heap's trim (:func:`plcrt.compiler.cache.release_free_memory`)
or LLVM's own memory (:mod:`.jit` disposes of its modules).  It imports
no llvmlite.
"""

from __future__ import annotations

import ctypes
import re
from pathlib import Path

__all__ = ["release_library_pages"]

#: the library whose mappings are handed back
LIBRARY = "libllvmlite"
#: Linux's MADV_DONTNEED
_DONTNEED = 4
#: a mapping's first line: ``start-end perms offset dev inode path``
_HEAD = re.compile(r"^([0-9a-f]+)-([0-9a-f]+) (\S+) \S+ \S+ \S+ *(.*)$")

_madvise: object = None


def _advise() -> object:
    """libc's ``madvise``, or False where there is none."""
    global _madvise
    if _madvise is None:
        _madvise = False
        try:
            fn = ctypes.CDLL(None, use_errno=True).madvise
            fn.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
            fn.restype = ctypes.c_int
            _madvise = fn
        except (OSError, AttributeError):
            pass
    return _madvise


def _clean_mappings(smaps: str, library: str) -> list[tuple[int, int]]:
    """(start, end) of each read-only mapping of ``library`` in ``smaps``
    (the text of ``/proc/self/smaps``) without a private page."""
    out: list[tuple[int, int]] = []
    current: tuple[int, int] | None = None
    for line in smaps.splitlines():
        head = _HEAD.match(line)
        if head is not None:
            start, end, perms, path = head.groups()
            name = path.rsplit("/", 1)[-1]
            current = (int(start, 16), int(end, 16)) \
                if name.startswith(library) and "w" not in perms else None
        elif current is not None and line.startswith("Anonymous:"):
            if line.split()[1] == "0":
                out.append(current)
            current = None
    return out


def release_library_pages(library: str = LIBRARY) -> int:
    """Hand back the resident pages of ``library``'s clean read-only
    mappings (see the module docstring); returns the bytes advised (0
    where this cannot be done)."""
    advise = _advise()
    if not advise:
        return 0
    try:
        smaps = Path("/proc/self/smaps").read_text()
    except OSError:
        return 0
    done = 0
    for start, end in _clean_mappings(smaps, library):
        if advise(start, end - start, _DONTNEED) == 0:   # type: ignore[operator]
            done += end - start
    return done
