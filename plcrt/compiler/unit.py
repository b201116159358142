"""The data of one compilation: the unit, its blocks and their pieces.

:class:`Unit` is everything shared while one program is compiled (the
model, the symbols, the diagnostics, the run-time objects the generated
code binds, the instruction locations); :class:`PouInfo` is one block of
it and :class:`Piece` one generated function's instructions;
:class:`Compiled` is the result.  The emitters of :mod:`plcrt.isa` see the
unit and the current block and piece through ``Gen.unit`` (duck-typed: they
never import this module).

It builds nothing: :mod:`.pieces` fills a unit, :mod:`.codegen` generates
its module.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from ..errors import DiagnosticSink, SourceLoc
from ..gen.resolve import LocalVar
from ..lang import ir
from ..memory.cpu import CpuModel
from .locs import LineLocs, LocTable


@dataclass(slots=True)
class Piece:
    """Instructions of one network (or of a part of it between cuts) that
    become one generated function; a program keeps one per network, so
    slots and a slice of the network's tuple (the tuple itself for a whole
    network) instead of a list."""

    pou: ir.Pou
    network: ir.Network
    insns: tuple[ir.Insn, ...]
    index: int = 0
    suffix: str = ""
    #: (mnemonic, resolved operands, site) of each instruction, for the
    #: native backend (recorded only when it is asked for); site: the index
    #: of an EU/ED's edge memory byte, else -1
    resolved: list[tuple[str, list[Any], int]] | None = None
    #: logic-stack levels the piece starts with (a loop body inside its
    #: FOR's network starts with the FOR's enable levels)
    entry_depth: int = 0


@dataclass
class PouInfo:
    pou: ir.Pou
    fname: str                      #: runner function name
    local_vars: dict[str, LocalVar]
    pieces: list[Piece] = field(default_factory=list)
    labels: dict[int, int] = field(default_factory=dict)
    loops: dict[int, tuple[int, int, Any]] = field(default_factory=dict)  # for piece -> (body, exit, for insn)
    next_of: dict[int, int] = field(default_factory=dict)  # next piece -> for piece
    scr_exit: dict[int, int] = field(default_factory=dict)  # piece -> exit piece of its SCR segment
    scr_bit: dict[int, Any] = field(default_factory=dict)   # piece -> resolved S bit of the segment
    scr_pieces: dict[int, list[int]] = field(default_factory=dict)  # LSCR piece -> pieces in segment
    calls: dict[str, SourceLoc] = field(default_factory=dict)  #: callee -> first CALL
    flow: bool = False
    cost: list[int] = field(default_factory=list)
    depth_after: dict[int, int] = field(default_factory=dict)  #: FOR piece -> stack depth at its end
    #: variables of a type plcrt cannot hold (reported at the declaration)
    bad_vars: list[str] = field(default_factory=list)


class Unit:
    """Everything shared while compiling one program."""

    def __init__(self, program: ir.Program, model: CpuModel, symbols: Any,
                 system_symbols: dict[str, str], diag: DiagnosticSink) -> None:
        self.program = program
        self.model = model
        self.symbols = symbols
        self.system_symbols = system_symbols
        self.diag = diag
        #: generated name -> what it is bound to: a recipe each PLC resolves
        #: for itself (:mod:`plcrt.gen.recipe`), a buffer (made anew for
        #: each PLC from its contents) or a constant every PLC shares
        self.bindings: dict[str, Any] = {}
        #: names of the bindings that are constants (lookup tables, string
        #: constants): shared by every PLC built from this unit, never
        #: copied by a fork (only state is)
        self.constants: set[str] = set()
        self._ids: dict[int, str] = {}
        self._counter = 0
        self.locs = LocTable()                #: instruction id -> location
        self.pous: dict[str, PouInfo] = {}    #: ident -> info
        self.by_name: dict[str, PouInfo] = {}
        self.timer_use: dict[int, list[tuple[str, SourceLoc]]] = {}
        self.counter_use: dict[int, list[tuple[str, SourceLoc]]] = {}
        self.edge_count = 0
        #: compile-time tables of the emitters and the hooks of the layers
        #: above (``library_call``); emptied when the program is compiled
        self.hooks: dict[str, Any] = {}
        #: the parsed plant the program is compiled for, or None
        self.plant: Any = None
        self.current: PouInfo | None = None
        self.current_piece: Piece | None = None
        #: a :class:`plcrt.engine.coverage.CoverageMap` to add probes for
        #: (coverage and breakpoints), or None for the plain fast code
        self.probes: Any = None
        #: CALLs count nesting levels at run time (recursion, or chains
        #: deeper than the limit; see :func:`check_calls`)
        self.nest_check = False
        #: (caller, callee) pairs inside a call cycle
        self.recursive_sites: set[tuple[str, str]] = set()
        #: some generated code counts on the watchdog words WD (loops,
        #: WDR, call nesting): the scan must clear them at its start
        self.uses_wd = False
        #: (first line, character offset) of each piece of the generated
        #: module that is compiled on its own (cut between top-level
        #: statements every :data:`~plcrt.compiler.cache.CHUNK_LINES` lines)
        self.chunks: list[tuple[int, int]] = [(1, 0)]
        #: the native backend's plan (:mod:`plcrt.compiler.native`), or None
        #: for Python only
        self.native: Any = None
        #: the bits kept in locals in the function being emitted
        #: (:class:`plcrt.compiler.bitcache.BitCache`), or None
        self.bitcache: Any = None

    def fresh(self, hint: str) -> str:
        self._counter += 1
        return f"_{hint}{self._counter}"

    def bind(self, obj: object, hint: str = "o", constant: bool = False) -> str:
        """The generated name of run-time object ``obj`` (one name per
        object); ``constant``: the generated code only reads it.  An
        immutable value (bytes, a tuple of numbers ...) is a constant
        whoever binds it."""
        key = id(obj)
        name = self._ids.get(key)
        if name is None:
            name = self.fresh(hint)
            self._ids[key] = name
            self.bindings[name] = obj
        if constant or _immutable(obj):
            self.constants.add(name)
        return name

    def callee(self, name: str) -> PouInfo | None:
        key = name.strip().upper()
        return self.pous.get(key) or self.by_name.get(key)


_IMMUTABLE = (bytes, str, int, float, complex, bool, type(None), range)


def _immutable(obj: object, depth: int = 0) -> bool:
    """``obj`` can never change: an immutable scalar, or a tuple or
    frozenset of such (a few levels deep)."""
    if isinstance(obj, _IMMUTABLE):
        return True
    if isinstance(obj, (tuple, frozenset)) and depth < 4:
        return all(_immutable(x, depth + 1) for x in obj)
    return False


def pou_fname(p: ir.Pou) -> str:
    """The name of a block's runner in the generated module."""
    return f"pou_{p.kind}{p.number}"


class Compiled:
    """Output of code generation: module source plus per-POU runners."""

    def __init__(self, source: str, namespace: dict[str, Any], unit: Unit,
                 line_locs: LineLocs) -> None:
        self.source = source
        self.namespace = namespace
        self.unit = unit
        self.line_locs = line_locs

    def runner(self, ident: str) -> Callable[[bytearray], Any] | None:
        info = self.unit.pous.get(ident)
        return self.namespace.get(info.fname) if info else None


__all__ = ["Compiled", "Piece", "PouInfo", "Unit", "pou_fname"]
