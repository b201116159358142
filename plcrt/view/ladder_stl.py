"""The editable ladder model from STL and back, exactly.

:func:`network_to_model` reads a network through the ladder conversion the
renderer uses (:func:`plcrt.view.ladder.to_ladder`, the logic stack run
symbolically) and turns its tree into the editable :class:`Model`.
:func:`model_to_stl` writes the STL Micro/WIN's LAD editor writes for a
drawing: ``LD``/``A``/``O`` for contacts, ``LD .. ALD`` for a parallel
block inside a series, ``LD .. OLD`` for a parallel branch of several
elements, ``LPS``/``LRD``/``LPP`` around the branches of a split and
``AENO`` after a box whose ENO goes on (System Manual, "Bit logic" and
"Logic stack"; the rules are listed in docs/ladder-view.md).

A network is editable as ladder only when its STL is the STL the model
writes back: read, written and read again, it must give the same
instructions (mnemonics and operand texts).  Any other network keeps its
STL, and :class:`NoLadder` says why, in the words of the renderer's
conversion or naming the first instruction that the ladder form would
write differently.

This module knows the shapes of instructions only through the shape table
(:mod:`plcrt.isa.shape`); it does not check operands (that is
:mod:`plcrt.view.ladder_edit`).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import PlcConfigError
from ..isa.shape import shape
from ..lang import ir
from ..safetext import excerpt
from . import ladder as lad
from .ladder_model import (Box, Coil, Contact, Logic, Model, Node, Parallel, Series, as_items,
                           join)

#: the logic stack of the S7-200 holds nine levels (System Manual, "logic stack")
STACK_DEPTH = lad.STACK_DEPTH


@dataclass(frozen=True)
class NoLadder:
    """A network without a ladder form: it stays STL, for this reason."""

    reason: str


# ---------------------------------------------------------------------------
# STL -> model
# ---------------------------------------------------------------------------

def network_to_model(network: ir.Network) -> Model | NoLadder:
    """The editable model of a network, or why it has none.

    The model is given only when writing it back gives the network's own
    instructions (same mnemonics, same operand texts, same order)."""
    noted = next((i for i in network.insns if i.comment), None)
    if noted is not None:
        # LAD has a comment per network, none per element (docs/ladder-view.md)
        return NoLadder(f"{stl_line(noted.mnemonic, _ops(noted))} has a comment of its own, "
                        "which a ladder element cannot keep")
    ladder = lad.to_ladder(network)
    if not ladder.ok:
        return NoLadder(ladder.reason)
    try:
        model = _from_ladder(ladder, network)
        lines = model_lines(model)
    except PlcConfigError as e:
        return NoLadder(str(e))
    want = [(i.mnemonic, tuple(o.text for o in i.operands)) for i in network.insns]
    for k, (got, exp) in enumerate(zip(lines, want)):
        if got != exp:
            return NoLadder(f"instruction {k + 1} ({stl_line(*exp)}) is not where Micro/WIN's LAD "
                            f"editor writes it: the drawing's STL has {stl_line(*got)} there")
    if len(lines) != len(want):
        return NoLadder(f"the drawing's STL has {len(lines)} instructions, the network "
                        f"{len(want)}")
    return model


def _from_ladder(ladder: lad.Ladder, network: ir.Network) -> Model:
    rail = tuple(_out(e) for e in ladder.rail)
    conv = None if ladder.rung is None else _out(ladder.rung)
    return Model(conv, rail, network.title, network.comment)  # type: ignore[arg-type]


def _ops(insn: ir.Insn) -> tuple[str, ...]:
    return tuple(o.text for o in insn.operands)


def _logic(x: lad.Logic) -> Logic:
    if isinstance(x, lad.Contact):
        return Contact.from_mnemonic(x.insn.mnemonic, _ops(x.insn))
    return join(Series if isinstance(x, lad.Series) else Parallel, [_logic(i) for i in x.items])


def _out(x: lad.Coil | lad.Box | lad.Node) -> Coil | Box | Node:
    if isinstance(x, lad.Coil):
        return Coil(x.insn.mnemonic, _ops(x.insn))
    if isinstance(x, lad.Box):
        if shape(x.insn.mnemonic).kind == "rail":
            return Coil(x.insn.mnemonic, _ops(x.insn))
        nxt = None if x.next is None else _out(x.next)
        return Box(x.insn.mnemonic, _ops(x.insn), nxt,  # type: ignore[arg-type]
                   tuple(_logic(i) for i in x.inputs))
    return Node(None if x.logic is None else _logic(x.logic), tuple(_out(o) for o in x.outs))


# ---------------------------------------------------------------------------
# model -> STL
# ---------------------------------------------------------------------------

Line = tuple[str, tuple[str, ...]]


def model_to_stl(model: Model) -> str:
    """The STL of the model's instructions, one per line, in the layout of a
    Micro/WIN export (mnemonic in a column of seven, operands after it).

    Raises :class:`PlcConfigError` for a drawing that has no STL form (a
    parallel branch that starts with P, N or NOT, a stack deeper than nine
    levels, a branch without an output ...)."""
    return "".join(stl_line(m, ops) + "\n" for m, ops in model_lines(model))


def network_text(model: Model, number: int) -> str:
    """The whole network as an export writes it: ``Network n // title``, the
    comment lines, the instructions."""
    head = f"Network {number}" + (f" // {model.title}" if model.title else "")
    comment = "".join(f"//{c}\n" if c else "//\n" for c in model.comment.splitlines())
    return head + "\n" + comment + model_to_stl(model)


def stl_line(mnemonic: str, ops: tuple[str, ...]) -> str:
    """One instruction as an export writes it (``LD     I0.0``)."""
    return f"{mnemonic:<6} {', '.join(ops)}" if ops else mnemonic


def model_lines(model: Model) -> list[Line]:
    """The model's instructions as (mnemonic, operands)."""
    w = _Writer()
    if model.rung is not None and model.rail:
        raise PlcConfigError("a network holds either a rung or elements on the rail, not both")
    for e in model.rail:
        if shape(e.insn).kind != "rail":
            raise PlcConfigError(f"{excerpt(e.insn, 16)} does not stand on the rail")
        w.emit(e.insn, e.ops)
    if isinstance(model.rung, Box):
        w.counter(model.rung)
    elif model.rung is not None:
        if not isinstance(model.rung, Node):
            raise PlcConfigError("a rung is a node or a counter box")
        if model.rung.logic is None:
            raise PlcConfigError("a rung starts with a contact from the rail")
        w.load(model.rung.logic)
        w.outs(model.rung.outs)
        w.pop()
    if w.depth != 0:  # pragma: no cover - the writer keeps the stack balanced
        raise AssertionError("stack not balanced")
    return w.lines


