"""Instruction family: moves (MOVB MOVW MOVD MOVR BMB BMW BMD SWAP FILL BIR BIW).

S7-200 System Manual, "Move instructions".  Moves copy bit patterns, so
no SM flags change.  ``MOVD &VB100, AC1`` loads a pointer.  Block moves copy
N (1..255) elements; the manual leaves overlapping source and destination
open, plcrt copies element by element in ascending order (docs/decisions.md).
"""

from __future__ import annotations

from ..errors import PlcRuntimeError
from ..gen.emit import Gen
from ..gen.operands import Addr, Const, Indirect, area_size
from ..safetext import excerpt
from .registry import Role, Span, insn

F = "move"


@insn("MOVB", Role.B_R, Role.B_W, family=F, summary="OUT := IN (byte)")
def _movb(g: Gen, src, dst) -> None:
    with g.box():
        g.wr(dst, "B", g.rd(src, "B"), exact=not isinstance(src, Const))


@insn("MOVW", Role.W_R, Role.W_W, family=F, summary="OUT := IN (word)")
def _movw(g: Gen, src, dst) -> None:
    with g.box():
        g.copy(src, dst, "WU")


@insn("MOVD", Role.D_PTR, Role.D_W, family=F, summary="OUT := IN (double word or pointer)")
def _movd(g: Gen, src, dst) -> None:
    with g.box():
        g.copy(src, dst, "DU")


@insn("MOVR", Role.R_R, Role.D_W, family=F, summary="OUT := IN (real)")
def _movr(g: Gen, src, dst) -> None:
    with g.box():
        if isinstance(src, Const):
            g.wr(dst, "R", g.rd(src, "R"))
        else:
            g.copy(src, dst, "DU")


def _block(g: Gen, src, dst, n, kind: str, width: int) -> None:
    with g.box():
        if isinstance(n, Const):
            count = int(n.value)
            if not 1 <= count <= 255:
                g.fail("N must be 1..255")
            if (isinstance(src, Addr) and isinstance(dst, Addr)
                    and src.area not in ("AC", "T", "C") and dst.area not in ("AC", "T", "C")):
                _check_span(g, src, count * width)
                _check_span(g, dst, count * width)
                sb, db = g.use(src.area), g.use(dst.area)
                a, b = src.offset, dst.offset
                if a == b and sb == db:
                    return
                if sb != db or b < a or b >= a + count * width:
                    # perf: non-overlapping (or backward-safe) block as one slice copy
                    g.line(f"{db}[{b}:{b + count * width}] = {sb}[{a}:{a + count * width}]")
                    return
        cnt = g.rd(n, "B")
        i = g.tmp("i")
        with g.block(f"for {i} in range({cnt}):"):
            _elem_copy(g, src, dst, i, kind, width)


def _check_span(g: Gen, a: Addr, nbytes: int) -> None:
    if a.offset + nbytes > area_size(g.unit.model, a.area):
        g.fail(f"the block at {excerpt(a.text)} runs past the end of the {a.area} area")


def _elem_copy(g: Gen, src, dst, i: str, kind: str, width: int) -> None:
    """Copy element ``i`` (a loop variable) of a block; run-time bounds-checked."""
    helper = g.bind(_block_elem, "blk")
    sref = _ref(g, src)
    dref = _ref(g, dst)
    g.line(f"{helper}({sref}, {dref}, {i}, {width}, {g.insn_id}, _LOCS)")
    g.use("_LOCS")


def _ref(g: Gen, op) -> str:
    if isinstance(op, Indirect):
        pbuf, poff = g._place(op.ptr, 4)
        return f"{g.use('_ptr')}({pbuf}, {poff}, 1, {g.insn_id})"
    buf, off = g._place(op, 1)
    return f"({buf}, {off})"


def _block_elem(src, dst, i: int, width: int, insn: int, locs) -> None:
    sb, so = src
    db, do = dst
    a, b = so + i * width, do + i * width
    if a + width > len(sb) or b + width > len(db):
        raise PlcRuntimeError("block move runs past the end of its memory area", locs[insn])
    db[b:b + width] = sb[a:a + width]


