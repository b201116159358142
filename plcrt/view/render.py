"""Drawing ladder rungs on a character grid, with optional live status.

Each element of a :mod:`plcrt.view.ladder` rung becomes a :class:`Block`, a
rectangle of cells with one *wire row* where power enters on the left and
leaves on the right.  Series is horizontal concatenation aligned on the
wire rows, parallel is vertical stacking between two connector columns, an
output branch (LPS/LRD/LPP) is stacking behind one connector column.  Every
cell carries a tag; the tags decide the heavy lines of energized wires and
the rich styles, so the plain text holds everything and colour is extra.

Status conventions (docs/ladder-view.md): an energized wire is ``━`` (and
blue), a closed contact has heavy sides ``┫ ┣`` (a normally open one is
also filled, ``┫█┣``), a coil that gets power is ``(█)``, and box operands
show their values (``VW100=+25``, ``T37=+57``).

This module is the presentation layer: it decides nothing about what a
network means, and it is the only part of the view that uses rich.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from itertools import groupby
from typing import Callable

from rich.cells import cell_len
from rich.text import Text

from ..isa.shape import shape
from ..lang import ir
from ..safetext import printable
from .ladder import Box, Coil, Contact, Logic, Node, Parallel, Series, to_ladder
from .status import Power, Status, and3, contact_state, eno_power, modifier_power, or3

Cell = tuple[str, str | None]

#: light -> heavy box-drawing characters for energized wires, and dashed
#: lines for wires whose power cannot be told in status mode
_HEAVY = str.maketrans("─│┬┴├┤└┘┌┐┼", "━┃┳┻┣┫┗┛┏┓╋")
_DASHED = str.maketrans("─│", "┄┆")

#: rich styles of the cell tags: energized wire (w1), unknown (w?), closed
#: contact or energized coil (c1), values, headers ...  Blue for power flow
#: as in Micro/WIN's program status.
_STYLES = {
    "w1": "bold blue", "w?": "dim", "c1": "bold white on blue", "val": "green",
    "hdr": "bold", "title": "bold", "rail": "bold", "note": "dim", "why": "yellow",
    "pou": "bold underline",
}


class Block:
    """A rectangle of (character, tag) cells with its wire row."""

    def __init__(self, width: int, height: int, wire: int = 0) -> None:
        self.w, self.h, self.wire = width, height, wire
        self.rows: list[list[Cell]] = [[(" ", None)] * width for _ in range(height)]

    def put(self, r: int, c: int, text: str, tag: str | None = None) -> int:
        """Write ``text`` at (r, c); wide characters take two cells, control
        characters from the program are written as escapes (``\\x1b``)."""
        for ch in printable(text):
            n = cell_len(ch)
            if n == 0:
                continue
            self.rows[r][c] = (ch, tag)
            if n == 2:
                self.rows[r][c + 1] = ("", tag)
            c += n
        return c

    def paste(self, other: Block, r0: int, c0: int) -> None:
        for i, row in enumerate(other.rows):
            self.rows[r0 + i][c0:c0 + other.w] = row

    def extend(self, width: int, tag: str) -> None:
        """Widen to ``width``, continuing the wire row with a wire."""
        if width <= self.w:
            return
        for r, row in enumerate(self.rows):
            row.extend([("─", tag) if r == self.wire else (" ", None)] * (width - self.w))
        self.w = width


def _w(p: Power) -> str:
    """The tag of a wire: energized, not energized, or unknown (drawn as
    plain wire when there is no status at all)."""
    return "w1" if p is True else "w0" if p is False else "w?"


def _stub(p: Power) -> Block:
    b = Block(1, 1)
    b.put(0, 0, "─", _w(p))
    return b


def hcat(blocks: list[Block]) -> Block:
    """Series: side by side, aligned on the wire rows."""
    wire = max(b.wire for b in blocks)
    height = max(wire - b.wire + b.h for b in blocks)
    out = Block(sum(b.w for b in blocks), height, wire)
    c = 0
    for b in blocks:
        out.paste(b, wire - b.wire, c)
        c += b.w
    return out


def vstack(blocks: list[Block], left: Power, right: list[Power] | None) -> Block:
    """Branches one under the other, joined by a connector column on the
    left (one electric node, powered like ``left``) and, for a parallel
    block (``right`` = the branches' output power), on the right, where a
    segment carries power when a branch at or below it conducts: the way
    power flows back up to the wire row."""
    if right is None:  # output branches: a wire stub after the split
        blocks = [hcat([_stub(left), b]) for b in blocks]
    width = max(b.w for b in blocks)
    out = Block(width + (1 if right is None else 2), sum(b.h for b in blocks), blocks[0].wire)
    rows, y = [], 0
    for i, b in enumerate(blocks):
        if right is not None:
            b.extend(width, _w(right[i]))
        out.paste(b, y, 1)
        rows.append(y + b.wire)
        y += b.h
    first, last = rows[0], rows[-1]
    for r in range(first, last + 1):
        at = r in rows
        out.put(r, 0, "┬" if r == first else "└" if r == last else "├" if at else "│", _w(left))
        if right is not None:
            up = or3([p for p, rr in zip(right, rows) if rr >= r])
            out.put(r, width + 1, "┬" if r == first else "┘" if r == last else "┤" if at
                    else "│", _w(up))
    if right is None:
        return out
    # a stub on both sides keeps two parallels in series apart
    return hcat([_stub(left), out, _stub(or3(right))])


#: operand text -> the text drawn (``Start_PB:I0.0`` with a symbol table)
Names = Callable[[str], str]


class _Ctx:
    """The block being drawn, where its status values come from and how its
    operands are named."""

    def __init__(self, pou: str, status: Status | None, names: Names | None = None) -> None:
        self.pou, self.status, self._names = pou, status, names

    def name(self, text: str) -> str:
        """The operand as drawn: ``name:address`` when a symbol is involved."""
        return self._names(text) if self._names is not None and text else text

    def label(self, text: str, kind: str | None = None) -> tuple[str, str]:
        """(operand as drawn, "=value" or "") of an address in status mode."""
        if self.status is None or not text:
            return self.name(text), ""
        v = self.status.value(self.pou, text, kind)
        return self.name(text), "" if v is None else "=" + fmt_value(v, text, kind)


_BYTE_RE = re.compile(r"(SM|[IQMVSL])B\d+$", re.I)
_BIT_RE = re.compile(r".*\.\d$")


def fmt_value(v: int | float, text: str = "", kind: str | None = None) -> str:
    """A status value as Micro/WIN's status shows it: signed numbers with
    their sign (``+25``), bytes unsigned, bits 0/1, reals to 7 digits."""
    if kind == "BIT" or _BIT_RE.match(text):
        return "1" if v else "0"
    if isinstance(v, float):
        return f"{v:+.7g}"
    if _BYTE_RE.match(text):
        return str(v)
    return f"{v:+d}"


def _text_put(b: Block, r: int, c: int, pair: tuple[str, str]) -> None:
    c = b.put(r, c, pair[0], "lbl")
    b.put(r, c, pair[1], "val")


def _cells(text: str) -> int:
    """Columns ``text`` takes once :meth:`Block.put` wrote it."""
    return cell_len(printable(text))


def _width(pair: tuple[str, str]) -> int:
    return _cells(pair[0]) + _cells(pair[1])


# ---------------------------------------------------------------------------
# Elements
# ---------------------------------------------------------------------------

def _contact(c: Contact, p_in: Power, ctx: _Ctx) -> tuple[Block, Power]:
    shp = c.shape
    if shp.kind == "modifier":
        p_out = modifier_power(c, p_in)
        closed = p_out
    else:
        closed = contact_state(c, ctx.pou, ctx.status)
        p_out = and3(p_in, closed)
    kind = "REAL" if shp.compare.startswith("R") else None
    above = ctx.label(c.above, kind) if shp.compare else (ctx.name(c.above), "")
    below = ctx.label(c.below, kind) if shp.compare else ("", "")
    inside = shp.lad
    if closed is True:
        inside = inside.replace(" ", "█")
    iw = cell_len(inside)
    width = max(_width(above) + 2, _width(below) + 2, iw + 6)
    lead = (width - iw - 2) // 2
    rows = (1 if c.above else 0) + 1 + (1 if c.below else 0)
    b = Block(width, rows, 1 if c.above else 0)
    if c.above:
        _text_put(b, 0, max(0, (width - _width(above) + 1) // 2), above)
    if c.below:
        _text_put(b, b.wire + 1, max(0, (width - _width(below) + 1) // 2), below)
    tag = "c1" if closed is True else "ct"
    col = b.put(b.wire, 0, "─" * lead, _w(p_in))
    col = b.put(b.wire, col, "┫" if closed is True else "┤", tag)
    col = b.put(b.wire, col, inside, tag)
    col = b.put(b.wire, col, "┣" if closed is True else "├", tag)
    b.put(b.wire, col, "─" * (width - col), _w(p_out))
    return b, p_out


def _logic(e: Logic, p_in: Power, ctx: _Ctx) -> tuple[Block, Power]:
    if isinstance(e, Contact):
        return _contact(e, p_in, ctx)
    if isinstance(e, Series):
        blocks, p = [], p_in
        for item in e.items:
            b, p = _logic(item, p, ctx)
            blocks.append(b)
        return hcat(blocks), p
    assert isinstance(e, Parallel)
    done = [_logic(item, p_in, ctx) for item in e.items]
    outs = [p for _, p in done]
    return vstack([b for b, _ in done], p_in, outs), or3(outs)


def _coil(c: Coil, p: Power, ctx: _Ctx) -> Block:
    sym = c.symbol
    if p is True:
        sym = sym.replace(" ", "█")
    above, below = (ctx.name(c.above), ""), (c.below, "")
    sw = cell_len(sym)
    width = max(sw + 2, _width(above) + 1, _width(below) + 1)
    lead = width - sw
    b = Block(width, (1 if c.above else 0) + 1 + (1 if c.below else 0), 1 if c.above else 0)
    for r, pair, on in ((0, above, c.above), (b.wire + 1, below, c.below)):
        if on:
            w = _width(pair)
            _text_put(b, r, max(0, min(lead + (sw - w) // 2, width - w)), pair)
    col = b.put(b.wire, 0, "─" * lead, _w(p))
    b.put(b.wire, col, sym, "c1" if p is True else "co")
    return b


def _box(box: Box, powers: list[Power], ctx: _Ctx,
         gaps: list[int] | None = None) -> tuple[Block, Power]:
    """A box; ``gaps`` are the row distances between its power pins (set by
    the rungs feeding a counter's inputs).  Returns the block and ENO."""
    power_names = list(box.power)
    gaps = gaps or [2] * max(0, len(power_names) - 1)
    en = powers[0] if powers else None
    eno = eno_power(box, en) if box.eno else None
    lefts = [p for p in box.pins if not p.right]
    rights = [p for p in box.pins if p.right]
    lvals = [ctx.label(p.operand, p.kind) for p in lefts]
    rvals = [ctx.label(p.operand, p.kind) for p in rights]
    pin_rows = max(len(lefts), len(rights))
    lname = max([cell_len(p.name) for p in lefts] + [cell_len(n) for n in power_names] + [0])
    rname = max([cell_len(p.name) for p in rights] + [3 if box.eno else 0])
    above = (ctx.name(box.above), "")
    if box.above:  # timer / counter: its current value; SCR bit: its state
        above = ctx.label(box.above, "BIT" if not box.eno and not box.power else None)
    # the box is at least as wide as the name above it (Jam_Timer:T37)
    inner = max(_cells(box.title) + 2, lname + rname + 2, cell_len(box.note) + 2, 6,
                _width(above) - 2)
    # a blank between an operand and the next element's (chained boxes)
    lm = max([_width(v) + 2 for v in lvals] + [3])
    rm = max([_width(v) + 2 for v in rvals] + [0])
    top = 1 if box.above else 0
    first = top + 2                                 # first power pin (or title) row
    prow = [first]
    for g in gaps:
        prow.append(prow[-1] + g)
    if not power_names:
        first, prow = top + 1, []
    pins0 = (prow[-1] + 1) if prow else first + 1
    note_row = pins0 + pin_rows
    height = note_row + (1 if box.note else 0) + 1
    b = Block(lm + inner + 2 + rm, height, first)
    L, R = lm, lm + inner + 1
    if box.above:
        _text_put(b, 0, max(0, L + (inner + 2 - _width(above)) // 2), above)
    b.put(top, L, "┌" + "─" * inner + "┐", "box")
    b.put(height - 1, L, "└" + "─" * inner + "┘", "box")
    for r in range(top + 1, height - 1):
        b.put(r, L, "│", "box")
        b.put(r, R, "│", "box")
    title_row = top + 1
    b.put(title_row, L + 1 + (inner - _cells(box.title)) // 2, box.title, "title")
    if not power_names:  # on the rail: the rail feeds the title row
        b.put(title_row, 0, "─" * L, _w(en))
        b.put(title_row, L, "┤", "box")
    for i, (name, r) in enumerate(zip(power_names, prow)):
        p = powers[i] if i < len(powers) else None
        b.put(r, 0, "─" * L, _w(p))
        b.put(r, L, "┤", "box")
        b.put(r, L + 1, name, "pin")
    if box.eno and prow:
        b.put(prow[0], R - 3, "ENO", "pin")
        if box.next is not None:
            b.put(prow[0], R, "├", "box")
            b.put(prow[0], R + 1, "─" * rm, _w(eno))
    for i, (pin, val) in enumerate(zip(lefts, lvals)):
        r = pins0 + i
        _text_put(b, r, L - 1 - _width(val), val)
        b.put(r, L - 1, "─┤", "box")
        b.put(r, L + 1, pin.name, "pin")
    for i, (pin, val) in enumerate(zip(rights, rvals)):
        r = pins0 + i
        b.put(r, R - cell_len(pin.name), pin.name, "pin")
        b.put(r, R, "├─", "box")
        _text_put(b, r, R + 2, val)
    if box.note:
        b.put(note_row, R - cell_len(box.note), box.note, "note")
    return b, eno


def _out(o: Coil | Box | Node, p: Power, ctx: _Ctx) -> Block:
    if isinstance(o, Coil):
        return _coil(o, p, ctx)
    if isinstance(o, Box):
        b, eno = _box(o, [p], ctx)
        return hcat([b, _node(o.next, eno, ctx)]) if o.next is not None else b
    return _node(o, p, ctx)


def _node(node: Node, p_in: Power, ctx: _Ctx) -> Block:
    parts, p = [], p_in
    if node.logic is not None:
        b, p = _logic(node.logic, p_in, ctx)
        parts.append(b)
    outs = [_out(o, p, ctx) for o in node.outs]
    parts.append(outs[0] if len(outs) == 1 else vstack(outs, p, None))
    return hcat(parts)


def _multi(box: Box, ctx: _Ctx, p_rail: Power) -> tuple[Block, list[int]]:
    """A counter: one rung from the rail into each power pin."""
    done = [_logic(e, p_rail, ctx) for e in box.inputs]
    blocks = [b for b, _ in done]
    gaps = [max(2, (blocks[k - 1].h - blocks[k - 1].wire) + blocks[k].wire)
            for k in range(1, len(blocks))]
    bb, _ = _box(box, [p for _, p in done], ctx, gaps)
    offs = [0]
    for g in gaps:
        offs.append(offs[-1] + g)
    shift = max(0, blocks[0].wire - bb.wire)  # room above the first input
    width = max(b.w for b in blocks)
    rows = [shift + bb.wire + o for o in offs]
    height = max([shift + bb.h] + [r - b.wire + b.h for r, b in zip(rows, blocks)])
    out = Block(width + bb.w, height, rows[0])
    out.paste(bb, shift, width)
    for (b, p), r in zip(done, rows):
        b.extend(width, _w(p))
        out.paste(b, r - b.wire, 0)
    return out, rows


# ---------------------------------------------------------------------------
# Networks
# ---------------------------------------------------------------------------

def _rail(body: Block, rail_rows: list[int], p_rail: Power) -> Block:
    """The left power rail ``┃`` with a junction where a rung starts."""
    out = Block(body.w + 2, body.h, body.wire)
    for r in range(body.h):
        out.put(r, 0, ("┣" if p_rail else "┠") if r in rail_rows else "┃", "rail")
        if r in rail_rows:
            out.put(r, 1, "─", _w(p_rail))
    out.paste(body, 0, 2)
    return out


def _stl_lines(network: ir.Network, ctx: _Ctx) -> Block:
    """The STL text, Micro/WIN's fallback; in status mode each line is
    followed by the values of its addresses."""
    lines = []
    for insn in network.insns:
        stl = f"{insn.mnemonic:<6} {', '.join(ctx.name(o.text) for o in insn.operands)}"
        stl = stl.rstrip()
        shp = shape(insn.mnemonic)
        bit = shp.kind in ("contact", "coil", "rail") and not shp.compare
        kind = "REAL" if shp.compare.startswith("R") else None
        vals = [ctx.label(o.text, "BIT" if bit and i == 0 else kind)
                for i, o in enumerate(insn.operands)]
        lines.append((stl, [v for v in vals if v[1]]))
    width = max([_cells(stl) for stl, _ in lines] + [0])
    extra = max([sum(_width(v) + 2 for v in vals) for _, vals in lines] + [0])
    b = Block(width + extra, len(lines))
    for r, (stl, vals) in enumerate(lines):
        b.put(r, 0, stl, "stl")
        c = width + 2
        for v in vals:
            _text_put(b, r, c, v)
            c += _width(v) + 2
    return b


def _network_block(pou: ir.Pou, network: ir.Network, status: Status | None,
                   program: ir.Program | None, stl: bool,
                   names: Names | None = None) -> tuple[Block, str]:
    ctx = _Ctx(pou.ident, status, names)
    p_rail: Power = True if status is not None else None
    lad = to_ladder(network, program=program)
    if stl or not lad.ok:
        return _stl_lines(network, ctx), lad.reason
    if lad.rail:
        parts = []
        for e in lad.rail:
            parts.append(_coil(e, p_rail, ctx) if isinstance(e, Coil)
                         else _box(e, [p_rail], ctx)[0])
        body = Block(max(b.w for b in parts), sum(b.h for b in parts))
        rows, y = [], 0
        for b in parts:
            body.paste(b, y, 0)
            rows.append(y + b.wire)
            y += b.h
        return _rail(body, rows, p_rail), ""
    if lad.rung is None:  # an empty network
        return _rail(Block(0, 1), [], p_rail), ""
    if isinstance(lad.rung, Box):
        body, rows = _multi(lad.rung, ctx, p_rail)
        return _rail(body, rows, p_rail), ""
    body = _node(lad.rung, p_rail, ctx)
    return _rail(body, [body.wire], p_rail), ""


def _to_text(block: Block, styled: bool, status: bool) -> Text:
    """The cells as rich text: energized wires heavy, unknown ones dashed
    (in status mode only), one span per run of equal tags."""
    out = Text()
    for i, row in enumerate(block.rows):
        if i:
            out.append("\n")
        cells = [(ch.translate(_HEAVY) if tag == "w1" else
                  ch.translate(_DASHED) if tag == "w?" and status else ch, tag)
                 for ch, tag in row if ch]
        while cells and cells[-1][0] == " ":
            cells.pop()
        for tag, run in groupby(cells, key=lambda cell: cell[1]):
            out.append("".join(ch for ch, _ in run), _STYLES.get(tag or "") if styled else None)
    return out


def render_network(pou: ir.Pou, network: ir.Network, *, status: Status | None = None,
                   styled: bool = True, program: ir.Program | None = None,
                   stl: bool = False, names: Names | None = None) -> Text:
    """One network: a ``Network n  title`` line, then the rung in LAD, or
    the STL (``stl=True``, or when the network has no LAD form, saying why).
    ``status`` gives live values; ``program`` names CALL box pins;
    ``names`` gives the text drawn for an operand (symbol names)."""
    block, reason = _network_block(pou, network, status, program, stl, names)
    style: Callable[[str], str | None] = (lambda k: _STYLES[k]) if styled else (lambda k: None)
    out = Text()
    out.append(f"Network {network.number}", style("hdr"))
    if network.title:
        # program text: appended as plain Text (never markup), escaped
        out.append(f"  {printable(network.title)}", style("hdr"))
    if reason and not stl:
        out.append(f"\n(STL: not LAD-representable: {reason})", style("why"))
    if block.h:
        out.append("\n")
        out.append_text(_to_text(block, styled, status is not None))
    return out


def render_program(program: ir.Program, *, status: Status | None = None,
                   networks: Iterable[tuple[str, int]] | None = None,
                   styled: bool = True, stl: bool = False,
                   names: Names | None = None) -> list[Text]:
    """Every network (or those in ``networks``, as ``(block id, number)``),
    each block introduced by a ``OB1 (MAIN)  title`` line; ``names`` as in
    :func:`render_network`."""
    wanted = None if networks is None else set(networks)
    out: list[Text] = []
    for pou in program.pous:
        nets = [n for n in pou.networks if wanted is None or (pou.ident, n.number) in wanted]
        if not nets:
            continue
        head = pou.ident + (f" ({pou.name})" if pou.name and pou.name != pou.ident else "")
        out.append(Text(printable(head + (f"  {pou.title}" if pou.title else "")),
                        _STYLES["pou"] if styled else ""))
        for n in nets:
            out.append(render_network(pou, n, status=status, styled=styled,
                                      program=program, stl=stl, names=names))
    return out


def ladder_text(pou: ir.Pou, network: ir.Network, status: Status | None = None, *,
                program: ir.Program | None = None, names: Names | None = None) -> str:
    """The plain text of :func:`render_network` (for tests and logs)."""
    return render_network(pou, network, status=status, styled=False, program=program,
                          names=names).plain


__all__ = ["Block", "fmt_value", "hcat", "ladder_text", "render_network", "render_program",
           "vstack"]
