"""One LLVM function under construction, for the native backend.

:class:`Fn` holds the function's SSA names, the logic stack as a list of
``i1`` values and the buffers it reaches (:data:`SLOTS`, the order of the
context table each segment function is called with), and writes the
function's text (split into parts of :data:`PART_LINES` lines).
:class:`NotLowered` is raised by everything that cannot run natively.
It knows no instruction: the lowerings are :mod:`.lower`'s, reading and
writing operands :mod:`.values`'.
"""

from __future__ import annotations

from typing import Callable

from ...gen.limits import MAX_STACK

#: the buffers a segment can reach, in the order of the context table
#: (NC, OC, CC, BP: an instrumented program's coverage tables, BRK: the
#: function a breakpoint calls, see :mod:`.probes`)
SLOTS = ("I", "Q", "M", "V", "SM", "S", "TV", "TB", "CV", "CB", "AC", "AI", "AQ",
         "T_RUN", "T_PRE", "T_D100", "T_PREV", "EDGES", "NC", "OC", "CC", "BP", "BRK")
SLOT = {name: i for i, name in enumerate(SLOTS)}

#: operand areas a native piece may read and write directly (L is per call,
#: HC is brought up to date by the engine, the immediate forms reach terminals)
AREAS = {"I", "Q", "M", "V", "SM", "S", "T", "C", "AC", "AI", "AQ"}

#: IR lines per generated function: a segment longer than this is split
#: into functions it calls in turn.  Code generation grows faster than
#: linearly with the size of one function (measured: a 1000-statement mixed
#: program's single function took 1.1 s, 2000 statements 10.5 s, 4000 47 s);
#: in parts of this size it stays linear.
PART_LINES = 2000


#: what every module declares: the byte swaps of 2- and 4-byte values (the
#: image is big-endian, see :func:`.values.rd`)
DECLARE = ("declare i16 @llvm.bswap.i16(i16)\n"
           "declare i32 @llvm.bswap.i32(i32)\n")


class NotLowered(Exception):
    """The piece cannot run natively (the reason is reported by ``plcrt dump``)."""


class Fn:
    """One LLVM function under construction: SSA names, the logic stack as a
    list of ``i1`` values, and the buffer pointers it loads at its entry."""

    def __init__(self, sink: Callable[[list[str], set[str]], str] | None = None) -> None:
        self.body: list[str] = []
        self.stack: list[str] = []
        self.slots: set[str] = set()
        self._n = 0
        #: the names of the finished parts (see :data:`PART_LINES`)
        self.parts: list[str] = []
        #: where a finished part goes: ``sink(body, slots)`` names it, writes
        #: its function and returns the name (a program's module stream,
        #: :meth:`plcrt.compiler.native.NativePlan.part`); without one,
        #: :meth:`emit` returns the parts (``part0``, ...) with the function
        self.sink = sink
        self._texts: list[str] = []
        self.site = -1    #: the instruction's EU/ED edge memory byte

    # -- SSA -------------------------------------------------------------
    def t(self) -> str:
        self._n += 1
        return f"%v{self._n}"

    def op(self, text: str) -> str:
        """Append ``%new = text`` and return the new name."""
        name = self.t()
        self.body.append(f"  {name} = {text}")
        return name

    def select(self, cond: str, ty: str, a: str, b: str) -> str:
        """``cond ? a : b`` of type ``ty``.

        perf: an ``i1`` or ``i8`` select is made in ``i32``: without
        optimisation LLVM's x86 code generator turns a narrow select into
        a branch, and every value alive across that branch goes to the
        stack (about twice the machine code of the whole statement); a
        32-bit select is one conditional move.
        """
        if ty not in ("i1", "i8"):
            return self.op(f"select i1 {cond}, {ty} {a}, {ty} {b}")
        wa = self.op(f"zext {ty} {a} to i32")
        wb = self.op(f"zext {ty} {b} to i32")
        return self.op(f"trunc i32 {self.op(f'select i1 {cond}, i32 {wa}, i32 {wb}')} to {ty}")

    def stmt(self, text: str) -> None:
        self.body.append(f"  {text}")

    def label(self) -> str:
        """A new basic block's name (the probes' breakpoint call only:
        everything else keeps a piece one block)."""
        self._n += 1
        return f"L{self._n}"

    def start(self, label: str) -> None:
        self.body.append(f"{label}:")

    # -- stack -------------------------------------------------------------
    def push(self, v: str) -> None:
        if len(self.stack) >= MAX_STACK:
            raise NotLowered("the logic stack overflows (the bottom level is lost)")
        self.stack.append(v)

    def combine(self, how: str, v: str) -> None:
        """A contact's or a compare's result: ``push`` it, or ``and``/``or``
        it into the top of the stack."""
        if how == "push":
            self.push(v)
        else:
            self.stack[-1] = self.op(f"{how} i1 {self.top}, {v}")

    @property
    def top(self) -> str:
        if not self.stack:
            raise NotLowered("the logic stack is empty")
        return self.stack[-1]

    def level(self, n: int) -> str:
        if len(self.stack) <= n:
            raise NotLowered("the logic stack holds too few levels")
        return self.stack[-1 - n]

    # -- memory ------------------------------------------------------------
    def base(self, slot: str) -> str:
        self.slots.add(slot)
        return f"%b{SLOT[slot]}"

    def at(self, slot: str, off: int) -> str:
        return self.op(f"getelementptr i8, ptr {self.base(slot)}, i64 {int(off)}")

    def load8(self, slot: str, off: int) -> str:
        return self.op(f"load i8, ptr {self.at(slot, off)}, align 1")

    def store8(self, slot: str, off: int, v: str) -> None:
        self.stmt(f"store i8 {v}, ptr {self.at(slot, off)}, align 1")

    def split(self) -> None:
        """Close the current part once it is long enough (between pieces):
        its text goes to the sink at once, so a long segment's lines are
        never all held."""
        if len(self.body) >= PART_LINES:
            self._part()

    def _part(self) -> None:
        body, slots = self.body, self.slots
        self.body, self.slots = [], set()
        if self.sink is not None:
            self.parts.append(self.sink(body, slots))
            return
        name = f"part{len(self.parts)}"
        self.parts.append(name)
        self._texts.append(function(name, body, slots))

    def emit(self, name: str) -> str:
        """The text of function ``name``: the segment's code, or, when it
        was split, calls of its parts in turn (whose texts went to the
        sink, or come first in the returned text without one)."""
        if not self.parts:
            return function(name, self.body, self.slots)
        self._part()
        calls = [f"  call void @{part}(ptr %ctx)" for part in self.parts]
        texts, self._texts = self._texts, []
        return "".join(texts) + "\n".join([f"define void @{name}(ptr %ctx) {{", "entry:",
                                             *calls, "  ret void", "}", ""])


def function(name: str, body: list[str], slots: set[str]) -> str:
    """The text of function ``name`` with ``body``, loading the buffer
    pointers of ``slots`` from the context table at its entry."""
    head = [f"define void @{name}(ptr %ctx) noinline {{", "entry:"]
    for slot in sorted(slots, key=SLOT.__getitem__):
        k = SLOT[slot]
        head.append(f"  %c{k} = getelementptr ptr, ptr %ctx, i64 {k}")
        head.append(f"  %b{k} = load ptr, ptr %c{k}, align 8")
    return "\n".join(head + body + ["  ret void", "}", ""])


__all__ = ["AREAS", "DECLARE", "PART_LINES", "SLOT", "SLOTS", "Fn", "NotLowered", "function"]
