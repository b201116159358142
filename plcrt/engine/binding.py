"""Building a PLC of a compiled program: the program from the cache (or
compiled now), then its bindings resolved against this PLC's own objects.

What it is: :class:`Binding`, a mixin of :class:`plcrt.engine.runtime.Plc`:
:meth:`~Binding._compiled_program` finds the
:class:`~plcrt.compiler.program.CompiledProgram` for this PLC's options in
the program cache (:mod:`plcrt.compiler.cache`) or compiles it (no PLC is
handed to the compiler: the program is data); :meth:`~Binding._adopt`
makes this PLC an instance of it: its own copy of the probe tables, the
recipes of the bindings resolved to its own timer bank, CPU methods,
library blocks and buffers (:func:`plcrt.gen.recipe.resolve`), and the
shared code objects executed in its own namespace.  Also what a PLC says
of its compiled code (``source``, ``backend``).

What it is not: the compiler (:mod:`plcrt.compiler`), the cache, copying a
running PLC's state (:mod:`.forking`).
"""

from __future__ import annotations

import copy
import time
import zlib
from typing import Any

from ..compiler import tiermarks
from ..compiler.cache import program_key, programs, with_options
from ..compiler.program import CompiledProgram, compile_to_program
from ..compiler.rt import CODECS, make_indirect
from ..errors import Diagnostic, PlcCompileError, PlcConfigError, PlcError
from ..gen.recipe import resolve
from ..lang import ir
from .coverage import CoverageMap

__all__ = ["Binding"]

#: the options of ``Plc()`` that change the compiled program (the rest --
#: scan time, watchdog, pace, clock, entry, data -- are the PLC's own)
COMPILE_OPTIONS = ("symbols", "system_symbols", "plant", "instrument", "library", "backend")


