"""The intermediate representation produced by the front end.

A :class:`Program` is a list of :class:`Pou` (OB1, SBRs, INTs) made of
:class:`Network` s of :class:`Insn` s.  Operands are kept as the text the user
wrote (``VW100``, ``+10``, ``&VB0``, ``#Start``, ``电机启动``); classifying and
resolving them is the compiler's job, so the grammar stays generic.  All nodes
are immutable and carry their :class:`~plcrt.errors.SourceLoc`.

This module holds data only: no parsing and no semantics.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from ..errors import SourceLoc

PouKind = Literal["OB", "SBR", "INT"]
VarSection = Literal["IN", "IN_OUT", "OUT", "TEMP"]


@dataclass(frozen=True, slots=True)
class Operand:
    """One operand exactly as written (stripped of surrounding blanks)."""

    text: str
    loc: SourceLoc


@dataclass(frozen=True, slots=True)
class Insn:
    """One STL instruction: upper-cased mnemonic plus raw operands."""

    mnemonic: str
    operands: tuple[Operand, ...]
    loc: SourceLoc
    comment: str = ""


@dataclass(frozen=True, slots=True)
class Network:
    """A network: its number as written, optional title and instructions."""

    number: int
    title: str
    insns: tuple[Insn, ...]
    loc: SourceLoc
    comment: str = ""


@dataclass(frozen=True, slots=True)
class VarDecl:
    """A subroutine interface or temporary variable (``Start:BOOL;``)."""

    section: VarSection
    name: str
    type: str  #: upper-cased: BOOL BYTE WORD DWORD INT DINT REAL CHAR STRING
    loc: SourceLoc
    comment: str = ""


@dataclass(frozen=True, slots=True)
class Pou:
    """A program organisation unit: OB1, SBRn or INTn."""

    kind: PouKind
    number: int  #: 1 for OB1, n for SBRn / INTn
    name: str  #: symbolic name ("MAIN", "系统初始化"); the id when none given
    title: str
    variables: tuple[VarDecl, ...]
    networks: tuple[Network, ...]
    loc: SourceLoc
    comment: str = ""

    @property
    def ident(self) -> str:
        """The block id as Micro/WIN shows it: ``OB1``, ``SBR3``, ``INT0``."""
        return f"{self.kind}{self.number}"


@dataclass(frozen=True, slots=True)
class Program:
    """A parsed program file (or several concatenated)."""

    pous: tuple[Pou, ...]
    file: str
    source: str = field(repr=False, default="")
    #: codec its files were decoded with ("" for text, or files that differ)
    encoding: str = ""

    def instruction_count(self) -> int:
        return sum(len(n.insns) for p in self.pous for n in p.networks)

    def network_count(self) -> int:
        return sum(len(p.networks) for p in self.pous)
