"""An STL network as a ladder (LAD) rung: the model and the conversion.

:func:`to_ladder` runs the logic stack of one network symbolically, the way
Micro/WIN converts STL to LAD: ``LD`` starts a path from the power rail,
``A``/``O`` put a contact in series / in parallel, ``ALD``/``OLD`` join two
paths, ``LPS``/``LRD``/``LPP`` split the rung into branches, and coils and
boxes end a path.  What each mnemonic looks like comes from the shape table
(:mod:`plcrt.isa.shape`); this module has no mnemonic lists.  A network
Micro/WIN could not show as LAD yields a :class:`Ladder` with a ``reason``,
and the renderer falls back to STL.

This module is pure data: no drawing, no rich, no live values (those are
:mod:`plcrt.view.status`), no PLC semantics beyond what the picture needs.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Union

from ..errors import PlcError
from ..isa.shape import FIND_CMD, Shape, shape
from ..lang import ir

#: Logic stack depth of the S7-200 (System Manual, "logic stack"); deeper
#: loads lose the bottom level, which a drawing cannot show.
STACK_DEPTH = 9


class NotLad(Exception):
    """Raised inside the conversion; becomes :attr:`Ladder.reason`."""


# ---------------------------------------------------------------------------
# The model
# ---------------------------------------------------------------------------

@dataclass(eq=False)
class Contact:
    """A contact, compare contact or modifier (``NOT``, ``P``, ``N``)."""

    insn: ir.Insn
    shape: Shape
    above: str = ""        #: operand above (the bit; IN1 of a compare)
    below: str = ""        #: operand below (IN2 of a compare)


@dataclass(eq=False)
class Series:
    """Elements one after the other on a wire (AND)."""

    items: list[Logic]


@dataclass(eq=False)
class Parallel:
    """Branches between two vertical connectors (OR)."""

    items: list[Logic]


Logic = Union[Contact, Series, Parallel]


@dataclass(frozen=True)
class Pin:
    """A named box connection showing an operand."""

    name: str
    operand: str
    right: bool = False      #: output pin (right side of the box)
    kind: str | None = None  #: "BIT" / "REAL": how to read it for status


@dataclass(eq=False)
class Coil:
    """An element that ends a path: ``( )``, ``(S)``, ``(JMP)`` ..."""

    insn: ir.Insn
    symbol: str              #: "( )", "(S)", "(JMP)" ...
    above: str = ""
    below: str = ""


@dataclass(eq=False)
class Box:
    """A box: power inputs, operand pins, and ENO to go on in series."""

    insn: ir.Insn
    title: str               #: MOV_W, TON, a subroutine or library block name
    above: str = ""          #: timer / counter number, label, SCR bit
    power: tuple[str, ...] = ("EN",)  #: power-flow input pins
    pins: tuple[Pin, ...] = ()
    eno: bool = True         #: passes power on (ENO)
    note: str = ""           #: e.g. "100 ms" of a timer
    next: Node | None = None  #: what follows ENO (after AENO)
    #: a box with several power inputs (counters): the rung into each pin
    inputs: list[Logic] = field(default_factory=list)


@dataclass(eq=False)
class Node:
    """A point of the rung: optional series logic from its parent, then the
    outputs hanging off it (coils, boxes and further branches, in order)."""

    logic: Logic | None
    outs: list[Coil | Box | Node] = field(default_factory=list)
    root: bool = False       #: starts at the power rail (``LD``)


@dataclass(frozen=True)
class Ladder:
    """The LAD form of one network, or why there is none."""

    network: ir.Network
    rung: Node | Box | None = None   #: a Box here has several power inputs
    rail: tuple[Coil | Box, ...] = ()  #: elements on the rail (LBL, SCR ...)
    reason: str = ""                 #: non-empty: not LAD-representable

    @property
    def ok(self) -> bool:
        return not self.reason


# ---------------------------------------------------------------------------
# STL -> LAD
# ---------------------------------------------------------------------------

def to_ladder(network: ir.Network, *, program: ir.Program | None = None) -> Ladder:
    """Convert one network; ``program`` names the pins of ``CALL`` boxes."""
    try:
        return _Builder(network, program).build()
    except NotLad as e:
        return Ladder(network, reason=str(e))


class _Dead:
    """The stack level a counter box leaves behind (nothing may use it)."""


class _Builder:
    def __init__(self, network: ir.Network, program: ir.Program | None) -> None:
        self.net = network
        self.program = program
        self.stack: list[Node | _Dead] = []
        self.roots: list[Node] = []
        self.rung: Node | Box | None = None
        self.last_box: Box | None = None

    def build(self) -> Ladder:
        insns = self.net.insns
        shapes = [shape(i.mnemonic) for i in insns]
        if insns and all(s.kind == "rail" for s in shapes):
            return Ladder(self.net, rail=tuple(_element(i, s, self.program)
                                               for i, s in zip(insns, shapes)))
        for insn, shp in zip(insns, shapes):
            self.step(insn, shp)
        return self.finish()

    # -- stack helpers ---------------------------------------------------
    def top(self, insn: ir.Insn) -> Node:
        if not self.stack:
            raise NotLad(f"{insn.mnemonic} without a value on the logic stack")
        t = self.stack[-1]
        if isinstance(t, _Dead):
            raise NotLad(f"{insn.mnemonic} after a counter box")
        return t

    def pure(self, insn: ir.Insn) -> Node:
        """Pop a path that is only logic from the rail (operand of ALD/OLD)."""
        t = self.top(insn)
        if not t.root or t.outs or self.stack.count(t) > 1:
            raise NotLad(f"{insn.mnemonic} combines a path that already feeds an output")
        self.stack.pop()
        self.roots.remove(t)
        return t

    def series(self, insn: ir.Insn, logic: Logic) -> None:
        """top := top AND logic: extend the path, or branch off a point that
        already feeds outputs or is kept by LPS."""
        t = self.top(insn)
        if not t.outs and self.stack.count(t) == 1:
            t.logic = _join(Series, t.logic, logic)
        else:
            child = Node(logic)
            t.outs.append(child)
            self.stack[-1] = child

    def parallel(self, insn: ir.Insn, logic: Logic) -> None:
        """top := top OR logic: only a path from the rail without outputs can
        get a parallel branch (an OR after a split reaches back to the rail)."""
        t = self.top(insn)
        if not t.root or t.outs or self.stack.count(t) > 1:
            raise NotLad(f"{insn.mnemonic} after an output or a branch point")
        t.logic = _join(Parallel, t.logic, logic)

    def attach(self, insn: ir.Insn, out: Coil | Box) -> None:
        t = self.top(insn)
        t.outs.append(out)
        self._rung_of(t)

    def _rung_of(self, t: Node) -> None:
        """Record the rail path ``t`` belongs to as the network's rung."""
        root = t if t.root else next(n for n in self.roots if _contains(n, t))
        if self.rung is None:
            self.rung = root
        elif self.rung is not root:
            raise NotLad("several rungs in one network (Micro/WIN's LAD shows one per network)")

    # -- one instruction ---------------------------------------------------
    def step(self, insn: ir.Insn, shp: Shape) -> None:
        kind, m = shp.kind, insn.mnemonic
        if kind == "contact":
            c = _contact(insn, shp)
            if shp.op == "load":
                node = Node(c, root=True)
                self.stack.append(node)
                self.roots.append(node)
                if len(self.stack) > STACK_DEPTH:
                    raise NotLad("logic stack deeper than 9 levels")
            elif shp.op == "and":
                self.series(insn, c)
            else:
                self.parallel(insn, c)
        elif kind == "modifier":
            self.series(insn, Contact(insn, shp))
        elif kind == "coil":
            self.attach(insn, _element(insn, shp, self.program))
        elif kind == "box":
            box = _element(insn, shp, self.program)
            assert isinstance(box, Box)
            if shp.inputs > 1:
                self.multi_box(insn, box, shp.inputs)
            else:
                self.attach(insn, box)
            self.last_box = box
        elif kind == "rail":
            raise NotLad(f"{m} together with rung logic")
        elif shp.op in ("and", "or"):  # ALD, OLD
            x = self.pure(insn)  # a rail path always has logic (its LD)
            assert x.logic is not None
            (self.series if shp.op == "and" else self.parallel)(insn, x.logic)
        elif shp.op == "push":  # LPS: the top becomes a branch point
            self.stack.append(self.top(insn))
            if len(self.stack) > STACK_DEPTH:
                raise NotLad("logic stack deeper than 9 levels")
        elif shp.op in ("read", "pop"):  # LRD, LPP: back to the branch point
            if len(self.stack) < 2:
                raise NotLad(f"{m} without a matching LPS")
            self.top(insn)
            self.stack.pop()
            if shp.op == "read":
                self.stack.append(self.stack[-1])
        elif shp.op == "eno":
            self.aeno(insn)
        else:  # LDS: a copy from deep in the stack has no picture
            raise NotLad(f"{m} has no LAD form")

    def aeno(self, insn: ir.Insn) -> None:
        """AENO after a box: the path continues from the box's ENO
        (System Manual, AENO: the STL form of a box's ENO in LAD)."""
        t = self.top(insn)
        box = self.last_box
        if box is None or not box.eno or box.next is not None or box not in t.outs:
            raise NotLad("AENO not directly after a box on the same path")
        box.next = Node(None)
        self.stack[-1] = box.next

    def multi_box(self, insn: ir.Insn, box: Box, n: int) -> None:
        """A counter: each power input is its own rung from the rail (System
        Manual, CTU/CTD/CTUD), so each must be plain logic."""
        if len(self.stack) < n:
            raise NotLad(f"{insn.mnemonic} needs {n} values on the logic stack")
        paths = [self.pure(insn) for _ in range(n)][::-1]
        if any(p.logic is None for p in paths):
            raise NotLad(f"{insn.mnemonic} input without logic")
        box.inputs = [p.logic for p in paths if p.logic is not None]
        if self.rung is not None:
            raise NotLad("several rungs in one network (Micro/WIN's LAD shows one per network)")
        self.rung = box
        self.stack.append(_Dead())  # the CU/CD level stays (docs/decisions.md)

    def finish(self) -> Ladder:
        if self.rung is None:
            if not self.net.insns:
                return Ladder(self.net)
            raise NotLad("logic without an output")
        if any(r is not self.rung for r in self.roots):
            raise NotLad("logic without an output")
        if len(self.stack) != 1:
            raise NotLad("the logic stack is not back to one level at the end "
                         "(an LPS without LPP)")
        if isinstance(self.rung, Node):
            _check_leaves(self.rung)
        return Ladder(self.net, rung=self.rung)


