"""Operands that name the start of a run of bytes (a table, a clock buffer,
an ASCII field): where the run lives, for run-time helpers; and how those
helpers report a non-fatal run-time error.

What it is: one function turning a resolved byte or word operand into the
source text of a ``(buffer, offset)`` pair, checked against the end of its
memory area at compile time for a direct address and at run time (by the
``_ptr`` helper) for ``*VD``/``*LD``/``*AC``.  What it is not: a helper
that reads or writes; each family reads its own layout.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.operands import Addr, Indirect, area_size
from ..safetext import excerpt


def region(g: Gen, op, nbytes: int, what: str) -> str:
    """``(buf, off)`` source of the *nbytes* bytes from *op*; a compile
    error naming *what* for an accumulator or a run past the area's end."""
    if isinstance(op, Indirect):
        pbuf, poff = g._place(op.ptr, 4)
        return f"{g.use('_ptr')}({pbuf}, {poff}, {nbytes}, {g.insn_id})"
    if not isinstance(op, Addr) or op.area in ("AC", "HC"):
        g.fail(f"{what} must be a memory address or a pointer (*VD, *LD, *AC), "
               f"not {excerpt(getattr(op, 'text', ''))}")
    buf, off = g._place(op, nbytes)
    if off + nbytes > area_size(g.unit.model, op.area):
        g.fail(f"{what} at {excerpt(op.text)} runs past the end of the {op.area} area "
               f"({nbytes} bytes)")
    return f"({buf}, {off})"


def runtime_error(plc, insn: int, code: int, message: str) -> int:
    """Report run-time error *code* of instruction *insn*: SM4.3 set and a
    warning (once per instruction); returns 0, the box's ENO."""
    plc.mem.areas["SM"][4] |= 0x08
    locs = plc.unit.locs
    loc = locs[insn] if 0 <= insn < len(locs) else None
    plc.warn(f"{message} (run-time error {code:04X}; SM4.3 set, ENO 0)", loc,
             f"rt{code:04X}:{insn}")
    return 0


__all__ = ["region", "runtime_error"]
