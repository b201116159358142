"""Compiler hook: ``CALL NAME, args...`` of a built-in library block.

Checks the call against the block's interface (argument count, operand
kind and width, addresses where the block writes), then emits::

    if s1:
        r = _blk3(<IN values...>)
        <write r[0], r[1], ... to the OUT / written-back arguments>

(outputs at neighbouring addresses written by one store, Gen.wr_seq).
A block class with an ``exact_results`` attribute (a tuple of result
names) promises that every call returns a tuple of exactly its results:
the call unpacks them into locals, and the results named there are
always within their parameter's type (BOOL 0/1, BYTE 0..255, WORD and
DWORD unsigned, INT and DINT signed), so they are written without a mask
(out of range, the store raises: never a silently wrong value).  A block
with a ``constant_args`` method is told, once, the names of the IN
parameters its call site gives as constants: they are the same at every
call of the site, so a shortcut need not compare them.

``_blk3`` is the per-call-site callable built by the block's factory, so
each call site has its own state (like the memory a Micro/WIN library
subroutine gets per instance).  When the block is an object with a Python
``__call__``, the code calls that bound method (``_call4``) and the object
is bound too, for the copies of its state.
"""

from __future__ import annotations

from types import FunctionType
from typing import Any

from ..compiler.operands import Addr, Const, Indirect
from ..compiler.resolve import ResolveError, check_role
from ..gen.recipe import CPU, Attr, Call
from ..isa.registry import Role
from ..safetext import excerpt
from . import BLOCK_FACTORIES, PROTECTED, load_libraries
from .interface import interfaces

_READ = {"BOOL": Role.BIT_R, "BYTE": Role.B_R, "WORD": Role.W_R, "INT": Role.W_R,
         "DINT": Role.D_R, "DWORD": Role.D_R, "REAL": Role.R_R}
_WRITE = {"BOOL": Role.BIT_W, "BYTE": Role.B_W, "WORD": Role.W_W, "INT": Role.W_W,
          "DINT": Role.D_W, "DWORD": Role.D_W, "REAL": Role.R_W}
_KIND = {"BYTE": "B", "WORD": "WU", "INT": "W", "DINT": "D", "DWORD": "DU", "REAL": "R"}


