"""Assemble the generated module: one function per network (piece).

Pipeline: for each POU the instruction stream is split into *pieces*: one per
network, with extra cuts where control flow lands inside a network (after
``LBL`` / ``FOR`` / ``NEXT`` / ``SCRE``).  Each piece becomes one generated
function ``def n_SBR3_7(L, ...)`` that returns ``None`` to fall through or a
piece index to continue at (``-1`` returns from the POU).  A POU without
control flow gets a straight-line runner; a POU with jumps or loops gets a
small program-counter loop that also feeds the watchdog.

The generated module text is kept for ``plcrt dump``; only validated numbers
from the program ever reach it (names are built from block kind + number).

This module writes the functions, groups, native segments, runners and
compile chunks; the unit's data is :mod:`.unit`, cutting blocks into pieces
:mod:`.pieces`, the call graph :mod:`.callgraph`, and emitting one piece's
instructions and probes :mod:`.network` (their names are re-exported here).
"""

from __future__ import annotations

from typing import Any

from ..errors import Diagnostic
from ..gen.emit import Gen
from ..gen.limits import MAX_FOR_NESTING, MAX_NESTING
from ..gen.resolve import Resolver
from ..lang.codepage import program_codepage
from . import cache
from .bitcache import BitCache
from .callgraph import check_calls
from .locs import LineLocs
from .network import emit_piece, network_probe, plcrt_bug
from .pieces import build_unit, split_pieces
from .unit import Compiled, Piece, PouInfo, Unit

