"""Operands in LLVM IR for the native backend: bits, values and SMB1 flags.

Reading and writing a resolved operand (:func:`rbit`, :func:`wbit`,
:func:`rd`, :func:`wr`), its place in the context table (:func:`place`)
and the status bits of a result (:func:`set_sm1`, :func:`zn_bits`), each
the same bytes as the Python generator's (:class:`plcrt.gen.emit.Gen`).
Only integers computed from resolved operands reach the text.  The table
of instructions is :mod:`.lower`'s.
"""

from __future__ import annotations

from typing import Any

from ...gen.exprs import VALUE_WIDTH, const_expr
from ...gen.operands import Addr, Const, Pointer
from .fn import AREAS, Fn, NotLowered


def native_area(op: Any) -> str:
    """The area of an operand a native piece reads and writes directly."""
    if not isinstance(op, Addr) or op.area not in AREAS:
        what = getattr(op, "area", type(op).__name__)
        raise NotLowered(f"operand area {what} is not reached natively")
    return op.area


def get_bit(f: Fn, slot: str, byte: int, bit: int) -> str:
    """``i1`` of bit ``bit`` of byte ``byte`` of a buffer."""
    v = f.load8(slot, byte)
    if bit:
        v = f.op(f"lshr i8 {v}, {int(bit)}")
    return f.op(f"trunc i8 {v} to i1")


def put_bit(f: Fn, slot: str, byte: int, bit: int, v: str) -> None:
    """Write ``i1`` ``v`` to bit ``bit`` of byte ``byte`` of a buffer."""
    old = f.load8(slot, byte)
    kept = f.op(f"and i8 {old}, {~(1 << bit) & 0xFF}")
    b = f.op(f"zext i1 {v} to i8")
    if bit:
        b = f.op(f"shl i8 {b}, {int(bit)}")
    f.store8(slot, byte, f.op(f"or i8 {kept}, {b}"))


def rbit(f: Fn, op: Any) -> str:
    """``i1`` value of a bit operand (T/C: the bit of the TB/CB bitmap)."""
    area = native_area(op)
    if area in ("T", "C"):
        return get_bit(f, "TB" if area == "T" else "CB", op.offset >> 3, op.offset & 7)
    return get_bit(f, area, op.offset, op.bit)


def wbit(f: Fn, op: Any, v: str) -> None:
    """Write ``i1`` ``v`` to a bit operand (T/C bits are not written by ``=``)."""
    area = native_area(op)
    if area in ("T", "C"):
        raise NotLowered("timer and counter bits are written by their boxes")
    put_bit(f, area, op.offset, op.bit, v)


def place(op: Any, width: int) -> tuple[str, int]:
    """Buffer slot and byte offset of a value operand (as Gen._place)."""
    area = native_area(op)
    if area == "T":
        return "TV", op.offset * 2
    if area == "C":
        return "CV", op.offset * 2
    if area == "AC":
        return "AC", op.offset * 4 + 4 - width
    return area, op.offset


#: the LLVM type a value of each kind is computed in (wide enough for the
#: result of one math step before its range check)
WIDE = {"B": "i32", "W": "i32", "WU": "i32", "D": "i64", "DU": "i64"}


def rd(f: Fn, op: Any, kind: str) -> str:
    """Value of an operand as ``WIDE[kind]`` (B, WU, DU unsigned; W, D signed)."""
    ty = WIDE[kind]
    if isinstance(op, Const):
        # the value the Python code uses (a character constant's code, a
        # REAL constant's bit pattern in a double word)
        return str(int(const_expr(op, kind)))
    if isinstance(op, Pointer):
        return str(int(op.value))
    width = VALUE_WIDTH[kind[0]]
    slot, off = place(op, width)
    # perf: one load of the whole value and a byte swap (the image is
    # big-endian), not a load, shift and or per byte: a quarter of the
    # machine code, which keeps a large program's code in the caches
    raw = f.op(f"load {_INT[width]}, ptr {f.at(slot, off)}, align 1")
    if width > 1:
        raw = f.op(f"call {_INT[width]} @llvm.bswap.{_INT[width]}({_INT[width]} {raw})")
    if ty == _INT[width]:
        return raw
    ext = "sext" if kind in ("W", "D") else "zext"
    return f.op(f"{ext} {_INT[width]} {raw} to {ty}")


def wr(f: Fn, op: Any, kind: str, v: str, cond: str | None) -> None:
    """Store ``v`` (type ``WIDE[kind]``) big-endian; only where ``cond`` (i1)
    holds when given (the old bytes are written back otherwise)."""
    ty = WIDE[kind]
    width = VALUE_WIDTH[kind[0]]
    slot, off = place(op, width)
    it = _INT[width]
    if v.lstrip("-").isdigit():           # a constant: its low bytes
        v = str(int(v) & ((1 << (8 * width)) - 1))
    else:                                 # WIDE[kind] is always wider
        v = f.op(f"trunc {ty} {v} to {it}")
    if width > 1:
        v = _swapped(f, it, width, v)
    where = f.at(slot, off)
    if cond is not None:
        old = f.op(f"load {it}, ptr {where}, align 1")
        v = f.select(cond, it, v, old)
    f.stmt(f"store {it} {v}, ptr {where}, align 1")


def copy(f: Fn, src: Any, dst: Any, width: int, cond: str) -> bool:
    """Copy a value of ``width`` bytes from memory ``src`` to ``dst`` where
    ``cond`` holds, without swapping its bytes twice (perf: a move is a
    third of a mixed program's statements).  False when ``src`` is not in
    memory (a constant, a pointer): the caller reads it as a value."""
    if not isinstance(src, Addr):
        return False
    it = _INT[width]
    v = f.op(f"load {it}, ptr {f.at(*place(src, width))}, align 1")
    where = f.at(*place(dst, width))
    old = f.op(f"load {it}, ptr {where}, align 1")
    f.stmt(f"store {it} {f.select(cond, it, v, old)}, ptr {where}, align 1")
    return True


def _swapped(f: Fn, it: str, width: int, v: str) -> str:
    """``v`` byte-swapped (a constant is swapped here, not in the code)."""
    if v.lstrip("-").isdigit():
        return str(int.from_bytes(int(v).to_bytes(width, "big"), "little"))
    return f.op(f"call {it} @llvm.bswap.{it}({it} {v})")


#: the LLVM integer type of a value of 1, 2 or 4 bytes
_INT = {1: "i8", 2: "i16", 4: "i32"}


def set_sm1(f: Fn, cond: str, keep: int, bits: str) -> None:
    """``SM1 := SM1 & keep | bits`` where ``cond`` holds (``bits``: i8)."""
    old = f.load8("SM", 1)
    new = f.op(f"or i8 {f.op(f'and i8 {old}, {keep}')}, {bits}")
    f.store8("SM", 1, f.select(cond, "i8", new, old))


def zn_bits(f: Fn, ty: str, r: str, signed: bool = True) -> str:
    """i8 of SM1.0 (zero) and, for signed kinds, SM1.2 (negative) of ``r``."""
    z = f.op(f"zext i1 {f.op(f'icmp eq {ty} {r}, 0')} to i8")
    if not signed:
        return z
    n = f.op(f"zext i1 {f.op(f'icmp slt {ty} {r}, 0')} to i8")
    return f.op(f"or i8 {z}, {f.op(f'shl i8 {n}, 2')}")


__all__ = ["WIDE", "copy", "get_bit", "native_area", "place", "put_bit", "rbit", "rd", "set_sm1", "wbit", "wr",
           "zn_bits"]
