"""Compile lowered segments to machine code with llvmlite, cached on disk.

This is the only module that imports llvmlite (the ``native`` extra).  A
:class:`NativeCode` holds one compiled module (every segment of a program)
and is shared by every PLC built from the same cache entry; each PLC gets
its own context table of buffer addresses from :meth:`NativeCode.bind`.

The machine code of a module is cached in ``$PLCRT_CACHE_DIR/native`` (else
``~/.cache/plcrt/native``), keyed by a hash of the IR text, the llvmlite
version and the host CPU.  A cached file carries a hash of its own bytes and
is used only when that hash matches: a torn or foreign file is compiled
again, never loaded.  A cache that cannot be written is skipped silently:
the code is still compiled, only not kept.

Code generation runs without optimisation passes: on straight-line code of
byte loads and stores the optimiser costs more time at load than it saves
per scan, and it grows faster than linearly with function size.
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import logging
import os
import time
from pathlib import Path
from typing import Any, Callable

from .fn import SLOTS

_MAGIC = b"plcrt-native-1\n"


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


def cache_dir() -> Path:
    """Where machine code is kept: ``$PLCRT_CACHE_DIR/native``, else
    ``~/.cache/plcrt/native`` (the temporary folder without a home)."""
    base = os.environ.get("PLCRT_CACHE_DIR")
    if base:
        return Path(base) / "native"
    try:
        home = Path.home()
    except RuntimeError:          # no HOME and no password entry (a bare container)
        import tempfile
        home = Path(tempfile.gettempdir())
    return home / ".cache" / "plcrt" / "native"


class _ObjectCache:
    """llvmlite's object cache callbacks, on files with a checksum."""

    def __init__(self, key: str) -> None:
        self.path = cache_dir() / f"{key}.o"
        self.hit = False

    def load(self, _module: Any) -> bytes | None:
        try:
            data = self.path.read_bytes()
        except OSError:
            return None
        head = len(_MAGIC) + 64
        if len(data) < head or not data.startswith(_MAGIC):
            return None
        digest, body = data[len(_MAGIC):head], data[head:]
        if hashlib.sha256(body).hexdigest().encode() != digest:
            return None
        self.hit = True
        return body

    def store(self, _module: Any, body: bytes) -> None:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            tmp = self.path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_bytes(_MAGIC + hashlib.sha256(body).hexdigest().encode() + body)
            os.replace(tmp, self.path)
        except OSError:
            pass


class NativeCode:
    """One compiled module: the segment functions' addresses.

    Attributes:
        names: segment function names, in segment order.
        compile_s: seconds spent parsing and generating (or loading) code.
        cached: the machine code came from the disk cache.
    """

    def __init__(self, ir_text: str, names: list[str]) -> None:
        llvm = _llvm()
        t0 = time.perf_counter()
        self.names = names
        target = llvm.Target.from_default_triple()
        cpu = llvm.get_host_cpu_name()
        key = hashlib.sha256("\0".join((ir_text, llvm_version(), target.triple, cpu))
                             .encode()).hexdigest()[:40]
        mod = llvm.parse_assembly(ir_text)
        mod.name = key
        tm = target.create_target_machine(cpu=cpu, opt=0, codemodel="jitdefault")
        self._engine = llvm.create_mcjit_compiler(mod, tm)
        cache = _ObjectCache(key)
        self._engine.set_object_cache(cache.store, cache.load)
        self._engine.finalize_object()
        proto = ctypes.CFUNCTYPE(None, ctypes.c_void_p)
        self._fns = [proto(self._engine.get_function_address(n)) for n in names]
        self.cached = cache.hit
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


def llvm_version() -> str:
    import llvmlite
    return str(llvmlite.__version__)
