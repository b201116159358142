"""Build a unit from a checked program: blocks, their locals and pieces.

:func:`build_unit` indexes the program's blocks, lays out their locals in
L memory, cuts each block into pieces where control flow lands
(:func:`split_pieces`, which also matches labels, FOR/NEXT and SCR
segments), records the calls between blocks and checks the call graph
(:mod:`.callgraph`).  It generates no code (:mod:`.codegen` does).
"""

from __future__ import annotations

from typing import Any

from ..errors import Diagnostic, DiagnosticSink, SourceLoc
from ..gen.limits import MAX_FOR_NESTING
from ..gen.resolve import ResolveError, layout_locals
from ..isa.libraries import interfaces
from ..isa.registry import lookup
from ..lang import ir
from ..memory.cpu import CpuModel
from ..safetext import excerpt
from .callgraph import check_calls
from .entry import block_list
from .unit import Piece, PouInfo, Unit, pou_fname

# Flow kinds that start a new piece at the instruction / after it.
_CUT_BEFORE = {"label"}
_CUT_AFTER = {"for", "next", "scre"}


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
        info = PouInfo(p, pou_fname(p), local_vars, bad_vars=[d.name for d in bad])
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


__all__ = ["build_unit", "split_pieces"]