def _join(kind: type, a: Logic | None, b: Logic) -> Logic:
    """``kind(a, b)`` with nested nodes of the same kind flattened."""
    if a is None:
        return b
    items = (a.items if isinstance(a, kind) else [a]) + (b.items if isinstance(b, kind) else [b])
    return kind(list(items))


def _contains(root: Node, target: Node) -> bool:
    if root is target:
        return True
    for o in root.outs:
        if isinstance(o, Node) and _contains(o, target):
            return True
        if isinstance(o, Box) and o.next is not None and _contains(o.next, target):
            return True
    return False


def _check_leaves(node: Node) -> None:
    if not node.outs:
        raise NotLad("a branch without an output")
    for o in node.outs:
        if isinstance(o, Node):
            _check_leaves(o)
        elif isinstance(o, Box) and o.next is not None:
            _check_leaves(o.next)


def _ops(insn: ir.Insn) -> list[str]:
    return [o.text for o in insn.operands]


def _contact(insn: ir.Insn, shp: Shape) -> Contact:
    ops = _ops(insn)
    need = 2 if shp.compare else 1
    if len(ops) != need:
        raise NotLad(f"{insn.mnemonic} needs {need} operand(s)")
    return Contact(insn, shp, ops[0], ops[1] if shp.compare else "")


