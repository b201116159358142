"""The PLC: a compiled program bound to a memory image, a clock and devices.

What it is: :class:`Plc` and how one is built (``__init__``: the memory
image, timers, counters, interrupts, pulse outputs, PID loops, HSCs, ports,
the devices the plant describes, then the compiled program bound to them),
what it reports of its devices (``axis``, ``drive``...), and
:func:`parse_sources`.  Its behaviour is in mixins along the engine's seams:

* :mod:`.scan` -- the scan loop (one scan, as on the S7-200, step by step);
* :mod:`.access` -- reading, writing and forcing by address;
* :mod:`.eventcalls` -- interrupts, HSC, PLS, ports: what the generated code
  and the time line call in the CPU;
* :mod:`.faults` -- faults, the watchdog, run-time warnings;
* :mod:`.binding` -- the compiled program (from the cache or compiled) and
  the PLC made an instance of it;
* :mod:`.forking` -- forks, snapshots, recompiled twins.

What it is not: reading files or plant files and fitting the PLC with
devices and library blocks: that is :mod:`plcrt.loader` (``plcrt.load``),
which reaches the engine through :mod:`plcrt.parts`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Sequence

from ..compiler.cache import gc_paused
from ..compiler.entry import check_entry, main_block
from ..compiler.program import CompiledProgram
from ..errors import Diagnostic, PlcAddressError, PlcConfigError, PlcError
from ..lang import ir
from ..memory import MemoryImage, cpu_model
from ..parts import Parts, supplied
from .access import AddressAccess
from .binding import Binding
from .clock import Clock, Station, start_time
from .counters import CounterBank
from .coverage import CoverageMap
from .device import AxisState, DriveState
from .edges import SignalEdges
from .eventcalls import EventCalls
from .events import Scheduler
from .faults import WATCHDOG_MS, WATCHDOG_US_PER_INSN, Faults
from .forking import Forking
from .hsc import Encoder, make_counters
from .interrupts import Interrupts
from .netjobs import make_ethernet
from .pid import make_loops
from .power import PowerCycle, project_cpu
from .ports import make_ports
from .pulse import make_outputs
from .scan import SMB0, ScanLoop
from .tiering import Tiering
from .timers import TimerBank
from .values import check_backend, check_parsed_inputs, scan_time_us, shown_value, source_items


class Plc(ScanLoop, EventCalls, Faults, Binding, Tiering, Forking, PowerCycle,
          AddressAccess):
    """A loaded program, ready to scan.  Create it with :func:`plcrt.load`
    (or :meth:`from_program`, another instance of a compiled program)."""

    def __init__(self, program: ir.Program, *, symbols: Any = None, data: Any = None,
                 scan_ms: float = 10.0, cpu: str | None = None,
                 system_symbols: dict[str, str] | None = None,
                 watchdog_ms: float = WATCHDOG_MS, pace: str = "simulated",
                 plant: Any = None, instrument: bool = False, library: bool = False,
                 auto_symbols: bool = False, clock: Any = None, backend: str | None = None,
                 entry: str | None = None,
                 _entry: Any = None, _parts: Parts | None = None) -> None:
        scan_us = scan_time_us(scan_ms)
        for name, flag in (("instrument", instrument), ("library", library),
                           ("auto_symbols", auto_symbols)):
            if not isinstance(flag, bool):
                raise PlcConfigError(f"{name} must be True or False, got "
                                     f"{type(flag).__name__}")
        if not isinstance(pace, str) or pace not in ("simulated", "realtime"):
            raise PlcConfigError(f"pace must be 'simulated' or 'realtime', got "
                                 f"{shown_value(pace)}")
        if isinstance(watchdog_ms, bool) or not (isinstance(watchdog_ms, (int, float))
                                                 and 0 < watchdog_ms <= 1e9):
            raise PlcConfigError(f"watchdog_ms must be a positive number of milliseconds, "
                                 f"got {shown_value(watchdog_ms)}")
        requested = backend if backend is not None else _env_backend()
        if isinstance(requested, str) and requested == "auto" and _llvmlite_importable():
            # Python at once, native when ready (engine/tiering.py); whether
            # LLVM works is found out in the compile thread
            backend = "auto"
        else:
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
        if cpu is None:         # a project file's CPU, where plcrt has its model
            cpu = project_cpu(program)
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
        if _entry is None:
            # parse -> check -> compile, before anything of this PLC exists:
            # the compiler is handed the program and options, never the PLC
            with gc_paused():
                _entry = self._compiled_program(program, auto_diags)
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
        self._entered_run = False  #: see set_mode: the next scan is a first scan
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
        #: what a library family keeps per CPU (its Modbus master, a pulse
        #: wizard's axes ...), by the family's key; made when this PLC's
        #: library blocks are (kept here, not in a table outside the PLC
        #: that would keep every PLC alive)
        self.family_states: dict[Any, Any] = {}
        if plant is not None:
            self.devices = parts.build_devices(self, plant)
            self.modules = {d.slot: d for d in self.devices if d.slot is not None}
            # I0.0–I0.3 a device drives at exact times (a machine's sensors): their
            # edges come from the time line too (engine/edges.py)
            for d in self.devices:
                for b in getattr(d, "edge_bits", ()):
                    self._edge_mask &= ~(1 << b)
        with gc_paused():
            self._adopt(_entry, auto_diags)
        a = self.mem.areas
        # perf: the buffers a scan's start and end use, unpacked once each
        self._bufs_begin = (a["I"], a["PI"], a["SM"], a["L"])
        self._clk_lo = self._clk_hi = 0    # the window of SM0.4/SM0.5 in _smb0
        self._calm_lo = self._calm_hi = 0  # see _calm_start
        self._smb0 = SMB0                   # SMB0 by scan parity (_clock)
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
        # retentive ranges, start-up mode, port addresses (engine/power.py)
        self._power_up_settings(plant, data)
        # SMW22/24/26: last, minimum and maximum scan time in ms.  SMB0..29
        # are read-only to the program, so they are written once.
        ms = min(self.scan_us // 1000, 0xFFFF).to_bytes(2, "big")
        self.mem.areas["SM"][22:28] = ms * 3
        parts.attach_port_devices(self.ports, plant)   # a plant device sends at given times
        self._replain()
        if backend == "auto":
            if _entry.options.get("backend") == "python":
                self._tier_begin(self._native_maker(_entry), self._load_s)
            else:                  # the native build at once: no scan in Python
                self._python_scans = 0

    @classmethod
    def from_program(cls, compiled: CompiledProgram, *, data: Any = None,
                     scan_ms: float = 10.0, watchdog_ms: float = WATCHDOG_MS,
                     pace: str = "simulated", clock: Any = None,
                     entry: str | None = None) -> "Plc":
        """A new PLC of ``compiled`` (:attr:`compiled` of another PLC, or
        one unpickled from another process) with its own memory, devices
        and state, compiled with the program's options; nothing is
        compiled again.  The arguments are those of :func:`plcrt.load`
        that do not change the compiled program.

        Raises:
            PlcConfigError: ``compiled`` is not a compiled program, or a bad
                run-time option.
        """
        if not isinstance(compiled, CompiledProgram):
            raise PlcConfigError(f"Plc.from_program() needs a compiled program (plc.compiled), "
                                 f"got {type(compiled).__name__}")
        return cls(compiled.program, **compiled.options, data=data, scan_ms=scan_ms,
                   watchdog_ms=watchdog_ms, pace=pace, clock=clock, entry=entry,
                   _entry=compiled)

    @property
    def now_us(self) -> int:
        """Simulated time of the current scan in µs (library blocks, devices)."""
        return self._t_us

    def module(self, slot: int) -> Any:
        """The simulated module in expansion slot ``slot`` (EmNo), or None."""
        if isinstance(slot, bool) or not isinstance(slot, int):
            raise PlcConfigError(f"a module is named by its slot, an int, got "
                                 f"{type(slot).__name__}")
        return self.modules.get(slot)

    def axis(self, slot: int = 0, axis: int = 0) -> AxisState:
        """State of one configured axis (:class:`plcrt.devices.AxisState`:
        ``a.position`` and ``a["position"]`` alike): slot, axis, position
        (the module's counter), mechanical (plant position), speed (Hz,
        signed), status, masked, stf."""
        if isinstance(slot, bool) or not isinstance(slot, int) \
                or isinstance(axis, bool) or not isinstance(axis, int):
            raise PlcAddressError(f"an axis is named by two ints, slot and axis, got "
                                  f"{shown_value(slot)}, {shown_value(axis)}")
        mod = self.modules.get(slot)
        if mod is None:
            raise PlcAddressError(f"no module in slot {shown_value(slot)}")
        for entry in mod.snapshot(self._t_us):
            if entry["axis"] == axis:
                return entry
        raise PlcAddressError(f"axis {shown_value(axis)} of slot {slot} is not configured in "
                              f"the plant")

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
                                  f"its module's slot, got {shown_value(node)}, "
                                  f"{shown_value(slot)}")
        found = [d for d in self.drives() if d.node == node and slot in (None, d.slot)]
        if not found:
            where = f" on the module in slot {shown_value(slot)}" if slot is not None else ""
            raise PlcAddressError(f"no drive at node {shown_value(node)}{where} in the plant")
        if len(found) > 1:
            raise PlcAddressError(f"node {node} is on several fieldbus modules (slots "
                                  f"{', '.join(str(d.slot) for d in found)}): name the slot")
        return found[0]

    def machine(self, name: str) -> Any:
        """The machine *name* of the plant (``[machine.NAME]``), a
        :class:`plcrt.devices.machines.Machine`: ``state()``, ``fault()``,
        ``press()`` ... (docs/machines.md)."""
        found = {m.name: m for m in self.machines()}
        if not isinstance(name, str) or name not in found:
            raise PlcAddressError(f"no machine {shown_value(name)} in the plant (its machines: "
                                  f"{', '.join(found) or 'none'})")
        return found[name]

    def machines(self) -> list[Any]:
        """Every machine of the plant, in the plant file's order (see :meth:`machine`)."""
        # the machines are the devices that hand out a view (plcrt.devices.machines)
        return [d.view() for d in self.devices if hasattr(d, "view")]

    def request_stop(self) -> None:
        """STOP instruction: finish this scan, then go to STOP mode."""
        self.stop_requested = True


def _llvmlite_importable() -> bool:
    """Whether the llvmlite package imports (what :func:`plcrt.compiler.native.jit.importable`
    says), without importing the native backend's modules: a load of
    ``backend="auto"`` that finds no machine code on disk runs the Python
    build, and a short run never needs them."""
    # perf: the bare package costs 0.2 ms; plcrt.compiler.native and its
    # jit 1.5 ms (measured 2026-12-05), 4 % of the corpus file's first load
    try:
        import llvmlite  # noqa: F401
    except ImportError:
        return False
    return True


def _env_backend() -> str:
    import os
    return os.environ.get("PLCRT_BACKEND") or "auto"


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
