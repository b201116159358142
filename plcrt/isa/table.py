"""Instruction family: tables (ATT FIFO LIFO FND= FND<> FND< FND>).

S7-200 System Manual, "Table instructions".  A table is a run of words:

    TBL+0  TL, the maximum number of entries (ATT only reads it)
    TBL+2  EC, the entry count
    TBL+4  entry 0, TBL+6 entry 1, ... (at most 100 entries)

``ATT DATA, TBL`` appends DATA as entry EC and counts it; ``FIFO TBL,
DATA`` takes entry 0 and moves the others up one word; ``LIFO TBL, DATA``
takes the last entry.  ``FND<cmp> TBL, PATRN, INDX`` searches a table whose
first word is the entry count (the manual: give FND the address of EC, two
bytes after the TBL of ATT/FIFO/LIFO) from entry INDX on and leaves in INDX
the number of the first entry that compares true with PATRN, or EC when
none does; to find the next one, the program increments INDX.

Flags and errors: ATT on a full table (EC >= TL, or EC >= 100) sets SM1.4,
changes nothing and gives ENO 0; a successful ATT clears SM1.4.  FIFO/LIFO
on an empty table sets SM1.5, leaves DATA unchanged, ENO 0; success clears
SM1.5.  An entry count below 0 or above 100, or a table running past the
end of its memory area, is run-time error 0091 (operand out of range:
SM4.3, ENO 0, nothing changed).  Entries and PATRN compare as INT.  FIFO
leaves the word after the new last entry as it was (the manual shows it as
undefined).  What is not here: FILL (move.py).
"""

from __future__ import annotations

import operator
from typing import Callable

from ..gen.emit import Gen
from ..gen.recipe import CPU, Call, Item
from ..gen.rt import s16
from .region import region, runtime_error
from .registry import Role, Span, insn

F = "table"

MAX_ENTRIES = 100   #: System Manual: a table holds at most 100 entries
TABLE_BYTES = 4 + 2 * MAX_ENTRIES   #: TL, EC and the entries of the largest table
SM1_FULL, SM1_EMPTY = 0x10, 0x20   #: SM1.4, SM1.5

#: FND's compare by mnemonic (CMD 1..4 of the LAD box: =, <>, <, >)
FIND: dict[str, Callable[[int, int], bool]] = {
    "FND=": operator.eq, "FND<>": operator.ne, "FND<": operator.lt, "FND>": operator.gt,
}


def _word(buf: bytearray, i: int) -> int:
    return s16(buf[i] << 8 | buf[i + 1])


def _put(buf: bytearray, i: int, v: int) -> None:
    buf[i] = v >> 8 & 255
    buf[i + 1] = v & 255


