"""The error an instruction emitter raises when it cannot generate code.

:class:`CodegenError` becomes a compile diagnostic at the instruction (or
at one of its operands); the resolver's :class:`plcrt.gen.resolve.ResolveError`
is the other error an emitter may let through.  Neither reaches the user as
an exception: the compiler turns both into ``PlcCompileError`` entries.
"""

from __future__ import annotations

from ..errors import SourceLoc


class CodegenError(Exception):
    """An instruction cannot be generated; becomes a diagnostic at its
    location, or at ``loc`` (an operand's) when given.  ``reported``: the
    problem is already a diagnostic (an unmatched FOR/NEXT or LSCR/SCRE
    found while splitting the block), so it is not listed twice."""

    def __init__(self, message: str, loc: SourceLoc | None = None, *,
                 reported: bool = False) -> None:
        super().__init__(message)
        self.loc = loc
        self.reported = reported


__all__ = ["CodegenError"]
