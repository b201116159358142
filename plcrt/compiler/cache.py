"""Loading in linear time and little memory: the compiled-program cache,
chunked compilation of the generated module, and the paused garbage
collector.

*Cache.*  Compiling is by far the largest part of a load, and a test suite
loads the same program once per test.  :class:`ProgramCache` keeps, per
program text and every option that changes the generated code, what a
compile produces (the checked unit, the generated source, its line map,
the code objects) together with a *template*: a PLC compiled from it that
never runs.  Every :class:`plcrt.engine.Plc` is built from a template, also
right after a miss, so there is one way of binding a PLC and every load
exercises it: the template's run-time bindings (timer methods, library
block objects, closures over the CPU, L buffers) are copied onto the new
PLC's own objects (:func:`rebind`).  The code objects are shared; each PLC
executes them in its own namespace, so it has its own functions whose
default arguments are its own objects.

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

import copy
import gc
import hashlib
import pickle
import threading
import types
from collections import OrderedDict, deque
from contextlib import contextmanager
from dataclasses import dataclass, field
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
# Rebinding a template's run-time objects onto a new PLC
# ---------------------------------------------------------------------------

_ATOMIC = (int, float, complex, str, bytes, bool, type(None), range, type,
           types.BuiltinFunctionType, types.ModuleType)


Path = tuple[tuple[str, Any], ...]


#: attributes of a PLC that are not its engine: the compiled program it
#: shares with the others of its entry, and its own copy of the probes
SHARED_ATTRS = frozenset({"_entry", "unit", "_bindings", "_ns", "program", "source",
                          "line_locs", "coverage"})


def object_paths(root: Any) -> dict[int, tuple[Any, Path]]:
    """The engine objects of a PLC, each with its path from the PLC
    (attribute names, list indexes and dict keys): two PLCs built by the
    same constructor have corresponding objects at the same paths, so a
    template's memory areas, timer bank, ports, devices ... are found in a
    new PLC by following the path there (:func:`pair_objects`)."""
    found: dict[int, tuple[Any, Path]] = {}
    # breadth first: an object reached two ways gets its shortest path.  The
    # whole graph is walked (a few ms: the areas are bytearrays and the
    # banks' long lists hold numbers), so a binding that refers to an
    # engine object however deep never gets a private copy of it
    todo: deque[tuple[Any, Path]] = deque([(root, ())])
    while todo:
        obj, path = todo.popleft()
        if isinstance(obj, _ATOMIC) or id(obj) in found:
            continue
        found[id(obj)] = (obj, path)
        if isinstance(obj, (list, tuple)):
            todo += [(x, path + (("i", i),)) for i, x in enumerate(obj)
                     if not isinstance(x, _ATOMIC)]
        elif isinstance(obj, dict):
            todo += [(x, path + (("k", k),)) for k, x in obj.items()
                     if not isinstance(x, _ATOMIC)]
        else:
            attrs = getattr(obj, "__dict__", None)
            if attrs is not None:
                todo += [(x, path + (("a", k),)) for k, x in attrs.items()
                         if (obj is not root or k not in SHARED_ATTRS)
                         and not isinstance(x, _ATOMIC)]
    return found


def needed_paths(template: Any, roots: list[Any]) -> list[tuple[int, Path]]:
    """The paths of the template's engine objects that its run-time
    bindings (``roots``) refer to, which is all a new PLC's memo needs.

    The walk follows what :func:`rebind` and ``copy.deepcopy`` follow
    (``gc.get_referents``: attributes, slots, items, closure cells, bound
    objects), and stops at an engine object (it is mapped whole), at
    functions without a closure, classes and modules (they are shared)."""
    engine = object_paths(template)
    needed: dict[int, Path] = {}
    seen: set[int] = set()
    todo = list(roots)
    while todo:
        obj = todo.pop()
        key = id(obj)
        if key in seen:
            continue
        seen.add(key)
        if key in engine:
            needed[key] = engine[key][1]
            continue
        if isinstance(obj, _ATOMIC) or isinstance(obj, types.CodeType):
            continue
        if isinstance(obj, types.FunctionType):
            todo += [c for c in obj.__closure__ or ()]
            continue
        if isinstance(obj, types.CellType):
            try:
                todo.append(obj.cell_contents)
            except ValueError:
                pass
            continue
        todo += [x for x in gc.get_referents(obj) if not isinstance(x, type)]
    return sorted(needed.items(), key=lambda kv: len(kv[1]))


def follow(root: Any, path: Path) -> Any:
    """The object at ``path`` from ``root`` (:func:`object_paths`), or
    None where the path does not exist."""
    obj = root
    for kind, step in path:
        try:
            obj = obj.__dict__[step] if kind == "a" else obj[step]
        except (AttributeError, KeyError, IndexError, TypeError):
            return None
    return obj


def pair_objects(template: Any, plc: Any, paths: list[tuple[int, Path]],
                 memo: dict[int, Any]) -> list[Path]:
    """Record in ``memo`` which object of ``plc`` plays the part of each
    template object in ``paths`` (:func:`needed_paths`); entries already
    in ``memo`` stay.  Returns the paths that ``plc`` lacks (none when the
    two were built alike): a binding would otherwise get a private copy of
    an engine object instead of the new PLC's own."""
    missing = []
    for key, path in paths:
        if key in memo:
            continue
        obj = follow(plc, path)
        if obj is None:
            missing.append(path)
        else:
            memo[key] = obj
    return missing