def _helpers(plc) -> dict[str, Callable]:
    """The run-time table operations of *plc* (closures: a fork compiles its own)."""
    sm = plc.mem.areas["SM"]

    def bad(insn_id: int, mn: str, why: str) -> None:
        runtime_error(plc, insn_id, 0x0091, f"{mn}: {why}; the table is unchanged")

    def count(buf: bytearray, at: int, mn: str, insn_id: int) -> int | None:
        """The entry count at ``buf[at]``, None (error 0091) when it is out
        of 0..100 or its entries run past the end of the area."""
        ec = _word(buf, at)
        if not 0 <= ec <= MAX_ENTRIES:
            bad(insn_id, mn, f"the entry count {ec} is outside 0..{MAX_ENTRIES}")
            return None
        if at + 2 + 2 * ec > len(buf):
            bad(insn_id, mn, "the table runs past the end of its memory area")
            return None
        return ec

    def att(data: int, where: tuple, insn_id: int) -> int:
        buf, off = where
        ec = count(buf, off + 2, "ATT", insn_id)
        if ec is None:
            return 0
        if ec >= min(_word(buf, off), MAX_ENTRIES):
            sm[1] |= SM1_FULL
            return 0
        at = off + 4 + 2 * ec
        if at + 2 > len(buf):
            return bad(insn_id, "ATT", "the new entry is past the end of its memory area") or 0
        _put(buf, at, data)
        _put(buf, off + 2, ec + 1)
        sm[1] &= ~SM1_FULL & 255
        return 1

    def take(where: tuple, insn_id: int, first: bool) -> int | None:
        buf, off = where
        ec = count(buf, off + 2, "FIFO" if first else "LIFO", insn_id)
        if ec is None:
            return None
        if ec == 0:
            sm[1] |= SM1_EMPTY
            return None
        data = off + 4
        if first:
            value = _word(buf, data)
            # the other entries move up one word (slice copy: left to right)
            buf[data:data + 2 * (ec - 1)] = buf[data + 2:data + 2 * ec]
        else:
            value = _word(buf, data + 2 * (ec - 1))
        _put(buf, off + 2, ec - 1)
        sm[1] &= ~SM1_EMPTY & 255
        return value

    def fifo(where: tuple, insn_id: int) -> int | None:
        return take(where, insn_id, True)

    def lifo(where: tuple, insn_id: int) -> int | None:
        return take(where, insn_id, False)

    def find(mn: str) -> Callable:
        rel = FIND[mn]

        def fnd(where: tuple, pattern: int, index: int, insn_id: int) -> int | None:
            buf, off = where
            ec = count(buf, off, mn, insn_id)
            if ec is None:
                return None
            for i in range(index, ec):
                if rel(_word(buf, off + 2 + 2 * i), pattern):
                    return i
            return ec

        return fnd

    out = {"ATT": att, "FIFO": fifo, "LIFO": lifo}
    out.update((mn, find(mn)) for mn in FIND)
    return out


def _helper(g: Gen, mn: str) -> str:
    table = g.unit.hooks.get("tables")
    if table is None:
        table = g.unit.hooks["tables"] = Call(_helpers, (CPU,))
    return g.bind(Item(table, mn), mn.lower().replace("=", "eq").replace("<>", "ne")
                  .replace("<", "lt").replace(">", "gt"))


@insn("ATT", Role.W_R, Role.W_MW, family=F, may_fail=True,
      summary="append DATA to the table TBL (SM1.4 when full)", spans=(Span(1, 8, TABLE_BYTES),))
def _att(g: Gen, data, tbl) -> None:
    fn = _helper(g, "ATT")
    where = region(g, tbl, 4, "the table TBL")
    with g.box():
        g.eno(f"{fn}({g.rd(data, 'W')}, {where}, {g.insn_id})")


def _make_take(mn: str) -> None:
    def emit(g: Gen, tbl, data) -> None:
        fn = _helper(g, mn)
        where = region(g, tbl, 4, "the table TBL")
        with g.box():
            v = g.tmp("v")
            g.line(f"{v} = {fn}({where}, {g.insn_id})")
            with g.block(f"if {v} is not None:"):
                g.wr(data, "W", v)
                g.eno("1")
            with g.block("else:"):
                g.line("eno = 0")

    which = "first (oldest)" if mn == "FIFO" else "last (newest)"
    insn(mn, Role.W_MW, Role.W_W, family=F, may_fail=True,
         summary=f"DATA := the {which} entry of TBL, removed (SM1.5 when empty)",
         spans=(Span(0, 8, TABLE_BYTES),))(emit)


def _make_find(mn: str) -> None:
    def emit(g: Gen, tbl, pattern, index) -> None:
        fn = _helper(g, mn)
        where = region(g, tbl, 2, "the table TBL")
        with g.box():
            r = g.tmp("r")
            g.line(f"{r} = {fn}({where}, {g.rd(pattern, 'W')}, {g.rd(index, 'WU')}, "
                   f"{g.insn_id})")
            with g.block(f"if {r} is not None:"):
                g.wr(index, "W", r)
                g.eno("1")
            with g.block("else:"):
                g.line("eno = 0")

    insn(mn, Role.W_M, Role.W_R, Role.W_W, family=F, may_fail=True,
         summary=f"INDX := first entry from INDX with entry {mn[3:]} PATRN, else EC",
         spans=(Span(0, 8, TABLE_BYTES),))(emit)


for _mn in ("FIFO", "LIFO"):
    _make_take(_mn)
for _mn in FIND:
    _make_find(_mn)
