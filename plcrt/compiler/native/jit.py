"""Compile lowered segments to machine code with llvmlite, cached on disk.

This is the only module that imports llvmlite.  A :class:`NativeCode`
holds the machine code of a program (every segment, compiled module by
module) and is shared by every PLC built from the same cache entry; each
PLC gets its own context table of buffer addresses from
:meth:`NativeCode.bind`.

The machine code is kept on disk (:mod:`.diskcache`: atomic writes, a
checksum, bounded in size), keyed by the modules' IR, the llvmlite version
and the host (triple, CPU name and features).

Code generation runs without optimisation passes: on straight-line code of
byte loads and stores the optimiser costs more time at load than it saves
per scan, and it grows faster than linearly with function size.
"""

from __future__ import annotations

import ctypes
import functools
import logging
import time
import zlib
from typing import Any, Callable

from ..cache import release_free_memory
from . import diskcache
from .fn import SLOTS
from .pages import release_library_pages

def available() -> bool:
    """Whether llvmlite can be imported (the ``native`` extra is installed)."""
    try:
        import llvmlite.binding  # noqa: F401
    except ImportError:
        return False
    return True


def importable() -> bool:
    """Whether the llvmlite package imports at all (perf: without loading
    LLVM's library, which :func:`usable` does, in the compile thread of
    ``backend="auto"``)."""
    try:
        import llvmlite  # noqa: F401
    except ImportError:
        return False
    return True


#: the one line said when ``backend="auto"`` falls back to Python
FALLBACK = "plcrt: the native backend is not available ({why}); running on the Python backend"

_log = logging.getLogger("plcrt")


@functools.lru_cache(maxsize=1)
def usable() -> str | None:
    """Why the native backend cannot run here, or None when it can.

    llvmlite must import and compile and run a one-instruction function (a
    wheel for another CPU, a missing LLVM library or a refused executable
    page all fail here, once per process, not in the middle of a load).
    """
    try:
        llvm = _llvm()
        target = llvm.Target.from_default_triple()
        tm = target.create_target_machine(opt=0, codemodel="jitdefault")
        mod = llvm.parse_assembly("define i32 @probe() {\nentry:\n  ret i32 7\n}\n")
        engine = llvm.create_mcjit_compiler(mod, tm)
        engine.finalize_object()
        fn = ctypes.CFUNCTYPE(ctypes.c_int32)(engine.get_function_address("probe"))
        if fn() != 7:
            return "llvmlite's machine code gives wrong results"
    except ImportError:
        return "llvmlite is not installed"
    except Exception as e:  # noqa: BLE001 - any failure means: not here
        return f"llvmlite does not work: {type(e).__name__}"
    return None


def auto_backend() -> str:
    """What ``backend="auto"`` means here: ``"native"`` where llvmlite
    imports and works, else ``"python"``, said once per process in one
    line on the ``plcrt`` logger (stderr for a command; in a pytest run it
    is shown only with a failing test or when logging output is asked for)."""
    why = usable()
    if why is None:
        return "native"
    _say_fallback(why)
    return "python"


def say_fallback(why: str) -> None:
    """Say :data:`FALLBACK` (once per process)."""
    _say_fallback(why)


@functools.lru_cache(maxsize=1)
def _say_fallback(why: str) -> None:
    _log.warning(FALLBACK.format(why=why))


@functools.lru_cache(maxsize=1)
def _llvm() -> Any:
    import llvmlite.binding as llvm
    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    return llvm


