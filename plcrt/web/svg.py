"""Ladder rungs as SVG for the panel, from :mod:`plcrt.view`'s model.

:func:`network_svg` draws one network of :func:`plcrt.view.ladder.to_ladder`
as an SVG document: power rail, wires, contacts, coils and boxes.  Every
element whose look depends on status carries ``data-k="N"`` (a wire, a
contact, a coil), every live value a ``data-v="N"`` text; both are numbered
in one walk of the model.  :func:`network_state` walks the same model with
live values (:class:`plcrt.view.status.Status`) and returns, for those
numbers, the three-valued power (``"1"``, ``"0"``, ``"?"``) and the value
texts, so the page draws a network once and a frame only changes classes
and texts.  Power flow is :mod:`plcrt.view.status`'s, not a second
reading of the program.

Program text (operands, symbol names, comments in tooltips) is written
through :func:`esc`: XML-escaped, quotes included, and control characters
shown as escapes, so a program cannot put markup or script into the page.
A network without a LAD form yields None here; the page shows its STL
lines (:func:`stl_lines`).

This module draws; it does not run anything and holds no PLC semantics.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable
from xml.sax.saxutils import escape

from ..isa.shape import shape
from ..lang import ir
from ..safetext import printable
from ..view.ladder import Box, Coil, Contact, Ladder, Logic, Node, Parallel, Series, to_ladder
from ..view.render import fmt_value
from ..view.status import Power, Status, and3, contact_state, eno_power, modifier_power, or3

#: width of one character of the 12 px monospace labels
CH = 7.3
ROW = 20
#: the pitch of a box's operand pins: an operand and its live value below it
PIN_ROW = 26
#: width of one character of the 10 px texts inside contacts and coils
CH_IN = 6.1
#: width of one character of the 11 px live values
CH_VAL = 6.7
#: the longest value text of a compare contact's operands, by compared type
#: (``-32768``, ``-2147483648``, ``+1.234568e+38``); strings are not reserved
_CMP_VALUE = {"B": 3, "W": 6, "D": 11, "R": 14}


def esc(text: str) -> str:
    """Program text made safe for SVG/HTML text and attribute values."""
    return escape(printable(str(text)), {'"': "&quot;", "'": "&#39;"})


@dataclass
class Fig:
    """A drawn piece in its own coordinates: size, the y of its wire."""

    w: float
    h: float
    wire: float
    parts: list[str] = field(default_factory=list)

    def at(self, x: float, y: float) -> str:
        return f'<g transform="translate({x:g},{y:g})">{"".join(self.parts)}</g>'


Namer = Callable[[str], tuple[str, str]]


class _Walk:
    """One walk of a rung: numbers the live elements in a fixed order,
    records their power and values, and (``draw``) builds the figures."""

    def __init__(self, pou: str, status: Status | None, names: Namer | None) -> None:
        self.pou, self.status = pou, status
        self.names = names or (lambda t: (t, ""))
        self.powers: list[Power] = []
        self.values: list[str] = []

    # -- live numbers ---------------------------------------------------------
    def k(self, p: Power) -> int:
        self.powers.append(p)
        return len(self.powers) - 1

    def v(self, text: str, kind: str | None = None) -> int:
        val = ""
        if self.status is not None and text:
            x = self.status.value(self.pou, text, kind)
            if x is not None:
                val = fmt_value(x, text, kind)
        self.values.append(val)
        return len(self.values) - 1

    # -- drawing helpers --------------------------------------------------------
    def label(self, text: str, x: float, y: float, anchor: str = "middle",
              cls: str = "op") -> str:
        """An operand: the text as written (``name:addr`` when a symbol is
        involved), the symbol's comment as a tooltip, clickable."""
        shown, tip = self.names(text)
        title = f"<title>{esc(tip)}</title>" if tip else ""
        return (f'<text class="{cls}" x="{x:g}" y="{y:g}" text-anchor="{anchor}" '
                f'data-op="{esc(text)}">{title}{esc(shown)}</text>')

    def value(self, n: int, x: float, y: float, anchor: str = "middle") -> str:
        return f'<text class="val" x="{x:g}" y="{y:g}" text-anchor="{anchor}" data-v="{n}"></text>'

    def width(self, text: str) -> float:
        return len(printable(self.names(text)[0])) * CH

    @staticmethod
    def line(k: int, x1: float, y1: float, x2: float, y2: float) -> str:
        return f'<line class="w" data-k="{k}" x1="{x1:g}" y1="{y1:g}" x2="{x2:g}" y2="{y2:g}"/>'

    # -- elements ----------------------------------------------------------------
    def contact(self, c: Contact, p_in: Power) -> tuple[Fig, Power]:
        shp = c.shape
        if shp.kind == "modifier":
            p_out = modifier_power(c, p_in)
            closed = p_out
        else:
            closed = contact_state(c, self.pou, self.status)
            p_out = and3(p_in, closed)
        kind = "REAL" if shp.compare.startswith("R") else None
        below = bool(c.below)
        inside = shp.lad.strip()
        # The inside (``I``, ``/I``, ``>=I``) is written between the bars,
        # which move apart to hold it; a compare contact also makes room for
        # the values above and below it, so no two texts overlap.
        written = inside if inside != "/" else ""
        half = max(8.0, len(written) * CH_IN / 2 + 4)
        cmp = _CMP_VALUE.get(shp.compare[:1], 0) * CH_VAL if shp.compare else 0.0
        w = max(70.0, self.width(c.above) + 14, self.width(c.below) + 14 if below else 0,
                2 * half + 30, cmp + 10)
        wire = 42.0 if shp.compare else 36.0
        h = wire + 42 if below else (wire + 14 if shp.compare else 50.0)
        cx = w / 2
        f = Fig(w, h, wire)
        kin, kc, kout = self.k(p_in), self.k(closed), self.k(p_out)
        if shp.kind == "modifier":
            f.parts.append(self.line(kin, 0, wire, cx - 10, wire))
            f.parts.append(self.line(kout, cx + 10, wire, w, wire))
            f.parts.append(f'<rect class="ct" data-k="{kc}" x="{cx - 10:g}" y="{wire - 9:g}" '
                           f'width="20" height="18" rx="3"/>')
            f.parts.append(f'<text class="in" x="{cx:g}" y="{wire + 4:g}" '
                           f'text-anchor="middle">{esc(inside)}</text>')
            return f, p_out
        f.parts.append(self.line(kin, 0, wire, cx - half, wire))
        f.parts.append(self.line(kout, cx + half, wire, w, wire))
        f.parts.append(f'<path class="ct" data-k="{kc}" d="M{cx - half:g},{wire - 11:g}v22'
                       f'M{cx + half:g},{wire - 11:g}v22"/>')
        f.parts.append(f'<rect class="cf" data-k="{kc}" x="{cx - half + 2:g}" y="{wire - 9:g}" '
                       f'width="{2 * half - 4:g}" height="18"/>')
        if inside == "/":
            f.parts.append(f'<path class="nc" d="M{cx - 6:g},{wire + 9:g}L{cx + 6:g},'
                           f'{wire - 9:g}"/>')
        elif written:   # coloured with the contact, so it stays readable when closed
            f.parts.append(f'<text class="in" data-k="{kc}" x="{cx:g}" y="{wire + 4:g}" '
                           f'text-anchor="middle">{esc(written)}</text>')
        f.parts.append(self.label(c.above, cx, 12))
        if shp.compare:
            f.parts.append(self.value(self.v(c.above, kind), cx, 27))
        else:
            self.v("")  # keeps the numbering independent of the contact kind
        if below:
            f.parts.append(self.label(c.below, cx, wire + 25))
            f.parts.append(self.value(self.v(c.below, kind), cx, wire + 39))
        return f, p_out

    def logic(self, e: Logic, p_in: Power) -> tuple[Fig, Power]:
        if isinstance(e, Contact):
            return self.contact(e, p_in)
        if isinstance(e, Series):
            figs, p = [], p_in
            for item in e.items:
                fig, p = self.logic(item, p)
                figs.append(fig)
            return hcat(figs), p
        assert isinstance(e, Parallel)
        done = [self.logic(item, p_in) for item in e.items]
        outs = [p for _, p in done]
        p_out = or3(outs)
        return self.stack([f for f, _ in done], p_in, outs, p_out), p_out

    def stack(self, figs: list[Fig], p_in: Power, outs: list[Power] | None,
              p_out: Power) -> Fig:
        """Branches one under another between connectors (``outs`` None:
        output branches, joined on the left only)."""
        pad = 12.0
        width = max(f.w for f in figs) + 2 * pad if outs is not None else \
            max(f.w for f in figs) + pad
        out = Fig(width, sum(f.h for f in figs), figs[0].wire)
        y, rows = 0.0, []
        kl = self.k(p_in)
        for i, f in enumerate(figs):
            out.parts.append(self.line(kl, 0, y + f.wire, pad, y + f.wire))
            out.parts.append(f.at(pad, y))
            if outs is not None:
                ke = self.k(outs[i])
                out.parts.append(self.line(ke, pad + f.w, y + f.wire, width, y + f.wire))
            rows.append(y + f.wire)
            y += f.h
        out.parts.append(self.line(kl, 0, rows[0], 0, rows[-1]))
        if outs is not None:
            out.parts.append(self.line(self.k(p_out), width, rows[0], width, rows[-1]))
        return out

    def coil(self, c: Coil, p: Power) -> Fig:
        inner = c.symbol[1:-1].strip()
        w = max(70.0, self.width(c.above) + 24, self.width(c.below) + 24,
                len(inner) * CH + 40)
        wire = 36.0
        h = 72.0 if c.below else 50.0
        f = Fig(w, h, wire)
        kp = self.k(p)
        r = max(10.0, len(inner) * CH / 2 + 6)
        cx = w - r - 4
        f.parts.append(self.line(kp, 0, wire, cx - r, wire))
        f.parts.append(f'<rect class="cf" data-k="{kp}" x="{cx - r + 3:g}" y="{wire - 9:g}" '
                       f'width="{2 * r - 6:g}" height="18" rx="9"/>')
        f.parts.append(f'<path class="co" data-k="{kp}" d="M{cx - r + 6:g},{wire - 11:g}'
                       f'q-7,11 0,22M{cx + r - 6:g},{wire - 11:g}q7,11 0,22"/>')
        if inner:   # coloured with the coil: white on the powered fill
            f.parts.append(f'<text class="in" data-k="{kp}" x="{cx:g}" y="{wire + 4:g}" '
                           f'text-anchor="middle">{esc(inner)}</text>')
        if c.above:  # centred on the coil, kept inside the element
            f.parts.append(self.label(c.above, min(cx, w - self.width(c.above) / 2 - 2), 12))
        self.v("")
        if c.below:
            f.parts.append(self.label(c.below, cx, h - 12))
            f.parts.append(self.value(self.v(c.below), cx, h - 1))
        else:
            self.v("")
        return f

    def box(self, box: Box, powers: list[Power], gaps: list[float] | None = None
            ) -> tuple[Fig, Power, list[float]]:
        """A box; returns it, its ENO and the y of each power pin."""
        names = list(box.power)
        gaps = gaps or [ROW] * max(0, len(names) - 1)
        en = powers[0] if powers else None
        eno = eno_power(box, en) if box.eno else None
        lefts = [p for p in box.pins if not p.right]
        rights = [p for p in box.pins if p.right]
        lm = max([self.width(p.operand) + 16 for p in lefts] + [24.0])
        rm = max([self.width(p.operand) + 16 for p in rights] + [12.0])
        inner = max(len(printable(box.title)) * CH + 20, 90.0, len(box.note) * CH + 12)
        top = 26.0 if box.above else 4.0
        first = top + 2 * ROW
        prow = [first]
        for g in gaps:
            prow.append(prow[-1] + g)
        if not names:
            first, prow = top + ROW, []
        pins0 = (prow[-1] + ROW) if prow else first + ROW
        note = pins0 + max(len(lefts), len(rights)) * PIN_ROW
        bottom = note + (ROW if box.note else 0)
        h = bottom + 8
        L, R = lm, lm + inner
        f = Fig(lm + inner + rm, h, prow[0] if prow else first)
        kb = self.k(en)
        f.parts.append(f'<rect class="box" data-k="{kb}" x="{L:g}" y="{top:g}" '
                       f'width="{inner:g}" height="{bottom - top:g}"/>')
        f.parts.append(f'<text class="title" x="{L + inner / 2:g}" y="{top + 15:g}" '
                       f'text-anchor="middle">{esc(box.title)}</text>')
        if box.above:
            kind = "BIT" if not box.eno and not box.power else None
            f.parts.append(self.label(box.above, L + inner / 2, 12))
            f.parts.append(self.value(self.v(box.above, kind), L + inner / 2, 24))
        else:
            self.v("")
        if not names:
            f.parts.append(self.line(self.k(en), 0, first, L, first))
        for i, (name, r) in enumerate(zip(names, prow)):
            p = powers[i] if i < len(powers) else None
            f.parts.append(self.line(self.k(p), 0, r, L, r))
            f.parts.append(f'<text class="pin" x="{L + 4:g}" y="{r + 4:g}">{esc(name)}</text>')
        if box.eno and prow:
            f.parts.append(f'<text class="pin" x="{R - 4:g}" y="{prow[0] + 4:g}" '
                           f'text-anchor="end">ENO</text>')
            ke = self.k(eno)
            if box.next is not None:
                f.parts.append(self.line(ke, R, prow[0], R + rm, prow[0]))
        for i, pin in enumerate(lefts):
            r = pins0 + i * PIN_ROW
            f.parts.append(f'<line class="pl" x1="{L - 8:g}" y1="{r:g}" x2="{L:g}" y2="{r:g}"/>')
            f.parts.append(f'<text class="pin" x="{L + 4:g}" y="{r + 4:g}">{esc(pin.name)}</text>')
            f.parts.append(self.label(pin.operand, L - 10, r - 1, "end"))
            f.parts.append(self.value(self.v(pin.operand, pin.kind), L - 10, r + 10, "end"))
        for i, pin in enumerate(rights):
            r = pins0 + i * PIN_ROW
            f.parts.append(f'<line class="pl" x1="{R:g}" y1="{r:g}" x2="{R + 8:g}" y2="{r:g}"/>')
            f.parts.append(f'<text class="pin" x="{R - 4:g}" y="{r + 4:g}" '
                           f'text-anchor="end">{esc(pin.name)}</text>')
            f.parts.append(self.label(pin.operand, R + 10, r - 1, "start"))
            f.parts.append(self.value(self.v(pin.operand, pin.kind), R + 10, r + 10, "start"))
        if box.note:
            f.parts.append(f'<text class="note" x="{R - 4:g}" y="{note + 4:g}" '
                           f'text-anchor="end">{esc(box.note)}</text>')
        return f, eno, prow

    def out(self, o: Coil | Box | Node, p: Power) -> Fig:
        if isinstance(o, Coil):
            return self.coil(o, p)
        if isinstance(o, Box):
            f, eno, _ = self.box(o, [p])
            return hcat([f, self.node(o.next, eno)]) if o.next is not None else f
        return self.node(o, p)

    def node(self, node: Node, p_in: Power) -> Fig:
        parts, p = [], p_in
        if node.logic is not None:
            f, p = self.logic(node.logic, p_in)
            parts.append(f)
        outs = [self.out(o, p) for o in node.outs]
        parts.append(outs[0] if len(outs) == 1 else self.stack(outs, p, None, p))
        return hcat(parts)

    def multi(self, box: Box, p_rail: Power) -> tuple[Fig, list[float]]:
        """A counter: one rung from the rail into each power pin."""
        done = [self.logic(e, p_rail) for e in box.inputs]
        figs = [f for f, _ in done]
        gaps = [max(float(ROW), (figs[i - 1].h - figs[i - 1].wire) + figs[i].wire)
                for i in range(1, len(figs))]
        bf, _, prow = self.box(box, [p for _, p in done], gaps)
        width = max(f.w for f in figs)
        shift = max(0.0, figs[0].wire - prow[0])
        out = Fig(width + bf.w, 0, prow[0] + shift)
        out.parts.append(bf.at(width, shift))
        height = shift + bf.h
        for (f, p), r in zip(done, prow):
            y = shift + r - f.wire
            out.parts.append(f.at(0, y))
            out.parts.append(self.line(self.k(p), f.w, shift + r, width, shift + r))
            height = max(height, y + f.h)
        out.h = height
        return out, [shift + r for r in prow]

    def network(self, lad: Ladder, p_rail: Power) -> Fig:
        if lad.rail:
            figs = []
            for e in lad.rail:
                figs.append(self.coil(e, p_rail) if isinstance(e, Coil)
                            else self.box(e, [p_rail])[0])
            body = Fig(max(f.w for f in figs), 0, figs[0].wire)
            rows, y = [], 0.0
            for f in figs:
                body.parts.append(f.at(0, y))
                rows.append(y + f.wire)
                y += f.h
            body.h = y
            return self.rail(body, rows, p_rail)
        if lad.rung is None:
            return self.rail(Fig(40, 30, 15), [], p_rail)
        if isinstance(lad.rung, Box):
            body, rows = self.multi(lad.rung, p_rail)
            return self.rail(body, rows, p_rail)
        body = self.node(lad.rung, p_rail)
        return self.rail(body, [body.wire], p_rail)

    def rail(self, body: Fig, rows: list[float], p_rail: Power) -> Fig:
        out = Fig(body.w + 14, body.h + 4, body.wire)
        kr = self.k(p_rail)
        out.parts.append(f'<line class="rail" x1="3" y1="0" x2="3" y2="{body.h + 4:g}"/>')
        for r in rows:
            out.parts.append(self.line(kr, 3, r, 14, r))
        out.parts.append(body.at(14, 0))
        return out


