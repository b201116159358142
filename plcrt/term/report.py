"""Exit statuses and diagnostics as every ``plcrt`` command reports them.

Exit status: 0 success, 1 a problem with the input (missing file, syntax or
compile error, bad option or address, internal error), 2 a run-time fault of
the PLC program (the CPU went to STOP), 3 a run stopped by ``--max-wall``.

Diagnostics go to stderr GNU-style (``file:line:col: error: ...``), at most
:data:`~plcrt.errors.MAX_LISTED` of them.  This module prints; what a
diagnostic says is decided by the core (:mod:`plcrt.errors`).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import TextIO

from ..errors import Diagnostic, capped

EXIT_OK = 0
EXIT_ERROR = 1
EXIT_FAULT = 2
EXIT_WALL = 3   #: the run reached --max-wall

#: the command's name in messages without a program location
PROG = "plcrt"


def print_diagnostics(diags: Sequence[Diagnostic], stream: TextIO | None = None) -> None:
    """GNU-style lines, in source order (stable for equal positions); at
    most :data:`~plcrt.errors.MAX_LISTED` of them (errors first), then one
    line counting the rest."""
    stream = stream or sys.stderr
    kept, more = capped(diags, ordered=True)
    for d in kept:
        print(str(d) if d.loc is not None else f"{PROG}: {d}", file=stream)
    if more is not None:
        print(f"{PROG}: {more}", file=stream)


def count_text(diags: Sequence[Diagnostic]) -> str:
    """``2 errors, 1 warning``: the summary ``plcrt check`` prints."""
    errors = sum(d.severity == "error" for d in diags)
    warnings = sum(d.severity == "warning" for d in diags)
    return (f"{errors} error{'s' if errors != 1 else ''}, "
            f"{warnings} warning{'s' if warnings != 1 else ''}")


__all__ = ["EXIT_ERROR", "EXIT_FAULT", "EXIT_OK", "EXIT_WALL", "PROG", "count_text",
           "print_diagnostics"]