class NativeCode:
    """A program's machine code: the segment functions' addresses.

    The modules (:attr:`plcrt.compiler.native.NativePlan.modules`) are
    compiled one at a time to object code, each module's LLVM memory
    released before the next is parsed (perf: a 100 000-statement program
    as one module held 400 MiB of LLVM memory for good; module by module
    the peak stays at one module's); then one engine loads the objects and
    links them (a segment may call parts in other modules).  The objects
    come from the disk cache (:mod:`.diskcache`) when it has them.

    Attributes:
        names: segment function names, in segment order.
        compile_s: seconds spent generating (or loading) code.
        cached: the machine code came from the disk cache.
        code_bytes: the size of the object code.
    """

    def __init__(self, modules: tuple[bytes, ...] | list[bytes], names: list[str]) -> None:
        llvm = _llvm()
        t0 = time.perf_counter()
        self.names = names
        target = llvm.Target.from_default_triple()
        cpu = llvm.get_host_cpu_name()
        tm = target.create_target_machine(cpu=cpu, opt=0, codemodel="jitdefault")
        key = diskcache.make_key([llvm_version(), target.triple, cpu,
                                  llvm.get_host_cpu_features().flatten(),
                                  zlib.ZLIB_VERSION, *modules])
        objects = diskcache.load(key)
        self.cached = objects is not None
        #: the machine code is in the disk cache (found there, or kept now)
        self.stored = self.cached
        if objects is None:
            objects = [_object(llvm, tm, m) for m in modules]
            self.stored = diskcache.store(key, objects)
        self.code_bytes = sum(len(o) for o in objects)
        empty = llvm.parse_assembly("")
        self._engine = llvm.create_mcjit_compiler(empty, tm)
        while objects:                  # LLVM copies an object: drop ours at once
            self._engine.add_object_file(llvm.ObjectFileRef.from_data(objects.pop(0)))
        self._engine.finalize_object()
        proto = ctypes.CFUNCTYPE(None, ctypes.c_void_p)
        self._fns = [proto(self._engine.get_function_address(n)) for n in names]
        if len(modules) > 1:
            # a large program: hand back the modules' freed LLVM memory and
            # the library's code pages, which the machine code does not need
            # (about 100 MiB of RSS on a recent Linux kernel; .pages)
            if not self.cached:
                release_free_memory()
            release_library_pages()
        self.compile_s = time.perf_counter() - t0

    def bind(self, buffers: dict[str, Any]) -> "NativeContext":
        """A context table over one PLC's buffers (``buffers[slot]`` for
        every name in :data:`~.lower.SLOTS`), with its segment callables."""
        return NativeContext(self, buffers)


class NativeContext:
    """One PLC's table of buffer addresses and its bound segment calls.

    ``calls[k]()`` runs segment ``k`` on this PLC's memory.  The views over
    the buffers are kept here: they pin the buffers' addresses (a bytearray
    with a view cannot be resized, and the image's never are).
    """

    def __init__(self, code: NativeCode, buffers: dict[str, Any]) -> None:
        self.code = code
        self.table = (ctypes.c_void_p * len(SLOTS))()
        self._views: list[Any] = []
        self.point(buffers)
        addr = ctypes.addressof(self.table)
        # perf: the table's address is bound once; a call is one ctypes call
        self.calls: list[Callable[[], None]] = [functools.partial(fn, addr)
                                                for fn in code._fns]

    def point(self, buffers: dict[str, Any]) -> None:
        """(Re)point the table at ``buffers`` (after a restore replaced the
        timer bank's arrays)."""
        views: list[Any] = []
        for i, name in enumerate(SLOTS):
            buf = buffers[name]
            if isinstance(buf, _BREAK):    # a function, not a buffer
                views.append(buf)
                self.table[i] = ctypes.cast(buf, ctypes.c_void_p).value
                continue
            size = memoryview(buf).nbytes
            view = (ctypes.c_char * size).from_buffer(buf) if size else None
            views.append(view)
            self.table[i] = ctypes.addressof(view) if view is not None else None
        self._views = views


#: what a segment calls before a network with a breakpoint: ``(network index)``
_BREAK = ctypes.CFUNCTYPE(None, ctypes.c_int32)


def probe_buffers(coverage: Any) -> dict[str, Any]:
    """The context table's probe slots for a PLC's ``coverage`` (a
    :class:`plcrt.engine.coverage.CoverageMap`, or None without probes):
    its tables, which the PLC's Python code writes too, and a callback to
    its ``hit`` (which calls ``on_break``; it never raises, see
    :mod:`plcrt.debug.session`)."""
    if coverage is None:
        return {"NC": bytearray(1), "OC": bytearray(1), "CC": bytearray(1),
                "BP": bytearray(1), "BRK": bytearray(1)}
    return {"NC": coverage.hits, "OC": coverage.power, "CC": coverage.closed,
            "BP": coverage.breakpoints, "BRK": _BREAK(coverage.hit)}


def _object(llvm: Any, tm: Any, module: bytes) -> bytes:
    """Object code of one compressed module; its LLVM module is disposed
    at once (the text and the parsed module are the large part)."""
    mod = llvm.parse_assembly(zlib.decompress(module).decode("utf-8"))
    try:
        return bytes(tm.emit_object(mod))
    finally:
        mod.close()


def llvm_version() -> str:
    import llvmlite
    return str(llvmlite.__version__)
