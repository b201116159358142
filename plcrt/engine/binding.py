"""Compiling a program for a PLC and binding the compiled program to it.

What it is: :class:`Binding`, a mixin of :class:`plcrt.engine.runtime.Plc`:
a template PLC compiles the program once (:meth:`~Binding._compile_template`,
the entry of the program cache :mod:`plcrt.compiler.cache`), and every PLC
of the same program and options adopts that entry
(:meth:`~Binding._adopt`): the template's run-time objects are matched to
its own and the shared code objects run in its own namespace.  Also what a
PLC says of its compiled code (``source``, ``backend``).

What it is not: the compiler (:mod:`plcrt.compiler`), the cache's object
matching (:mod:`plcrt.compiler.cache`), copying a running PLC's state
(:mod:`.forking`).
"""

from __future__ import annotations

import copy
import zlib
from typing import Any

from ..compiler import compile_program
from ..compiler.cache import (Entry, compile_chunks, gc_paused, needed_paths, pair_objects,
                              per_cpu_states, program_key, programs, rebind, rebind_per_cpu)
from ..compiler.rt import CODECS, make_indirect
from ..errors import Diagnostic, PlcCompileError, PlcConfigError, PlcRuntimeError
from ..lang import ir

__all__ = ["Binding"]


class Binding:
    """Compiling and binding (a mixin of :class:`plcrt.engine.runtime.Plc`)."""

    def _compile_template(self, program: ir.Program, symbols: Any,
                          system_symbols: dict[str, str], library: bool) -> None:
        """Compile ``program`` for this PLC, which becomes the template of a
        cache entry (:mod:`plcrt.compiler.cache`): it never runs, so its
        run-time objects stay as they are at power-up for every PLC built
        from it."""
        def setup(unit: Any) -> None:
            unit.hooks["plc"] = self
            unit.hooks.update(self._parts.compile_hooks)
            unit.hooks["timers"] = self.timers
            unit.hooks["counters"] = self.counters

        before, warned = len(self.diagnostics), set(self._warned)
        with gc_paused():
            self.unit, source, self.line_locs = compile_program(
                program, self.model, symbols=symbols, system_symbols=system_symbols,
                setup=setup, probes=self.coverage, library=library,
                native=self._config["backend"] == "native")
            try:
                codes = compile_chunks(source, self.unit.chunks,
                                       f"<plcrt {program.file}>")
            except SyntaxError as e:  # a plcrt bug, never the user's: say so clearly
                raise PlcConfigError(f"internal error: generated code does not compile "
                                     f"({e.msg}, generated line {e.lineno}); please report "
                                     f"it with the program") from None
        # the emitters' compile-time tables (they refer to this template) are
        # not needed any more; the bindings hold what the code uses
        self.unit.hooks.clear()
        self._bindings = self.unit.bindings
        # the generated text is kept for plcrt dump only: compressed, it
        # is about a tenth of its size (a 100 000-statement program's 10 MiB)
        packed = zlib.compress(source.encode("utf-8"), 1)
        del source
        self._entry = Entry(program, self.unit, packed, self.line_locs, codes, self,
                            self.diagnostics[before:], self._warned - warned)
        plan = self.unit.native
        if plan is not None and plan.names:
            from ..compiler.native.jit import NativeCode
            try:
                self._entry.native = NativeCode(plan.ir, plan.names)
            except Exception as e:  # a plcrt bug or a broken llvmlite, never the user's
                raise PlcConfigError(f"internal error: the native backend cannot compile "
                                     f"this program ({type(e).__name__}: {str(e)[:200]}); "
                                     f"load it with backend='python', and please report "
                                     f"it with the program") from None
            plan.functions = []      # the IR text is compiled (and cached on disk)

    def _cached_entry(self, program: ir.Program, auto_diags: list[Diagnostic]) -> Entry:
        """The compiled program for this PLC's options, from the program
        cache or compiled now (and kept there)."""
        cfg = self._config
        key = program_key(program, cpu=self.model.name, symbols=cfg["symbols"],
                          system_symbols=cfg["system_symbols"], plant=cfg["plant"],
                          instrument=cfg["instrument"], library=cfg["library"],
                          backend=cfg["backend"])
        entry = programs.get(key, program)
        if entry is None:
            try:
                template = type(self)(program, **cfg, _template=True, _parts=self._parts)
            except PlcCompileError as e:
                e.diagnostics[:0] = auto_diags     # what was assigned, then what failed
                raise
            entry = template._entry
            programs.put(key, entry)
        return entry

    def _adopt(self, entry: Entry, auto_diags: list[Diagnostic]) -> None:
        """Bind the compiled program of ``entry`` to this PLC: the template's
        run-time objects are copied onto this PLC's own (timer bank, ports,
        devices, library blocks, closures over the CPU), and the shared code
        objects are executed in this PLC's namespace, so its functions'
        default arguments are its own objects."""
        template = entry.template
        memo: dict[int, Any] = {}
        if template.coverage is not None:
            # the probes' tables were filled while compiling: copy them
            self.coverage = copy.deepcopy(template.coverage, memo)
        if entry.paths is None:
            entry.paths = needed_paths(template, [*entry.unit.bindings.values(),
                                                  *per_cpu_states(template)])
        missing = pair_objects(template, self, entry.paths, memo)
        if missing:
            where = ".".join(str(step) for _, step in missing[0])
            raise PlcRuntimeError(f"internal error: the compiled program refers to "
                                  f"plc.{where}, which this PLC does not have")
        # constants (tables, string constants) are shared, state is this PLC's
        constants = entry.unit.constants
        self._bindings = {name: obj if name in constants else rebind(obj, memo)
                          for name, obj in entry.unit.bindings.items()}
        rebind_per_cpu(template, self, memo)
        self._entry = entry
        self.unit, self.line_locs = entry.unit, entry.line_locs
        self.diagnostics = (auto_diags + list(self.unit.diag.items) + self.diagnostics
                            + list(entry.diagnostics))
        self._warned |= entry.warned
        self._filename = f"<plcrt {self.program.file}>"
        ns: dict[str, Any] = dict(CODECS)
        ns.update(self.mem.areas)
        ird, iwr, ptr = make_indirect(self.mem.areas, self.unit.locs,
                                      self.model.sm_readonly, self.warn)
        ns.update(_ird=ird, _iwr=iwr, _ptr=ptr, _LOCS=self.unit.locs, WD=self.wd,
                  _watchdog=self._watchdog, _watchdog_wdr=self._watchdog_wdr)
        ns.update(self._bindings)
        if entry.native is not None:
            self._native = entry.native.bind(self._native_buffers())
            ns.update({f"_nseg{k}": call for k, call in enumerate(self._native.calls)})
        for code in entry.codes:
            exec(code, ns)  # noqa: S102 - source built only from validated numbers
        self._ns = ns

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
        """How the program runs: ``name`` (``"python"`` or ``"native"``) and,
        for native, ``pieces`` run as machine code, ``python`` (block,
        network, reason) of the pieces left in Python, ``segments``,
        ``compile_s`` and ``cached`` (machine code from the disk cache)."""
        name = self._config["backend"]
        plan = self.unit.native
        if name != "native" or plan is None:
            return {"name": name}
        code = self._entry.native
        return {"name": name, "pieces": plan.pieces, "python": list(plan.python),
                "segments": len(plan.names),
                "compile_s": code.compile_s if code is not None else 0.0,
                "cached": bool(code is not None and code.cached)}