def hcat(figs: list[Fig]) -> Fig:
    """Series: side by side, aligned on the wires."""
    wire = max(f.wire for f in figs)
    h = max(wire - f.wire + f.h for f in figs)
    out = Fig(sum(f.w for f in figs), h, wire)
    x = 0.0
    for f in figs:
        out.parts.append(f.at(x, wire - f.wire))
        x += f.w
    return out


# ---------------------------------------------------------------------------
# The public functions
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class NetworkState:
    """Live status of one network: a power character per ``data-k`` and a
    value text per ``data-v`` ("" when there is none to show)."""

    power: str
    values: list[str]

    def to_dict(self) -> dict[str, Any]:
        return {"p": self.power, "v": self.values}


def _power_chars(powers: list[Power]) -> str:
    return "".join("1" if p is True else "0" if p is False else "?" for p in powers)


def network_svg(pou: ir.Pou, network: ir.Network, *, program: ir.Program | None = None,
                names: Namer | None = None, lad: Ladder | None = None) -> str | None:
    """The network's rung as an SVG document, or None when it has no LAD
    form (see :func:`stl_lines`).  ``names`` maps an operand to its shown
    text and tooltip (symbol names and comments)."""
    lad = lad if lad is not None else to_ladder(network, program=program)
    if not lad.ok:
        return None
    walk = _Walk(pou.ident, None, names)
    fig = walk.network(lad, None)
    w, h = fig.w + 10, fig.h + 4
    return (f'<svg xmlns="http://www.w3.org/2000/svg" class="rung" width="{w:g}" '
            f'height="{h:g}" viewBox="0 0 {w:g} {h:g}">{fig.at(2, 2)}</svg>')