def library_call(g: Any, insn: Any, resolver: Any, name: str | None = None) -> bool:
    """Emit a built-in block call; False if ``insn`` does not name one.
    *name*: the block, when the call names it otherwise (a program
    subroutine standing for it, called as ``SBR3``)."""
    name = (name or insn.operands[0].text.split(":")[0]).strip().upper()
    itf = interfaces().get(name)
    if itf is None:
        return False
    smart = interfaces().get(name + "_SMART")
    if smart is not None and len(insn.operands) - 1 == len(smart.params) != len(itf.params):
        name, itf = smart.name.upper(), smart     # the SMART variant (an extra input)
    factory = BLOCK_FACTORIES.get(name)
    if factory is None:
        load_libraries()
        factory = BLOCK_FACTORIES.get(name)
    if factory is None:
        g.fail(f"library instruction {itf.name} has no implementation")
    args = insn.operands[1:]
    if len(args) != len(itf.params):
        order = ", ".join(p.name for p in itf.params)
        g.fail(f"{itf.name} takes {len(itf.params)} arguments ({order}); "
               f"the call passes {len(args)}")
    reads: list[Any] = []   # expressions, or bit operands (see _bit_reads)
    writes: list[tuple[Any, str]] = []   # (operand or None, type)
    constants: set[str] = set()   # IN parameters given as constants
    for p, op_ir in zip(itf.params, args):
        typ = p.type   #: the type the argument is read as
        try:
            op = resolver.parse(op_ir.text)
            if p.dir == "OUT" or p.address:
                if isinstance(op, Const):
                    raise ResolveError(f"must be an address, not the constant "
                                       f"'{excerpt(op_ir.text)}'")
                op = check_role(op, _WRITE[p.type], op_ir.text, g.unit.model)
            else:
                role = Role.D_PTR if p.pointer else _READ[p.type]
                op, typ = _check_in(g, itf, p, op, role, op_ir.text)
        except ResolveError as e:
            where = op_ir.loc if op_ir.loc.block is not None else op_ir.loc.within(
                g.loc.block, g.loc.network)
            g.fail(f"{itf.name} argument {p.name} ({p.dir} {p.type}): {e}", where)
        if p.dir == "IN":
            if isinstance(op, Const):
                constants.add(p.name)
            reads.append(op if typ == "BOOL" and isinstance(op, Addr)
                         else g.rbit(op) if typ == "BOOL" else g.rd(op, _KIND[typ]))
        if p.dir == "OUT" or p.written:
            target = op if isinstance(op, (Addr, Indirect)) else None
            writes.append((target, p.type))
    at_load = getattr(factory, "at_load", None)
    if at_load is not None:
        at_load(g, itf)               # load-time warnings of the block's family
    # each PLC of the program makes its own block of this call site
    block = Call(make_block, (factory, CPU, g.loc, itf, frozenset(constants)))
    cls = factory if isinstance(factory, type) else None
    call = getattr(cls, "__call__", None)
    # (a factory is a block class; its instances have a __dict__ unless slotted)
    if not (isinstance(call, FunctionType) and getattr(cls, "__dictoffset__", 0)):
        fn = g.bind(block, "blk")
    else:
        # perf: the generated code calls the block's bound __call__: a
        # Python function called as such is run in the caller's evaluation
        # loop, an object's __call__ through a slot and a new one (about
        # half the cost of a call).  The block object stays bound as well:
        # fork() and snapshots copy its state through that binding, and the
        # method, rebound for each PLC, is bound to that PLC's block.
        g.unit.bind(block, "blk")
        fn = g.bind(Attr(block, "__call__"), "call")
    exact = getattr(cls, "exact_results", None)
    with g.box(alone=True):
        args = ', '.join(_bit_reads(g, reads))
        if exact is None:
            r = g.tmp("r")
            g.line(f"{r} = {fn}({args})")
            g.wr_seq([(target, "X" if typ == "BOOL" else _KIND[typ], f"{r}[{i}]")
                      for i, (target, typ) in enumerate(writes) if target is not None])
        elif writes:
            # perf: the block returns exactly its results: unpacked into
            # locals, and those it keeps in range written without a mask
            rs = [g.tmp("r") for _ in writes]
            g.line(f"{', '.join(rs)}{',' if len(rs) == 1 else ''} = {fn}({args})")
            names = [p.name for p in itf.results]
            g.wr_seq([(target, "X" if typ == "BOOL" else _KIND[typ], r, name in exact)
                      for r, name, (target, typ) in zip(rs, names, writes)
                      if target is not None])
        else:
            g.line(f"{fn}({args})")
    return True


def make_block(factory: Any, plc: Any, loc: Any, itf: Any, constants: frozenset[str]) -> Any:
    """The block of one call site for ``plc``: ``factory(plc, loc, itf)``,
    told the IN parameters the site gives as constants (perf: see the
    module docstring)."""
    block = factory(plc, loc, itf)
    told = getattr(block, "constant_args", None)
    if told is not None:
        told(constants)
    return block


def _bit_reads(g: Any, reads: list[Any]) -> list[str]:
    """The argument expressions: bit operands read with :meth:`Gen.rbit`,
    except that a byte holding several of them is read once, as the tuple
    of its bits (plcrt.compiler.rt.BITS), into a local first (perf: one
    load instead of one per bit, and a tuple subscript per bit instead of
    a shift and a mask; reading has no effect, so the order of the reads
    does not matter)."""
    bytes_of = [(op.area, op.offset) for op in reads
                if isinstance(op, Addr) and op.area not in ("T", "C")]
    shared: dict[tuple[str, int], str] = {}
    for key in dict.fromkeys(bytes_of):
        if bytes_of.count(key) > 1:
            shared[key] = var = g.tmp("b")
            g.line(f"{var} = {g.use('_bits')}[{g.rd(Addr(key[0], key[1], 1), 'B')}]")
    out = []
    for op in reads:
        if not isinstance(op, Addr):
            out.append(op)
            continue
        var = shared.get((op.area, op.offset))
        out.append(g.rbit(op) if var is None else f"{var}[{op.bit}]")
    return out


