"""The native backend's disk cache of machine code: safe to share, bounded.

What it is: files of machine code (one per program build: the object
code of each of its LLVM modules, :mod:`.jit`) in ``$PLCRT_CACHE_DIR/native``
(else ``~/.cache/plcrt/native``), under a key that :mod:`.jit` makes of the
modules' IR, the llvmlite version and the host (target triple, CPU name
and features): machine code is never loaded by another llvmlite or on
another CPU.

- *Atomic.*  A file is written under a name of its own (process, thread,
  random) in the same folder and renamed over the entry (``os.replace``):
  a reader sees the old file, the new one or none, never a part.  Several
  processes writing one key at once (pytest-xdist workers loading the
  same program) each rename a complete file; the last one stays.
- *Checked.*  A file carries a SHA-256 of its contents and is used only
  when it matches and its table of objects is in bounds: a torn, foreign
  or damaged file is a miss (compiled again), never executed.
- *Bounded.*  After a write the folder is trimmed to
  ``$PLCRT_NATIVE_CACHE_MB`` MiB (:data:`DEFAULT_LIMIT_MB` by default),
  least recently used first: a hit touches its file's modification time
  (access times are often not kept, ``noatime``).  ``0`` keeps nothing.
- *Optional.*  A folder that cannot be written or read only means nothing
  is kept: the code is compiled, never an error.

What it is not: the compiler (:mod:`.jit`) or the in-memory program
cache (:mod:`plcrt.compiler.cache`).  It imports no llvmlite.
"""

from __future__ import annotations

import hashlib
import os
import struct
import tempfile
import threading
import time
from pathlib import Path
from typing import Iterable

__all__ = ["DEFAULT_LIMIT_MB", "cache_dir", "limit_bytes", "load", "make_key", "store", "trim"]

#: the cache's size limit in MiB unless ``$PLCRT_NATIVE_CACHE_MB`` says
#: otherwise (a 100 000-statement program's machine code is about 8 MiB)
DEFAULT_LIMIT_MB = 256

_MAGIC = b"plcrt-native-2\n"
_SUFFIX = ".native"
_TMP = ".tmp"
#: the files of an older plcrt (one object per file), which nothing reads now
_LEGACY = ".o"
#: the most objects one file may list (a program's modules are far fewer)
MAX_OBJECTS = 1 << 16
#: a temporary file older than this is a writer's leftover (killed mid-write)
STALE_TMP_S = 3600.0


def cache_dir() -> Path:
    """Where machine code is kept: ``$PLCRT_CACHE_DIR/native``, else
    ``~/.cache/plcrt/native`` (the temporary folder without a home)."""
    base = os.environ.get("PLCRT_CACHE_DIR")
    if base:
        return Path(base) / "native"
    try:
        home = Path.home()
    except RuntimeError:          # no HOME and no password entry (a bare container)
        home = Path(tempfile.gettempdir())
    return home / ".cache" / "plcrt" / "native"


def limit_bytes() -> int:
    """The size limit in bytes: ``$PLCRT_NATIVE_CACHE_MB`` (a number of MiB,
    0 keeps nothing), else :data:`DEFAULT_LIMIT_MB`; an unreadable value
    is the default."""
    raw = os.environ.get("PLCRT_NATIVE_CACHE_MB", "").strip()
    try:
        mb = float(raw) if raw else DEFAULT_LIMIT_MB
    except ValueError:
        mb = DEFAULT_LIMIT_MB
    if not mb >= 0 or mb > 1 << 30:       # NaN, negative or absurd: the default
        mb = DEFAULT_LIMIT_MB
    return int(mb * 2**20)


def make_key(parts: Iterable[bytes | str]) -> str:
    """A file key over ``parts`` (each hashed with its length, so no two
    sequences of parts give one stream)."""
    h = hashlib.sha256()
    for part in parts:
        data = part.encode("utf-8") if isinstance(part, str) else part
        h.update(struct.pack("<Q", len(data)))
        h.update(data)
    return h.hexdigest()[:40]


def _path(key: str) -> Path:
    if not key.isalnum():             # keys are hex digests; never a path
        raise ValueError("a cache key is a hex digest")
    return cache_dir() / f"{key}{_SUFFIX}"


def _pack(objects: list[bytes]) -> bytes:
    body = b"".join([struct.pack("<I", len(objects)),
                     *(struct.pack("<Q", len(o)) for o in objects), *objects])
    return _MAGIC + hashlib.sha256(body).hexdigest().encode() + body


def _unpack(data: bytes) -> list[bytes] | None:
    head = len(_MAGIC) + 64
    if len(data) < head + 4 or not data.startswith(_MAGIC):
        return None
    body = memoryview(data)[head:]
    if hashlib.sha256(body).hexdigest().encode() != data[len(_MAGIC):head]:
        return None
    (count,) = struct.unpack_from("<I", body, 0)
    if count > MAX_OBJECTS or 4 + 8 * count > len(body):
        return None
    sizes = struct.unpack_from(f"<{count}Q", body, 4)
    at = 4 + 8 * count
    if at + sum(sizes) != len(body):
        return None
    out = []
    for size in sizes:
        out.append(bytes(body[at:at + size]))
        at += size
    return out


def load(key: str) -> list[bytes] | None:
    """The objects stored under ``key``, or None (missing, unreadable,
    torn or not ours).  A hit marks the file as just used."""
    path = _path(key)
    try:
        data = path.read_bytes()
    except OSError:
        return None
    objects = _unpack(data)
    if objects is not None:
        try:
            os.utime(path)                # least recently used goes first
        except OSError:
            pass
    return objects


def store(key: str, objects: list[bytes]) -> bool:
    """Keep ``objects`` under ``key`` (atomically), then trim the folder to
    :func:`limit_bytes`.  False when nothing was kept."""
    limit = limit_bytes()
    data = _pack(objects)
    if len(data) > limit:
        return False
    path = _path(key)
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f"{key}.{os.getpid()}.{threading.get_ident()}.",
                                   suffix=_TMP, dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
        tmp = None
    except OSError:
        return False
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
    trim(limit, keep=path)
    return True


def trim(limit: int | None = None, keep: Path | None = None) -> int:
    """Delete the least recently used files until the folder holds at most
    ``limit`` bytes (:func:`limit_bytes` by default), never ``keep`` (the
    file just written), writers' leftovers older than :data:`STALE_TMP_S`
    and an older plcrt's files (``*.o``).  Returns the bytes left.  Another process may
    trim at the same time: a file already gone is skipped."""
    if limit is None:
        limit = limit_bytes()
    entries = []
    now = time.time()
    try:
        with os.scandir(cache_dir()) as it:
            for e in it:
                try:
                    st = e.stat(follow_symlinks=False)
                except OSError:
                    continue
                if e.name.endswith(_TMP):
                    if now - st.st_mtime > STALE_TMP_S:
                        _unlink(e.path)
                    continue
                if e.name.endswith(_LEGACY):      # an older plcrt's format: never read
                    _unlink(e.path)
                    continue
                if e.name.endswith(_SUFFIX) and e.is_file(follow_symlinks=False):
                    entries.append((st.st_mtime, e.path, st.st_size))
    except OSError:
        return 0
    total = sum(size for _, _, size in entries)
    keep_s = str(keep) if keep is not None else None
    for _mtime, path, size in sorted(entries):
        if total <= limit:
            break
        if path == keep_s:
            continue
        if _unlink(path):
            total -= size
    return total


def _unlink(path: str) -> bool:
    try:
        os.unlink(path)
    except FileNotFoundError:
        return True                       # another process trimmed it
    except OSError:
        return False
    return True