def rebind(obj: Any, memo: dict[int, Any]) -> Any:
    """A copy of the run-time binding ``obj`` of a template for a new PLC.

    ``memo`` maps the template's engine objects to the new PLC's
    (:func:`pair_objects`).  Bound methods are bound to the corresponding
    object, closures get new cells holding the corresponding objects (a
    closure over the CPU, such as the table or SPA helpers), containers are
    rebuilt, and everything else is deep-copied with the same memo, so a
    library block's reference to the CPU or a device lands on the new
    PLC's.  Plain functions and constants are shared.
    """
    key = id(obj)
    if key in memo:
        return memo[key]
    if isinstance(obj, _ATOMIC):
        return obj
    if isinstance(obj, types.FunctionType):
        if not obj.__closure__:
            return obj
        cells = tuple(_rebind_cell(c, memo) for c in obj.__closure__)
        fn = types.FunctionType(obj.__code__, obj.__globals__, obj.__name__,
                                obj.__defaults__, cells)
        fn.__kwdefaults__ = obj.__kwdefaults__
        fn.__dict__.update(obj.__dict__)
        fn.__qualname__ = obj.__qualname__
        memo[key] = fn
        return fn
    if isinstance(obj, types.MethodType):
        out: Any = types.MethodType(rebind(obj.__func__, memo), rebind(obj.__self__, memo))
        memo[key] = out
        return out
    if isinstance(obj, list):
        out = []
        memo[key] = out
        out.extend(rebind(x, memo) for x in obj)
        return out
    if isinstance(obj, tuple):
        out = tuple(rebind(x, memo) for x in obj)
        memo[key] = out
        return out
    if isinstance(obj, dict):
        out = {}
        memo[key] = out
        out.update((k, rebind(v, memo)) for k, v in obj.items())
        return out
    return copy.deepcopy(obj, memo)


def _rebind_cell(cell: types.CellType, memo: dict[int, Any]) -> types.CellType:
    key = id(cell)
    if key in memo:
        return memo[key]
    new = types.CellType()
    memo[key] = new            # closures that share a cell keep sharing it
    try:
        value = cell.cell_contents
    except ValueError:         # an empty cell (a name not assigned yet)
        return new
    new.cell_contents = rebind(value, memo)
    return new


#: mappings CPU -> state that library families keep outside the PLC
#: (:func:`per_cpu`)
_PER_CPU: list[Any] = []


def per_cpu(mapping: Any) -> Any:
    """Register ``mapping`` (a ``WeakKeyDictionary`` PLC -> the family's
    state of that CPU, such as its Modbus master) and return it: a PLC
    built from a template gets the copy of the template's state, the same
    object its library blocks were rebound to."""
    _PER_CPU.append(mapping)
    return mapping


def per_cpu_states(template: Any) -> list[Any]:
    """The template's entries of the :func:`per_cpu` mappings."""
    return [m[template] for m in _PER_CPU if template in m]


def rebind_per_cpu(template: Any, plc: Any, memo: dict[int, Any]) -> None:
    """Give ``plc`` its copy of the template's entries of every
    :func:`per_cpu` mapping."""
    for mapping in _PER_CPU:
        state = mapping.get(template)
        if state is not None:
            mapping[plc] = rebind(state, memo)


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


@dataclass
class Entry:
    """One compiled program: what every PLC of it shares, and its template."""

    program: Any
    unit: Any
    source: bytes                       #: the generated module, zlib-compressed
    line_locs: dict[int, Any]
    codes: list[types.CodeType]
    template: Any                       #: a Plc compiled from it that never runs
    #: diagnostics the template's own objects reported while compiling
    #: (library blocks' load notices), and the keys of its warn-once set
    diagnostics: list[Any] = field(default_factory=list)
    warned: set[str] = field(default_factory=set)
    #: paths of the template's engine objects its bindings refer to
    #: (:func:`needed_paths`), found when the first PLC is bound
    paths: list[tuple[int, Path]] | None = None
    #: the machine code of the native backend's segments, or None
    native: Any = None


class ProgramCache:
    """Compiled programs by :func:`program_key`, least recently used first
    out.  ``hits`` and ``misses`` count lookups (the bench and the tests
    read them)."""

    def __init__(self, entries: int = DEFAULT_ENTRIES) -> None:
        self.max_entries = entries
        self._entries: OrderedDict[tuple[Any, ...], Entry] = OrderedDict()
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    def get(self, key: tuple[Any, ...], program: Any) -> Entry | None:
        with self._lock:
            entry = self._entries.get(key) if self.max_entries > 0 else None
            if entry is None or not (entry.program is program or entry.program == program):
                self.misses += 1
                return None
            self._entries.move_to_end(key)
            self.hits += 1
            return entry

    def put(self, key: tuple[Any, ...], entry: Entry) -> None:
        with self._lock:
            if self.max_entries <= 0:
                return
            self._entries[key] = entry
            self._entries.move_to_end(key)
            while len(self._entries) > self.max_entries:
                self._entries.popitem(last=False)

    def clear(self) -> None:
        """Forget every compiled program (the next load compiles)."""
        with self._lock:
            self._entries.clear()
            self.hits = self.misses = 0

    def __len__(self) -> int:
        return len(self._entries)


#: The process's cache; ``programs.max_entries = 0`` turns caching off.
programs = ProgramCache()


__all__ = ["CHUNK_LINES", "Entry", "ProgramCache", "TRIM_SOURCE_CHARS", "compile_chunks",
           "follow", "gc_paused", "needed_paths", "object_paths", "pair_objects", "per_cpu",
           "per_cpu_states", "program_key", "programs", "rebind", "rebind_per_cpu",
           "release_free_memory"]