class _Writer:
    """Writes STL and counts the logic stack's levels as it goes."""

    def __init__(self) -> None:
        self.lines: list[Line] = []
        self.depth = 0

    def emit(self, mnemonic: str, ops: tuple[str, ...] = ()) -> None:
        self.lines.append((mnemonic, ops))

    def push(self) -> None:
        self.depth += 1
        if self.depth > STACK_DEPTH:
            raise PlcConfigError(f"the rung needs more than the {STACK_DEPTH} levels of the "
                                 "logic stack")

    def pop(self, n: int = 1) -> None:
        self.depth -= n

    # -- logic --------------------------------------------------------------
    def load(self, x: Logic) -> None:
        """Start a new level with ``x`` (``LD`` ...)."""
        if isinstance(x, Contact):
            if x.modifier:
                raise PlcConfigError(f"a branch cannot start with {x.kind}: it needs power "
                                     "from a contact before it")
            self.push()
            self.emit(x.mnemonic("LD"), x.ops)
            return
        items = x.items
        self.load(items[0])
        for i in items[1:]:
            (self.and_ if isinstance(x, Series) else self.or_)(i)

    def and_(self, x: Logic) -> None:
        """top := top AND ``x``."""
        if isinstance(x, Contact):
            self.emit(x.mnemonic("A"), x.ops)
        elif isinstance(x, Series):
            for i in x.items:
                self.and_(i)
        else:
            self.load(x)
            self.emit("ALD")
            self.pop()

    def or_(self, x: Logic) -> None:
        """top := top OR ``x``."""
        if isinstance(x, Contact) and not x.modifier:
            self.emit(x.mnemonic("O"), x.ops)
        else:
            self.load(x)
            self.emit("OLD")
            self.pop()

    # -- outputs ------------------------------------------------------------
    def outs(self, outs: tuple[Coil | Box | Node, ...]) -> None:
        """The outputs of the point on top of the stack, in order.  A branch
        or a box whose ENO goes on changes the top, so an output after one
        gets the point back: ``LPS`` before the first such branch,
        ``LRD`` before each later output that another such branch follows,
        ``LPP`` before the rest."""
        if not outs:
            raise PlcConfigError("a branch without an output")
        n = len(outs)
        changes = [_changes_top(o) for o in outs]
        kept = dirty = False
        for k, o in enumerate(outs):
            if dirty:
                # the point is needed again after output k when a later one
                # (not the last) changes the top
                if any(changes[j] for j in range(k, n - 1)):
                    self.emit("LRD")
                else:
                    self.emit("LPP")
                    self.pop()
                    kept = False
                dirty = False
            if changes[k] and k < n - 1 and not kept:
                self.emit("LPS")
                self.push()
                kept = True
            self.out(o)
            dirty = changes[k]

    def out(self, o: Coil | Box | Node) -> None:
        if isinstance(o, Coil):
            if shape(o.insn).kind != "coil":
                raise PlcConfigError(f"{excerpt(o.insn, 16)} is not a coil")
            self.emit(o.insn, o.ops)
        elif isinstance(o, Box):
            if shape(o.insn).kind != "box" or shape(o.insn).inputs != 1 or o.inputs:
                raise PlcConfigError(f"{excerpt(o.insn, 16)} is not a box with one power input")
            self.emit(o.insn, o.ops)
            if o.next is not None:
                self.emit("AENO")
                self.branch(o.next)
        else:
            if o.logic is None:
                raise PlcConfigError("a branch starts with a contact")
            self.branch(o)

    def branch(self, node: Node) -> None:
        if not isinstance(node, Node):
            raise PlcConfigError("what follows a box's ENO is a node")
        if node.logic is not None:
            self.and_(node.logic)
        self.outs(node.outs)

    def counter(self, box: Box) -> None:
        """A counter: one rung from the rail into each power input, then the box
        (System Manual, CTU/CTD/CTUD)."""
        n = shape(box.insn).inputs
        if shape(box.insn).kind != "box" or n < 2 or len(box.inputs) != n or box.next:
            raise PlcConfigError(f"a rung from the rail is a node or a counter box with one "
                                 f"rung per power input, not {excerpt(box.insn, 16)}")
        for i in box.inputs:
            self.load(i)
        self.emit(box.insn, box.ops)
        self.pop(n)


