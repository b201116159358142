"""The native backend: network pieces as machine code (optional, llvmlite).

``plcrt.load(..., backend="native")`` compiles the pieces that
:mod:`.lower` can lower (bit logic, the logic stack, byte/word/double-word
compares and moves, integer math with its flags, 100 ms TON) to machine
code; consecutive lowered pieces of a block become one *segment*, one call
from the block's runner.  Everything else -- a piece with a call, a jump or
loop in its block, an instruction outside the table, an L-memory operand,
an instrumented program (coverage, breakpoints) -- runs as the Python
backend's code, which is generated for every piece in either case (``plcrt
dump`` shows it).  Both backends give the same memory image after every
scan: the differential tests compare them.

This package is not the compiler of llvmlite itself (:mod:`.jit`), and
imports it only there: the default install stays pure Python.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

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

    @property
    def ir(self) -> str:
        return "".join(self.functions)


def plan_pou(plan: NativePlan, block: str, flow: bool,
             pieces: list[tuple[int, list[tuple[str, list[Any]]] | None]]) -> list[int | None]:
    """Group the pieces of one block into segments.

    ``pieces``: per piece, its network number and its resolved instructions
    (None: the piece could not be recorded, it stays Python).  Returns, per
    piece, the segment index it belongs to or None (Python).  Only blocks
    without jumps and loops are lowered: their runner is a straight list of
    calls.
    """
    out: list[int | None] = [None] * len(pieces)
    if flow:
        for net, _ in pieces:
            plan.python.append((block, net, "the block has jumps, loops or SCR segments"))
        return out
    seg: Fn | None = None
    for i, (net, insns) in enumerate(pieces):
        if insns is None:
            plan.python.append((block, net, "not recorded"))
            seg = _close(plan, seg)
            continue
        f = seg if seg is not None else Fn()
        mark = (len(f.body), set(f.slots))
        try:
            lower_piece(f, insns)
        except NotLowered as e:
            del f.body[mark[0]:]
            f.slots = mark[1]
            f.stack.clear()
            plan.python.append((block, net, str(e)))
            seg = _close(plan, seg)
            continue
        seg = f
        plan.pieces += 1
        out[i] = len(plan.names)
    _close(plan, seg)
    return out


def _close(plan: NativePlan, seg: Fn | None) -> None:
    """End the open segment (its index is ``len(plan.names)`` until now)."""
    if seg is not None:
        name = f"seg{len(plan.names)}"
        plan.names.append(name)
        plan.functions.append(seg.emit(name))
    return None
