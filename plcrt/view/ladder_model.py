"""The editable ladder (LAD) model of one network, and its JSON form.

A drawn network is a tree of immutable values: a :class:`Node` is a point of
the rung with the series/parallel logic that leads to it (:class:`Contact`,
:class:`Series`, :class:`Parallel`) and the outputs that hang off it
(:class:`Coil`, :class:`Box`, and further branches, which are nodes again).
A box's ENO may continue in series (:attr:`Box.next`, the ``AENO`` of STL);
a counter box takes one rung per power input (:attr:`Box.inputs`).  The
elements keep the STL mnemonic and the operands as typed text, so that the
model holds exactly what the STL holds and nothing the STL cannot hold.

This module is the data and its JSON form only.  Reading it from STL and
writing STL is :mod:`plcrt.view.ladder_stl`; edit operations are
:mod:`plcrt.view.ladder_edit`.  JSON from a page is untrusted: every field is
checked, the nesting and the element count are bounded, and a bad document is
a :class:`~plcrt.errors.PlcConfigError` naming the place, never an exception
from deep inside.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Union

from ..errors import PlcConfigError
from ..isa.shape import shape
from ..safetext import excerpt

#: JSON format name and version of :func:`model_to_json`
FORMAT = "plcrt-ladder"
VERSION = 1
#: the most elements (contacts, coils, boxes, branches) one model may hold
#: (the largest network of the samples and the corpus has 22)
MAX_ELEMENTS = 256
#: the deepest nesting of the JSON document (and of the tree)
MAX_DEPTH = 40
#: the longest operand, title or comment text accepted
MAX_OPERAND = 256
MAX_TEXT = 4096
#: the most operands of one element (a CALL: the block and its parameters)
MAX_OPERANDS = 24

#: contact kinds of the JSON form -> the STL mnemonic of the series (``A``) form
CONTACTS = {"NO": "A", "NC": "AN", "NOI": "AI", "NCI": "ANI"}
#: inline elements without an operand (System Manual, "Bit logic": EU, ED, NOT)
MODIFIERS = {"P": "EU", "N": "ED", "NOT": "NOT"}
#: compare contacts: types and relations as STL writes them (``AW>=``)
COMPARE_TYPES = "BWDRS"
RELATIONS = ("=", "<>", "<=", ">=", "<", ">")

_KIND_OF = {v: k for k, v in {**CONTACTS, **MODIFIERS}.items()}


# ---------------------------------------------------------------------------
# The model
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class Contact:
    """A contact (``NO``, ``NC``, ``NOI``, ``NCI`` with one bit operand), a
    compare contact (``CMP`` with ``cmp`` such as ``"W>="`` and IN1, IN2) or an
    inline modifier (``P``, ``N``, ``NOT``: no operand)."""

    kind: str
    ops: tuple[str, ...] = ()
    cmp: str = ""

    @property
    def modifier(self) -> bool:
        return self.kind in MODIFIERS

    def mnemonic(self, op: str) -> str:
        """The STL mnemonic in position ``op`` (``"LD"``, ``"A"``, ``"O"``)."""
        if self.kind in MODIFIERS:
            return MODIFIERS[self.kind]
        tail = self.cmp if self.kind == "CMP" else CONTACTS[self.kind][1:]
        return op + tail

    @staticmethod
    def from_mnemonic(mnemonic: str, ops: tuple[str, ...]) -> Contact:
        """The contact of an ``LD``/``A``/``O`` (or EU, ED, NOT) mnemonic."""
        if mnemonic in _KIND_OF:
            return Contact(_KIND_OF[mnemonic], ops)
        for prefix in ("LD", "A", "O"):
            if mnemonic.startswith(prefix):
                rest = mnemonic[len(prefix):]
                kind = _KIND_OF.get("A" + rest)
                if kind is not None:
                    return Contact(kind, ops)
                return Contact("CMP", ops, rest)
        raise ValueError(f"not a contact: {mnemonic}")


@dataclass(frozen=True)
class Series:
    """Elements one after the other (AND); at least two, none a Series."""

    items: tuple[Logic, ...]


@dataclass(frozen=True)
class Parallel:
    """Branches side by side (OR); at least two, none a Parallel."""

    items: tuple[Logic, ...]


Logic = Union[Contact, Series, Parallel]


@dataclass(frozen=True)
class Coil:
    """An element that ends a path (``=``, ``S``, ``R``, ``=I``, ``SI``,
    ``RI``, ``JMP``, ...) or stands on the rail (``LBL``, ``LSCR``, ...)."""

    insn: str
    ops: tuple[str, ...] = ()


@dataclass(frozen=True)
class Box:
    """A box: the STL mnemonic (``MOVW``, ``+I``, ``TON``, ``CALL``) and its
    operands in STL order (for CALL the block name first)."""

    insn: str
    ops: tuple[str, ...] = ()
    next: Node | None = None          #: what follows ENO (``AENO``)
    inputs: tuple[Logic, ...] = ()    #: a counter: the rung into each power input


@dataclass(frozen=True)
class Node:
    """A point of the rung: the logic that leads to it (None only after a
    box's ENO) and what hangs off it, in order."""

    logic: Logic | None
    outs: tuple[Coil | Box | Node, ...] = ()


@dataclass(frozen=True)
class Model:
    """One network: a rung (a node from the rail, or a counter box), or
    elements on the rail, or nothing; with the network's title and comment."""

    rung: Node | Box | None = None
    rail: tuple[Coil | Box, ...] = ()
    title: str = ""
    comment: str = ""


Element = Union[Contact, Series, Parallel, Coil, Box, Node]


def count_elements(x: Any) -> int:
    """How many elements (contacts, coils, boxes, nodes) a tree holds."""
    if isinstance(x, Model):
        return sum(count_elements(e) for e in ((x.rung,) if x.rung else ()) + x.rail)
    if isinstance(x, (Series, Parallel)):
        return sum(count_elements(i) for i in x.items)
    if isinstance(x, Node):
        return (1 + (count_elements(x.logic) if x.logic is not None else 0)
                + sum(count_elements(o) for o in x.outs))
    if isinstance(x, Box):
        return (1 + (count_elements(x.next) if x.next is not None else 0)
                + sum(count_elements(i) for i in x.inputs))
    return 1


def join(kind: type, items: list[Logic]) -> Logic:
    """``kind(items)`` with nested items of the same kind flattened and a
    single item returned as it is."""
    flat: list[Logic] = []
    for i in items:
        flat.extend(i.items if isinstance(i, kind) else (i,))
    if not flat:
        raise PlcConfigError("a series or parallel block without elements")
    return flat[0] if len(flat) == 1 else kind(tuple(flat))


def as_items(logic: Logic | None) -> list[Logic]:
    """A logic seen as a series of items."""
    if logic is None:
        return []
    return list(logic.items) if isinstance(logic, Series) else [logic]


# ---------------------------------------------------------------------------
# JSON
# ---------------------------------------------------------------------------

def model_to_json(model: Model) -> dict[str, Any]:
    """The JSON form: plain dicts, lists and strings."""
    out: dict[str, Any] = {"format": FORMAT, "version": VERSION,
                           "title": model.title, "comment": model.comment}
    out["rung"] = None if model.rung is None else _out_json(model.rung)
    out["rail"] = [_out_json(e) for e in model.rail]
    return out


def _logic_json(x: Logic) -> dict[str, Any]:
    if isinstance(x, Contact):
        if x.kind == "CMP":
            return {"el": "CMP", "cmp": x.cmp, "ops": list(x.ops)}
        return {"el": x.kind, "ops": list(x.ops)}
    return {"el": "series" if isinstance(x, Series) else "parallel",
            "items": [_logic_json(i) for i in x.items]}


_PIN = re.compile(r"~(\w+)$|([@_])(\d+)r?$|(\w+)([=>])(\d+)r?$")


def pins(insn: str) -> list[dict[str, Any]]:
    """Where the page shows each operand of a coil or box, from the shape
    table (:mod:`plcrt.isa.shape`): ``{"power": "IN"}`` for a power input,
    ``{"place": "above"|"below", "op": i}`` for an operand written above or
    below the element, ``{"name": "IN1", "op": i, "side": "in"|"out"}`` for a
    pin.  Empty for CALL (its pins are the called block's parameters, in
    order) and for what the table does not describe."""
    out: list[dict[str, Any]] = []
    for item in shape(insn).pins.split():
        m = _PIN.match(item)
        if m is None:  # pragma: no cover - the shape table's own test pins its grammar
            continue
        if m.group(1):
            out.append({"power": m.group(1)})
        elif m.group(2):
            out.append({"place": "above" if m.group(2) == "@" else "below",
                        "op": int(m.group(3))})
        else:
            out.append({"name": m.group(4), "op": int(m.group(6)),
                        "side": "out" if m.group(5) == ">" else "in"})
    return out


def _out_json(x: Coil | Box | Node) -> dict[str, Any]:
    if isinstance(x, Coil):
        return {"el": "coil", "insn": x.insn, "ops": list(x.ops), "lad": shape(x.insn).lad,
                "pins": pins(x.insn)}
    if isinstance(x, Box):
        d: dict[str, Any] = {"el": "box", "insn": x.insn, "ops": list(x.ops),
                             "lad": x.ops[0] if x.insn == "CALL" and x.ops else shape(x.insn).lad,
                             "pins": pins(x.insn)}
        d["next"] = None if x.next is None else _out_json(x.next)
        d["inputs"] = [_logic_json(i) for i in x.inputs]
        return d
    return {"el": "node", "logic": None if x.logic is None else _logic_json(x.logic),
            "outs": [_out_json(o) for o in x.outs]}


class JsonReader:
    """Reads an untrusted JSON document into a :class:`Model`; ``where`` is
    the path of the value being read, for messages."""

    def __init__(self) -> None:
        self.count = 0

    def fail(self, where: str, what: str) -> PlcConfigError:
        return PlcConfigError(f"ladder model {where or '(top)'}: {what}")

    def dict_(self, x: Any, where: str, keys: set[str], depth: int) -> dict[str, Any]:
        if depth > MAX_DEPTH:
            raise self.fail(where, f"nested deeper than {MAX_DEPTH} levels")
        if not isinstance(x, dict):
            raise self.fail(where, "expected an object")
        extra = [k for k in x if k not in keys]
        if extra:
            raise self.fail(where, f"unknown field {excerpt(str(extra[0]), 40)!r}")
        self.count += 1
        if self.count > MAX_ELEMENTS:
            raise self.fail(where, f"more than {MAX_ELEMENTS} elements")
        return x

    def text(self, x: Any, where: str, limit: int = MAX_OPERAND) -> str:
        if not isinstance(x, str):
            raise self.fail(where, "expected a text")
        if len(x) > limit:
            raise self.fail(where, f"longer than {limit} characters")
        return x

    def list_(self, x: Any, where: str, limit: int) -> list[Any]:
        if not isinstance(x, list):
            raise self.fail(where, "expected a list")
        if len(x) > limit:
            raise self.fail(where, f"more than {limit} items")
        return x

    def ops(self, d: dict[str, Any], where: str, n: int | None = None) -> tuple[str, ...]:
        raw = self.list_(d.get("ops", []), where + ".ops", MAX_OPERANDS)
        ops = tuple(self.text(o, f"{where}.ops[{i}]") for i, o in enumerate(raw))
        if n is not None and len(ops) != n:
            raise self.fail(where, f"{d.get('el')} takes {n} operand(s), got {len(ops)}")
        return ops

    def logic(self, x: Any, where: str, depth: int) -> Logic:
        d = self.dict_(x, where, {"el", "ops", "cmp", "items"}, depth)
        el = self.text(d.get("el"), where + ".el", 16)
        if el in ("series", "parallel"):
            raw = self.list_(d.get("items"), where + ".items", MAX_ELEMENTS)
            if len(raw) < 2:
                raise self.fail(where, f"a {el} block needs at least two items")
            items = [self.logic(i, f"{where}.items[{k}]", depth + 1) for k, i in enumerate(raw)]
            return join(Series if el == "series" else Parallel, items)
        if el in CONTACTS:
            return Contact(el, self.ops(d, where, 1))
        if el in MODIFIERS:
            return Contact(el, self.ops(d, where, 0))
        if el == "CMP":
            cmp = self.text(d.get("cmp"), where + ".cmp", 4)
            if not (len(cmp) >= 2 and cmp[0] in COMPARE_TYPES and cmp[1:] in RELATIONS):
                raise self.fail(where, f"unknown compare {excerpt(cmp, 8)!r} (a type of "
                                       f"{COMPARE_TYPES} and one of {' '.join(RELATIONS)})")
            return Contact("CMP", self.ops(d, where, 2), cmp)
        raise self.fail(where, f"unknown element {excerpt(str(el), 40)!r}")

    def out(self, x: Any, where: str, depth: int, rail: bool = False) -> Coil | Box | Node:
        d = self.dict_(x, where, {"el", "insn", "ops", "lad", "pins", "next", "inputs", "logic",
                                  "outs"}, depth)
        el = self.text(d.get("el"), where + ".el", 16)
        if el == "node" and not rail:
            logic = None if d.get("logic") is None else self.logic(d["logic"], where + ".logic",
                                                                    depth + 1)
            raw = self.list_(d.get("outs", []), where + ".outs", MAX_ELEMENTS)
            return Node(logic, tuple(self.out(o, f"{where}.outs[{k}]", depth + 1)
                                     for k, o in enumerate(raw)))
        if el not in ("coil", "box"):
            raise self.fail(where, f"unknown element {excerpt(str(el), 40)!r}")
        insn = self.text(d.get("insn"), where + ".insn", 16).upper()
        kind = shape(insn).kind
        want = ("rail",) if rail else (("coil",) if el == "coil" else ("box",))
        if kind not in want:
            what = "rail element" if rail else el
            raise self.fail(where, f"{excerpt(insn, 16)!r} is not a {what}")
        ops = self.ops(d, where)
        if el == "coil":
            return Coil(insn, ops)
        nxt = d.get("next")
        node = None if nxt is None else self.out(nxt, where + ".next", depth + 1)
        if node is not None and not isinstance(node, Node):
            raise self.fail(where + ".next", "expected a node")
        raw = self.list_(d.get("inputs", []), where + ".inputs", 3)
        inputs = tuple(self.logic(i, f"{where}.inputs[{k}]", depth + 1) for k, i in enumerate(raw))
        return Box(insn, ops, node, inputs)


def model_from_json(doc: Any) -> Model:
    """Read a model from untrusted JSON (already decoded); every field is
    checked (:class:`PlcConfigError` naming the place).  The structure is
    checked for what JSON can say; whether the drawing has an STL form is
    :func:`plcrt.view.ladder_stl.model_to_stl`'s check."""
    r = JsonReader()
    d = r.dict_(doc, "", {"format", "version", "title", "comment", "rung", "rail"}, 0)
    r.count = 0
    if d.get("format") != FORMAT or d.get("version") != VERSION:
        raise r.fail("", f"not a {FORMAT} document of version {VERSION}")
    title = r.text(d.get("title", ""), "title", MAX_TEXT)
    comment = r.text(d.get("comment", ""), "comment", MAX_TEXT)
    raw = d.get("rung")
    rung = None if raw is None else r.out(raw, "rung", 1)
    if isinstance(rung, Coil):
        raise r.fail("rung", "a rung starts with a node or a counter box")
    rail = tuple(r.out(e, f"rail[{k}]", 1, rail=True)
                 for k, e in enumerate(r.list_(d.get("rail", []), "rail", MAX_ELEMENTS)))
    return Model(rung, rail, title, comment)  # type: ignore[arg-type]


__all__ = ["Box", "COMPARE_TYPES", "CONTACTS", "Coil", "Contact", "Element", "FORMAT",
           "JsonReader", "Logic", "MAX_ELEMENTS", "MODIFIERS", "Model", "Node", "Parallel",
           "RELATIONS", "Series", "VERSION", "as_items", "count_elements", "join",
           "model_from_json", "model_to_json", "pins"]
