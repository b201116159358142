"""The intermediate representation produced by the front end.

A :class:`Program` is a list of :class:`Pou` (OB1, SBRs, INTs) made of
:class:`Network` s of :class:`Insn` s.  Operands are kept as the text the user
wrote (``VW100``, ``+10``, ``&VB0``, ``#Start``, ``电机启动``); classifying and
resolving them is the compiler's job, so the grammar stays generic.  All nodes
are immutable and carry their :class:`~plcrt.errors.SourceLoc` (an operand:
its instruction's, with its own column).

This module holds data only: no parsing and no semantics.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

from ..errors import SourceLoc

PouKind = Literal["OB", "SBR", "INT"]
VarSection = Literal["IN", "IN_OUT", "OUT", "TEMP"]


@dataclass(frozen=True, slots=True, repr=False)
class Operand:
    """One operand exactly as written (stripped of surrounding blanks).

    Its location is a location on its line (the parsers give the operand
    its instruction's :class:`~plcrt.errors.SourceLoc`, the one object
    they share) and its own column: a program keeps no location object per
    operand.  ``Operand(text, loc)`` (no column) has the location ``loc``.
    """

    text: str
    #: a location on the operand's line: its file, line, block and network
    at: SourceLoc
    #: the operand's column, or 0 for the column of ``at``
    column: int = 0

    @property
    def loc(self) -> SourceLoc:
        """Where the operand is (file, line, column, block, network)."""
        at = self.at
        if not self.column or self.column == at.column:
            return at
        # perf: built when asked (error messages, coverage), not stored
        return SourceLoc(at.file, at.line, self.column, at.block, at.network)

    def __repr__(self) -> str:
        return f"Operand(text={self.text!r}, loc={self.loc!r})"


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
    #: plant tables a project file's wizards give (TOML, as a plant file
    #: writes them; docs/project-files.md, "Wizards"); "" for none
    project_plant: str = ""
    #: the system block of the project file it was read from (None for an
    #: export): settings for the CPU, not part of the program's IR
    system: Any = field(default=None, compare=False, repr=False)
    #: what the project file's reader left out or could not map (one line
    #: each, names read from the file; ``plcrt check`` prints them)
    project_notes: tuple[str, ...] = field(default=(), compare=False, repr=False)
    #: read from a project file, which stores a local variable's size and
    #: not its sign (a protected block's interface is matched by size)
    from_project: bool = field(default=False, compare=False, repr=False)

    def instruction_count(self) -> int:
        return sum(len(n.insns) for p in self.pous for n in p.networks)

    def network_count(self) -> int:
        return sum(len(p.networks) for p in self.pous)
