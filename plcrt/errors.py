"""Source locations, diagnostics and the plcrt error hierarchy.

Every stage reports problems as :class:`Diagnostic` values that carry a
:class:`SourceLoc`; a stage that fails raises one :class:`PlcError` subclass
holding *all* diagnostics it found.  Messages are GNU style so editors can jump
to them::

    prog.awl:12:5: error: unknown instruction 'LDX' [OB1 network 7]

This module is not a logger and does no I/O.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterable, Literal, Sequence

from .safetext import excerpt, printable

Severity = Literal["error", "warning", "note"]


@dataclass(frozen=True, slots=True)
class SourceLoc:
    """A position in a source file, optionally inside a block and network."""

    file: str
    line: int
    column: int
    block: str | None = None  #: block id as the user sees it, e.g. "OB1", "SBR3"
    network: int | None = None  #: network number as written in the file

    def within(self, block: str | None, network: int | None) -> SourceLoc:
        """Return a copy that also names the block and network."""
        # perf: the constructor, not dataclasses.replace (once per
        # instruction of every load)
        return SourceLoc(self.file, self.line, self.column, block, network)

    def context(self) -> str:
        """The ``[OB1 network 7]`` suffix, or an empty string."""
        if self.block is None:
            return ""
        block = excerpt(self.block)
        if self.network is None:
            return f" [{block}]"
        return f" [{block} network {self.network}]"

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


@dataclass(frozen=True, slots=True)
class Diagnostic:
    """One finding of a compiler or runtime stage."""

    severity: Severity
    message: str
    loc: SourceLoc | None = None
    code: str = ""  #: short machine-readable tag, e.g. "unimplemented"

    def __str__(self) -> str:
        # One line, whatever the message quotes from the program (operand
        # text, symbol names): control characters are shown as escapes.
        if self.loc is None:
            return printable(f"{self.severity}: {self.message}")
        return printable(f"{self.loc}: {self.severity}: {self.message}{self.loc.context()}")


#: most diagnostics listed in one report (``plcrt check``, ``str(PlcError)``);
#: a file with thousands of errors gets the first ones and a count of the rest
MAX_LISTED = 100

_RANK = {"error": 0, "warning": 1, "note": 2}


def _position(d: Diagnostic) -> tuple[int, str, int, int]:
    if d.loc is None:
        return (0, "", 0, 0)
    return (1, d.loc.file, d.loc.line, d.loc.column)


def capped(diags: Sequence[Diagnostic], limit: int = MAX_LISTED, *,
           ordered: bool = False) -> tuple[list[Diagnostic], str | None]:
    """The diagnostics to list, at most ``limit``, and the summary line of
    the ones left out (None when all are listed).

    Errors are kept before warnings and notes, so a warning flood cannot
    hide an error.  ``ordered`` sorts the kept ones by source position
    (stable), as :func:`plcrt.cli.print_diagnostics` lists them.
    """
    if len(diags) <= limit:
        kept = list(diags)
        rest: list[Diagnostic] = []
    else:
        by_rank = sorted(range(len(diags)), key=lambda i: _RANK.get(diags[i].severity, 3))
        keep = set(by_rank[:limit])
        kept = [d for i, d in enumerate(diags) if i in keep]
        rest = [d for i, d in enumerate(diags) if i not in keep]
    if ordered:
        kept.sort(key=_position)
    if not rest:
        return kept, None
    errors = sum(d.severity == "error" for d in rest)
    warnings = sum(d.severity == "warning" for d in rest)
    notes = len(rest) - errors - warnings
    parts = [f"{errors} more error{'s' if errors != 1 else ''}"] if errors else []
    if warnings:
        parts.append(f"{warnings} {'more ' if not errors else ''}"
                     f"warning{'s' if warnings != 1 else ''}")
    if notes:
        parts.append(f"{notes} note{'s' if notes != 1 else ''}")
    return kept, f"... and {', '.join(parts)} not listed (the first {limit} are shown)"


class PlcError(Exception):
    """Root of all errors plcrt reports to users."""

    def __init__(self, message: str, loc: SourceLoc | None = None,
                 diagnostics: Iterable[Diagnostic] = ()) -> None:
        super().__init__(message)
        self.message = message
        self.loc = loc
        self.diagnostics: list[Diagnostic] = list(diagnostics)
        if not self.diagnostics:
            self.diagnostics = [Diagnostic("error", message, loc)]

    def __str__(self) -> str:
        # at most MAX_LISTED lines and a count of the rest: a file with
        # thousands of errors must not turn one exception into a book
        kept, more = capped(self.diagnostics)
        lines = [str(d) for d in kept]
        if more is not None:
            lines.append(more)
        return "\n".join(lines)


class PlcSyntaxError(PlcError):
    """The program, symbol or data file text cannot be parsed.

    ``partial``: for a program, the blocks that parsed without an error
    (a :class:`plcrt.lang.ir.Program`), so that a viewer can draw them."""

    partial: Any = None


class PlcCompileError(PlcError):
    """The program parsed but cannot be compiled (all problems listed)."""


class PlcRuntimeError(PlcError):
    """A fatal fault while the program runs; the CPU goes to STOP."""


class PlcAddressError(PlcError, ValueError):
    """An address given through the API or the command line is not valid."""


class PlcConfigError(PlcError, ValueError):
    """A bad option or configuration value."""


class PlcKeyError(PlcAddressError, KeyError):
    """A name that is not a key of one of plcrt's mappings (a trace's
    signals, the fields of an axis or drive state); also a ``KeyError``, as
    the mapping protocol asks."""

    def __str__(self) -> str:
        return PlcError.__str__(self)   # not KeyError's repr() of the message


@dataclass
class DiagnosticSink:
    """Collects diagnostics of one stage; ``raise_if_errors`` ends the stage."""

    items: list[Diagnostic] = field(default_factory=list)

    def error(self, message: str, loc: SourceLoc | None, code: str = "") -> None:
        self.items.append(Diagnostic("error", message, loc, code))

    def warning(self, message: str, loc: SourceLoc | None, code: str = "") -> None:
        self.items.append(Diagnostic("warning", message, loc, code))

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.items if d.severity == "error"]

    def raise_if_errors(self, kind: type[PlcError] = PlcCompileError) -> None:
        errors = self.errors
        if errors:
            # the first error is the message (what a one-line report shows);
            # str() of the exception lists them all
            head = errors[0].message
            if len(errors) > 1:
                head += f" (and {len(errors) - 1} more error(s))"
            raise kind(head, errors[0].loc, self.items)
