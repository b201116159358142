"""The native backend: network pieces as machine code (optional, llvmlite).

``plcrt.load(..., backend="native")`` compiles the pieces that
:mod:`.lower` can lower (bit logic, the logic stack, byte/word/double-word
compares and moves, integer math with its flags, word logic, conversions,
edges, the 100 ms timers' boxes and resets) to machine code; consecutive
lowered pieces of a block become one *segment*, one call from the block's
runner.  An instrumented program's probes (coverage, breakpoints) are
lowered too (:mod:`.probes`).  Everything else -- a piece with a call, a
jump, a label or a loop, an instruction outside the table, an L-memory
operand -- runs as the Python backend's code, which is generated for every
piece in either case (``plcrt dump`` shows it).  Both backends give the
same memory image and the same coverage after every scan: the differential
tests compare them.

This package is not the compiler of llvmlite itself (:mod:`.jit`), and
imports it only there: where llvmlite is missing the rest still imports,
and ``backend="auto"`` runs the Python backend.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from . import probes  # noqa: F401 - registers the probes' lowerings
from .fn import DECLARE
from .lower import Fn, NotLowered, lower_piece

__all__ = ["NativePlan", "NotLowered", "plan_pou"]


@dataclass
class NativePlan:
    """What the native backend makes of one program.

    Attributes:
        functions: LLVM IR text of each segment function, in segment order.
        names: the segment functions' names.
        pieces: how many pieces run natively.
        python: ``(block, network, reason)`` of each piece left in Python.
    """

    functions: list[str] = field(default_factory=list)
    names: list[str] = field(default_factory=list)
    pieces: int = 0
    python: list[tuple[str, int, str]] = field(default_factory=list)
    #: the binding name of the program's EU/ED edge memory, if it has any
    edges: str | None = None

    @property
    def ir(self) -> str:
        return DECLARE + "".join(self.functions)


def plan_pou(plan: NativePlan, block: str, flow: bool,
             pieces: list[tuple[int, list[tuple[str, list[Any], int]], int]]
             ) -> list[int | None]:
    """Group the pieces of one block into segments.

    ``pieces``: per piece, its network number, its resolved instructions and
    the stack levels it starts with (a loop body that shares its FOR's
    network starts with the FOR's enable levels, all 1).  Returns, per piece, the segment index it belongs to or None
    (Python).  In a block without jumps and loops consecutive lowered pieces
    share one segment (the runner is a straight list of calls); in a block
    with them each lowered piece is its own segment, since a jump may land
    on any piece.  The pieces that hold the jumps, labels and loops
    themselves stay Python.
    """
    out: list[int | None] = [None] * len(pieces)
    seg: Fn | None = None
    for i, (net, insns, depth) in enumerate(pieces):
        f = seg if seg is not None else Fn()
        mark = (len(f.body), set(f.slots))
        try:
            f.stack = ["true"] * depth
            lower_piece(f, insns)
        except NotLowered as e:
            del f.body[mark[0]:]
            f.slots = mark[1]
            f.stack.clear()
            plan.python.append((block, net, str(e)))
            seg = _close(plan, seg)
            continue
        f.split()
        seg = f
        plan.pieces += 1
        out[i] = len(plan.names)
        if flow:
            seg = _close(plan, seg)
    _close(plan, seg)
    return out


def _close(plan: NativePlan, seg: Fn | None) -> None:
    """End the open segment (its index is ``len(plan.names)`` until now)."""
    if seg is not None:
        name = f"seg{len(plan.names)}"
        plan.names.append(name)
        plan.functions.append(seg.emit(name))
    return None
