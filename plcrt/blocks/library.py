"""The base of built-in blocks that stand for a Siemens instruction library
(the Modbus master and slave, USS): one state per CPU shared by the call
sites, and a load-time notice once per program.

What it is: :class:`LibraryBlock`.  A family sets ``family`` (the key of
its notice, whose code is ``<family>-library``), ``bind_as`` (the name its
state is bound under in the generated code, so that a fork copies the state
with the blocks), :meth:`shared` and :meth:`notice`.  What it is not: the
call's code (plcrt.blocks.call) or any protocol.
"""

from __future__ import annotations

from typing import Any

__all__ = ["LibraryBlock"]


class LibraryBlock:
    """One call site of a library block."""

    family = ""
    bind_as = "lib"

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        self.plc, self.loc, self.name = plc, loc, itf.name

    @staticmethod
    def shared(plc: Any) -> Any:
        """The family's state of *plc* (one per CPU)."""
        raise NotImplementedError

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
        g.bind(cls.shared(plc), cls.bind_as)
        g.warn(cls.notice(itf), f"{cls.family}-library")
