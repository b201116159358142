"""The compiled program: what parse -> check -> compile produces, once.

What it is: :class:`CompiledProgram`, an immutable value shared by every
PLC of one program and options (through the program cache,
:mod:`.cache`), picklable, so a program compiled in one process runs in
another; and :func:`compile_to_program`, which makes one.  It holds the
checked unit (blocks, instruction locations, the native plan), the code
objects of the generated module, its source (compressed, for ``plcrt
dump``), the line map, the probe tables of an instrumented build and the
*bindings as data*: a table of generated name -> recipe
(:mod:`plcrt.gen.recipe`: "the CPU's timer bank's ``ton``", "a new L
buffer of 64 bytes", "the library block of this call site") or a constant
every PLC shares (a lookup table, a plain function).

A PLC is an instance of it (:meth:`plcrt.engine.runtime.Plc.from_program`):
the engine resolves the recipes against the new PLC's own objects and
executes the code objects in the PLC's own namespace.  Nothing here holds
a PLC, a timer bank or a device: the compiler is never handed one.

What it is not: the compiler (:func:`plcrt.compiler.compile_program`), the
cache (:mod:`.cache`), binding a PLC (:mod:`plcrt.engine.binding`).
"""

from __future__ import annotations

import marshal
import types
import zlib
from dataclasses import dataclass, field
from typing import Any, Mapping

from ..errors import PlcConfigError
from ..gen.recipe import Call, buffers, is_recipe
from ..lang import ir
from ..memory.cpu import CpuModel
from . import compile_program
from .cache import compile_chunks, gc_paused

__all__ = ["CompiledProgram", "compile_to_program"]

_SHARED = (types.FunctionType, types.BuiltinFunctionType, type)


@dataclass(frozen=True, eq=False)
class CompiledProgram:
    """One program compiled with one set of options (see the module
    docstring).  Equal programs compare by identity: the cache decides
    which are the same."""

    program: ir.Program
    #: the options it was compiled with, as ``Plc()`` takes them (``cpu``,
    #: ``symbols``, ``system_symbols``, ``plant``, ``instrument``,
    #: ``library``, ``backend``): a PLC built from it uses them
    options: Mapping[str, Any]
    unit: Any                           #: the checked unit; its ``bindings`` are recipes
    source: bytes                       #: the generated module, zlib-compressed
    line_locs: dict[int, Any]
    codes: tuple[types.CodeType, ...]
    #: the native segments' LLVM modules (IR text, each zlib-compressed), or None
    native_ir: tuple[bytes, ...] | None = None
    #: the machine code of the native segments (made again after unpickling)
    _native: Any = field(default=None, repr=False)

    @property
    def bindings(self) -> dict[str, Any]:
        """Generated name -> recipe or shared constant."""
        return self.unit.bindings

    @property
    def coverage(self) -> Any:
        """The probe tables of an instrumented build (every PLC copies
        them), or None."""
        return self.unit.probes

    @property
    def native(self) -> Any:
        """The machine code of the native segments, or None (compiled at
        first use after unpickling; the disk cache makes that cheap)."""
        if self._native is None and self.native_ir is not None:
            object.__setattr__(self, "_native", _native_code(self.native_ir,
                                                             self.unit.native.names))
        return self._native

    def __getstate__(self) -> dict[str, Any]:
        # code objects do not pickle: marshal them (the same interpreter
        # version loads them); the machine code is made again
        state = dict(self.__dict__)
        state["codes"] = [marshal.dumps(c) for c in self.codes]
        state["_native"] = None
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        state = dict(state)
        state["codes"] = tuple(marshal.loads(c) for c in state["codes"])
        self.__dict__.update(state)


def compile_to_program(program: ir.Program, model: CpuModel, options: Mapping[str, Any], *,
                       probes: Any = None, hooks: Mapping[str, Any] | None = None
                       ) -> CompiledProgram:
    """Check and compile ``program`` for ``model`` with ``options`` (see
    :attr:`CompiledProgram.options`).

    Args:
        probes: empty probe tables to fill (``instrument``: a
            :class:`plcrt.engine.coverage.CoverageMap`), or None.
        hooks: the compile-time hooks of the layers above (``library_call``,
            ``protected_call``: :mod:`plcrt.parts`).

    Raises:
        PlcCompileError: the program's errors; PlcConfigError: a plcrt bug
            in the generated code or the native backend.
    """
    with gc_paused():
        unit, source, line_locs = compile_program(
            program, model, symbols=options.get("symbols"),
            system_symbols=options.get("system_symbols"), hooks=hooks,
            plant=options.get("plant"), probes=probes, library=bool(options.get("library")),
            native=options.get("backend") == "native")
        try:
            codes = compile_chunks(source, unit.chunks, f"<plcrt {program.file}>")
        except SyntaxError as e:  # a plcrt bug, never the user's: say so clearly
            raise PlcConfigError(f"internal error: generated code does not compile "
                                 f"({e.msg}, generated line {e.lineno}); please report "
                                 f"it with the program") from None
    # the emitters' compile-time tables are not needed any more
    unit.hooks.clear()
    unit.current = unit.current_piece = None
    unit.bindings = _as_data(unit.bindings, unit.constants)
    # the generated text is kept for plcrt dump only: compressed, it is
    # about a tenth of its size (a 100 000-statement program's 10 MiB)
    packed = zlib.compress(source.encode("utf-8"), 1)
    del source
    native = native_ir = None
    plan = unit.native
    if plan is not None and plan.names:
        plan.finish()
        native_ir, plan.modules = tuple(plan.modules), []
        native = _native_code(native_ir, plan.names)
    return CompiledProgram(program, dict(options), unit, packed, line_locs, tuple(codes),
                           native_ir, native)


def _as_data(bindings: dict[str, Any], constants: set[str]) -> dict[str, Any]:
    """The bindings as a table every PLC resolves for itself: recipes stay,
    constants and plain functions are shared, and a buffer the generated
    code keeps state in (an edge memory, a call's L buffer) becomes a
    recipe for a new one with the same contents."""
    table: dict[str, Any] = {}
    for name, obj in bindings.items():
        if is_recipe(obj) or name in constants:
            table[name] = obj
        elif isinstance(obj, bytearray):
            table[name] = Call(bytearray, (bytes(obj),))
        elif isinstance(obj, list) and all(isinstance(b, bytearray) for b in obj):
            table[name] = Call(buffers, (tuple(bytes(b) for b in obj),))
        elif isinstance(obj, _SHARED) and not getattr(obj, "__closure__", None):
            table[name] = obj
        else:
            raise PlcConfigError(f"internal error: the generated code binds a "
                                 f"{type(obj).__name__} ({name}) that is neither a recipe "
                                 f"nor a constant; please report it with the program")
    return table


def _native_code(modules: tuple[bytes, ...], names: list[str]) -> Any:
    # perf: llvmlite is imported for the native backend only
    from .native.jit import NativeCode
    try:
        return NativeCode(modules, names)
    except Exception as e:  # a plcrt bug or a broken llvmlite, never the user's
        raise PlcConfigError(f"internal error: the native backend cannot compile "
                             f"this program ({type(e).__name__}: {str(e)[:200]}); "
                             f"load it with backend='python', and please report "
                             f"it with the program") from None
