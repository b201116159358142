"""The probes of an instrumented program in native code.

The code generator records, in a piece's resolved instructions, where the
Python code gets its probes (:mod:`plcrt.compiler.network`): ``@NET``
(network ``k`` ran; on its first piece the breakpoint check), ``@OUT``
(output ``j`` reached with the power of stack level ``n``) and ``@CON``
(contact ``j``: the top of the stack).  These lowerings write the same
bytes into the same tables of :class:`plcrt.engine.coverage.CoverageMap`
(``hits``, ``power``, ``closed``) as the Python probes, so both backends
count coverage alike (the differential tests compare them).

A breakpoint is a byte of ``breakpoints``: when it is set, the segment
calls back into Python (:func:`plcrt.compiler.native.jit.probe_buffers`
makes the callback, ``CoverageMap.hit``) before the network runs, and goes
on when it returns.  Every operand is read from memory when used, never
kept from before the call, so what the debugger writes while paused is
what the network sees.

It is not the coverage report (:mod:`plcrt.engine.coverage`) and imports
no llvmlite.
"""

from __future__ import annotations

from .fn import Fn
from .lower import lowers


def _mark(f: Fn, slot: str, j: int, v: str) -> None:
    """``table[j] |= v + 1`` for an ``i1`` value (bit 0: seen 0, bit 1: seen 1)."""
    old = f.load8(slot, j)
    bit = f.op(f"add i8 {f.op(f'zext i1 {v} to i8')}, 1")
    f.store8(slot, j, f.op(f"or i8 {old}, {bit}"))


@lowers("@NET")
def _network(f: Fn, k: int, first: bool) -> None:
    f.store8("NC", int(k), "1")
    if not first:
        return
    flag = f.load8("BP", int(k))
    on = f.op(f"icmp ne i8 {flag}, 0")
    call, go = f.label(), f.label()
    f.stmt(f"br i1 {on}, label %{call}, label %{go}")
    f.start(call)
    f.stmt(f"call void {f.base('BRK')}(i32 {int(k)})")
    f.stmt(f"br label %{go}")
    f.start(go)


@lowers("@OUT")
def _output(f: Fn, j: int, level: int) -> None:
    _mark(f, "OC", int(j), f.level(int(level)))


@lowers("@CON")
def _contact(f: Fn, j: int) -> None:
    # ``closed[2j + top] = 1``: a store without a read (perf: contacts are
    # most of a boolean program's probes)
    bit = f.op(f"zext i1 {f.top} to i64")
    at = f.op(f"add i64 {bit}, {2 * int(j)}")
    ptr = f.op(f"getelementptr i8, ptr {f.base('CC')}, i64 {at}")
    f.stmt(f"store i8 1, ptr {ptr}, align 1")


__all__: list[str] = []
