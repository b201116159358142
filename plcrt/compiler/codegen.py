"""Compile a checked program to Python: one function per network (piece).

Pipeline: for each POU the instruction stream is split into *pieces*: one per
network, with extra cuts where control flow lands inside a network (after
``LBL`` / ``FOR`` / ``NEXT`` / ``SCRE``).  Each piece becomes one generated
function ``def n_SBR3_7(L, ...)`` that returns ``None`` to fall through or a
piece index to continue at (``-1`` returns from the POU).  A POU without
control flow gets a straight-line runner; a POU with jumps or loops gets a
small program-counter loop that also feeds the watchdog.

The generated module text is kept for ``plcrt dump``; only validated numbers
from the program ever reach it (names are built from block kind + number).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from ..errors import Diagnostic, DiagnosticSink, PlcError, SourceLoc
from ..isa.libraries import interfaces
from ..isa.registry import KNOWN_UNIMPLEMENTED, InsnSpec, lookup
from ..isa.shape import shape
from ..lang import ir
from ..lang.codepage import program_codepage
from ..memory.cpu import CpuModel
from ..safetext import excerpt
from .constpower import ConstantPower, contact_value
from ..gen.emit import CodegenError, Gen
from ..gen.limits import MAX_FOR_NESTING, MAX_NESTING, MAX_STACK
from .locs import LineLocs, LocTable
from ..gen.resolve import LocalVar, ResolveError, Resolver, layout_locals

#: depth of the S7-200 logic stack (System Manual, "Logic stack")
MAX_STACK_LEVELS = MAX_STACK

# Flow kinds that start a new piece at the instruction / after it.
_CUT_BEFORE = {"label"}
_CUT_AFTER = {"for", "next", "scre"}

#: perf: at most this many pieces, or about this many lines, per function of
#: a block without jumps (a bound on what one call and one compile chunk hold)
GROUP_PIECES = 32
GROUP_LINES = 400


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
        self.hooks: dict[str, Any] = {}       #: family-specific run-time tables
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


def _pou_fname(p: ir.Pou) -> str:
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


def split_pieces(info: PouInfo, diag: DiagnosticSink) -> None:
    """Cut a POU into pieces and match labels, loops and SCR segments."""
    pieces: list[Piece] = []
    for net in info.pou.networks:
        insns = net.insns
        start = 0               # where the piece being cut starts in insns
        for i, insn in enumerate(insns):
            spec = lookup(insn.mnemonic)
            flow = spec.flow if spec else ""
            if flow in _CUT_BEFORE and i > start:
                pieces.append(Piece(info.pou, net, insns[start:i]))
                start = i
            if flow in _CUT_AFTER:
                pieces.append(Piece(info.pou, net, insns[start:i + 1]))
                start = i + 1
        # perf: insns[0:] is the network's own tuple (no copy)
        pieces.append(Piece(info.pou, net, insns[start:]))
    # drop empty trailing pieces created by cuts (keep one per network)
    kept: list[Piece] = []
    seen_nets: set[int] = set()
    for p in pieces:
        if p.insns or id(p.network) not in seen_nets:
            kept.append(p)
            seen_nets.add(id(p.network))
    counts: dict[int, int] = {}
    for i, p in enumerate(kept):
        p.index = i
        k = counts.get(id(p.network), 0)
        counts[id(p.network)] = k + 1
        p.suffix = "" if k == 0 else "_" + "abcdefghijklmnopqrstuvwxyz"[min(k - 1, 25)] + (str(k) if k > 26 else "")
    info.pieces = kept
    info.cost = [len(p.insns) for p in kept]

    for_stack: list[tuple[int, ir.Insn]] = []
    scr_open: tuple[int, ir.Insn] | None = None
    scr_members: list[int] = []
    for p in kept:
        for insn in p.insns:
            spec = lookup(insn.mnemonic)
            flow = spec.flow if spec else ""
            if flow:
                info.flow = info.flow or flow not in ("label",)
            if flow == "label":
                n = _label_number(insn)
                if n is None:
                    continue
                if n in info.labels:
                    diag.error(f"label {n} is defined twice in {info.pou.ident}", insn.loc)
                info.labels[n] = p.index
            elif flow == "for":
                if len(for_stack) >= MAX_FOR_NESTING:
                    diag.error(f"FOR loops nest deeper than {MAX_FOR_NESTING} levels", insn.loc)
                for_stack.append((p.index, insn))
            elif flow == "next":
                if not for_stack:
                    diag.error("NEXT without a matching FOR", insn.loc)
                    continue
                fp, finsn = for_stack.pop()
                info.loops[fp] = (fp + 1, p.index + 1, finsn)
                info.next_of[p.index] = fp
            elif flow == "lscr":
                if scr_open is not None:
                    diag.error("LSCR inside an open SCR segment (SCR segments cannot nest)", insn.loc)
                scr_open = (p.index, insn)
                scr_members = [p.index]
            elif flow in ("scre", "cscre", "scrt") and scr_open is None:
                diag.error(f"{insn.mnemonic} outside an SCR segment (no LSCR before it)", insn.loc)
            elif flow == "scre":
                assert scr_open is not None
                start = scr_open[0]
                if p.index not in scr_members:
                    scr_members.append(p.index)
                for m in scr_members:
                    info.scr_exit[m] = p.index + 1
                info.scr_pieces[start] = list(scr_members)
                scr_open = None
        if scr_open is not None and p.index not in scr_members:
            scr_members.append(p.index)
    for fp, finsn in for_stack:
        diag.error("FOR without a matching NEXT", finsn.loc)
    if scr_open is not None:
        diag.error("LSCR without a matching SCRE", scr_open[1].loc)


def _label_number(insn: ir.Insn) -> int | None:
    if len(insn.operands) != 1:
        return None
    t = insn.operands[0].text.strip()
    return int(t) if t.isdigit() and len(t) <= 3 and int(t) <= 255 else None


def check_calls(unit: Unit) -> None:
    """Check the call graph against the S7-200's nesting limit.

    System Manual, CALL: subroutines nest at most eight levels deep from
    the main program; recursion is allowed ("use caution").  So recursion
    and call chains deeper than eight are warnings here (naming the cycle
    or the chain), and they switch on the run-time nesting check
    (:attr:`Unit.nest_check`): a CALL that would be the ninth level is not
    executed, sets SM4.3 and gives ENO 0 (error 0008).  Call sites inside a
    cycle (:attr:`Unit.recursive_sites`) get one L buffer per nesting level.
    A program without either pays nothing at run time.
    """
    order = list(unit.pous)
    comp = _components(unit, order)
    for ident in order:
        info = unit.pous[ident]
        for callee, loc in info.calls.items():
            if comp[callee] == comp[ident]:
                unit.recursive_sites.add((ident, callee))
    reported: set[int] = set()
    for ident in order:
        info = unit.pous[ident]
        cycle = [] if comp[ident] in reported else _cycle(unit, ident, comp)
        if cycle:
            reported.add(comp[ident])
            shown = cycle + [cycle[0]]
            if len(shown) > 7:   # a hostile program's cycle of thousands of blocks
                shown = shown[:3] + [f"... ({len(cycle)} blocks) ..."] + shown[-2:]
            names = " -> ".join(shown)
            loc = info.calls[cycle[1] if len(cycle) > 1 else ident]
            unit.diag.warning(
                f"recursion: {names}; the S7-200 allows it but nests subroutines at most "
                f"{MAX_NESTING} levels deep: a deeper CALL is not executed (SM4.3 is set)",
                loc, "recursion")
            unit.nest_check = True
    if unit.nest_check:
        return
    height = _heights(unit)
    for ident, info in unit.pous.items():
        if info.pou.kind != "SBR" and height[ident] > MAX_NESTING:
            deepest = max(info.calls, key=height.__getitem__)
            unit.diag.warning(f"subroutine calls from {ident} nest {height[ident]} levels "
                              f"deep; the S7-200 allows {MAX_NESTING}: a deeper CALL is not "
                              f"executed (SM4.3 is set)", info.calls[deepest], "nesting")
            unit.nest_check = True


def _heights(unit: Unit) -> dict[str, int]:
    """How many subroutine levels each block's deepest call chain has (the
    call graph has no cycle here).  Iterative: a hostile program may chain
    thousands of blocks, deeper than Python's recursion limit."""
    memo: dict[str, int] = {}
    for root in unit.pous:
        stack = [(root, False)]
        while stack:
            node, children_done = stack.pop()
            if node in memo:
                continue
            calls = unit.pous[node].calls
            if children_done:
                memo[node] = max((1 + memo[c] for c in calls), default=0)
            else:
                stack.append((node, True))
                stack.extend((c, False) for c in calls if c not in memo)
    return memo


