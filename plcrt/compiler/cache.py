"""Loading in linear time and little memory: the compiled-program cache,
chunked compilation of the generated module, and the paused garbage
collector.

*Cache.*  Compiling is by far the largest part of a load, and a test suite
loads the same program once per test.  :class:`ProgramCache` keeps, per
program text and every option that changes the generated code, the
compiled program (:class:`plcrt.compiler.program.CompiledProgram`: the
checked unit, the code objects, the generated source, its line map and
the bindings as recipes).  Every :class:`plcrt.engine.Plc` is an instance
of one, also right after a miss, so there is one way of binding a PLC and
every load exercises it: the recipes are resolved against the new PLC's
own objects, and the shared code objects run in its own namespace, so it
has its own functions whose default arguments are its own objects.

*Chunks.*  ``compile()`` of one module with a hundred thousand statements
builds its whole syntax tree first: hundreds of MiB that the allocator
keeps after they are freed.  The code generator cuts the module between
top-level statements (:attr:`plcrt.compiler.codegen.Unit.chunks`) and turns
each piece's lines into one text as soon as the piece is complete, so the
whole module's lines are never held at once; :func:`compile_chunks`
compiles the pieces one by one, moving each piece's line numbers to where
the piece is in the whole module, so tracebacks, ``plcrt dump`` and error
locations see one module.

*Garbage collector.*  Loading allocates millions of objects and frees
almost none: every automatic collection during it only walks what is still
alive, so :func:`gc_paused` turns the cyclic collector off while parsing
and compiling (the load itself makes no garbage cycles worth collecting).

*Free pages.*  What a large compile does free (syntax trees, lines) stays
mapped in the C heap; :func:`release_free_memory` hands it back to the
system once the chunks are compiled.
"""

from __future__ import annotations

import gc
import hashlib
import pickle
import threading
import types
from collections import OrderedDict
from contextlib import contextmanager
from typing import Any, Iterator

#: Lines of generated source per compiled chunk: big enough that the
#: per-call overhead of ``compile()`` does not count, small enough that a
#: chunk's syntax tree stays small (measured on 2026-12-02 with 20 000
#: boolean statements: 1000-line chunks compiled in about 15 % less CPU
#: time than 4000-line ones, and the peak while compiling is lower).
CHUNK_LINES = 1000

#: Programs (text + options) kept compiled; the least recently used goes.
DEFAULT_ENTRIES = 8


# ---------------------------------------------------------------------------
# Garbage collector
# ---------------------------------------------------------------------------

_gc_lock = threading.Lock()
_gc_depth = 0
_gc_was_enabled = False


@contextmanager
def gc_paused() -> Iterator[None]:
    """Run the body with the cyclic garbage collector off; nested uses (a
    load inside a load, a fork's twin) keep it off until the outermost one
    ends, which restores the state it found, also when the body raises."""
    global _gc_depth, _gc_was_enabled
    with _gc_lock:
        if _gc_depth == 0:
            _gc_was_enabled = gc.isenabled()
            gc.disable()
        _gc_depth += 1
    try:
        yield
    finally:
        with _gc_lock:
            _gc_depth -= 1
            if _gc_depth == 0 and _gc_was_enabled:
                gc.enable()


# ---------------------------------------------------------------------------
# Chunked compilation
# ---------------------------------------------------------------------------

def _shift_lines(code: types.CodeType, offset: int) -> types.CodeType:
    """``code`` (and the functions defined in it) moved down by ``offset``
    lines.  A code object's line table counts from its ``co_firstlineno``,
    so moving the first line moves every line of it."""
    consts = tuple(_shift_lines(c, offset) if isinstance(c, types.CodeType) else c
                   for c in code.co_consts)
    return code.replace(co_firstlineno=code.co_firstlineno + offset, co_consts=consts)


def compile_chunks(source: str, chunks: list[tuple[int, int]], filename: str
                   ) -> list[types.CodeType]:
    """Compile ``source`` piece by piece.

    ``chunks`` lists ``(first line, character offset)`` of each piece (the
    first is ``(1, 0)``); executing the returned code objects in order in
    one namespace does what executing the whole module does, because the
    cuts are between top-level statements.
    """
    codes: list[types.CodeType] = []
    bounds = list(chunks) + [(0, len(source))]
    for (line, start), (_, end) in zip(bounds, bounds[1:]):
        if start == end:
            continue
        # perf: one piece's syntax tree at a time (see the module docstring)
        code = compile(source[start:end], filename, "exec", dont_inherit=True)
        codes.append(_shift_lines(code, line - 1) if line > 1 else code)
    if len(source) >= TRIM_SOURCE_CHARS:
        release_free_memory()
    return codes


#: Generated source (characters) from which a compile hands the C heap's
#: free pages back to the system: about 5 000 statements, whose load frees
#: some MiB; below that the few pages are not worth the call.
TRIM_SOURCE_CHARS = 256 * 1024

_malloc_trim: Any = None


