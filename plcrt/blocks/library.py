"""The base of built-in blocks that stand for a Siemens instruction library
(the Modbus master and slave, USS): one state per CPU shared by the call
sites, and a load-time notice once per program.

What it is: :class:`LibraryBlock`.  A family sets ``family`` (the key of
its notice, whose code is ``<family>-library``), ``bind_as`` (the name its
state is bound under in the generated code, so that a fork copies the state
with the blocks), ``state_of`` (made by :func:`per_cpu_state`),
``state_attr`` and :meth:`notice`.  What it is not: the call's code
(plcrt.blocks.call) or any protocol.
"""

from __future__ import annotations

import weakref
from typing import Any, Callable, TypeVar

from ..compiler.cache import per_cpu

__all__ = ["LibraryBlock", "per_cpu_state"]

T = TypeVar("T")


def per_cpu_state(make: Callable[[Any], T]) -> Callable[[Any], T]:
    """A function giving a CPU's state of a library family (its Modbus
    master, its USS master ...), made by ``make(plc)`` at the first call
    for that CPU.  The states are registered with the program cache
    (:func:`plcrt.compiler.cache.per_cpu`), so a PLC built from a cached
    program gets its own copy, the one its blocks were rebound to."""
    states: "weakref.WeakKeyDictionary[Any, T]" = per_cpu(weakref.WeakKeyDictionary())

    def state_of(plc: Any) -> T:
        state = states.get(plc)
        if state is None:
            state = states[plc] = make(plc)
        return state

    return state_of


class LibraryBlock:
    """One call site of a library block."""

    family = ""
    bind_as = "lib"
    #: plc -> the family's state of that CPU (a staticmethod of a
    #: :func:`per_cpu_state` function)
    state_of: Callable[[Any], Any]
    #: the attribute of a call site that holds that state
    state_attr = "state"

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        self.plc, self.loc, self.name = plc, loc, itf.name
        setattr(self, self.state_attr, type(self).state_of(plc))

    @classmethod
    def notice(cls, itf: Any) -> str:
        """The load-time warning: what is emulated, what is plcrt's choice."""
        raise NotImplementedError

    def warn(self, msg: str, code: str) -> None:
        """A diagnostic of this call site, once per site and code."""
        self.plc.warn(f"{self.name}: {msg}", self.loc, f"{self.name}:{code}:{id(self)}")

    @classmethod
    def at_load(cls, g: Any, itf: Any, plc: Any) -> None:
        """Once per program and family: bind the shared state into the code
        and warn :meth:`notice`."""
        once = g.unit.hooks.setdefault("library-once", set())
        if cls.family in once:
            return
        once.add(cls.family)
        g.bind(cls.state_of(plc), cls.bind_as)
        g.warn(cls.notice(itf), f"{cls.family}-library")