_PIN_RE = re.compile(r"(~)(\w+)$|([@_])(\d+)r?$|(\w+)([=>])(\d+)(r?)$")


def _element(insn: ir.Insn, shp: Shape, program: ir.Program | None) -> Coil | Box:
    """A coil or box (also on the rail) from the shape's picture and pins."""
    ops = _ops(insn)
    if insn.mnemonic == "CALL":
        return _call(insn, ops, program)
    above = below = ""
    power: list[str] = []
    pins: list[Pin] = []
    used: set[int] = set()
    for item in shp.pins.split():
        m = _PIN_RE.match(item)
        if m is None:
            raise ValueError(f"bad pin {item!r} in the shape of {insn.mnemonic}")
        if m.group(1):
            power.append(m.group(2))
            continue
        i = int(m.group(4) or m.group(7))
        if i >= len(ops):
            raise NotLad(f"{insn.mnemonic} has too few operands")
        used.add(i)
        if m.group(3) == "@":
            above = ops[i]
        elif m.group(3) == "_":
            below = ops[i]
        else:
            pins.append(Pin(m.group(5), ops[i], m.group(6) == ">",
                            "REAL" if m.group(8) else None))
    if len(used) != len(ops) and shp.pins:
        raise NotLad(f"{insn.mnemonic} has {len(ops)} operand(s), LAD shows {len(used)}")
    if not shp.pins:  # a box the table does not describe: operands as inputs
        pins = [Pin("", t) for t in ops]
    if shp.lad.startswith("("):
        return Coil(insn, shp.lad, above, below)
    note = ""
    if _is_timer(insn.mnemonic) and above[1:].isdigit():
        # Micro/WIN writes the resolution, fixed by the timer number, in the box
        from ..engine.timers import resolution_ms
        note = f"{resolution_ms(int(above[1:]))} ms"
    elif insn.mnemonic in FIND_CMD:
        # STL's FND= .. FND> are one LAD box whose CMD input picks the compare
        note = f"CMD {FIND_CMD[insn.mnemonic]}"
    # a box without power pins of its own has EN and ENO; a rail box neither
    plain = not power and shp.kind == "box"
    return Box(insn, shp.lad, above, ("EN",) if plain else tuple(power), tuple(pins),
               eno=plain, note=note)