def release_free_memory() -> bool:
    """Give the C allocator's free pages back to the operating system
    (glibc's ``malloc_trim``); False where there is no such call.

    A load's syntax trees, source lines and tables are freed when it ends,
    but glibc keeps the freed pages of its heap mapped, so the process
    stays as large as at the peak of the load (measured on 2026-12-02:
    15 MiB of a 100 000-statement boolean program's 93, 43 MiB of the
    mixed one's 158).  Python's own small-object arenas are not affected.
    """
    global _malloc_trim
    if _malloc_trim is None:
        _malloc_trim = False
        try:
            import ctypes
            import ctypes.util
            name = ctypes.util.find_library("c")
            trim = getattr(ctypes.CDLL(name), "malloc_trim", None) if name else None
            if trim is not None:
                trim.argtypes = [ctypes.c_size_t]
                trim.restype = ctypes.c_int
                _malloc_trim = trim
        except (OSError, AttributeError, ImportError):
            pass
    if not _malloc_trim:
        return False
    _malloc_trim(0)
    return True


# ---------------------------------------------------------------------------
# The cache
# ---------------------------------------------------------------------------

def _fingerprint(obj: Any) -> tuple[str, Any]:
    """A hashable stand-in for an option's value: a digest of its pickle,
    or, for an object that cannot be pickled, the object itself (held by
    the key, so its identity stays unique)."""
    if obj is None:
        return ("none", None)
    try:
        return ("sha1", hashlib.sha1(pickle.dumps(obj, protocol=5)).hexdigest())
    except Exception:   # noqa: BLE001 - any object: unpicklable ones use identity
        return ("id", _Identity(obj))


class _Identity:
    """Hashes and compares by identity, and keeps the object alive."""

    __slots__ = ("obj",)

    def __init__(self, obj: Any) -> None:
        self.obj = obj

    def __hash__(self) -> int:
        return id(self.obj)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, _Identity) and other.obj is self.obj


def program_key(program: Any, **options: Any) -> tuple[Any, ...]:
    """The cache key of ``program`` compiled with ``options`` (every option
    that changes the generated code or its bindings): a hash of the
    program's text, its file name, encoding and size, and a fingerprint of
    each option.  A hit is confirmed by comparing the parsed programs
    (:meth:`ProgramCache.get`), so programs merged from several files,
    whose ``source`` holds only the first file's text, cannot collide."""
    text = hashlib.sha1(program.source.encode("utf-8", "surrogatepass")).hexdigest()
    head = (text, program.file, program.encoding, len(program.pous),
            program.network_count(), program.instruction_count())
    return head + tuple((name, _fingerprint(value)) for name, value in sorted(options.items()))


def _same(cached: Any, program: Any) -> bool:
    """Whether a cached build's program is ``program``: equal IR, and the
    same system block (the settings a PLC of the build powers up with) and
    origin (a project file's interfaces match library blocks by size),
    which the IR's equality leaves out."""
    if cached is program:
        return True
    return cached == program and all(getattr(cached, name, None) == getattr(program, name, None)
                                     for name in ("system", "from_project"))


def with_options(key: tuple[Any, ...], **options: Any) -> tuple[Any, ...]:
    """``key`` (of :func:`program_key`) with the fingerprints of ``options``
    replaced: the key of the same program with other values of those
    options, without hashing the program again (perf: a load of
    ``backend="auto"`` looks for both builds)."""
    return tuple((item[0], _fingerprint(options[item[0]]))
                 if isinstance(item, tuple) and len(item) == 2 and item[0] in options else item
                 for item in key)


class ProgramCache:
    """Compiled programs (:class:`plcrt.compiler.program.CompiledProgram`)
    by :func:`program_key`, least recently used first
    out.  ``hits`` and ``misses`` count lookups (the bench and the tests
    read them)."""

    def __init__(self, entries: int = DEFAULT_ENTRIES) -> None:
        self.max_entries = entries
        self._entries: OrderedDict[tuple[Any, ...], Any] = OrderedDict()
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    def get(self, key: tuple[Any, ...], program: Any) -> Any:
        """The compiled program under ``key`` if it is of ``program``, else None."""
        with self._lock:
            entry = self._entries.get(key) if self.max_entries > 0 else None
            if entry is None or not _same(entry.program, program):
                self.misses += 1
                return None
            self._entries.move_to_end(key)
            self.hits += 1
            return entry

    def peek(self, key: tuple[Any, ...], program: Any) -> Any:
        """:meth:`get` that counts no miss (a load that only looks whether
        a build of another backend is made already)."""
        with self._lock:
            entry = self._entries.get(key) if self.max_entries > 0 else None
            if entry is None or not _same(entry.program, program):
                return None
        return self.get(key, program)

    def put(self, key: tuple[Any, ...], entry: Any) -> None:
        with self._lock:
            if self.max_entries <= 0:
                return
            self._entries[key] = entry
            self._entries.move_to_end(key)
            while len(self._entries) > self.max_entries:
                self._entries.popitem(last=False)

    def drop(self, entry: Any) -> bool:
        """Forget ``entry`` (the compiled program itself, whatever its key):
        the Python build of a program whose native build has taken over
        (:mod:`plcrt.engine.tiering`), so that its memory goes with the
        last PLC running it.  True when it was kept."""
        with self._lock:
            for key, value in self._entries.items():
                if value is entry:
                    del self._entries[key]
                    return True
        return False

    def clear(self) -> None:
        """Forget every compiled program (the next load compiles)."""
        with self._lock:
            self._entries.clear()
            self.hits = self.misses = 0

    def __len__(self) -> int:
        return len(self._entries)


#: The process's cache; ``programs.max_entries = 0`` turns caching off.
programs = ProgramCache()


__all__ = ["CHUNK_LINES", "ProgramCache", "TRIM_SOURCE_CHARS", "compile_chunks", "gc_paused",
           "program_key", "programs", "release_free_memory", "with_options"]
