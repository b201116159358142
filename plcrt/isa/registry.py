"""The instruction registry: one :class:`InsnSpec` per STL mnemonic.

Adding an instruction means one decorated emitter function in the module of
its family plus one row in that family's table test::

    @insn("INCW", W_RW, family="math", summary="OUT := OUT + 1")
    def _incw(g, out): ...

An emitter receives the code generator (:class:`plcrt.compiler.emit.Gen`) and
the already resolved and role-checked operands, and emits Python source
through ``g``.  Emitters never see operand text, so nothing from the program
text can reach generated code except validated numbers.

This module defines the data model only; the families live beside it.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Callable


class Role(enum.Enum):
    """What an instruction accepts at one operand position."""

    BIT_R = "bit"                    #: readable bit: I Q M V SM S T C L
    BIT_W = "writable bit"           #: I Q M V SM(>=SMB30) S L
    BIT_TC = "bit, timer or counter"  #: S/R ranges: writable bit or T/C
    IBIT = "input bit (I)"           #: immediate contacts
    QBIT = "output bit (Q)"          #: immediate outputs
    B_R = "byte"                     #: readable byte incl. constants, *ptr
    W_R = "word"
    D_R = "double word"
    R_R = "real"
    B_W = "writable byte"
    W_W = "writable word"
    D_W = "writable double word"
    R_W = "writable real"
    D_PTR = "double word or &address"  #: MOVD IN
    #: the start of a run of values in memory (block moves, tables, ASCII
    #: fields, the clock buffer): an address or a pointer, never a
    #: constant or an accumulator
    B_M = "byte in memory (an address or *pointer)"
    W_M = "word in memory (an address or *pointer)"
    D_M = "double word in memory (an address or *pointer)"
    B_MW = "writable byte in memory (an address or *pointer)"
    W_MW = "writable word in memory (an address or *pointer)"
    D_MW = "writable double word in memory (an address or *pointer)"
    B_IB = "input byte (IB)"           #: BIR IN
    B_QB = "output byte (QB)"          #: BIW OUT
    N = "constant count"             #: 1..255 (S/R ranges, BMx, FILL, shifts)
    TIMER = "timer (T0..T255)"
    COUNTER = "counter (C0..C255)"
    LABEL = "label number (0..255)"
    SBIT = "SCR bit (S)"
    STR_R = 'string (VB, LB, *VD, *LD, *AC or a constant "...")'  #: string input
    STR_M = "string in memory (VB, LB, *VD, *LD, *AC)"  #: string input, no constant
    STR_W = "writable string (VB, LB, *VD, *LD, *AC)"  #: string output
    NONE = "-"


@dataclass(frozen=True, slots=True)
class Span:
    """Operand *at* is the first of a run of memory: *count* elements of
    *unit* bits each, where the count is the value of operand *by* (its
    magnitude) when that is a constant, and *count* (the most it may be)
    when it is not or when *by* is None (a fixed run).  What memory an
    instruction reaches from an operand, for passes that place addresses
    (``--auto-symbols``); the emitters check the runs themselves."""

    at: int
    unit: int
    count: int
    by: int | None = None


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


_loaded = False


def lookup(mnemonic: str) -> InsnSpec | None:
    """The spec of a mnemonic, loading all families on first use."""
    if not _loaded:
        load_families()
    return REGISTRY.get(mnemonic)


def load_families() -> None:
    """Import every family module (each registers its instructions)."""
    global _loaded
    from . import families  # noqa: F401
    _loaded = True