class Binding:
    """Compiled program and bindings (a mixin of :class:`plcrt.engine.runtime.Plc`)."""

    #: seconds this PLC's load spent compiling (0: from the program cache)
    _load_s = 0.0
    #: the program cache's key of the native build (backend="auto" loads)
    _native_key: tuple[Any, ...] | None = None

    def _compiled_program(self, program: ir.Program,
                          auto_diags: list[Diagnostic]) -> CompiledProgram:
        """The compiled program for this PLC's options, from the program
        cache or compiled now (and kept there)."""
        cfg = self._config
        options = {name: cfg[name] for name in COMPILE_OPTIONS}
        if options["backend"] == "auto":
            # tiered (engine/tiering.py): the native build if it is made
            # already in this process, or if an earlier run left its
            # machine code on disk (compiler/tiermarks.py); else the Python
            # build now and the native one later
            options["backend"] = "native"
            key = self._native_key = program_key(program, cpu=self.model.name, **options)
            compiled = programs.peek(key, program)
            if compiled is not None:
                return compiled
            if tiermarks.marked(key):
                compiled = self._marked_native(key, program, options, auto_diags)
                if compiled is not None:
                    return compiled
            options["backend"] = "python"
            key = with_options(key, backend="python")
        else:
            key = program_key(program, cpu=self.model.name, **options)
        compiled = programs.get(key, program)
        if compiled is None:
            compiled = self._compile(key, program, options, auto_diags)
        return compiled

    def _compile(self, key: tuple[Any, ...], program: ir.Program, options: dict[str, Any],
                 auto_diags: list[Diagnostic]) -> CompiledProgram:
        """Compile ``program`` with ``options`` now and keep it in the
        program cache under ``key``."""
        t0 = time.perf_counter()
        try:
            compiled = compile_to_program(
                program, self.model, dict(options, cpu=self._config["cpu"]),
                probes=CoverageMap() if options["instrument"] else None,
                hooks=self._parts.compile_hooks)
        except PlcCompileError as e:
            e.diagnostics[:0] = auto_diags     # what was assigned, then what failed
            raise
        self._load_s = time.perf_counter() - t0
        programs.put(key, compiled)
        return compiled

    def _marked_native(self, key: tuple[Any, ...], program: ir.Program,
                       options: dict[str, Any], auto_diags: list[Diagnostic]
                       ) -> CompiledProgram | None:
        """The native build of a program whose machine code an earlier run
        left on disk (the machine code from the disk cache), or None when
        LLVM does not work here after all (the Python build then)."""
        from ..compiler.native.jit import usable
        if usable() is not None:
            return None
        tiermarks.touch(key)
        try:
            return self._compile(key, program, options, auto_diags)
        except PlcConfigError:        # the machine code could not be made
            return None

    def _native_maker(self, python: CompiledProgram) -> Any:
        """What compiles the native twin of ``python`` (in a worker thread:
        it holds the program and options, never this PLC) and keeps it in
        the program cache."""
        program, model, hooks = python.program, self.model, self._parts.compile_hooks
        options = dict(python.options, backend="native")
        key = self._native_key
        if key is None or python.program is not self.program:     # a PLC of a given build
            key_options = {name: options[name] for name in COMPILE_OPTIONS}
            key = program_key(program, cpu=model.name, **key_options)

        def make() -> CompiledProgram | None:
            from ..compiler.native.jit import say_fallback, usable
            why = usable()
            if why is not None:      # the PLC stays on its Python build
                say_fallback(why)
                return None
            compiled = programs.peek(key, program)
            if compiled is None:
                compiled = compile_to_program(
                    program, model, options,
                    probes=CoverageMap() if options["instrument"] else None, hooks=hooks)
                programs.put(key, compiled)
            code = compiled.native      # the machine code, made in this thread
            if code is not None and getattr(code, "stored", False):
                tiermarks.mark(key)     # the next run binds it at load
            return compiled
        return make

    def _adopt(self, compiled: CompiledProgram, auto_diags: list[Diagnostic]) -> None:
        """Make this PLC an instance of ``compiled``: its own probe tables,
        the bindings' recipes resolved against its own objects (timer bank,
        ports, library blocks, closures over the CPU, L buffers; constants
        are shared), and the shared code objects executed in its own
        namespace, so its functions' default arguments are its own objects."""
        if compiled.coverage is not None:
            # the probes' tables were filled while compiling: copy them
            self.coverage = copy.deepcopy(compiled.coverage)
        self._entry = compiled
        self.unit, self.line_locs = compiled.unit, compiled.line_locs
        self.diagnostics = auto_diags + list(self.unit.diag.items) + self.diagnostics
        # library blocks made now report to this PLC's diagnostics
        try:
            self._bindings = resolve(compiled.bindings, self)
        except PlcError:
            raise
        except Exception as e:  # a plcrt bug (a block's factory), never the user's
            raise PlcConfigError(f"internal error: the compiled program's bindings cannot "
                                 f"be made for this PLC ({type(e).__name__}: "
                                 f"{str(e)[:200]}); please report it with the program"
                                 ) from None
        self._filename = f"<plcrt {self.program.file}>"
        self._ns = self._namespace(compiled)

    def _namespace(self, compiled: CompiledProgram) -> dict[str, Any]:
        """``compiled``'s code objects executed over this PLC's buffers and
        resolved bindings (and its native segments, bound to this PLC)."""
        ns: dict[str, Any] = dict(CODECS)
        ns.update(self.mem.areas)
        ird, iwr, ptr = make_indirect(self.mem.areas, self.unit.locs,
                                      self.model.sm_readonly, self.warn)
        ns.update(_ird=ird, _iwr=iwr, _ptr=ptr, _LOCS=self.unit.locs, WD=self.wd,
                  _watchdog=self._watchdog, _watchdog_wdr=self._watchdog_wdr)
        ns.update(self._bindings)
        native = compiled.native
        if native is not None:
            self._native = native.bind(self._native_buffers())
            ns.update({f"_nseg{k}": call for k, call in enumerate(self._native.calls)})
        for code in compiled.codes:
            exec(code, ns)  # noqa: S102 - source built only from validated numbers
        return ns

    def _rebind(self, compiled: CompiledProgram) -> None:
        """Run ``compiled`` -- the other backend's build of this PLC's
        program and options, which binds the same objects under the same
        names -- from the next scan on, over this PLC's own objects (the
        switch of engine/tiering.py)."""
        if compiled.bindings.keys() != self._entry.bindings.keys():
            raise PlcConfigError("internal error: the two builds bind different state")
        self._entry = compiled
        self.unit, self.line_locs = compiled.unit, compiled.line_locs
        ns = self._ns = self._namespace(compiled)
        self._ob1 = ns[self.unit.pous[self.main_block].fname] \
            if self.main_block is not None else None
        self._int_fns = {number: ns[f"pou_INT{number}"] for number in self._int_fns}
        self._replain()

    @property
    def compiled(self) -> CompiledProgram:
        """The compiled program this PLC is an instance of (shared by every
        PLC of the same program and options; picklable)."""
        return self._entry

    @property
    def source(self) -> str:
        """The generated Python module (what ``plcrt dump`` annotates)."""
        return zlib.decompress(self._entry.source).decode("utf-8")

    def _native_buffers(self) -> dict[str, Any]:
        """The buffers the native segments reach (plcrt.compiler.native.lower.SLOTS)."""
        bufs: dict[str, Any] = dict(self.mem.areas)
        t = self.timers
        edges = self.unit.native.edges if self.unit.native is not None else None
        bufs.update(T_RUN=t.running, T_PRE=t.preset, T_D100=t.d100_buf, T_PREV=t.prev_in,
                    EDGES=self._bindings[edges] if edges else bytearray(1))
        from ..compiler.native.jit import probe_buffers
        bufs.update(probe_buffers(self.coverage))
        return bufs

    @property
    def backend(self) -> dict[str, Any]:
        """How the program runs: ``name`` (``"python"`` or ``"native"``: the
        build running now), with ``backend="auto"`` ``tiered`` (True) and
        ``python_scans`` (the scans run on the Python build before the
        native one took over, or so far; 0 with the native build bound at
        load, its machine code left on disk by an earlier run), and
        for native, ``pieces`` run as machine code, ``python`` (block,
        network, reason) of the pieces left in Python, ``segments``,
        ``compile_s`` and ``cached`` (machine code from the disk cache)."""
        name = self._entry.options.get("backend", self._config["backend"])
        plan = self.unit.native
        tier: dict[str, Any] = {}
        if self._python_scans is not None:
            # backend="auto": the scans run on the Python build first
            tier = {"tiered": True, "python_scans": self._python_scans}
        if name != "native" or plan is None:
            return {"name": name, **tier}
        code = self._entry.native
        return {**tier, "name": name, "pieces": plan.pieces, "python": list(plan.python),
                "segments": len(plan.names),
                "compile_s": code.compile_s if code is not None else 0.0,
                "cached": bool(code is not None and code.cached)}
