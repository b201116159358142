"""The instruction registry: one :class:`InsnSpec` per STL mnemonic.

Adding an instruction means one decorated emitter function in the module of
its family plus one row in that family's table test::

    @insn("INCW", W_RW, family="math", summary="OUT := OUT + 1")
    def _incw(g, out): ...

An emitter receives the code generator (:class:`plcrt.gen.emit.Gen`) and
the already resolved and role-checked operands, and emits Python source
through ``g``.  Emitters never see operand text, so nothing from the program
text can reach generated code except validated numbers.

This module defines the data model only; the families live beside it and
register themselves when the package is imported (``plcrt/isa/__init__.py``).
The operand roles are :mod:`plcrt.gen.roles`' (re-exported here).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..gen.roles import Role, Span


@dataclass(frozen=True, slots=True)
class InsnSpec:
    """Static description of one mnemonic."""

    mnemonic: str
    roles: tuple[Role, ...]
    emit: Callable[..., None]
    family: str
    summary: str
    variadic: bool = False   #: CALL: any number of trailing operands
    may_fail: bool = False   #: sets ENO = 0 on errors (for AENO)
    flow: str = ""           #: control-flow kind, see compiler.codegen
    spans: tuple[Span, ...] = ()   #: operands that start a run of memory


REGISTRY: dict[str, InsnSpec] = {}

#: Mnemonics the S7-200 has but plcrt does not execute (reported by ``plcrt
#: check`` with their locations, apart from unknown ones): none.
KNOWN_UNIMPLEMENTED: frozenset[str] = frozenset()


def insn(mnemonic: str, *roles: Role, family: str, summary: str,
         variadic: bool = False, may_fail: bool = False,
         flow: str = "", spans: tuple[Span, ...] = ()
         ) -> Callable[[Callable[..., None]], Callable[..., None]]:
    """Register an emitter for ``mnemonic`` (decorator)."""

    def register(fn: Callable[..., None]) -> Callable[..., None]:
        if mnemonic in REGISTRY:
            raise ValueError(f"instruction {mnemonic!r} registered twice")
        REGISTRY[mnemonic] = InsnSpec(mnemonic, roles, fn, family, summary,
                                      variadic, may_fail, flow, spans)
        return fn

    return register


def lookup(mnemonic: str) -> InsnSpec | None:
    """The spec of a mnemonic.  Every family is registered by then: importing
    this module imports the package :mod:`plcrt.isa`, which imports them."""
    return REGISTRY.get(mnemonic)


def load_families() -> None:
    """Nothing left to do: the families registered when :mod:`plcrt.isa`
    was imported (kept for callers that ask for the full registry)."""


__all__ = ["InsnSpec", "KNOWN_UNIMPLEMENTED", "REGISTRY", "Role", "Span", "insn", "load_families",
           "lookup"]