#: perf: at most this many pieces, or about this many lines, per function of
#: a block without jumps (a bound on what one call and one compile chunk
#: hold).  Large, because the bits of a function's bit logic are kept in
#: locals (.bitcache): the longer a function, the fewer times a bit is read
#: from the image.  Measured on 2026-12-04 with the peer benchmark's boolean
#: program (2000 statements), time per scan against a straight-line function
#: that keeps every bit in a local: 1.52x with 128 pieces / 1000 lines,
#: 1.15x with 256 / 2000; loading 20 000 or 100 000 statements took the
#: same time and memory as with 32 / 400.
GROUP_PIECES = 256
GROUP_LINES = 2000
#: perf: with the native backend a block's pieces are planned and emitted
#: this many at a time, so that their lines and resolved instructions are
#: never held for a whole block (measured on 2026-12-05: the 100 000-statement
#: mixed program's one block held about 100 MiB of them at once, which left
#: Python's small-object heap fragmented after the load)
NATIVE_WINDOW = 256


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
        if len(out) >= cache.CHUNK_LINES:
            flush()
            unit.chunks.append((line0 + 1, chars))

    unit.chunks = [(1, 0)]
    for info in unit.pous.values():
        p = info.pou
        unit.current = info
        resolver = Resolver(unit.model, unit.symbols, unit.system_symbols, info.local_vars,
                            codepage)

        def emit_def(name: str, parts: list[tuple[str, list[str], list[str], list]],
                     shown: bool = False) -> None:
            """One function holding the bodies of ``parts`` in order (only
            shown, as comments, for a piece that runs as machine code)."""
            used = sorted({n for part in parts for n in part[1]})
            maybe_cut()
            mark = "# " if shown else ""   # perf: no code object for a native piece
            out.append(f"{mark}def {name}({', '.join(['L'] + [f'{n}={n}' for n in used])}):")
            for _f, _u, body, line_map in parts:
                base = line0 + len(out)
                out.extend([mark + ln.replace("\n", "\n" + mark) for ln in body] if shown
                           else body)
                for rel, insn_id, indent in line_map:
                    assert insn_id == len(line_locs.starts)   # ids follow the text
                    line_locs.add(base + 1 + rel, indent)
            if all(not part[2] for part in parts):
                # only instructions without code (LBL, SCRE, NOP ...): a
                # def needs at least one statement
                out.append(f"{mark}    pass")
            out.append("")

        records: list[tuple[str, list[str], list[str], list[tuple[int, int, int]]]] = []
        calls: list[str] | None = None if info.flow else []
        #: perf: without the native backend a group is emitted as soon as it
        #: is full, so that the lines of a big block are not all held at once
        stream = unit.native is None and not info.flow
        # perf: bits kept in locals within a function of bit logic
        # (.bitcache): only in the plain Python build of a block without
        # jumps, where a function's pieces run one after the other
        unit.bitcache = BitCache.for_block(info.pieces) \
            if stream and unit.probes is None else None

        def emit_group(group: list[Any]) -> None:
            """Consecutive Python pieces of a block without jumps as one
            function (a call and a function object less per network, about
            550 bytes less per piece)."""
            assert calls is not None
            name = group[0][0] if len(group) == 1 else \
                f"g_{p.ident}_{len(calls)}_{group[0][0].rsplit('_', 1)[1]}"
            emit_def(name, group)
            calls.append(f"{name}(L)")

        fnames: list[str] = []
        group: list[Any] = []    # consecutive Python pieces not yet emitted
        prev: int | None = None  # the segment of the last record emitted
        planned: list[Any] = []  # native: the pieces of ``records``
        carry = None
        if unit.native is not None:
            from . import native
            carry = native.OpenSegment()

        def emit_records(recs: list[Any], segs: list[int | None] | None) -> None:
            """Emit the records of consecutive pieces, ``segs`` their segments."""
            nonlocal group, prev
            if info.flow:
                # a jump may land on any piece: one function each; a native
                # piece runs through a wrapper that falls through
                for i, rec in enumerate(recs):
                    emit_def(rec[0], [rec])
                    seg = segs[i] if segs is not None else None
                    if seg is None:
                        fnames.append(rec[0])
                    else:
                        out.extend([f"def _nw{seg}(L, _f=_nseg{seg}):", "    _f()", ""])
                        fnames.append(f"_nw{seg}")
                return
            # consecutive Python pieces share one function; a native piece
            # keeps its own function for plcrt dump, as comments
            assert calls is not None
            for i, rec in enumerate(recs):
                seg = segs[i] if segs is not None else None
                if seg is not None:
                    if group:
                        emit_group(group)
                        group = []
                    emit_def(rec[0], [rec], shown=True)
                    if seg != prev:
                        calls.append(f"_nseg{seg}()")
                else:
                    group.append(rec)
                    if _group_full(group):
                        emit_group(group)
                        group = []
                prev = seg

        def emit_planned() -> None:
            """Plan the native segments of the pieces in ``records`` and emit them."""
            edges = unit.hooks.get("edges")
            if edges is not None and unit.native.edges is None:
                unit.native.edges = unit.bind(edges, "EM")
            segs = native.plan_pou(unit.native, p.ident, info.flow,
                                   [(pc.network.number, pc.resolved, pc.entry_depth)
                                    for pc in planned], carry)
            for pc in planned:
                pc.resolved = None
            planned.clear()
            emit_records(records, segs)
            records.clear()

        for piece in info.pieces:
            unit.current_piece = piece
            if unit.native is not None:
                piece.resolved = []
            fname = f"n_{p.ident}_{piece.network.number}{piece.suffix}_{piece.index}"
            gen = Gen(unit, piece.network.loc, 0)
            if unit.probes is not None:
                network_probe(unit, gen, piece)
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
            gen.bits = None
            full = stream and _group_full(records + [(fname, [], gen.lines, [])])
            if unit.bitcache is not None and (full or piece is info.pieces[-1]):
                unit.bitcache.end(gen)     # the function ends after this piece
            records.append((fname, sorted(gen.used - {"L"}), gen.lines, gen.line_map))
            if "WD" in gen.used or info.flow:
                unit.uses_wd = True
            if full:
                emit_group(records)
                records = []
            if carry is not None:
                planned.append(piece)
                if len(planned) >= NATIVE_WINDOW:
                    emit_planned()
        if carry is not None:
            emit_planned()
            carry.close(unit.native)
        else:
            emit_records(records, None)
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


# also the names of the modules split off this one (.unit, .pieces, .callgraph,
# .network) and of the limits, importable from here as before
__all__ = ["GROUP_LINES", "GROUP_PIECES", "MAX_FOR_NESTING", "MAX_NESTING", "Compiled",
           "Piece", "PouInfo", "Unit", "build_unit", "check_calls", "emit_piece", "generate",
           "plcrt_bug", "split_pieces"]
