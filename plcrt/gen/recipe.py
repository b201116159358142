"""Bindings as data: how generated code names the run-time objects of a PLC.

What it is: the recipes an emitter binds instead of an object of a running
PLC, and :func:`resolve`, which turns a table of them into one PLC's own
objects.  A compiled program is shared by every PLC of it (and pickled
between processes), so what its code calls in the CPU -- a method of the
timer bank, the interrupt system's ``clear``, a library block of a call
site, a call's L buffer -- is written down as a recipe:

* :data:`CPU` -- the PLC itself;
* :class:`Attr` -- an attribute path of another recipe's object
  (``Attr(CPU, "timers.reset")``: the PLC's timer bank's ``reset``);
* :class:`Item` -- an item of another recipe's object (one helper of a
  table of helpers);
* :class:`Call` -- ``fn(*args)`` with the recipes among ``args`` resolved
  first (``Call(bytearray, (4,))``: a new L buffer; ``Call(make, (CPU,))``:
  a closure over the PLC made for it).

A recipe object resolved twice for one PLC gives the same object: two names
bound to one recipe share it (the memo is by identity, and pickling keeps
identity within one table).  ``fn`` of a :class:`Call` is a module-level
function or class, so a table pickles (by reference) and unpickles in
another process.

What it is not: the engine (it only follows attributes and calls what a
recipe names) nor the compiler (which decides what to bind).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import reduce
from typing import Any, Callable, Mapping

__all__ = ["Attr", "CPU", "Call", "Cpu", "Item", "Recipe", "buffers", "is_recipe", "resolve"]


class Recipe:
    """How to find or make one run-time object of a PLC."""

    __slots__ = ()

    def make(self, root: Any, memo: dict[int, Any]) -> Any:
        raise NotImplementedError


@dataclass(frozen=True, eq=False)
class Cpu(Recipe):
    """The PLC the table is resolved for."""

    def make(self, root: Any, memo: dict[int, Any]) -> Any:
        return root


#: the PLC itself
CPU = Cpu()


@dataclass(frozen=True, eq=False)
class Attr(Recipe):
    """The attribute at dotted ``path`` of ``of``'s object."""

    of: Recipe
    path: str

    def make(self, root: Any, memo: dict[int, Any]) -> Any:
        return reduce(getattr, self.path.split("."), _get(self.of, root, memo))


@dataclass(frozen=True, eq=False)
class Item(Recipe):
    """``of``'s object ``[key]``."""

    of: Recipe
    key: Any

    def make(self, root: Any, memo: dict[int, Any]) -> Any:
        return _get(self.of, root, memo)[self.key]


@dataclass(frozen=True, eq=False)
class Call(Recipe):
    """``fn(*args)``, recipes among ``args`` resolved for the PLC."""

    fn: Callable[..., Any]
    args: tuple[Any, ...] = ()

    def make(self, root: Any, memo: dict[int, Any]) -> Any:
        return self.fn(*(_get(a, root, memo) if isinstance(a, Recipe) else a
                         for a in self.args))


def _get(recipe: Recipe, root: Any, memo: dict[int, Any]) -> Any:
    key = id(recipe)
    if key not in memo:
        memo[key] = recipe.make(root, memo)
    return memo[key]


def is_recipe(obj: object) -> bool:
    """Whether ``obj`` is a recipe (resolved per PLC), not a shared value."""
    return isinstance(obj, Recipe)


def resolve(table: Mapping[str, Any], root: Any) -> dict[str, Any]:
    """``table`` (name -> recipe or shared value) for the PLC ``root``:
    recipes become that PLC's objects, in the table's order (a library
    block made before the name that binds its ``__call__``); other values
    are shared as they are."""
    memo: dict[int, Any] = {}
    return {name: _get(v, root, memo) if isinstance(v, Recipe) else v
            for name, v in table.items()}


def buffers(contents: tuple[bytes, ...]) -> list[bytearray]:
    """New buffers holding ``contents`` (the L buffers of a call site, one
    per nesting level)."""
    return [bytearray(c) for c in contents]
