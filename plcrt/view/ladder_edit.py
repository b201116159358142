"""Edit operations on the ladder model, undo/redo, and the page's API.

An edit operation is data (a JSON object from the page), applied to an
immutable :class:`~plcrt.view.ladder_model.Model` to give a new one:

========== ==================================================================
``insert``  ``{"op": "insert", "at": PATH, "side": "before"|"after",
            "element": LOGIC}``: a contact in series before or after the
            element at PATH (or into the empty logic slot PATH after a
            box's ENO)
``parallel`` ``{"op": "parallel", "at": PATH, "count": N, "branch": LOGIC}``:
            a parallel branch around N elements of a series from PATH on
``output``  ``{"op": "output", "at": PATH, "index": I, "element": OUT}``: a
            coil, box or branch among the outputs of the node at PATH (at a
            box: after its ENO)
``delete``  ``{"op": "delete", "at": PATH}``
``replace`` ``{"op": "replace", "at": PATH, "element": LOGIC|OUT}``
``operands`` ``{"op": "operands", "at": PATH, "ops": [TEXT, ...]}``
``move``    ``{"op": "move", "from": PATH, "to": PATH, "side": ...}`` or
            ``..., "index": I}``: delete, then insert (a contact) or add as
            an output (a coil, box or branch); ``to`` is a path in the model
            after the deletion
``title``   ``{"op": "title", "title": TEXT, "comment": TEXT}``
========== ==================================================================

A PATH is a list of field names and indexes from the model down:
``["rung", "logic", 1]`` is the second element of the rung's series,
``["rung", "outs", 0]`` its first output, ``["rung", "outs", 2, "logic"]``
the logic of a branch, ``["rung", "outs", 0, "next"]`` what follows a box's
ENO.  Every result is normalized and checked (:mod:`plcrt.view.ladder_check`:
operands, the STL round trip); an operation whose result would not be
accepted is refused with a :class:`~plcrt.errors.PlcConfigError`, and the
model is unchanged.

This module has no HTTP: :func:`model_json` and :func:`edit_json` take and
give plain JSON values for whatever serves the page.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Callable

from ..errors import PlcConfigError, SourceLoc
from ..lang import ir
from ..safetext import excerpt
from .ladder import Box as LadBox
from .ladder import to_ladder
from .ladder_check import check_operands, check_round_trip
from .ladder_model import (MAX_DEPTH, MAX_ELEMENTS, MAX_OPERANDS, MAX_TEXT, Box, Coil, Contact,
                           JsonReader, Logic, Model, Node, Parallel, Series, count_elements, join,
                           model_from_json, model_to_json)
from .ladder_stl import NoLadder, model_to_stl, network_to_model, stl_line

#: the undo history keeps this many models
MAX_HISTORY = 200
_FIELDS = {"rung", "rail", "logic", "outs", "next", "inputs"}
_DELETE = object()


# ---------------------------------------------------------------------------
# Paths
# ---------------------------------------------------------------------------

def _path(raw: Any, name: str = "at") -> tuple[str | int, ...]:
    if not isinstance(raw, list) or len(raw) > MAX_DEPTH:
        raise PlcConfigError(f"edit: {name} must be a list of at most {MAX_DEPTH} steps")
    for s in raw:
        if isinstance(s, bool) or not (s in _FIELDS if isinstance(s, str) else
                                       isinstance(s, int) and 0 <= s < MAX_ELEMENTS):
            raise PlcConfigError(f"edit: {name} has a bad step {excerpt(repr(s), 40)}")
    return tuple(raw)


def _where(path: tuple[Any, ...]) -> str:
    return "/".join(str(p) for p in path) or "(model)"


def get(model: Model, path: tuple[Any, ...]) -> Any:
    """The value at ``path`` (see the module docstring)."""
    cur: Any = model
    for k, step in enumerate(path):
        cur = _child(cur, step, path[:k + 1])
    return cur


def _child(x: Any, step: Any, path: tuple[Any, ...]) -> Any:
    if isinstance(step, int):
        seq = x.items if isinstance(x, (Series, Parallel)) else x
        if isinstance(seq, tuple) and step < len(seq):
            return seq[step]
    elif not isinstance(x, tuple) and step in getattr(x, "__dataclass_fields__", {}):
        return getattr(x, step)
    raise PlcConfigError(f"edit: no element at {_where(path)}")


def _update(x: Any, path: tuple[Any, ...], fn: Callable[[Any], Any], done: tuple[Any, ...] = ()
            ) -> Any:
    """``x`` with the value at ``path`` replaced by ``fn(value)``; ``_DELETE``
    removes it from its sequence (or empties its slot)."""
    if not path:
        return fn(x)
    step, rest = path[0], path[1:]
    here = done + (step,)
    if isinstance(step, int):
        seq = x.items if isinstance(x, (Series, Parallel)) else x
        if not isinstance(seq, tuple) or step >= len(seq):
            raise PlcConfigError(f"edit: no element at {_where(here)}")
        new = _update(seq[step], rest, fn, here)
        items = list(seq[:step]) + ([] if new is _DELETE else [new]) + list(seq[step + 1:])
        if isinstance(x, (Series, Parallel)):
            return join(type(x), items) if items else _DELETE
        return tuple(items)
    _child(x, step, here)
    new = _update(getattr(x, step), rest, fn, here)
    if new is _DELETE:
        new = () if isinstance(getattr(x, step), tuple) else None
    return replace(x, **{step: new})


# ---------------------------------------------------------------------------
# Operations
# ---------------------------------------------------------------------------

def _logic_of(raw: Any, name: str) -> Logic:
    return JsonReader().logic(raw, f"edit {name}", 1)


def _out_of(raw: Any, name: str, at: tuple[Any, ...]) -> Coil | Box | Node:
    """An output from the page; on the rail (``at`` under ``rail``) a rail
    element (``LBL``, ``LSCR`` ...)."""
    return JsonReader().out(raw, f"edit {name}", 1, rail=bool(at) and at[0] == "rail")


def _is_logic(x: Any) -> bool:
    return isinstance(x, (Contact, Series, Parallel))


def _insert(model: Model, at: tuple[Any, ...], side: Any, new: Logic) -> Model:
    if side not in ("before", "after"):
        raise PlcConfigError("edit: side must be \"before\" or \"after\"")

    def fn(x: Any) -> Any:
        if x is None and at and at[-1] == "logic":
            return new
        if not _is_logic(x):
            raise PlcConfigError(f"edit: {_where(at)} is not a contact or a logic block")
        return join(Series, [new, x] if side == "before" else [x, new])
    return _update(model, at, fn)


def _parallel(model: Model, at: tuple[Any, ...], count: Any, branch: Logic) -> Model:
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_ELEMENTS:
        raise PlcConfigError("edit: count must be a whole number from 1")
    target = get(model, at)
    if not _is_logic(target):
        raise PlcConfigError(f"edit: {_where(at)} is not a contact or a logic block")
    parent = get(model, at[:-1]) if at and isinstance(at[-1], int) else None
    if count > 1:
        if not isinstance(parent, Series) or at[-1] + count > len(parent.items):
            raise PlcConfigError(f"edit: {_where(at)} is not followed by {count - 1} more "
                                 "element(s) in series")
        k = at[-1]
        items = list(parent.items)
        block = Parallel((join(Series, items[k:k + count]), branch))
        return _update(model, at[:-1],
                       lambda _: join(Series, items[:k] + [block] + items[k + count:]))
    return _update(model, at, lambda x: join(Parallel, [x, branch]))


def _output(model: Model, at: tuple[Any, ...], index: Any, new: Coil | Box | Node) -> Model:
    def fn(x: Any) -> Any:
        if isinstance(x, tuple):  # the rail
            return x[:place(x)] + (new,) + x[place(x):]
        if isinstance(x, Box) and x.inputs:
            raise PlcConfigError(f"edit: {_where(at)} is a counter box, which has no ENO")
        if isinstance(x, Box):
            nxt = x.next or Node(None)
            return replace(x, next=replace(nxt, outs=add(nxt.outs)))
        if not isinstance(x, Node):
            raise PlcConfigError(f"edit: {_where(at)} is not a node or a box")
        return replace(x, outs=add(x.outs))

    def place(outs: tuple[Any, ...]) -> int:
        i = len(outs) if index is None else index
        if isinstance(i, bool) or not isinstance(i, int) or not 0 <= i <= len(outs):
            raise PlcConfigError(f"edit: index must be from 0 to {len(outs)}")
        return i

    def add(outs: tuple[Any, ...]) -> tuple[Any, ...]:
        return outs[:place(outs)] + (new,) + outs[place(outs):]
    if at == ("rail",) and model.rung is not None:
        raise PlcConfigError("edit: a network with a rung has no elements on the rail")
    return _update(model, at, fn)


def _element_for(model: Model, at: tuple[Any, ...], raw: Any) -> Any:
    """The element from the page for the place ``at``: a contact or logic
    block where logic goes, a node after ENO, a node or a counter box as the
    rung, a coil, box or branch among outputs, a rail element on the rail."""
    get(model, at)  # the place exists
    last, before = at[-1], (at[-2] if len(at) > 1 else None)
    if last == "logic" or before == "inputs" or (
            isinstance(last, int) and isinstance(get(model, at[:-1]), (Series, Parallel))):
        return _logic_of(raw, "element")
    new = _out_of(raw, "element", at)
    if last == "next" and not isinstance(new, Node):
        raise PlcConfigError("edit: what follows a box's ENO is a node")
    if last == "rung" and not (isinstance(new, Node) or isinstance(new, Box) and new.inputs):
        raise PlcConfigError("edit: a rung is a node or a counter box with its inputs")
    if isinstance(last, int) and before not in ("outs", "rail"):
        raise PlcConfigError(f"edit: nothing can be put at {_where(at)}")
    return new


def _apply(model: Model, op: Any) -> Model:
    if not isinstance(op, dict):
        raise PlcConfigError("edit: an operation is a JSON object")
    kind = op.get("op")
    allowed = {"insert": {"at", "side", "element"}, "parallel": {"at", "count", "branch"},
               "output": {"at", "index", "element"}, "delete": {"at"},
               "replace": {"at", "element"}, "operands": {"at", "ops"},
               "move": {"from", "to", "side", "index"}, "title": {"title", "comment"}}
    if not isinstance(kind, str) or kind not in allowed:
        raise PlcConfigError(f"edit: unknown operation {excerpt(repr(kind), 40)} "
                             f"(one of {', '.join(allowed)})")
    extra = [k for k in op if k != "op" and k not in allowed[kind]]
    if extra:
        raise PlcConfigError(f"edit {kind}: unknown field {excerpt(repr(extra[0]), 40)}")
    if kind == "title":
        r = JsonReader()
        title = r.text(op.get("title", model.title), "title", MAX_TEXT)
        if len(title.splitlines()) > 1:
            raise PlcConfigError("edit title: a network title is one line")
        # blanks around the title and the comment lines go (normalize: the
        # parser does not keep them)
        return replace(model, title=title,
                       comment=r.text(op.get("comment", model.comment), "comment", MAX_TEXT))
    if kind == "move":
        src = _path(op.get("from"), "from")
        if not src:
            raise PlcConfigError("edit move: the path is empty")
        moved = get(model, src)
        rest = _update(model, src, lambda _: _DELETE)
        to = _path(op.get("to"), "to")
        if _is_logic(moved):
            return _insert(rest, to, op.get("side", "after"), moved)
        return _output(rest, to, op.get("index"), moved)
    at = _path(op.get("at"))
    if not at:
        raise PlcConfigError(f"edit {kind}: the path is empty")
    if kind == "insert":
        return _insert(model, at, op.get("side", "after"), _logic_of(op.get("element"), "element"))
    if kind == "parallel":
        return _parallel(model, at, op.get("count", 1), _logic_of(op.get("branch"), "branch"))
    if kind == "output":
        return _output(model, at, op.get("index"), _out_of(op.get("element"), "element", at))
    if kind == "delete":
        return _update(model, at, lambda _: _DELETE)
    if kind == "replace":
        new = _element_for(model, at, op.get("element"))
        return _update(model, at, lambda _: new)
    # operands
    raw = JsonReader().list_(op.get("ops"), "edit ops", 32)
    ops = tuple(JsonReader().text(o, f"edit ops[{k}]") for k, o in enumerate(raw))
    old = get(model, at)
    if not hasattr(old, "ops") or len(ops) != len(old.ops) and not isinstance(old, Box):
        raise PlcConfigError(f"edit: {_where(at)} has {len(getattr(old, 'ops', ()))} "
                             "operand(s)")
    return _update(model, at, lambda x: replace(x, ops=ops))


def check_model(model: Model, cpu: str | None = None) -> Model:
    """The model normalized, if it is one the editor may produce: at most
    :data:`MAX_ELEMENTS` elements, a title of one line, operands that fit,
    and STL that reads back as the same ladder; else :class:`PlcConfigError`."""
    if count_elements(model) > MAX_ELEMENTS:
        raise PlcConfigError(f"a network holds at most {MAX_ELEMENTS} elements")
    if len(model.title.splitlines()) > 1:
        raise PlcConfigError("a network title is one line")
    check_operands(model, cpu)
    return check_round_trip(model)


Check = Callable[[Model], Any]


def apply_edit(model: Model | dict[str, Any], op: Any, *, cpu: str | None = None,
               check: Check | None = None) -> Model:
    """Apply one edit operation (module docstring) and return the checked
    new model; raises :class:`PlcConfigError` (or what ``check`` raises) and
    leaves nothing changed when the operation or its result is refused.
    ``model`` may be the JSON form (untrusted: it is read and checked too).
    ``check`` is called with the new model last: with the program at hand,
    ``lambda m: check_in_program(text, block, number, m)`` refuses what only
    the whole program can tell (a missing subroutine, a symbol not in the
    table)."""
    if not isinstance(model, Model):
        model = check_model(model_from_json(model), cpu)
    new = check_model(_apply(model, op), cpu)
    if check is not None:
        check(new)
    return new


class History:
    """A model with undo and redo: a stack of immutable models (at most
    :data:`MAX_HISTORY`; the oldest steps are forgotten first)."""

    def __init__(self, model: Model, *, cpu: str | None = None,
                 check: Check | None = None) -> None:
        self._past: list[Model] = []
        self._future: list[Model] = []
        self.model = model
        self.cpu = cpu
        self.check = check

    def apply(self, op: Any) -> Model:
        new = apply_edit(self.model, op, cpu=self.cpu, check=self.check)
        self._past.append(self.model)
        del self._past[:-MAX_HISTORY]
        self._future.clear()
        self.model = new
        return new

    def undo(self) -> Model:
        if not self._past:
            raise PlcConfigError("nothing to undo")
        self._future.append(self.model)
        self.model = self._past.pop()
        return self.model

    def redo(self) -> Model:
        if not self._future:
            raise PlcConfigError("nothing to redo")
        self._past.append(self.model)
        self.model = self._future.pop()
        return self.model

    @property
    def can_undo(self) -> bool:
        return bool(self._past)

    @property
    def can_redo(self) -> bool:
        return bool(self._future)


# ---------------------------------------------------------------------------
# JSON for the page
# ---------------------------------------------------------------------------

def model_json(network: ir.Network, *, program: ir.Program | None = None) -> dict[str, Any]:
    """What the page draws for a network: ``{"ladder": MODEL, "stl": TEXT}``,
    or ``{"ladder": null, "stl": TEXT, "reason": WHY}`` when it stays STL.
    With ``program``, a CALL box's pins are named after the called
    subroutine's parameters (a library block's are named without it)."""
    got = network_to_model(network)
    if isinstance(got, NoLadder):
        stl = "".join(stl_line(i.mnemonic, tuple(o.text for o in i.operands)) + "\n"
                      for i in network.insns)
        return {"ladder": None, "stl": stl, "reason": got.reason}
    return _page(got, program)


def edit_json(doc: Any, op: Any, *, cpu: str | None = None,
              program: ir.Program | None = None, check: Check | None = None) -> dict[str, Any]:
    """:func:`apply_edit` on JSON: the model's JSON and an operation in,
    ``{"ladder": MODEL, "stl": TEXT}`` out (CALL pins as in :func:`model_json`)."""
    return _page(apply_edit(doc, op, cpu=cpu, check=check), program)


def _page(model: Model, program: ir.Program | None) -> dict[str, Any]:
    doc = model_to_json(model)
    _name_call_pins(doc, program)
    return {"ladder": doc, "stl": model_to_stl(model)}


def _name_call_pins(x: Any, program: ir.Program | None) -> None:
    if isinstance(x, list):
        for i in x:
            _name_call_pins(i, program)
    elif isinstance(x, dict):
        if x.get("el") == "box" and x.get("insn") == "CALL" and x.get("ops"):
            params = call_parameters(x["ops"][0], program)
            x["pins"] = [dict(params[k], op=k + 1) if k < len(params) else {"op": k + 1}
                         for k in range(len(x["ops"]) - 1)]
        for v in x.values():
            _name_call_pins(v, program)


def call_parameters(block: str, program: ir.Program | None = None) -> list[dict[str, str]]:
    """The parameters of a CALL's block, in CALL order (IN, IN_OUT, OUT):
    ``[{"name": "Start", "side": "in"}, ...]``, from the subroutine of
    ``program`` or the library description (``library/*.toml``); empty when
    neither knows the block.  The renderer's naming (:mod:`plcrt.view.ladder`)
    is asked with as many arguments as a CALL may have."""
    loc = SourceLoc("<ladder>", 1, 1)
    args = (block,) + tuple(f"P{k}" for k in range(MAX_OPERANDS - 1))
    insns = (ir.Insn("LD", (ir.Operand("SM0.0", loc),), loc),
             ir.Insn("CALL", tuple(ir.Operand(a, loc) for a in args), loc))
    ladder = to_ladder(ir.Network(1, "", insns, loc), program=program)
    rung = ladder.rung
    box = rung.outs[0] if rung is not None and not isinstance(rung, LadBox) else None
    pins = box.pins if isinstance(box, LadBox) else ()
    return [{"name": p.name, "side": "out" if p.right else "in"} for p in pins if p.name]


__all__ = ["History", "MAX_HISTORY", "apply_edit", "call_parameters", "check_model", "edit_json",
           "get", "model_json"]
