"""Emit the instructions of one piece, with the probes of an instrumented load.

:func:`emit_piece` resolves each instruction's operands against its roles,
calls its emitter (:mod:`plcrt.isa`) on the piece's ``Gen`` and turns
every problem into a diagnostic at the instruction or operand; with
``instrument=True`` it adds the coverage and breakpoint probes
(:func:`network_probe`, and per coil, box and contact).  It does not cut
blocks into pieces (:mod:`.pieces`) or assemble the module (:mod:`.codegen`).
"""

from __future__ import annotations

from typing import Any

from ..errors import PlcError, SourceLoc
from ..gen.emit import CodegenError, Gen
from ..gen.limits import MAX_STACK
from ..gen.recipe import CPU, Attr
from ..gen.resolve import ResolveError, Resolver
from ..isa.registry import KNOWN_UNIMPLEMENTED, InsnSpec, lookup
from ..isa.shape import shape
from ..lang import ir
from ..safetext import excerpt
from .bitcache import REGION_INSNS
from .constpower import ConstantPower, contact_value
from .unit import Piece, Unit


#: the probe tables the instrumented code reaches: the PLC's own copy of
#: the program's coverage map (one recipe each, so one name each)
PROBES = {name: Attr(CPU, f"coverage.{name}")
          for name in ("hits", "breakpoints", "call_hit", "power", "closed")}


def network_probe(unit: Unit, gen: Gen, piece: Piece) -> None:
    """Mark the network as run; the first piece also checks for a breakpoint."""
    net = piece.network
    k = unit.probes.add_network(piece.pou.ident, net.number, net.title,
                                net.loc.within(piece.pou.ident, net.number))
    nc = gen.bind(PROBES["hits"], "NC")
    gen.line(f"{nc}[{k}] = 1")
    if not piece.suffix:
        bp = gen.bind(PROBES["breakpoints"], "BP")
        hit = gen.bind(PROBES["call_hit"], "HIT")
        with gen.block(f"if {bp}[{k}]:"):
            gen.line(f"{hit}({k})")
    if piece.resolved is not None:     # the native backend's probes: same tables
        piece.resolved.append(("@NET", [k, not piece.suffix], -1))


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
    oc = gen.bind(PROBES["power"], "OC")
    # the first power input (EN; CU of a counter) is the deepest of them
    gen.line(f"{oc}[{j}] |= {gen.level(shp.inputs - 1)} + 1")  # perf: 0/1 -> bit 0/1
    if piece.resolved is not None:
        piece.resolved.append(("@OUT", [j, shp.inputs - 1], -1))


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
    if shp.kind != "contact" or gen.depth >= MAX_STACK:
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
    cc = gen.bind(PROBES["closed"], "CC")
    load_spec.emit(gen, *ops)
    # perf: a stack value is 0 or 1: one store, no read (engine/coverage.py)
    gen.line(f"{cc}[{2 * j} + ({gen.top})] = 1")
    steps: list[tuple[str, list[Any], int]] = [(load, ops, -1), ("@CON", [j], -1)]
    if shp.op != "load":
        combine = lookup(_COMBINE[shp.op])
        assert combine is not None
        combine.emit(gen)
        steps.append((_COMBINE[shp.op], [], -1))
    if piece.resolved is not None:     # the native backend lowers the same steps
        piece.resolved.extend(steps)
    return True


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
        cache = unit.bitcache
        if cache is not None:
            # a region of bit logic keeps bits in locals (.bitcache); any
            # other instruction sees the image as the straight code leaves it
            if insn.mnemonic in REGION_INSNS:
                gen.bits = cache
                cache.at(insn)
            else:
                gen.bits = None
                cache.end(gen)
        # where its code starts (the module has no comment lines: they
        # made it a third longer to compile and keep)
        gen.line_map.append((len(gen.lines), insn_id, gen.indent))
        if unit.probes is not None and not broken:
            _output_probe(unit, gen, piece, insn, loc, power)
        # perf: emitters only append lines, so the length is what to restore
        saved = (len(gen.lines), gen.depth, gen.indent, gen.pending)
        try:
            probed = unit.probes is not None and not broken and \
                _contact_probe(unit, gen, piece, insn, ops, loc)
            if probed:
                pass
            elif spec.variadic:
                spec.emit(gen, insn, resolver, *ops)
            else:
                spec.emit(gen, *ops)
            if piece.resolved is not None and not probed:
                site = len(unit.hooks["edges"]) - 1 if insn.mnemonic in ("EU", "ED") else -1
                piece.resolved.append((insn.mnemonic, ops, site))
            if unit.probes is not None:
                power.step(insn.mnemonic, ops, gen.depth)
        except PlcError:
            raise   # a problem outside the program (a library description file)
        except Exception as e:  # noqa: BLE001 - a plcrt bug is reported at its instruction
            del gen.lines[saved[0]:]
            _, gen.depth, gen.indent, gen.pending = saved
            if cache is not None:
                cache.forget()      # a local it loaded went with the lines
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


__all__ = ["emit_piece", "network_probe", "plcrt_bug"]