def _fill_words(value: int, dst, count: int, insn: int, locs) -> None:
    """FILL at run time: ``count`` big-endian copies of ``value`` from ``dst``."""
    db, do = dst
    if do + 2 * count > len(db):
        raise PlcRuntimeError("FILL runs past the end of its memory area", locs[insn])
    db[do:do + 2 * count] = bytes((value >> 8 & 255, value & 255)) * count


@insn("BMB", Role.B_M, Role.B_MW, Role.B_R, family=F, summary="move N bytes",
      spans=(Span(0, 8, 255, by=2), Span(1, 8, 255, by=2)))
def _bmb(g: Gen, src, dst, n) -> None:
    _block(g, src, dst, n, "B", 1)


@insn("BMW", Role.W_M, Role.W_MW, Role.B_R, family=F, summary="move N words",
      spans=(Span(0, 16, 255, by=2), Span(1, 16, 255, by=2)))
def _bmw(g: Gen, src, dst, n) -> None:
    _block(g, src, dst, n, "WU", 2)


@insn("BMD", Role.D_M, Role.D_MW, Role.B_R, family=F, summary="move N double words",
      spans=(Span(0, 32, 255, by=2), Span(1, 32, 255, by=2)))
def _bmd(g: Gen, src, dst, n) -> None:
    _block(g, src, dst, n, "DU", 4)


@insn("SWAP", Role.W_W, family=F, summary="exchange the bytes of a word")
def _swap(g: Gen, op) -> None:
    with g.box():
        v = g.tmp("v")
        g.line(f"{v} = {g.rd(op, 'WU')}")
        g.wr(op, "W", f"({v} >> 8) | (({v} & 255) << 8)")


@insn("FILL", Role.W_R, Role.W_MW, Role.B_R, family=F, summary="write IN to N words from OUT",
      spans=(Span(1, 16, 255, by=2),))
def _fill(g: Gen, src, dst, n) -> None:
    with g.box():
        if isinstance(n, Const) and isinstance(dst, Addr) and dst.area not in ("AC", "T", "C"):
            count = int(n.value)
            if not 1 <= count <= 255:
                g.fail("N must be 1..255")
            _check_span(g, dst, count * 2)
            v = g.tmp("v")
            db = g.use(dst.area)
            g.line(f"{v} = {g.rd(src, 'WU')}")
            g.line(f"{db}[{dst.offset}:{dst.offset + 2 * count}] = "
                   f"bytes(({v} >> 8, {v} & 255)) * {count}")
            return
        if isinstance(dst, Addr) and dst.area == "AC":
            # The manual's OUT operands for FILL are word areas and *pointers;
            # an accumulator holds one word only.
            g.fail("FILL cannot write to an accumulator")
        # N from memory (VB, MB, ...) or OUT through a pointer (*VD, *LD,
        # *AC): both are legal (System Manual, FILL), so fill at run time
        # with a bounds check like the block moves.
        helper = g.bind(_fill_words, "fill")
        g.line(f"{helper}({g.rd(src, 'WU')}, {_ref(g, dst)}, {g.rd(n, 'B')}, "
               f"{g.insn_id}, {g.use('_LOCS')})")


@insn("BIR", Role.B_IB, Role.B_W, family=F, summary="OUT := physical input byte (immediate)")
def _bir(g: Gen, src: Addr, dst) -> None:
    with g.box():
        g.wr(dst, "B", f"{g.use('PI')}[{src.offset}]")


@insn("BIW", Role.B_R, Role.B_QB, family=F, summary="physical output byte := IN (immediate)")
def _biw(g: Gen, src, dst: Addr) -> None:
    with g.box():
        v = g.tmp("v")
        g.line(f"{v} = {g.rd(src, 'B')}")
        g.line(f"{g.use('PQ')}[{dst.offset}] = {v}")
        g.line(f"{g.use('Q')}[{dst.offset}] = {v}")
