"""The scan engine: a compiled program bound to a memory image and a clock.

One scan, as on the S7-200 (System Manual, "The scan cycle"); reading,
writing and forcing by address are in :mod:`.access`:

1. copy the physical inputs (PI) into the input image I;
2. special memory: SM0.0, SM0.1/SM0.3 on the first scan, the SM0.4/SM0.5
   clocks and SM0.6 scan clock from simulated time, scan-time words;
3. advance running 1 ms / 10 ms timers (100 ms timers advance in their box);
4. execute OB1 (and the subroutines it calls);
5. step simulated devices;
6. copy the output image Q to the physical outputs (PQ);
7. a STOP instruction executed in this scan switches to STOP mode now.

Simulated time is integer microseconds, advanced by a fixed scan time after
each scan: deterministic, no sleeping.  ``pace="realtime"`` sleeps to keep
wall-clock pace (for demos); it never changes results.
"""

from __future__ import annotations

import copy
import time as _time
import types
import zlib
from pathlib import Path
from typing import Any, Callable, NoReturn, Sequence

from ..compiler import compile_program
from ..compiler.cache import (Entry, compile_chunks, gc_paused, needed_paths, pair_objects,
                              per_cpu_states, program_key, programs, rebind, rebind_per_cpu)
from ..compiler.rt import CODECS, make_indirect
from ..errors import (Diagnostic, PlcAddressError, PlcCompileError, PlcConfigError, PlcError,
                      PlcRuntimeError, SourceLoc)
from ..lang import ir
from ..memory import MemoryImage, cpu_model
from .clock import Clock, Station, start_time
from .device import AxisState, DriveState
from .counters import CounterBank
from .coverage import CoverageMap
from .timers import TimerBank
from .access import AddressAccess
from .events import Scheduler
from .interrupts import Interrupts
from .edges import SignalEdges
from ..compiler.entry import check_entry, main_block
from .hsc import Encoder, make_counters
from .pid import make_loops
from .pulse import make_outputs
from .ports import make_ports
from .netjobs import make_ethernet, netr_netw
from ..parts import Parts, supplied
from .values import (MAX_STEPS, Duration, check_backend,
                     check_parsed_inputs, scan_number, scan_time_us, scan_total, source_items)


#: Estimated execution time per instruction for the watchdog (µs).  Only
#: loops (FOR/NEXT, backward jumps) are checked, and their instructions are
#: mostly word operations: even the faster S7-200 SMART needs 1.2 µs for a
#: word move (0.15 µs only for booleans), so 1.2 µs is a lower bound for the
#: classic CPU.  It also keeps an endless loop's fault well under a second
#: of wall time.
WATCHDOG_US_PER_INSN = 1.2
WATCHDOG_MS = 500  #: S7-200 watchdog time (System Manual, WDR)