def _changes_top(o: Coil | Box | Node) -> bool:
    return isinstance(o, Node) or (isinstance(o, Box) and o.next is not None)


def normalize(model: Model) -> Model:
    """The model as reading its STL gives it: a node whose only output is a
    branch is one node with the two logics in series; the title and the
    comment lines without blanks around them."""
    def node(n: Node) -> Node:
        outs = tuple(fix(o) for o in n.outs)
        if len(outs) == 1 and isinstance(outs[0], Node) and outs[0].logic is not None:
            child = outs[0]
            logic = (child.logic if n.logic is None
                     else join(Series, [n.logic] + as_items(child.logic)))
            return Node(logic, child.outs)
        return Node(n.logic, outs)

    def fix(o: Coil | Box | Node) -> Coil | Box | Node:
        if isinstance(o, Node):
            return node(o)
        if isinstance(o, Box) and o.next is not None:
            return Box(o.insn, o.ops, node(o.next), o.inputs)
        return o

    rung = model.rung
    new = node(rung) if isinstance(rung, Node) else rung
    # the parser keeps a title and comment lines without surrounding blanks
    comment = "\n".join(c.strip() for c in model.comment.splitlines())
    return Model(new, model.rail, model.title.strip(), comment)


__all__ = ["NoLadder", "model_lines", "model_to_stl", "network_text", "network_to_model",
           "normalize", "stl_line"]
