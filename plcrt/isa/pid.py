"""Instruction family: the PID loop.

``PID TBL, LOOP`` (S7-200 System Manual, "PID Loop instruction"): TBL is
the first byte of the loop's 36-byte table in V memory, LOOP a constant
0..7.  The box runs the loop with its power flow (the change 0 -> 1 is the
switch from manual to automatic); the algorithm is
:class:`plcrt.engine.pid.PidLoops`.  ENO is 0 without power flow and after
a math error (SM1.1).
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.operands import Addr
from ..gen.resolve import ResolveError
from ..memory.hardware import TABLE_BYTES
from ..safetext import excerpt
from .args import int_constant, operand_texts
from .registry import insn

F = "pid"


@insn("PID", family=F, summary="PID loop over its table in V memory (LOOP 0..7)",
      variadic=True, may_fail=True)
def _pid(g: Gen, insn_ir, resolver, *_ops) -> None:
    tbl, loop_text = operand_texts(g, insn_ir, 2, "a loop table and a loop number "
                                                 "(PID TBL, LOOP)")
    try:
        op = resolver.parse(tbl)
    except ResolveError as e:
        g.fail(f"PID TBL: {e}")
    if not (isinstance(op, Addr) and op.area == "V" and op.width == 1):
        g.fail(f"PID TBL must be a V byte address (VBn), the table's first byte; got "
               f"'{excerpt(tbl)}'")
    v_bytes = g.unit.model.v_bytes
    if op.offset + TABLE_BYTES > v_bytes:
        g.fail(f"PID TBL VB{op.offset}: the {TABLE_BYTES}-byte loop table runs past the end of "
               f"V memory (VB{v_bytes - 1})")
    loop = int_constant(g, resolver, loop_text, "PID LOOP",
                        f"PID LOOP must be a constant 0..7, got '{excerpt(loop_text)}'")
    if not 0 <= loop <= 7:
        g.fail(f"PID LOOP {loop}: the S7-200 has loops 0..7")
    used = g.unit.hooks.setdefault("pid_loops", {})
    first = used.setdefault(loop, g.loc)
    if first is not g.loc:
        # the CPU runs both, but they share the loop's manual/auto memory
        g.warn(f"PID loop {loop} is also used at line {first.line}: two PID boxes with one "
               f"loop number interfere with each other (System Manual, PID)", "pid-loop")
    pid = g.cpu("pid.execute", "pid")
    g.eno(f"{pid}({loop}, {op.offset}, {g.top})")