class Plc(AddressAccess):
    """A loaded program, ready to scan.  Create it with :func:`plcrt.load`."""

    def __init__(self, program: ir.Program, *, symbols: Any = None, data: Any = None,
                 scan_ms: float = 10.0, cpu: str | None = None,
                 system_symbols: dict[str, str] | None = None,
                 watchdog_ms: float = WATCHDOG_MS, pace: str = "simulated",
                 plant: Any = None, instrument: bool = False, library: bool = False,
                 auto_symbols: bool = False, clock: Any = None, backend: str | None = None,
                 entry: str | None = None,
                 _entry: Any = None, _template: bool = False, _parts: Parts | None = None) -> None:
        scan_us = scan_time_us(scan_ms)
        if pace not in ("simulated", "realtime"):
            raise PlcConfigError(f"pace must be 'simulated' or 'realtime', got {pace!r}")
        if isinstance(watchdog_ms, bool) or not (isinstance(watchdog_ms, (int, float))
                                                 and 0 < watchdog_ms <= 1e9):
            raise PlcConfigError(f"watchdog_ms must be a positive number of milliseconds, "
                                 f"got {watchdog_ms!r:.40}")
        backend = check_backend(backend)
        if backend == "native":
            from ..compiler.native.jit import available
            if not available():
                from ..extras import install_hint
                raise PlcConfigError(install_hint("backend 'native' needs llvmlite, which is "
                                                  "not installed", "native"))
        if not isinstance(program, ir.Program):
            raise PlcConfigError(f"Plc() needs a parsed program; load a file or text with "
                                 f"plcrt.load(), got {type(program).__name__}")
        #: what the layers above fit this PLC with: devices, port devices,
        #: library blocks (plcrt.parts; a fork gets the same)
        self._parts = parts = _parts if _parts is not None else supplied()
        check_parsed_inputs(symbols, data, plant, parts.is_plant)
        if system_symbols is not None and not isinstance(system_symbols, dict):
            raise PlcConfigError(f"system_symbols must be a dict of name -> address, got "
                                 f"{type(system_symbols).__name__}")
        if system_symbols is None:
            from ..lang.symbols import SYSTEM_SYMBOLS
            system_symbols = dict(SYSTEM_SYMBOLS)
        self.program = program
        self.model = cpu_model(cpu)
        auto_diags: list[Diagnostic] = []
        if auto_symbols:
            # unknown symbols get free M/V addresses, each reported (docs/decisions.md)
            from ..compiler.autosym import auto_symbols as assign_symbols
            symbols, auto_diags = assign_symbols(program, self.model, symbols,
                                                 system_symbols, data)
        self.symbols = symbols
        if entry is not None:
            check_entry(entry)
            library = True   # compiled as a library; the chosen block runs as OB1 does
        # what fork() needs to build a twin (the data block is in V already)
        self._config = dict(symbols=symbols, scan_ms=scan_ms, cpu=cpu,
                            system_symbols=system_symbols, watchdog_ms=watchdog_ms,
                            pace=pace, plant=plant, instrument=instrument, library=library,
                            clock=clock, backend=backend, entry=entry)
        #: the native segments' context over this PLC's buffers, or None
        self._native: Any = None
        #: network/output coverage and breakpoints (``instrument=True`` only)
        self.coverage: CoverageMap | None = CoverageMap() if instrument else None
        #: callables ``fn(plc)`` run after every scan (traces, test harness)
        self.observers: list[Callable[[Plc], None]] = []
        #: forced addresses -> value (see :meth:`force`)
        self.forces: dict[str, int | float] = {}
        self._force_slots: list[tuple[bytearray, int, int, int, int | float]] = []
        self.mem = MemoryImage(self.model)
        self.scan_us = scan_us
        self.pace = pace
        self.mode = "RUN"
        self.fault: PlcError | None = None
        self.scans = 0
        self._t_us = 0
        self._prev_start: int | None = None
        self._stop = False         #: see stop_requested
        #: perf: the scan loop's one test (_replain): False until the end of
        #: __init__ and whenever a scan needs more than the plain path
        self._plain = False
        self.timers = TimerBank(self.mem.areas["TV"], self.mem.areas["TB"], self.model.timers)
        self.counters = CounterBank(self.mem.areas["CV"], self.mem.areas["CB"], self.model.counters)
        #: watchdog and nesting state of the scan: instructions in loops,
        #: their limit, the count before the last WDR, active subroutines
        self.wd = [0, int(watchdog_ms * 1000 / WATCHDOG_US_PER_INSN), 0, 0]
        self.devices: list[Any] = []
        #: the interrupt system; routines run through _run_interrupt
        self.interrupts = Interrupts(self.mem.areas["SM"], self._run_interrupt, self._irq_warn)
        self.interrupts.attach_timer_events(self.timers)
        #: the CPU's pulse outputs Q0.0 and Q0.1 (PLS)
        self.pulse = make_outputs(self)
        #: the PID loops 0..7 (PID)
        self.pid = make_loops(self)
        #: input bit number (I0.0 = 0) -> the output bit (Q0.0 = 0) wired to it in the plant
        self.wiring: dict[int, int] = dict(getattr(plant, "wiring", None) or {})
        #: input bit number -> the plant's encoder signal on it
        self.encoders: dict[int, Any] = {}
        for spec in getattr(plant, "encoders", None) or ():
            enc = Encoder(**spec)
            self.encoders[enc.a] = enc
        #: the high-speed counters HSC0..HSC5 (HDEF, HSC)
        self.hsc = make_counters(self)
        #: the counters that count a pulse output or an encoder (HDEF adds them):
        #: event sources of the time line, made current at every instant
        self._counted: list[Any] = []
        #: one time line for the scan interval: event sources in priority order
        #: (a counter joins when HDEF gives it a pulse output to count)
        self.edges = SignalEdges(self)
        #: the network of linked CPUs this one is in (plcrt.link), or None
        self.network: Any = None
        #: the communication ports 0 (and 1): XMT, RCV, NETR, NETW, and the
        #: Ethernet interface: GET, PUT (plcrt.engine.ports, .netjobs)
        self.ports = make_ports(self, plant)
        self.ethernet = make_ethernet(self, plant)
        self.interrupts.ports = len(self.ports)
        # perf: a port or the Ethernet interface joins the time line when it
        # first has something to do (a program without traffic asks nothing)
        self.scheduler = Scheduler(self, [self.interrupts, self.edges, *self.pulse],
                                   self._instant)
        #: I0.0–I0.3 whose edges come from a signal at exact times, not from
        #: the scan start (a pulse output or an encoder drives them)
        driven = {b for b, out in self.wiring.items() if out in (0, 1)} | set(self.encoders)
        for enc in self.encoders.values():
            if enc.b is not None:
                driven.add(enc.b)
        self._edge_mask = 0x0F & ~sum(1 << b for b in driven if b < 4)
        self._irq_t = 0            #: the time the running code executes at (µs)
        #: the counters an HDEF defined, in HDEF order (perf: the others cost nothing)
        self._defined: list[Any] = []
        self._sources = False      #: see _sources_on
        self._pi0 = 0              #: I0.0–I0.3 as the edge interrupts last saw them
        self._pi0_raw = 0          #: PIB0 as the plain scan last saw it (perf)
        self._int_l = bytearray(self.model.l_bytes)
        #: the real-time clock (TODR/TODW): from ``clock=``, else the plant
        #: file's ``[cpu] clock``, else the fixed default date
        self.clock = Clock(start_time(clock if clock is not None
                                      else getattr(plant, "clock", None)), self)
        #: the diagnostic LED and port station addresses (DLED, GPA, SPA)
        self.station = Station()
        self._acc_sm = (self.mem.areas["AC"], self.mem.areas["SM"])

        self._warned: set[str] = set()
        self.diagnostics: list[Any] = []
        self.modules: dict[int, Any] = {}
        if plant is not None:
            self.devices = parts.build_devices(self, plant)
            self.modules = {d.slot: d for d in self.devices if d.slot is not None}
        if _entry is None and _template:
            # a template of the program cache: compiled here, never run
            self._compile_template(program, symbols, system_symbols, library)
            return
        with gc_paused():
            if _entry is None:
                _entry = self._cached_entry(program, auto_diags)
            self._adopt(_entry, auto_diags)
        a = self.mem.areas
        # perf: the buffers a scan's start and end use, unpacked once each
        self._bufs_begin = (a["I"], a["PI"], a["SM"], a["L"])
        self._clk_lo = self._clk_hi = 0    # the window of SM0.4/SM0.5 in _smb0
        self._calm_lo = self._calm_hi = 0  # see _calm_start
        self._smb0 = _SMB0                  # SMB0 by scan parity (_clock)
        self._wd_used = self.unit.uses_wd
        self._bufs_end = (a["PI"], a["Q"], a["PQ"])
        ns = self._ns
        #: the block each scan runs as the main program (OB1, or ``entry``)
        self.main_block: str | None = "OB1" if "OB1" in self.unit.pous else None
        if entry is not None:
            self.main_block = main_block(self.unit, entry)
            self.diagnostics = [d for d in self.diagnostics if d.code != "no-ob1"]
        self._ob1 = (ns[self.unit.pous[self.main_block].fname]
                     if self.main_block is not None else None)
        self._int_fns = {p.number: ns[f"pou_INT{p.number}"] for p in program.pous
                         if p.kind == "INT" and f"pou_INT{p.number}" in ns}
        if data is not None:
            data.apply(self.mem.areas["V"])
        # SMW22/24/26: last, minimum and maximum scan time in ms.  SMB0..29
        # are read-only to the program, so they are written once.
        ms = min(self.scan_us // 1000, 0xFFFF).to_bytes(2, "big")
        self.mem.areas["SM"][22:28] = ms * 3
        parts.attach_port_devices(self.ports, plant)   # a plant device sends at given times
        self._replain()

    # -- the plain scan ---------------------------------------------------------
    @property
    def stop_requested(self) -> bool:
        """A STOP instruction ran: the CPU goes to STOP at the scan's end."""
        return self._stop

    @stop_requested.setter
    def stop_requested(self, value: bool) -> None:
        self._stop = value
        self._replain()

    @property
    def _sources_on(self) -> bool:
        """A PLS, HDEF, a T32/T96 or port ATCH or a port's traffic ran: the
        scan's time line has event sources (perf: see :meth:`_timeline`).
        Devices and blocks set it; the engine reads ``_sources``."""
        return self._sources

    @_sources_on.setter
    def _sources_on(self, value: bool) -> None:
        self._sources = value
        self._replain()

    def _replain(self) -> None:
        """Whether a scan can take the plain path of :meth:`scan`: no HSC
        defined, no force, no event source on the time line (PLS, HDEF,
        a timed or port interrupt, port traffic), no STOP requested, no
        plant wires or encoders, no watchdog counting, and an OB1.

        perf: the scan loop tests this one flag, so it is recomputed by
        every change of what it depends on: force/unforce, the
        ``_sources_on`` and ``stop_requested`` setters (HDEF, PLS and the
        ports set ``_sources_on``), ATCH/DTCH, a restore.  The observers
        are tested at each scan's end."""
        self._plain = not (self._defined or self._force_slots or self._sources or self._stop
                           or self.interrupts.timed_next or self.encoders or self.wiring
                           or self._wd_used or self._ob1 is None)

    # -- compiling and binding ------------------------------------------------
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
                template = Plc(program, **cfg, _template=True, _parts=self._parts)
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

    # -- time -----------------------------------------------------------
    @property
    def time(self) -> float:
        """Simulated time in seconds since power-up."""
        return self._t_us / 1e6

    # -- scanning -------------------------------------------------------
    def scan(self, n: int = 1) -> None:
        """Run ``n`` scan cycles (nothing happens in STOP mode).

        Raises:
            PlcConfigError: ``n`` is not a non-negative whole number.
            PlcRuntimeError: on a fatal fault; the CPU is left in STOP.
        """
        if type(n) is not int or not 0 <= n <= MAX_STEPS:  # perf: one test for scan(1)
            n = scan_number(n)
        if self.network is not None:
            raise PlcConfigError("this PLC is linked to others: run them together with the "
                                 "network's run() (plcrt.link), not scan() or run()")
        if self.pace == "realtime":
            for _ in range(n):
                if self.mode != "RUN":
                    return
                t0 = _time.perf_counter()
                self._scan_once()
                left = self.scan_us / 1e6 - (_time.perf_counter() - t0)
                if left > 0:
                    _time.sleep(left)
            return
        # perf: the plain scan (_replain) inline: _scan_begin's work for a
        # program without forces, HSCs, watchdog counting or event sources,
        # the devices stepped in place of the time line (_timeline), the
        # usual scan end (_scan_end: no forces, pulse generator, plant
        # wires, STOP or observers); the buffers and methods looked up once
        i_img, pi, sm, l_ob1 = self._bufs_begin
        q, pq = self._bufs_end[1:]
        steps = [dev.step for dev in self.devices]
        # perf: one device (an EM253, a drive...) is called without a loop,
        # and its quiet steps (plcrt.devices.Device: before ``quiet_to`` a
        # step stores its two ``held`` byte runs again, nothing else) are
        # done here without calling it, while ``held`` is still the tuple
        # seen now (a restore replaces it) and the device's step is its
        # class's
        step1 = steps.pop() if len(steps) == 1 else None
        dev1 = self.devices[0] if step1 is not None else None
        held = getattr(dev1, "held", None)
        if getattr(step1, "__func__", None) is not getattr(type(dev1), "step", None):
            held = None   # its step replaced on the instance (a wrapper): call it
        if held is not None and len(held) == 2:
            (hb0, hs0, hd0), (hb1, hs1, hd1) = held
        else:
            dev1 = _NOT_QUIET   # never quiet: the test below is always False
        irq, timers, ob1 = self.interrupts, self.timers, self._ob1
        scan_us, edge_mask = self.scan_us, self._edge_mask
        if self.mode != "RUN":
            return
        for _ in range(n):
            now = self._t_us
            if not self._plain:
                self._scan_once()
                if self.mode != "RUN":
                    return
                continue
            # perf: the raw byte against the one last seen here first (any
            # stale value only costs the exact test below)
            if pi[0] != self._pi0_raw or irq.queued:
                self._pi0_raw = pi[0]
                if pi[0] & edge_mask != self._pi0 or irq.queued:
                    self._input_edges(now, pi[0] & edge_mask)
            i_img[:] = pi
            scans = self.scans
            # perf: time only moves forward and a restore clears the window,
            # so the window's start (_calm_lo) is never above ``now`` here
            if now < self._calm_hi and not timers._fast:
                # perf: SMB0 for this scan's parity, the timer bank's
                # millisecond (see _calm_start)
                sm[0] = self._smb0[scans & 1]
                timers.ms1 = now // 1000
            else:
                self._calm_start(sm, scans, now)
            self._prev_start = self._irq_t = now
            try:
                ob1(l_ob1)
            except Exception as e:
                self._fault(e)
            t_to = now + scan_us
            if self._plain:   # the program can end it (ATCH, PLS, HDEF, STOP...)
                try:
                    if t_to < dev1.quiet_to and dev1.held is held:
                        hb0[hs0] = hd0
                        hb1[hs1] = hd1
                    elif step1 is not None:
                        step1(self, now, t_to)
                    else:
                        for step in steps:
                            step(self, now, t_to)
                except Exception as e:
                    self._fault(e)
                if self._plain and not self.observers:
                    pq[:] = q
                    self.scans = scans + 1
                    self._t_us = t_to
                    continue
            else:
                self._timeline(now, t_to, True)
            self._scan_end(now)   # only _scan_end can end RUN mode, else a fault raises
            if self.mode != "RUN":
                return

    def run(self, seconds: Duration | None = None, scans: int | None = None) -> None:
        """Run for a simulated duration (``1.5``, ``"1.5s"``, ``"200ms"``,
        rounded up to whole scans) or a number of ``scans``.

        Raises:
            PlcConfigError: neither or both given, or a bad value (negative,
                NaN, infinite, not a number).
        """
        self.scan(scan_total(self.scan_us, seconds, scans))

    def _scan_once(self) -> None:
        now = self._t_us
        self._scan_begin()
        # perf: the time line only once a source may have events (a timed
        # interrupt attached, or ever a PLS, an HDEF, a CT=PT interrupt or
        # a port's traffic), or a device runs
        if self.interrupts.timed_next or self._sources or self.devices:
            self._timeline(now, now + self.scan_us, True)
        self._scan_end(now)

    def _scan_begin(self) -> None:
        """A scan up to and including the main program, at its start instant."""
        # perf: buffers are bound once in __init__ (self._bufs_begin)
        i_img, pi, sm, l_ob1 = self._bufs_begin
        now = self._t_us
        if self._defined:
            for c in self._defined:
                if c.scan_start(pi, now):
                    self.scheduler.touch()
        pi0 = pi[0] & self._edge_mask
        if pi0 != self._pi0 or self.interrupts.queued:
            self._input_edges(now, pi0)
        i_img[:] = pi
        if self._force_slots:
            self._apply_forces()
        scans = self.scans
        timers = self.timers
        if not timers._fast and self._calm_lo <= now < self._calm_hi:
            # perf: SMB0 is its byte for this scan's parity, the timer bank
            # needs only its millisecond (see _calm_start)
            sm[0] = self._smb0[scans & 1]
            timers.ms1 = now // 1000
        else:
            self._calm_start(sm, scans, now)
        self._prev_start = self._irq_t = now
        if self._wd_used:   # perf: only code that counts on them reads them
            wd = self.wd
            wd[0] = wd[2] = wd[3] = 0
        try:
            if self._ob1 is not None:
                self._ob1(l_ob1)
        except Exception as e:
            self._fault(e)

    def _input_edges(self, now: int, pi0: int) -> None:
        """Input edges from the outside world (I0.0-I0.3 now ``pi0``) and
        queued interrupts at a scan's start: their routines run before the
        image is read (System Manual: the routine runs when the edge occurs;
        the image changes next scan)."""
        irq = self.interrupts
        self._irq_t = now
        try:
            self.timers.refresh_1ms(now)
            irq.edges(self._pi0, pi0, now)
            self._pi0 = pi0
            irq.dispatch(now)
        except Exception as e:
            self._fault(e)

    def _calm_start(self, sm: bytearray, scans: int, now: int) -> None:
        """SMB0 and the timer bank at a scan start, and the window of scan
        starts (_calm_lo .. _calm_hi) that change neither but SMB0's scan
        parity bit and the bank's millisecond: inside the half second the
        clocks SM0.4 and SM0.5 hold (_clock) and the bank's quiet window
        (TimerBank.quiet), never including the first scan."""
        # SM0.0 and SM0.7, SM0.1/SM0.3 on the first scan, SM0.6 on every
        # other scan, the clocks SM0.4 and SM0.5
        if not self._clk_lo <= now < self._clk_hi:
            self._clock(now)
        sm[0] = self._smb0[scans & 1] if scans else 0x8B | 0x40 | self._smb0[0]
        timers = self.timers
        if timers.quiet(now):
            timers.ms1 = now // 1000
        else:
            timers.start_scan(self._prev_start, now)
        self._calm_lo = max(self._clk_lo, timers.quiet_lo)
        self._calm_hi = min(self._clk_hi, timers.quiet_hi) if scans else 0

    def _clock(self, now: int) -> None:
        """SMB0 by scan parity (_smb0) with SM0.4 (on for the second half of
        every minute) and SM0.5 (on for the second half of every second) at
        *now*, and the half second (_clk_lo .. _clk_hi) they hold for."""
        clk = (0x10 if now % 60_000_000 >= 30_000_000 else 0) | \
            (0x20 if now % 1_000_000 >= 500_000 else 0)
        self._smb0 = (_SMB0[0] | clk, _SMB0[1] | clk)
        self._clk_lo = now - now % 500_000
        self._clk_hi = self._clk_lo + 500_000

    def _timeline(self, t_from: int, t_to: int, first: bool) -> None:
        """The scan's time line over (t_from, t_to]: events, routines, devices
        (*first*: t_from is the scan's start; a linked network runs a scan's
        time line in pieces, plcrt.engine.link)."""
        try:
            # perf: the time line only once a source may have events (a timed
            # interrupt attached, or ever a PLS, an HDEF, a CT=PT interrupt or
            # a port's traffic)
            if self.interrupts.timed_next or self._sources:
                self.scheduler.run(t_from, t_to, first)
            elif self.devices:
                for dev in self.devices:
                    dev.step(self, t_from, t_to)
        except Exception as e:
            self._fault(e)

    def _scan_end(self, now: int) -> None:
        """The scan's end: forces, outputs, the plant's wires, time."""
        pi, q, pq = self._bufs_end
        if self._force_slots:
            self._apply_forces()
        pq[:] = q
        # perf: the generators' own fields, not their `running` property,
        # and only once a PLS has run (_sources_on)
        if self._sources and any(po.trains or po.mode == "PWM" for po in self.pulse):
            # a running generator drives its terminal, not the image bit
            t_end = now + self.scan_us
            for po in self.pulse:
                if po.running:
                    _put_bit(pq, po.number, po.level(t_end))
                    po.update_segment(t_end)
                    po.retire(t_end - 1)
        if self.encoders:
            t_end = now + self.scan_us
            for enc in self.encoders.values():        # the plant's encoders: their levels
                for inp in (enc.a, enc.b):
                    if inp is not None:
                        _put_bit(pi, inp, enc.level(t_end, inp))
        if self.wiring:
            for inp, out in self.wiring.items():      # the plant's wires: output -> input
                _put_bit(pi, inp, pq[out // 8] >> (out % 8) & 1)
        self.scans += 1
        self._t_us = now + self.scan_us
        if self._stop:
            # STOP instruction: the scan completes, then the CPU switches to
            # STOP and the outputs take their STOP state (off).
            self.mode = "STOP"
            pq[:] = bytes(len(pq))
        if self.observers:
            for fn in self.observers:
                fn(self)

    def _run_interrupt(self, number: int) -> None:
        """Run INT *number* now.  The CPU saves and restores the
        accumulators and the status bits SMB1 around a routine (System
        Manual, "System support for interrupts")."""
        fn = self._int_fns.get(number)
        if fn is None:
            return
        acc, sm = self._acc_sm
        saved_ac, saved_sm1 = bytes(acc), sm[1]
        try:
            fn(self._int_l)
        finally:
            acc[:] = saved_ac
            sm[1] = saved_sm1

    def _instant(self, t: int) -> None:
        """After the events of one instant: 1 ms timers and counters current,
        then the routines."""
        timers = self.timers
        if timers._fast:                # perf: no call without a running 1 ms timer
            timers.refresh_1ms(t)
        for c in self._counted:
            c.sync(t)
        irq = self.interrupts
        if irq.queued:                  # perf: nothing to run for an unattached event
            self._irq_t = t
            irq.dispatch(t)

    def _hdef(self, number: int, mode: int) -> None:
        self._sources_on = True
        counter = self.hsc[number]
        counter.hdef(mode, self._irq_t)
        if counter.mode is not None and counter not in self._defined:
            self._defined.append(counter)
        self.scheduler.touch()
        if counter.pulse is not None and counter not in self._counted:
            self._counted.append(counter)
            self.scheduler.add(counter)

    def _hsc(self, number: int) -> None:
        self.hsc[number].hsc(self._irq_t)
        self.scheduler.touch()

    def _pls(self, number: int) -> None:
        self.pulse[number].pls(self._irq_t)
        self._sources_on = True
        self.scheduler.touch()

    def _wake(self, source: Any) -> None:
        """A port's (or the Ethernet interface's) next event moved: a
        character on its way, a job; it joins the time line the first time."""
        self._sources_on = True
        if source.joined:
            self.scheduler.touch()
        else:
            source.joined = True
            self.scheduler.add(source)

    def _xmt(self, port: int, ptr: int) -> bool:
        return self.ports[port].xmt(self._irq_t, ptr)

    def _rcv(self, port: int, ptr: int) -> bool:
        return self.ports[port].rcv(self._irq_t, ptr)

    def _net(self, port: int, ptr: int, kind: str) -> bool:
        return netr_netw(self.ports[port], self._irq_t, ptr, kind)

    def _getput(self, ptr: int, kind: str) -> bool:
        return self.ethernet.get_put(self._irq_t, ptr, kind)

    def _irq_warn(self, message: str, key: str) -> None:
        self.warn(message, None, key)

    def _irq_attach(self, number: int, event: int) -> None:
        self.interrupts.attach(number, event, self._irq_t)
        if event in (21, 22) or (event < 8 and (self.wiring or self.encoders)):
            self._sources_on = True
        self.scheduler.touch()
        self._replain()   # a timed interrupt

    def _irq_detach(self, event: int) -> None:
        self.interrupts.detach(event)
        self.scheduler.touch()
        self._replain()

    def _irq_enable(self) -> None:
        self.interrupts.enable(self._irq_t)

    def _fault(self, exc: Exception) -> NoReturn:
        """Stop on an exception raised while executing: a PlcError as it is,
        anything else as an internal error at the program location it came
        from."""
        if isinstance(exc, PlcError):
            self._fail(exc)
        self._fail(PlcRuntimeError(f"internal error while executing: {exc!r}",
                                   self._loc_from_tb(exc)), exc)

    def _fail(self, err: PlcError, cause: BaseException | None = None) -> NoReturn:
        self.mode = "STOP"
        self.fault = err
        m = self.mem.areas
        m["PQ"][:] = bytes(len(m["PQ"]))  # outputs go to their STOP state (off)
        raise err from cause

    def _loc_from_tb(self, exc: BaseException) -> SourceLoc | None:
        tb = exc.__traceback__
        loc = None
        while tb is not None:
            if tb.tb_frame.f_code.co_filename == self._filename:
                lineno = tb.tb_lineno
                # the nearest instruction comment above the failing line
                for ln in range(lineno, 0, -1):
                    if ln in self.line_locs:
                        loc = self.line_locs[ln]
                        break
            tb = tb.tb_next
        return loc

    def _watchdog(self, kind: str, number: int, pc: int, target: int) -> None:
        """The scan's loops ran past the watchdog time; ``pc`` is the piece
        of block ``kind``+``number`` that jumped back to piece ``target``."""
        info = self.unit.pous[f"{kind}{number}"]
        # the NEXT, or the JMP to the target's label (a piece may hold more
        # instructions after its JMP)
        back = next((i for i in reversed(info.pieces[pc].insns) if i.mnemonic == "NEXT"
                     or i.mnemonic == "JMP" and i.operands
                     and info.labels.get(_int_or_none(i.operands[0].text)) == target),
                    None)
        start = next((f for _b, (body, _e, f) in info.loops.items() if body == target), None)
        if start is None and info.pieces[target].insns:
            start = info.pieces[target].insns[0]    # the LBL a JMP goes back to
        where = ""
        if start is not None and back is not None:
            where = (f" in the loop from {start.mnemonic} at line {start.loc.line} to "
                     f"{back.mnemonic} at line {back.loc.line}")
        loc = start.loc.within(info.pou.ident, _network_of(info, start)) if start else None
        raise PlcRuntimeError(
            f"watchdog: the scan ran longer than {WATCHDOG_MS} ms{where} of {kind}{number} "
            f"({self._loop_work()}); the CPU goes to STOP", loc)

    def _watchdog_wdr(self, insn_id: int) -> None:
        """A loop that retriggers the watchdog with WDR ran ten times the
        watchdog time in one scan (the limit plcrt puts on it)."""
        loc = self.unit.locs[insn_id] if 0 <= insn_id < len(self.unit.locs) else None
        line = f" at line {loc.line}" if loc is not None else ""
        raise PlcRuntimeError(
            f"watchdog: the loop around WDR{line} ran ten times the {WATCHDOG_MS} ms watchdog "
            f"time in one scan ({self._loop_work()}); WDR retriggers the watchdog, but plcrt "
            f"stops a scan that never ends; the CPU goes to STOP", loc)

    def _nesting_exceeded(self, insn_id: int) -> None:
        """A CALL that would nest a ninth subroutine level: the CPU does not
        execute it, sets SM4.3 (run-time programming error, code 0008) and
        gives ENO 0; plcrt warns once per CALL (System Manual, CALL)."""
        self.mem.areas["SM"][4] |= 0x08
        loc = self.unit.locs[insn_id] if 0 <= insn_id < len(self.unit.locs) else None
        self.warn("CALL not executed: it would nest subroutines deeper than the S7-200's "
                  "limit of 8 levels (run-time error 0008; SM4.3 set, ENO 0)", loc,
                  f"nesting:{insn_id}")

    def _loop_work(self) -> str:
        """``about N instructions in loops, about T s`` of this scan (WDR
        resets included)."""
        n = self.wd[0] + self.wd[2]
        return (f"about {n} instructions in loops, about {n * WATCHDOG_US_PER_INSN / 1e6:.2g} s "
                f"at {WATCHDOG_US_PER_INSN} \u00b5s each")

    @property
    def now_us(self) -> int:
        """Simulated time of the current scan in µs (library blocks, devices)."""
        return self._t_us

    def warn(self, message: str, loc: SourceLoc | None, key: str) -> None:
        """A run-time diagnostic (reported once per ``key``)."""
        if key in self._warned:
            return
        self._warned.add(key)
        from ..errors import Diagnostic
        self.diagnostics.append(Diagnostic("warning", message, loc, "runtime"))

    def module(self, slot: int) -> Any:
        """The simulated module in expansion slot ``slot`` (EmNo), or None."""
        return self.modules.get(slot)

    def axis(self, slot: int = 0, axis: int = 0) -> AxisState:
        """State of one configured axis (:class:`plcrt.devices.AxisState`:
        ``a.position`` and ``a["position"]`` alike): slot, axis, position
        (the module's counter), mechanical (plant position), speed (Hz,
        signed), status, masked, stf."""
        if isinstance(slot, bool) or not isinstance(slot, int) \
                or isinstance(axis, bool) or not isinstance(axis, int):
            raise PlcAddressError(f"an axis is named by two ints, slot and axis, got "
                                  f"{slot!r:.40}, {axis!r:.40}")
        mod = self.modules.get(slot)
        if mod is None:
            raise PlcAddressError(f"no module in slot {slot}")
        for entry in mod.snapshot(self._t_us):
            if entry["axis"] == axis:
                return entry
        raise PlcAddressError(f"axis {axis} of slot {slot} is not configured in the plant")

    def axes(self) -> list[AxisState]:
        """State of every configured axis (see :meth:`axis`)."""
        return [e for _, m in sorted(self.modules.items()) for e in m.snapshot(self._t_us)]

    def drives(self) -> list[DriveState]:
        """State of every CiA 402 drive on a fieldbus module of the plant
        (:class:`plcrt.devices.DriveState`), in slot and node order."""
        return [e for _, m in sorted(self.modules.items())
                if hasattr(m, "drive_states") for e in m.drive_states(self._t_us)]

    def drive(self, node: int, slot: int | None = None) -> DriveState:
        """State of the drive at bus address *node* (on the fieldbus module
        in *slot*, or the only one with that node): slot, node, model, state,
        statusword, controlword, mode, position, velocity, following_error,
        error_code, online."""
        if isinstance(node, bool) or not isinstance(node, int) or \
                (slot is not None and (isinstance(slot, bool) or not isinstance(slot, int))):
            raise PlcAddressError(f"a drive is named by its node address (int) and optionally "
                                  f"its module's slot, got {node!r:.40}, {slot!r:.40}")
        found = [d for d in self.drives() if d.node == node and slot in (None, d.slot)]
        if not found:
            where = f" on the module in slot {slot}" if slot is not None else ""
            raise PlcAddressError(f"no drive at node {node}{where} in the plant")
        if len(found) > 1:
            raise PlcAddressError(f"node {node} is on several fieldbus modules (slots "
                                  f"{', '.join(str(d.slot) for d in found)}): name the slot")
        return found[0]

    def request_stop(self) -> None:
        """STOP instruction: finish this scan, then go to STOP mode."""
        self.stop_requested = True

    # -- snapshots ------------------------------------------------------------
    def fork(self) -> Plc:
        """An independent twin in exactly this state (memory, timers,
        counters, edges, library blocks, devices, time, forces); running one
        never affects the other."""
        # the same compiled program (never compiled again, cached or not)
        twin = Plc(self.program, **self._config, _entry=self._entry, _parts=self._parts)
        self._copy_state(twin)
        return twin

    def _twin_at_power_up(self) -> Plc:
        """:meth:`fork` of a PLC that has not been touched since its load
        (the pytest plugin's power-up PLCs, which no test sees): a new PLC
        of the same compiled program with this one's memory (the data
        block).  Everything else already is as the load left it, so nothing
        needs deep-copying (perf: a fraction of a fork's time)."""
        twin = Plc(self.program, **self._config, _entry=self._entry, _parts=self._parts)
        dareas = twin.mem.areas
        for k, buf in self.mem.areas.items():
            dareas[k][:] = buf
        return twin

    def snapshot(self) -> Plc:
        """The current state, to :meth:`restore` later (a stopped twin)."""
        return self.fork()

    def restore(self, snapshot: Plc) -> None:
        """Go back to a state taken with :meth:`snapshot` of this PLC or of
        a fork of it (the same program object, compiled the same way).

        Raises:
            PlcConfigError: ``snapshot`` is not a snapshot, or it was taken
                from a different program, or from the same parsed program
                compiled with other options (symbols, CPU, plant, probes), or this
                PLC is linked to others (plcrt.link).
        """
        if not isinstance(snapshot, Plc):
            raise PlcConfigError(f"restore() needs a snapshot made by snapshot(), got "
                                 f"{type(snapshot).__name__}")
        if snapshot.program is not self.program:
            raise PlcConfigError("this snapshot was taken from a different program")
        if self.network is not None:
            raise PlcConfigError("this PLC is linked to others (plcrt.link): going back in time "
                                 "would break what they exchanged; restore before linking, or "
                                 "fork and restore the unlinked twin")
        if (snapshot._entry.source != self._entry.source or snapshot.model != self.model
                or len(snapshot.devices) != len(self.devices)
                or (snapshot.coverage is None) != (self.coverage is None)):
            raise PlcConfigError("this snapshot was taken from the same program compiled "
                                 "with other options (symbols, CPU, plant or instrumentation); "
                                 "restore it into a PLC loaded the same way")
        snapshot._copy_state(self)

    def recompiled(self, *, instrument: bool | None = None,
                   backend: str | None = None) -> Plc:
        """This PLC's program compiled with other probes or another code
        generator, in exactly this PLC's state (memory, timers, counters,
        edges, library blocks, devices, time, forces), as :meth:`fork` gives
        a twin compiled the same way.  The coverage counts start empty.

        A tool that shows breakpoints only now and then runs the fast
        build (no probes, the native backend) and moves to an instrumented
        one while a breakpoint is set, without losing a scan.

        Raises:
            PlcConfigError: a bad ``backend``, or ``native`` without llvmlite.
        """
        cfg = dict(self._config)
        if instrument is not None:
            cfg["instrument"] = bool(instrument)
        if backend is not None:
            cfg["backend"] = check_backend(backend)
        if cfg == self._config:
            return self.fork()
        twin = Plc(self.program, **cfg, _parts=self._parts)
        self._copy_state(twin, across=True)
        return twin

    def _copy_state(self, dst: Plc, across: bool = False) -> None:
        """Make ``dst`` (the same program, compiled the same way) equal to self.

        Everything stateful is either a memory buffer (copied in place) or a
        Python object bound into the generated code or held by the engine
        (timer and counter banks, library blocks, devices); those are deep-
        copied in one pass with a memo that maps each of our objects to its
        twin, so references between them (a block's axis, an axis's
        end-of-move handler) land on the twin's objects.
        """
        areas, dareas = self.mem.areas, dst.mem.areas
        memo: dict[int, Any] = {id(self): dst, id(self.mem): dst.mem}
        for k, buf in areas.items():
            dareas[k][:] = buf
            memo[id(buf)] = dareas[k]
        pairs: list[tuple[Any, Any]] = [(self.timers, dst.timers),
                                        (self.counters, dst.counters),
                                        (self.interrupts, dst.interrupts),
                                        *zip(self.pulse, dst.pulse),
                                        (self.pid, dst.pid),
                                        (self.edges, dst.edges),
                                        (self.clock, dst.clock), (self.station, dst.station),
                                        *zip(self.hsc, dst.hsc),
                                        *zip(self.ports, dst.ports),
                                        (self.ethernet, dst.ethernet)]
        pairs += list(zip(self.devices, dst.devices))
        constants = self.unit.constants   # shared, read-only: nothing to copy
        for name, obj, other in (_binding_pairs(self, dst) if across else
                                 ((n, o, dst._bindings.get(n))
                                  for n, o in self._bindings.items() if n not in constants)):
            if other is None or type(other) is not type(obj):
                raise PlcConfigError("internal error: the twin was compiled differently")
            if isinstance(obj, bytearray):
                other[:] = obj
                memo[id(obj)] = other
            elif isinstance(obj, list) and all(isinstance(b, bytearray) for b in obj):
                for mine, theirs in zip(obj, other):   # L buffers per nesting level
                    theirs[:] = mine
                    memo[id(mine)] = theirs
            elif isinstance(obj, (types.FunctionType, types.MethodType,
                                  types.BuiltinFunctionType)):
                continue   # code and bound methods of the banks: no own state
            elif hasattr(obj, "__dict__"):
                pairs.append((obj, other))   # library blocks
            else:
                raise PlcConfigError(f"internal error: cannot copy the state of "
                                     f"{type(obj).__name__}")
        for a, b in pairs:
            memo[id(a)] = b
        # a twin is not linked: what links other CPUs stays here
        if self.network is not None:
            memo[id(self.network)] = None
            for port in self.ports:
                if port.peer is not None and hasattr(port.peer, "other"):
                    memo[id(port.peer)] = None
        states = copy.deepcopy([a.__dict__ for a, _ in pairs], memo)
        for (_, b), state in zip(pairs, states):
            b.__dict__.clear()
            b.__dict__.update(state)
        dst.modules = {d.slot: d for d in dst.devices if d.slot is not None}
        if dst._native is not None:
            # the timer bank's arrays were replaced by copies: point the
            # native segments at them
            dst._native.point(dst._native_buffers())
        dst._int_l[:] = self._int_l
        dst._counted[:] = [dst.hsc[c.number] for c in self._counted]   # HDEF order
        dst._defined[:] = [dst.hsc[c.number] for c in self._defined]
        for port in (*dst.ports, dst.ethernet):
            port.drop_links()
        # the sources that joined the time line, in the order they joined
        twin = {id(c): dst.hsc[c.number] for c in self._counted}
        twin.update({id(p): dst.ports[p.number] for p in self.ports})
        twin[id(self.ethernet)] = dst.ethernet
        dst.scheduler.reset([dst.interrupts, dst.edges, *dst.pulse,
                             *(twin[id(s)] for s in self.scheduler.sources[4:])])
        for name in ("scans", "_t_us", "_prev_start", "mode", "fault", "stop_requested",
                     "_irq_t", "_pi0", "_sources_on"):
            setattr(dst, name, getattr(self, name))
        dst._calm_hi = 0   # its timer bank and scan count are ours now
        dst._warned = set(self._warned)
        dst.diagnostics = list(self.diagnostics)
        dst.wd[:] = self.wd
        dst.forces = {}
        dst._force_slots = []
        for key, value in self.forces.items():
            dst.force(key, value)
        dst._replain()


def _binding_pairs(src: Plc, dst: Plc) -> list[tuple[str, Any, Any]]:
    """(name, object, twin's object) for every stateful binding of ``src``,
    matched with ``dst``, a build of the same program with other probes or
    another backend.

    Names are numbered in the order the code generator bound its objects,
    and probes take numbers of their own, so the k-th binding of a kind
    (``_EM``, ``_blk``, ...) in one build is the k-th of that kind in the
    other.  The probes' own buffers and methods have no twin: skipped.
    """
    def stateful(plc: Plc) -> dict[str, list[tuple[int, str, Any]]]:
        cov = plc.coverage
        own = () if cov is None else (cov.hits, cov.power, cov.closed, cov.breakpoints)
        kinds: dict[str, list[tuple[int, str, Any]]] = {}
        for name, obj in plc._bindings.items():
            if isinstance(obj, (types.FunctionType, types.MethodType,
                                types.BuiltinFunctionType)) or any(obj is b for b in own) \
                    or name in plc.unit.constants:
                continue
            kind = name.rstrip("0123456789")
            kinds.setdefault(kind, []).append((int(name[len(kind):] or 0), name, obj))
        return kinds

    mine, theirs = stateful(src), stateful(dst)
    pairs = []
    for kind, objs in mine.items():
        others = sorted(theirs.get(kind, []))
        if len(others) != len(objs):
            raise PlcConfigError("internal error: the two builds bind different state")
        for (_, name, obj), (_, _, other) in zip(sorted(objs), others):
            if getattr(obj, "loc", None) != getattr(other, "loc", None):
                raise PlcConfigError("internal error: the two builds bind different state")
            pairs.append((name, obj, other))
    return pairs


class _NotQuiet:
    """The scan loop's stand-in for a device without held runs: never quiet."""

    quiet_to = -1
    held = None


_NOT_QUIET = _NotQuiet()

#: SMB0 of every scan but the first, by the scan count's parity: SM0.0
#: (always on), SM0.7 (RUN switch position), SM0.6 (on every other scan)
_SMB0 = (0x81 | 0x40, 0x81)


def _put_bit(buf: bytearray, n: int, level: int) -> None:
    """Bit *n* of *buf* (byte n // 8, bit n % 8) := *level*."""
    mask = 1 << (n % 8)
    buf[n // 8] = buf[n // 8] | mask if level else buf[n // 8] & ~mask & 0xFF


def _int_or_none(text: str) -> int | None:
    t = text.strip()
    return int(t) if t.isdigit() and len(t) <= 3 else None


def _network_of(info: Any, insn: ir.Insn) -> int | None:
    """The number of the network of ``info``'s block that holds ``insn``."""
    for piece in info.pieces:
        if any(i is insn for i in piece.insns):
            return piece.network.number
    return None


def _text_or_path(x: Any, encoding: str | None = None,
                  limit: int | None = None) -> tuple[str, str]:
    """(text, file name) for a path or literal text argument; a file is
    read, and text accepted, up to ``limit`` bytes/characters (default:
    :mod:`plcrt.lang.limits`)."""
    from ..lang import read_source
    from ..lang.limits import check_text_size, file_limit
    if limit is None:
        limit = file_limit()
    if isinstance(x, Path):
        return read_source(x, encoding, limit), str(x)
    s = str(x)
    if "\n" not in s and len(s) < 4096:
        return read_source(s, encoding, limit), s
    check_text_size(s, "<string>", limit)
    return s, "<string>"


def parse_sources(sources: str | Path | Sequence[str | Path], *,
                  encoding: str | None = None,
                  max_file_mb: float | None = None) -> ir.Program:
    """Parse one program file or text, or several (their blocks are merged,
    as Micro/WIN keeps OB1 and its subroutines in one project).  Files
    larger than ``max_file_mb`` (default: :mod:`plcrt.lang.limits`) are
    refused."""
    from ..lang.limits import file_limit
    from ..lang.sources import read_program
    return read_program(source_items(sources), encoding=encoding,
                        max_bytes=file_limit(max_file_mb))[0]


__all__ = ["Plc", "parse_sources"]
