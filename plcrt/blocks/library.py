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

from typing import Any, Callable, TypeVar

from ..gen.recipe import CPU, Call

__all__ = ["LibraryBlock", "library_state", "per_cpu_state"]

T = TypeVar("T")


def per_cpu_state(make: Callable[[Any], T]) -> Callable[[Any], T]:
    """A function giving a CPU's state of a library family (its Modbus
    master, its USS master ...), made by ``make(plc)`` at the first call
    for that CPU: every PLC has its own, shared by its call sites (a fork's
    state is copied into the twin's own, through the binding
    :meth:`LibraryBlock.at_load` makes).  It is kept in the PLC's
    ``family_states``."""
    def state_of(plc: Any) -> T:
        states = plc.family_states
        state = states.get(state_of)
        if state is None:
            state = states[state_of] = make(plc)
        return state

    return state_of


def library_state(cls: type["LibraryBlock"], plc: Any) -> Any:
    """The state of ``cls``'s family for ``plc`` (what the generated code
    binds as ``cls.bind_as``)."""
    return cls.state_of(plc)


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
    def at_load(cls, g: Any, itf: Any) -> None:
        """Once per program and family: bind the shared state into the code
        (each PLC's own, :func:`library_state`) and warn :meth:`notice`."""
        once = g.unit.hooks.setdefault("library-once", set())
        if cls.family in once:
            return
        once.add(cls.family)
        g.bind(Call(library_state, (cls, CPU)), cls.bind_as)
        g.warn(cls.notice(itf), f"{cls.family}-library")
