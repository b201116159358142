"""The text of Python expressions the generator builds from validated values.

:func:`const_expr` turns a checked constant into the literal of a value
kind (byte, INT, DINT, unsigned, REAL rounded to single precision);
:func:`is_atom` and :func:`is_int_literal` tell the generator
(:class:`plcrt.gen.emit.Gen`) which expressions need parentheses and which
are constants it may fold.  Only numbers are printed; no text of the
program reaches what these functions return.
"""

from __future__ import annotations

import re
import struct

from ..safetext import excerpt
from .errors import CodegenError
from .operands import Const

#: bytes of each value kind (its first letter)
VALUE_WIDTH = {"B": 1, "W": 2, "D": 4, "R": 4}

_NAME_OR_ITEM = re.compile(r"[A-Za-z_]\w*(?:\[\d+\])?|\d+")
#: one parenthesized whole with at most one level of parentheses inside,
#: the shape of every contact (``(V[3] >> 2 & 1)``, ``((M[0] & 1) ^ 1)``):
#: matched in C, the general scan below is for the rest
_GROUP = re.compile(r"\((?:[^()'\"]|\([^()'\"]*\))*\)")


def is_atom(expr: str) -> bool:
    """Whether ``expr`` needs no parentheses as an operand of any binary
    operator: a name, a number, ``name[n]``, or one parenthesized whole
    (``(V[3] >> 2 & 1)``, ``((M[0] & 1) ^ 1)``).  Text with a string
    literal is never taken for one (its parentheses are not counted)."""
    if _NAME_OR_ITEM.fullmatch(expr) or _GROUP.fullmatch(expr):
        return True
    if not (expr.startswith("(") and expr.endswith(")")) or "'" in expr or '"' in expr:
        return False
    depth = 0
    for i, ch in enumerate(expr):
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
            if depth == 0:
                return i == len(expr) - 1
    return False


def is_int_literal(expr: str) -> bool:
    """Whether ``expr`` is a decimal integer literal (``7``, ``-12``)."""
    t = expr[1:] if expr.startswith("-") else expr
    return t.isdigit()


def const_expr(c: Const, kind: str) -> str:
    """Source text of a validated constant converted to ``kind``."""
    v = c.value
    if isinstance(v, bytes):
        n = int.from_bytes(v[:4].ljust(VALUE_WIDTH[kind[0]], b"\0")[:VALUE_WIDTH[kind[0]]], "big")
        v = n
    if kind == "R":
        # A REAL constant is stored as IEEE single on the CPU: round it here,
        # or math would run on a more precise value than the program holds.
        try:
            return repr(struct.unpack(">f", struct.pack(">f", float(v)))[0])
        except OverflowError:
            raise CodegenError(f"real constant {excerpt(c.text)} is outside the REAL "
                               f"range") from None
    if isinstance(v, float):
        if kind[0] == "D" and not c.is_real:
            v = int(v)
        else:
                v = int.from_bytes(struct.pack(">f", v), "big")
    v = int(v)
    if kind == "B":
        return str(v & 0xFF)
    if kind == "WU":
        return str(v & 0xFFFF)
    if kind == "DU":
        return str(v & 0xFFFFFFFF)
    if kind == "W":
        v &= 0xFFFF
        return str(v - 0x10000 if v & 0x8000 else v)
    v &= 0xFFFFFFFF
    return str(v - 0x100000000 if v & 0x80000000 else v)


__all__ = ["VALUE_WIDTH", "const_expr", "is_atom", "is_int_literal"]
