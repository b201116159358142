"""Operand roles: what an instruction accepts at each operand position.

:class:`Role` names the kinds of operand (a readable bit, a writable word,
a timer, a label ...) that the resolver (:mod:`plcrt.gen.resolve`) checks
an operand against; :class:`Span` says which memory an operand starts a
run of.  The instruction registry (:mod:`plcrt.isa.registry`) gives each
mnemonic its roles and spans; this module is only the vocabulary, below
both the registry and the resolver.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


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


__all__ = ["Role", "Span"]