def network_state(pou: ir.Pou, network: ir.Network, status: Status | None, *,
                  program: ir.Program | None = None, lad: Ladder | None = None
                  ) -> NetworkState:
    """The live status of the numbered elements of :func:`network_svg`, or
    of the operands of :func:`stl_lines` for a network without LAD."""
    lad = lad if lad is not None else to_ladder(network, program=program)
    walk = _Walk(pou.ident, status, None)
    if lad.ok:
        walk.network(lad, True if status is not None else None)
    else:
        for insn in network.insns:
            shp = shape(insn.mnemonic)
            bit = shp.kind in ("contact", "coil", "rail") and not shp.compare
            kind = "REAL" if shp.compare.startswith("R") else None
            for i, o in enumerate(insn.operands):
                walk.v(o.text, "BIT" if bit and i == 0 else kind)
    return NetworkState(_power_chars(walk.powers), walk.values)


def stl_lines(network: ir.Network) -> list[dict[str, Any]]:
    """The STL of a network as data for the page: per instruction the
    mnemonic, its operands and its comment (the page writes them as text;
    value ``i`` of :func:`network_state` belongs to the i-th operand)."""
    return [{"m": insn.mnemonic, "ops": [o.text for o in insn.operands],
             "c": insn.comment} for insn in network.insns]


__all__ = ["NetworkState", "esc", "hcat", "network_state", "network_svg", "stl_lines"]