def _is_timer(mnemonic: str) -> bool:
    from ..isa.registry import Role, lookup
    spec = lookup(mnemonic)
    return spec is not None and bool(spec.roles) and spec.roles[0] is Role.TIMER


def _call(insn: ir.Insn, ops: list[str], program: ir.Program | None) -> Box:
    """A CALL box: pins named after the subroutine's interface (IN, IN_OUT
    left, OUT right; System Manual, CALL: "input parameters first, then
    input/output, then output") or the library block's, else unnamed."""
    if not ops:
        raise NotLad("CALL without a block name")
    name, args = ops[0], ops[1:]
    params: list[tuple[str, bool, str | None]] = []
    base = name.split(":")[0].strip()      # CALL NAME:SBRn names the block twice
    pou = _callee(program, base)
    if pou is not None:
        params = [(v.name, v.section == "OUT", _kind_of(v.type))
                  for v in pou.variables if v.section != "TEMP"]
    else:
        try:
            from ..blocks.interface import interfaces
            itf = interfaces().get(base.upper())
        except PlcError:
            itf = None
        if itf is not None:
            params = [(p.name, p.dir == "OUT", _kind_of(p.type)) for p in itf.params]
    pins = []
    for i, text in enumerate(args):
        pname, right, kind = params[i] if i < len(params) else ("", False, None)
        pins.append(Pin(pname, text, right, kind))
    return Box(insn, name, pins=tuple(pins))


def _callee(program: ir.Program | None, name: str) -> ir.Pou | None:
    if program is None:
        return None
    key = name.upper()
    for p in program.pous:
        if p.kind == "SBR" and key in (p.ident.upper(), p.name.upper()):
            return p
    return None


def _kind_of(type_: str) -> str | None:
    return {"BOOL": "BIT", "REAL": "REAL"}.get(type_.upper())


__all__ = ["Box", "Coil", "Contact", "Ladder", "Logic", "Node", "NotLad", "Parallel", "Pin",
           "Series", "to_ladder"]
