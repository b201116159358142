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
piece in either case (``plcrt dump`` shows it; a piece that runs natively
has it as comments, never compiled).  The IR is written as LLVM modules of
about :data:`MODULE_CHARS` characters, compressed as each is full; :mod:`.jit`
compiles them one at a time.  Both backends give the
same memory image and the same coverage after every scan: the differential
tests compare them.

This package is not the compiler of llvmlite itself (:mod:`.jit`), and
imports it only there: where llvmlite is missing the rest still imports,
and ``backend="auto"`` runs the Python backend.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field
from typing import Any

from . import probes  # noqa: F401 - registers the probes' lowerings
from .fn import DECLARE, function
from .lower import Fn, NotLowered, lower_piece

__all__ = ["MODULE_CHARS", "NativePlan", "NotLowered", "OpenSegment", "plan_pou"]


#: characters of IR text per LLVM module: a program's native code is
#: compiled module by module, and each module's LLVM memory is released
#: before the next is parsed (:mod:`.jit`), so this bounds the compiler's
#: peak.  Measured on 2026-12-04 (100 000-statement mixed program): 1 MB
#: modules (about 2000 statements) compile as fast as one module, and the
#: resident peak stays under 40 MiB of LLVM memory.
MODULE_CHARS = 1_000_000


@dataclass
class NativePlan:
    """What the native backend makes of one program.

    Attributes:
        modules: the LLVM modules' IR text, zlib-compressed, in order (a
            function of one module may call one of another: :mod:`.jit`
            links them); each is compressed as soon as it is full, so the
            program's IR text is never held whole.
        names: the segment functions' names.
        pieces: how many pieces run natively.
        python: ``(block, network, reason)`` of each piece left in Python.
    """

    modules: list[bytes] = field(default_factory=list)
    names: list[str] = field(default_factory=list)
    pieces: int = 0
    python: list[tuple[str, int, str]] = field(default_factory=list)
    #: the binding name of the program's EU/ED edge memory, if it has any
    edges: str | None = None
    #: the module being filled: function texts, their size, names defined
    #: and called
    _texts: list[str] = field(default_factory=list, repr=False)
    _chars: int = 0
    _defined: set[str] = field(default_factory=set, repr=False)
    _called: set[str] = field(default_factory=set, repr=False)
    _parts: int = 0

    @property
    def ir(self) -> str:
        """The whole IR text (every module; for ``plcrt dump`` and tests)."""
        self.finish()
        return "".join(zlib.decompress(m).decode("utf-8") for m in self.modules)

    def part(self, body: list[str], slots: set[str]) -> str:
        """Name and write one part of a long segment (:class:`Fn`'s sink)."""
        name = f"p{self._parts}"
        self._parts += 1
        self.add(name, function(name, body, slots))
        return name

    def add(self, name: str, text: str, calls: list[str] | tuple[str, ...] = ()) -> None:
        """Add the text of function ``name``, which calls ``calls``."""
        self._texts.append(text)
        self._chars += len(text)
        self._defined.add(name)
        self._called.update(calls)
        if self._chars >= MODULE_CHARS:
            self.finish()

    def finish(self) -> None:
        """Close the module being filled (declaring what it calls from
        the others) and compress it."""
        if not self._texts:
            return
        declare = "".join(f"declare void @{n}(ptr)\n"
                          for n in sorted(self._called - self._defined))
        text = DECLARE + declare + "".join(self._texts)
        self.modules.append(zlib.compress(text.encode("utf-8"), 1))
        self._texts, self._chars = [], 0
        self._defined, self._called = set(), set()


class OpenSegment:
    """The segment a block's planning leaves open between two runs of its
    pieces (:func:`plan_pou` with ``carry``): a block's pieces are planned
    as they are generated, a window at a time, so that their resolved
    instructions are never held for a whole block."""

    __slots__ = ("fn",)

    def __init__(self) -> None:
        self.fn: Fn | None = None

    def close(self, plan: NativePlan) -> None:
        """End the block: write its open segment."""
        self.fn = _close(plan, self.fn)


def plan_pou(plan: NativePlan, block: str, flow: bool,
             pieces: list[tuple[int, list[tuple[str, list[Any], int]], int]],
             carry: OpenSegment | None = None) -> list[int | None]:
    """Group the pieces of one block into segments.

    ``pieces``: per piece, its network number, its resolved instructions and
    the stack levels it starts with (a loop body that shares its FOR's
    network starts with the FOR's enable levels, all 1).  Returns, per piece, the segment index it belongs to or None
    (Python).  In a block without jumps and loops consecutive lowered pieces
    share one segment (the runner is a straight list of calls); in a block
    with them each lowered piece is its own segment, since a jump may land
    on any piece.  The pieces that hold the jumps, labels and loops
    themselves stay Python.  ``carry``: the pieces are one run of the
    block's, in order, and the segment open at their end stays open in it
    for the next run (:meth:`OpenSegment.close` ends the block); None: they
    are the whole block.
    """
    out: list[int | None] = [None] * len(pieces)
    seg: Fn | None = carry.fn if carry is not None else None
    for i, (net, insns, depth) in enumerate(pieces):
        f = seg if seg is not None else Fn(plan.part)
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
    if carry is not None:
        carry.fn = seg
    else:
        _close(plan, seg)
    return out


def _close(plan: NativePlan, seg: Fn | None) -> None:
    """End the open segment (its index is ``len(plan.names)`` until now)."""
    if seg is not None:
        name = f"seg{len(plan.names)}"
        plan.names.append(name)
        plan.add(name, seg.emit(name), seg.parts)
    return None
