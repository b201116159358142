"""The program as the panel's pages draw it.

Once per program: every network's ladder (:func:`plcrt.view.ladder.
to_ladder`) and SVG, the symbols, the inputs and outputs with their kinds,
the axes and drives: the ``hello`` message.  Per frame: the live status of
the networks some page has on screen (:class:`plcrt.view.status.
PlcStatus`), and no other.

What it is: the program's drawing and the block names a message may use.
What it is not: the SVG itself (:mod:`plcrt.web.svg`), the status of a
wire (:mod:`plcrt.view.status`) or anything that runs the PLC.
"""

from __future__ import annotations

from collections.abc import Container
from typing import Any

from ..engine.runtime import Plc
from ..lang import ir
from ..view.ladder import Ladder, to_ladder
from ..view.status import PlcStatus
from .present import axis_marks, drive_marks, symbol_names
from .svg import network_state, network_svg, stl_lines

#: symbols the hello message lists at most
MAX_SYMBOLS = 5000


class ProgramView:
    """The networks of ``plc``'s program, drawn once."""

    def __init__(self, plc: Plc) -> None:
        prog = plc.program
        #: (block id, network number) -> the network and its ladder
        self.nets: dict[tuple[str, int], tuple[ir.Pou, ir.Network, Ladder]] = {
            (p.ident, n.number): (p, n, to_ladder(n, program=prog))
            for p in prog.pous for n in p.networks}
        #: block ids and names (upper case) -> block id
        self.blocks = {p.ident.upper(): p.ident for p in prog.pous}
        for p in prog.pous:
            self.blocks.setdefault(p.name.upper(), p.ident)
        self.names = symbol_names(plc.symbols)

    def hello(self, plc: Plc, inputs: list[str], outputs: list[str], kinds: dict[str, str],
              breakable: bool) -> dict[str, Any]:
        """What a page needs to draw the program (the ``hello`` message,
        without its diagnostics)."""
        prog = plc.program
        blocks = []
        for p in prog.pous:
            nets = []
            for n in p.networks:
                lad = self.nets[(p.ident, n.number)][2]
                svg = network_svg(p, n, program=prog, names=self.names, lad=lad)
                nets.append({"number": n.number, "id": f"{p.ident}/{n.number}",
                             "title": n.title, "comment": n.comment, "svg": svg,
                             "stl": stl_lines(n) if svg is None else None,
                             "why": lad.reason})
            blocks.append({"id": p.ident, "name": p.name, "title": p.title,
                           "comment": p.comment, "networks": nets})
        symbols = []
        table = plc.symbols
        if table is not None:
            for s in list(table.entries.values())[:MAX_SYMBOLS]:
                symbols.append({"name": s.name, "address": s.address, "comment": s.comment})

        def io(addr: str) -> dict[str, str]:
            shown, tip = self.names(addr)
            return {"addr": addr, "name": shown if shown != addr else "", "comment": tip,
                    "kind": kinds.get(addr, "switch")}

        return {"type": "hello", "files": sorted({p.loc.file for p in prog.pous}),
                "blocks": blocks, "symbols": symbols,
                "inputs": [io(a) for a in inputs],
                "outputs": [io(a) for a in outputs],
                "scan_ms": plc.scan_us / 1000, "axes": axis_marks(plc),
                "drives": drive_marks(plc), "breakable": breakable}

    def states(self, plc: Plc, blocks: Container[str], shown: Container[str]) -> dict[str, Any]:
        """The status of every network of ``blocks`` and of the networks
        ``shown`` (``OB1/3``), by network id."""
        status = PlcStatus(plc)
        nets = {}
        for (b, n), (p, net, lad) in self.nets.items():
            key = f"{b}/{n}"
            if b in blocks or key in shown:
                nets[key] = network_state(p, net, status, program=plc.program,
                                          lad=lad).to_dict()
        return nets