#: a protected block's parameters in a program read from a project file are
#: matched by size: a project stores a local variable's size, not its
#: signedness (docs/project-files.md); an export names the type itself
_SIZE = {"DINT": "DWORD", "INT": "WORD"}


def protected_call(g: Any, insn: Any, resolver: Any, callee: Any) -> bool:
    """CALL of a program subroutine named like a registered library block:
    emit the built-in block when the body is empty (a protected block of the
    export) and the interface matches one of the block's (directions and
    types in order; names may differ); else False, with a warning once that
    the program's own subroutine runs (the blocks are those registered with
    :func:`plcrt.blocks.register_protected`)."""
    load_libraries()
    name = (callee.pou.name or "").strip().upper()
    entry = PROTECTED.get(name)
    if entry is None:
        return False
    variants, family = entry
    size = _SIZE if getattr(g.unit.program, "from_project", False) else {}
    own = [(v.decl.section, size.get(t, t)) for v in callee.local_vars.values()
           if v.decl.section != "TEMP" for t in (v.decl.type.upper(),)]
    empty = not any(net.insns for net in callee.pou.networks)
    itfs = [interfaces()[n] for n in variants if n in interfaces()]
    for itf in itfs:
        if empty and own == [(p.dir, size.get(p.type, p.type)) for p in itf.params]:
            return library_call(g, insn, resolver, name=itf.name)
    once = g.unit.hooks.setdefault("protected-once", set())
    if callee.pou.ident not in once:
        once.add(callee.pou.ident)
        wanted = " or ".join(", ".join(f"{p.dir} {p.type}" for p in itf.params) for itf in itfs)
        why = [w for w, bad in (
            ("has instructions", not empty),
            ("has the interface " + excerpt(", ".join(f"{d} {t}" for d, t in own) or "(none)")
             + f", not the library's {wanted}",
             all(own != [(p.dir, size.get(p.type, p.type)) for p in itf.params]
                 for itf in itfs))) if bad]
        g.warn(f"{callee.pou.ident} ({excerpt(callee.pou.name)}) is named like the {family} "
               f"block {name} but {' and '.join(why)}: the program's own subroutine runs, not "
               f"the library emulation", f"protected-own-{callee.pou.ident}")
    return False


def _check_in(g: Any, itf: Any, p: Any, op: Any, role: Role, text: str) -> tuple[Any, str]:
    """Check an IN argument against its declared type, then against the
    other types the interface allows (``also``); returns the operand and
    the type it is read as.  A value of another type is converted the way
    Micro/WIN converts a narrower actual parameter (a byte unsigned)."""
    try:
        return check_role(op, role, text, g.unit.model), p.type
    except ResolveError:
        for alt in p.also:
            try:
                op2 = check_role(op, _READ[alt], text, g.unit.model)
            except ResolveError:
                continue
            if not isinstance(op, Const):
                g.warn(f"{itf.name} argument {p.name} is a {alt} (as the manual's table types "
                       f"it); it is read as an unsigned {alt} and cannot be negative or "
                       f"larger than {(1 << (8 * _WIDTH[alt])) - 1}: use a {p.type} for "
                       f"larger or negative values", f"also-{itf.name}-{p.name}")
            return op2, alt
        raise


_WIDTH = {"BYTE": 1, "WORD": 2, "INT": 2, "DINT": 4, "DWORD": 4, "REAL": 4}