def _components(unit: Unit, order: list[str]) -> dict[str, int]:
    """Strongly connected components of the call graph (Tarjan), as a
    component number per block; blocks in one cycle share a number."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    comp: dict[str, int] = {}

    def visit(v: str) -> None:
        # iterative: a hostile program may chain thousands of blocks
        work = [(v, iter(unit.pous[v].calls))]
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        while work:
            node, edges = work[-1]
            for w in edges:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(unit.pous[w].calls)))
                    break
                if w in on:
                    low[node] = min(low[node], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    n = len(set(comp.values()))
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp[w] = n
                        if w == node:
                            break

    for v in order:
        if v not in index:
            visit(v)
    return comp


def _cycle(unit: Unit, start: str, comp: dict[str, int]) -> list[str]:
    """A call cycle through ``start`` (``[start, ..., last]``, where last
    calls start), or [] when ``start`` is not recursive."""
    if start in unit.pous[start].calls:
        return [start]
    # breadth-first inside the component, for the shortest cycle
    prev: dict[str, str] = {}
    queue = [start]
    for node in queue:
        for c in unit.pous[node].calls:
            if comp.get(c) != comp[start]:
                continue
            if c == start:
                path = [node]
                while path[-1] != start:
                    path.append(prev[path[-1]])
                return list(reversed(path))
            if c not in prev:
                prev[c] = node
                queue.append(c)
    return []


def generate(unit: Unit) -> tuple[str, LineLocs]:
    """Emit the module source for all POUs (diagnostics go to ``unit.diag``).

    The module has no comments: where each instruction's code starts is in
    the returned :class:`LineLocs` (``plcrt dump`` shows it as a marker
    comment), which keeps the text compiled and kept small.  Only the
    lines of the chunk being written (:attr:`Unit.chunks`) are held as
    lines; a finished chunk is kept as one text."""
    out: list[str] = []      # the lines of the chunk being written
    line_locs = LineLocs(unit.locs)
    constants = [op.text for info in unit.pous.values() for net in info.pou.networks
                 for insn in net.insns for op in insn.operands if op.text.startswith('"')]
    codepage, chosen = program_codepage(unit.program.encoding, constants)
    if chosen:
        first = next(info.pou.loc for info in unit.pous.values())
        unit.diag.items.append(Diagnostic(
            "note", f"the program is Unicode text and its string constants do not fit "
                    f"CP1252: they are stored in {codepage.upper()}, the first ANSI code page "
                    f"that holds them (docs/strings.md)", first, "codepage"))
    from .cache import CHUNK_LINES
    done: list[str] = []     # the text of each finished chunk
    line0 = 0                # lines in the finished chunks (``out`` follows them)
    chars = 0                # characters in the finished chunks

    def flush() -> None:
        """Finish the chunk in ``out``: keep its text, forget its lines."""
        nonlocal line0, chars
        # perf: a chunk's lines (about 80 bytes each as str objects) become
        # one compact text as soon as the chunk is complete, so the whole
        # module's lines are never held at once.  The chunks are compiled
        # after generation (compile_chunks), not as each one completes: that
        # interleaved the long-lived code objects with the generator's
        # short-lived objects, which left the resident set larger (measured
        # on 2026-12-02: 70.6 instead of 69.0 MiB for 100 000 mixed
        # statements) and ran compile() slower
        text = "\n".join(out) + "\n"
        done.append(text)
        line0 += len(out)
        chars += len(text)
        out.clear()

    def maybe_cut() -> None:
        """Start a new chunk here when the current one is long enough (a
        top-level statement starts here)."""
        if len(out) >= CHUNK_LINES:
            flush()
            unit.chunks.append((line0 + 1, chars))

    unit.chunks = [(1, 0)]
    for info in unit.pous.values():
        p = info.pou
        unit.current = info
        resolver = Resolver(unit.model, unit.symbols, unit.system_symbols, info.local_vars,
                            codepage)

        def emit_def(name: str, parts: list[tuple[str, list[str], list[str], list]]) -> None:
            """One function holding the bodies of ``parts`` in order."""
            used = sorted({n for part in parts for n in part[1]})
            maybe_cut()
            out.append(f"def {name}({', '.join(['L'] + [f'{n}={n}' for n in used])}):")
            for _f, _u, body, line_map in parts:
                base = line0 + len(out)
                out.extend(body)
                for rel, insn_id, indent in line_map:
                    assert insn_id == len(line_locs.starts)   # ids follow the text
                    line_locs.add(base + 1 + rel, indent)
            if all(not part[2] for part in parts):
                # only instructions without code (LBL, SCRE, NOP ...): a
                # def needs at least one statement
                out.append("    pass")
            out.append("")

        records: list[tuple[str, list[str], list[str], list[tuple[int, int, int]]]] = []
        calls: list[str] | None = None if info.flow else []
        #: perf: without the native backend a group is emitted as soon as it
        #: is full, so that the lines of a big block are not all held at once
        stream = unit.native is None and not info.flow

        def emit_group(group: list[Any]) -> None:
            """Consecutive Python pieces of a block without jumps as one
            function (a call and a function object less per network, about
            550 bytes less per piece)."""
            assert calls is not None
            name = group[0][0] if len(group) == 1 else \
                f"g_{p.ident}_{len(calls)}_{group[0][0].rsplit('_', 1)[1]}"
            emit_def(name, group)
            calls.append(f"{name}(L)")

        for piece in info.pieces:
            unit.current_piece = piece
            if unit.native is not None:
                piece.resolved = []
            fname = f"n_{p.ident}_{piece.network.number}{piece.suffix}_{piece.index}"
            gen = Gen(unit, piece.network.loc, 0)
            if unit.probes is not None:
                _network_probe(unit, gen, piece)
            loop_body = next((fp for fp, (body, _e, _f) in info.loops.items()
                              if body == piece.index), None)
            if loop_body is not None:
                # A loop body is entered only when FOR's enable was 1: the
                # stack continues with ones (only relevant when the body
                # shares the FOR's network).
                for _ in range(info.depth_after.get(loop_body, 0)):
                    gen.push("1")
                piece.entry_depth = gen.depth
            emit_piece(unit, gen, piece, resolver)
            gen.pending = None  # a value left on the stack at the end is dead
            if piece.index in info.loops:
                # perf: only a FOR's depth is asked for (its loop body's start)
                info.depth_after[piece.index] = gen.depth
            records.append((fname, sorted(gen.used - {"L"}), gen.lines, gen.line_map))
            if "WD" in gen.used or info.flow:
                unit.uses_wd = True
            if stream and _group_full(records):
                emit_group(records)
                records = []
        segs = None
        if unit.native is not None:
            from .native import plan_pou
            edges = unit.hooks.get("edges")
            if edges is not None and unit.native.edges is None:
                unit.native.edges = unit.bind(edges, "EM")
            segs = plan_pou(unit.native, p.ident, info.flow,
                            [(pc.network.number, pc.resolved, pc.entry_depth)
                             for pc in info.pieces])
            for pc in info.pieces:
                pc.resolved = None

        fnames: list[str] = []
        if info.flow:
            # a jump may land on any piece: one function each; a native
            # piece runs through a wrapper that falls through
            for i, rec in enumerate(records):
                emit_def(rec[0], [rec])
                seg = segs[i] if segs is not None else None
                if seg is None:
                    fnames.append(rec[0])
                else:
                    out.extend([f"def _nw{seg}(L, _f=_nseg{seg}):", "    _f()", ""])
                    fnames.append(f"_nw{seg}")
        else:
            # consecutive Python pieces share one function; a native piece
            # keeps its own, uncalled function for plcrt dump
            assert calls is not None
            group: list[Any] = []
            prev: int | None = None
            for i, rec in enumerate(records):
                seg = segs[i] if segs is not None else None
                if seg is not None:
                    if group:
                        emit_group(group)
                        group = []
                    emit_def(rec[0], [rec])
                    if seg != prev:
                        calls.append(f"_nseg{seg}()")
                else:
                    group.append(rec)
                    if _group_full(group):
                        emit_group(group)
                        group = []
                prev = seg
            if group:
                emit_group(group)
        maybe_cut()
        out.extend(_runner(unit, info, fnames, calls))
        out.append("")
    flush()
    return "".join(done), line_locs


def _group_full(group: list[Any]) -> bool:
    """A group of piece records (name, names used, lines, line map) holds
    :data:`GROUP_PIECES` pieces or :data:`GROUP_LINES` lines."""
    return len(group) >= GROUP_PIECES or sum(len(r[2]) for r in group) >= GROUP_LINES


def _network_probe(unit: Unit, gen: Gen, piece: Piece) -> None:
    """Mark the network as run; the first piece also checks for a breakpoint."""
    net = piece.network
    k = unit.probes.add_network(piece.pou.ident, net.number, net.title,
                                net.loc.within(piece.pou.ident, net.number))
    nc = gen.bind(unit.probes.hits, "NC")
    gen.line(f"{nc}[{k}] = 1")
    if not piece.suffix:
        bp = gen.bind(unit.probes.breakpoints, "BP")
        hit = gen.bind(unit.probes.call_hit, "HIT")
        with gen.block(f"if {bp}[{k}]:"):
            gen.line(f"{hit}({k})")


def _output_probe(unit: Unit, gen: Gen, piece: Piece, insn: ir.Insn, loc: SourceLoc,
                  power: ConstantPower) -> None:
    """Record whether a coil or box is reached with or without power flow
    (not when its power is constant: SM0.0, see :mod:`.constpower`)."""
    shp = shape(insn.mnemonic)
    if shp.kind not in ("coil", "box") or shp.inputs < 1 or gen.depth < shp.inputs:
        return
    if power.level(shp.inputs - 1) is not None:
        return
    net = piece.network
    k = unit.probes.add_network(piece.pou.ident, net.number, net.title,
                                net.loc.within(piece.pou.ident, net.number))
    j = unit.probes.add_output(k, insn.mnemonic,
                               insn.operands[0].text if insn.operands else "", loc)
    oc = gen.bind(unit.probes.power, "OC")
    # the first power input (EN; CU of a counter) is the deepest of them
    gen.line(f"{oc}[{j}] |= {gen.level(shp.inputs - 1)} + 1")  # perf: 0/1 -> bit 0/1


#: A and O contacts are emitted as their load form plus ALD / OLD when
#: probed, so that the contact's own value is on the stack to record
_COMBINE = {"and": "ALD", "or": "OLD"}


def _contact_probe(unit: Unit, gen: Gen, piece: Piece, insn: ir.Insn, ops: list[Any],
                   loc: SourceLoc) -> bool:
    """Emit a contact so that whether it was open or closed is recorded.

    ``A x`` is ``LD x`` + ``ALD`` and ``O x`` is ``LD x`` + ``OLD`` (System
    Manual, logic stack), so the probe can read the contact alone from the
    top of the stack.  That needs one free stack level: with nine in use the
    contact is emitted as written and not probed.  Returns False when the
    instruction is not a contact (nothing emitted).
    """
    shp = shape(insn.mnemonic)
    if shp.kind != "contact" or gen.depth >= MAX_STACK_LEVELS:
        return False
    if contact_value(insn.mnemonic, ops) is not None:
        return False            # a constant bit (SM0.0) is no coverage goal
    m = insn.mnemonic
    load = m if shp.op == "load" else "LD" + m[1:]
    load_spec = lookup(load)
    if load_spec is None or (shp.op != "load" and gen.depth < 1):
        return False
    net = piece.network
    k = unit.probes.add_network(piece.pou.ident, net.number, net.title,
                                net.loc.within(piece.pou.ident, net.number))
    j = unit.probes.add_contact(k, m, insn.operands[0].text if insn.operands else "", loc)
    cc = gen.bind(unit.probes.closed, "CC")
    load_spec.emit(gen, *ops)
    gen.line(f"{cc}[{j}] |= {gen.top} + 1")  # perf: a stack value is 0 or 1
    if shp.op != "load":
        combine = lookup(_COMBINE[shp.op])
        assert combine is not None
        combine.emit(gen)
    return True


def _runner(unit: Unit, info: PouInfo, fnames: list[str],
            calls: list[str] | None = None) -> list[str]:
    """The block's runner: ``calls`` in order for a block without jumps and
    loops (grouped piece functions, native segments), else a
    program-counter loop over the piece functions ``fnames``."""
    if not info.flow:
        assert calls is not None
        if len(calls) == 1 and calls[0].endswith("(L)"):
            # perf: a block of one function is that function (one call less)
            return [f"{info.fname} = {calls[0][:-3]}"]
        return [f"def {info.fname}(L):"] + [f"    {c}" for c in calls or ["pass"]]
    costs = ", ".join(str(c) for c in info.cost)
    return [
        f"_pieces_{info.fname} = ({', '.join(fnames)},)",
        f"_costs_{info.fname} = ({costs},)",
        f"def {info.fname}(L, P=_pieces_{info.fname}, C=_costs_{info.fname}, WD=WD):",
        "    pc = 0",
        f"    n = {len(fnames)}",
        "    while pc < n:",
        "        WD[0] += C[pc]",
        "        r = P[pc](L)",
        "        if r is None:",
        "            pc += 1",
        "        elif r < 0:",
        "            return",
        "        else:",
        "            if r <= pc and WD[0] > WD[1]:",
        f"                _watchdog({info.pou.kind!r}, {int(info.pou.number)}, pc, r)",
        "            pc = r",
    ]


def emit_piece(unit: Unit, gen: Gen, piece: Piece, resolver: Resolver) -> None:
    """Emit the instructions of one piece into ``gen``.

    After the first error in a piece the static stack depth is unreliable,
    so later stack complaints in the same piece are suppressed (they would
    only repeat the first error); operand and mnemonic errors are still
    reported.
    """
    block = piece.pou.ident
    broken = False
    power = ConstantPower(gen.depth)    # probes only: which outcomes are constant
    for insn in piece.insns:
        loc = insn.loc.within(block, piece.network.number) if insn.loc.block is None else insn.loc
        spec = lookup(insn.mnemonic)
        if spec is None:
            if insn.mnemonic in KNOWN_UNIMPLEMENTED:
                unit.diag.error(f"instruction {insn.mnemonic} is not implemented yet",
                                loc, "unimplemented")
            else:
                unit.diag.error(f"unknown instruction '{excerpt(insn.mnemonic)}'", loc, "unknown")
            broken = True
            continue
        ops = _resolve_ops(unit, spec, insn, resolver, loc)
        if ops is None:
            broken = True
            _assume_stack_effect(gen, insn.mnemonic)
            continue
        insn_id = len(unit.locs)
        unit.locs.append(loc)
        gen.loc = loc
        gen.insn_id = insn_id
        # where its code starts (the module has no comment lines: they
        # made it a third longer to compile and keep)
        gen.line_map.append((len(gen.lines), insn_id, gen.indent))
        if unit.probes is not None and not broken:
            _output_probe(unit, gen, piece, insn, loc, power)
        # perf: emitters only append lines, so the length is what to restore
        saved = (len(gen.lines), gen.depth, gen.indent, gen.pending)
        try:
            if unit.probes is not None and not broken and \
                    _contact_probe(unit, gen, piece, insn, ops, loc):
                pass
            elif spec.variadic:
                spec.emit(gen, insn, resolver, *ops)
            else:
                spec.emit(gen, *ops)
            if piece.resolved is not None:
                site = len(unit.hooks["edges"]) - 1 if insn.mnemonic in ("EU", "ED") else -1
                piece.resolved.append((insn.mnemonic, ops, site))
            if unit.probes is not None:
                power.step(insn.mnemonic, ops, gen.depth)
        except PlcError:
            raise   # a problem outside the program (a library description file)
        except Exception as e:  # noqa: BLE001 - a plcrt bug is reported at its instruction
            del gen.lines[saved[0]:]
            _, gen.depth, gen.indent, gen.pending = saved
            if not isinstance(e, (CodegenError, ResolveError)):
                unit.diag.error(plcrt_bug(insn.mnemonic, e), loc, "plcrt-bug")
            elif not getattr(e, "reported", False) and not (broken and "logic stack" in str(e)):
                unit.diag.error(f"{insn.mnemonic}: {e}", getattr(e, "loc", None) or loc)
            broken = True
            _assume_stack_effect(gen, insn.mnemonic)
        if not spec.may_fail and spec.family != "stack":
            gen.eno_valid = False


def _assume_stack_effect(gen: Gen, mnemonic: str) -> None:
    """Keep the static depth plausible after an instruction that failed."""
    if mnemonic.startswith("LD") and mnemonic not in ("LDS",):
        gen.depth = min(gen.depth + 1, 9)
    elif mnemonic in ("ALD", "OLD", "LPP") and gen.depth > 1:
        gen.depth -= 1


def _resolve_ops(unit: Unit, spec: InsnSpec, insn: ir.Insn, resolver: Resolver,
                 loc: SourceLoc) -> list[Any] | None:
    roles = spec.roles
    n = len(insn.operands)
    if spec.variadic:
        if n < len(roles):
            unit.diag.error(f"{insn.mnemonic} needs at least {len(roles)} operand(s), "
                            f"got {n}", loc)
            return None
        fixed = insn.operands[:len(roles)]
    else:
        if n != len(roles):
            unit.diag.error(f"{insn.mnemonic} takes {len(roles)} operand(s), got {n}", loc)
            return None
        fixed = insn.operands
    ops: list[Any] = []
    ok = True
    for i, (operand, role) in enumerate(zip(fixed, roles)):
        where = operand.loc.within(loc.block, loc.network) if operand.loc.block is None \
            else operand.loc
        try:
            ops.append(resolver.resolve(operand, role))
        except ResolveError as e:
            unit.diag.error(f"{insn.mnemonic} operand {i + 1}: {e}", where)
            ok = False
        except PlcError:
            raise
        except Exception as e:  # noqa: BLE001 - a plcrt bug is reported at its operand
            unit.diag.error(plcrt_bug(f"{insn.mnemonic} operand {i + 1}", e), where,
                            "plcrt-bug")
            ok = False
    return ops if ok else None


def plcrt_bug(what: str, exc: BaseException) -> str:
    """The message of an error that is plcrt's, not the program's, at the
    instruction (or operand) *what* that met it: every problem in a program
    is one the checks name, so anything else is a bug to report."""
    return (f"{what}: plcrt cannot compile this ({type(exc).__name__}: "
            f"{excerpt(str(exc))}); this is a bug in plcrt, please report it with the "
            f"program")


def build_unit(program: ir.Program, model: CpuModel, symbols: Any,
               system_symbols: dict[str, str], diag: DiagnosticSink, *,
               library: bool = False) -> Unit:
    """Index POUs, lay out locals, split pieces and check the call graph.

    A program without OB1 cannot run, so it is an error, unless
    ``library`` (``plcrt check`` of a subroutine library): then a note says
    it was checked as one.  A program without any block is an error either
    way: there is nothing to check.
    """
    unit = Unit(program, model, symbols, system_symbols, diag)
    ob_count = 0
    for p in program.pous:
        ident = p.ident
        if ident in unit.pous:
            diag.error(f"block {ident} is defined twice", p.loc.within(ident, None))
            continue
        if p.kind == "OB":
            ob_count += 1
            if p.number != 1:
                diag.error(f"organization block {ident}: the S7-200 has only OB1",
                           p.loc.within(ident, None))
        bad: list[ir.VarDecl] = []
        try:
            local_vars = layout_locals(p, model.l_bytes, bad)
        except ResolveError as e:
            diag.error(str(e), p.loc.within(ident, None))
            local_vars = {}
        for d in bad:
            diag.error(f"variable '#{excerpt(d.name)}': type {excerpt(d.type)} is not "
                       f"supported; the block cannot run and its calls are not checked",
                       d.loc.within(ident, None))
        info = PouInfo(p, _pou_fname(p), local_vars, bad_vars=[d.name for d in bad])
        unit.pous[ident] = info
        if p.name and p.name.upper() != ident:
            if p.name.upper() in unit.by_name:
                diag.error(f"block name '{excerpt(p.name)}' is used twice",
                           p.loc.within(ident, None))
            unit.by_name[p.name.upper()] = info
    if not program.pous:
        diag.error("the file holds no program block (it is empty, or only comments), so "
                   "there is nothing to check or run", SourceLoc(program.file, 1, 1),
                   "no-blocks")
    elif "OB1" not in unit.pous:
        where = program.pous[0].loc.within(program.pous[0].ident, None)
        if library:
            diag.items.append(Diagnostic(
                "note", "no main program block (OB1): checked as a subroutine library, "
                        "which cannot run on its own", where, "no-ob1"))
        else:
            from .entry import block_list
            diag.error("the program has no main program block (OB1), so there is nothing "
                       "to run; give the file with OB1 as well, or choose the block to run "
                       "as the main program (plcrt run --entry BLOCK, plcrt.load(..., "
                       f"entry=BLOCK)); its blocks: {block_list(program.pous)}", where,
                       "no-ob1")
    for info in unit.pous.values():
        split_pieces(info, diag)
        for net in info.pou.networks:
            for insn in net.insns:
                if insn.mnemonic == "CALL" and insn.operands:
                    callee = unit.callee(insn.operands[0].text.split(":")[0])
                    if callee is not None and callee.pou.ident not in info.calls:
                        info.calls[callee.pou.ident] = insn.loc.within(
                            info.pou.ident, net.number)
    check_calls(unit)
    _empty_library_blocks(unit)
    return unit


def _empty_library_blocks(unit: Unit) -> None:
    """Warn about called subroutines that have an interface and no code.

    Micro/WIN exports a protected block (a Siemens instruction library such
    as MBUS_INIT or USS_INIT, wizard code, a password-protected block) with
    its interface and an empty body: its calls run nothing here.  Blocks
    plcrt emulates by name (a library interface in ``library/``) are left
    to that emulation."""
    emulated = interfaces()
    called = {callee for info in unit.pous.values() for callee in info.calls}
    for ident in called:
        info = unit.pous[ident]
        pou = info.pou
        if not pou.variables or any(net.insns for net in pou.networks):
            continue
        if pou.name.upper() in emulated:
            continue
        unit.diag.warning(
            f"{ident} ({excerpt(pou.name)}) has an interface and no code: a protected "
            f"library, wizard or password block exported without its body; its calls do "
            f"nothing here (what it would do is not simulated)",
            pou.loc.within(ident, None), "empty-block")
