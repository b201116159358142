"""Operands of the instructions that take their operands as written (ATCH,
DTCH, CEVNT, PLS, HDEF, HSC): the count, and integer constants.

What it is: two checks for emitters registered ``variadic=True``, which
receive the operand text instead of resolved operands.  What it is not: no
ranges; each instruction checks its own values and says which it takes.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.operands import Const
from ..gen.resolve import ResolveError

__all__ = ["operand_texts", "int_constant"]


def operand_texts(g: Gen, insn_ir, n: int, what: str) -> list[str]:
    """The *n* operand texts of *insn_ir*; else a compile error saying that
    the instruction takes *what*."""
    ops = [o.text for o in insn_ir.operands]
    if len(ops) != n:
        g.fail(f"{insn_ir.mnemonic} takes {what}, got {len(ops)} operand(s)")
    return ops


def int_constant(g: Gen, resolver, text: str, what: str, not_constant: str) -> int:
    """The integer constant written as *text*; a compile error ``what: …``
    when it does not resolve, *not_constant* when it is no integer constant."""
    try:
        op = resolver.parse(text)
    except ResolveError as e:
        g.fail(f"{what}: {e}")
    if not isinstance(op, Const) or op.is_real or not isinstance(op.value, int):
        g.fail(not_constant)
    return int(op.value)
