"""The ladder drawing's HTTP endpoints: ``/ladder/networks``, ``/ladder/open``,
``/ladder/new``, ``/ladder/edit``, ``/ladder/undo`` and ``/ladder/redo``.

The page draws one network of the editor's current text at a time.
``open`` gives the network's editable model
(:func:`plcrt.view.ladder_edit.model_json`) or, when it has no ladder form,
the reason it stays STL, and a drawing id; each ``edit`` (one operation of
:mod:`plcrt.view.ladder_edit`), ``undo`` and ``redo`` of that id answers
with the new model, the network's STL and the editor's whole text with the
network replaced (:func:`plcrt.view.ladder_check.replace_network`: the
other lines byte for byte), which the page puts into the editor, so that
*Save* and *Download* apply the drawing.  An edit is refused when the
network in the text sent is no longer the one drawn (it was typed over
in the editor): the page opens it again.

The requests pass the same checks as the editor's
(:mod:`plcrt.web.editroutes`): the server's ``Host`` check, the page's own
``Origin``, ``application/json`` bodies of at most
:data:`~plcrt.web.editroutes.MAX_BODY` bytes, texts of at most
:data:`plcrt.web.editor.MAX_TEXT` characters.  The model JSON and the
operations are read as untrusted by the ladder model (bounded sizes and
depths, every result checked).  At most :data:`MAX_DRAWINGS` drawings are
kept (the oldest is forgotten first), each with its undo history
(:data:`plcrt.view.ladder_edit.MAX_HISTORY` steps).

What it is: HTTP and the drawings of the open pages.  What it is not: the
model and its edits (:mod:`plcrt.view.ladder_edit`), the drawing in the
page (``static/ladder_edit.js``).
"""

from __future__ import annotations

import asyncio
import secrets
from collections import OrderedDict
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import Any

from aiohttp import web

from ..errors import PlcConfigError, PlcError
from ..lang import ir
from ..lang.stl import parse_program
from ..safetext import excerpt, printable
from ..view.ladder_check import replace_network
from ..view.ladder_edit import History, model_json
from ..view.ladder_model import model_to_json
from ..view.ladder_stl import NoLadder, model_to_stl, network_to_model
from .editroutes import json_answer, read_body, text_of

#: drawings kept at once (all pages together); the oldest goes first
MAX_DRAWINGS = 32
#: networks listed by ``/ladder/networks``
MAX_LISTED = 2000
_NO_STORE = {"Cache-Control": "no-store"}

Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]


@dataclass
class Drawing:
    """One network drawn in a page: where it is and its undo history."""

    block: str
    number: int
    history: History


def _network(text: str, block: str, number: int) -> tuple[ir.Program, ir.Network]:
    prog = parse_program(text, "<editor>")
    for pou in prog.pous:
        if block.upper() in (pou.ident.upper(), pou.name.upper()):
            for net in pou.networks:
                if net.number == number:
                    return prog, net
            raise PlcConfigError(f"block {excerpt(block, 40)} has no network {number}")
    raise PlcConfigError(f"no block {excerpt(block, 40)} in the program")


def networks(text: str) -> list[dict[str, Any]]:
    """The networks of a program text, each with whether it can be drawn
    (and why not)."""
    out: list[dict[str, Any]] = []
    for pou in parse_program(text, "<editor>").pous:
        for net in pou.networks:
            if len(out) >= MAX_LISTED:
                return out
            got = network_to_model(net)
            row = {"block": pou.ident, "name": printable(pou.name), "number": net.number,
                   "title": printable(net.title)[:200], "drawable": not isinstance(got, NoLadder)}
            if isinstance(got, NoLadder):
                row["reason"] = printable(got.reason)
            out.append(row)
    return out


def new_network(text: str, block: str) -> dict[str, Any]:
    """The text with an empty network after the last one of ``block``,
    numbered after the block's highest; the other lines stay as they are."""
    prog = parse_program(text, "<editor>")
    pou = next((p for p in prog.pous if block.upper() in (p.ident.upper(), p.name.upper())), None)
    if pou is None:
        raise PlcConfigError(f"no block {excerpt(block, 40)} in the program")
    if not pou.networks:
        raise PlcConfigError(f"block {excerpt(block, 40)} has no network to add one after: "
                             "type the first one in the text")
    lines = text.splitlines(keepends=True)
    start = pou.networks[-1].loc.line - 1
    end = next((k for k in range(start + 1, len(lines))
                if lines[k].strip().upper().startswith("END_")), len(lines))
    number = max(n.number for n in pou.networks) + 1
    eol = "\r\n" if lines[start].endswith("\r\n") else "\n"
    if end > 0 and not lines[end - 1].endswith(("\n", "\r")):
        lines[end - 1] += eol
    lines.insert(end, f"Network {number}{eol}")
    return {"ok": True, "block": pou.ident, "number": number, "text": "".join(lines)}


class Drawings:
    """The open drawings by id (bounded; see :data:`MAX_DRAWINGS`)."""

    def __init__(self) -> None:
        self._by_id: OrderedDict[str, Drawing] = OrderedDict()

    def open(self, text: str, block: str, number: int) -> dict[str, Any]:
        prog, net = _network(text, block, number)
        page = model_json(net, program=prog)
        answer: dict[str, Any] = {"ok": True, "block": block, "number": number,
                                  "stl": page["stl"]}
        model = network_to_model(net)
        if isinstance(model, NoLadder):
            answer.update(ladder=None, reason=printable(model.reason))
            return answer
        key = secrets.token_urlsafe(12)
        self._by_id[key] = Drawing(block, number, History(model))
        while len(self._by_id) > MAX_DRAWINGS:
            self._by_id.popitem(last=False)
        answer.update(id=key, ladder=page["ladder"], undo=False, redo=False)
        return answer

    def step(self, key: Any, text: str, what: str, op: Any = None) -> dict[str, Any]:
        """Apply ``what`` (``edit`` with ``op``, ``undo``, ``redo``) to the
        drawing ``key`` of the network in ``text``."""
        d = self._by_id.get(key) if isinstance(key, str) else None
        if d is None:
            raise PlcConfigError("this drawing is closed: open the network again")
        prog, net = _network(text, d.block, d.number)
        if network_to_model(net) != d.history.model:
            raise PlcConfigError(f"network {d.number} was changed in the text: open it again "
                                 "to draw it")
        h = d.history
        model = h.apply(op) if what == "edit" else h.undo() if what == "undo" else h.redo()
        self._by_id.move_to_end(key)
        new = replace_network(text, d.block, d.number, model)
        # the new network read back from the new text: the JSON open gives
        # (a CALL's pins named from the program)
        page = model_json(_network(new, d.block, d.number)[1], program=prog)
        return {"ok": True, "id": key, "ladder": page["ladder"] or model_to_json(model),
                "stl": model_to_stl(model), "text": new,
                "undo": h.can_undo, "redo": h.can_redo}


def add_routes(app: web.Application, origin_ok: Callable[[web.Request], bool]) -> None:
    """Add the drawing's endpoints to ``app`` (the panel's); ``origin_ok``
    is the server's ``Origin`` check."""
    drawings = Drawings()
    busy = asyncio.Lock()

    def guarded(fields: tuple[str, ...], fn: Callable[[dict[str, Any]], dict[str, Any]]
                ) -> Handler:
        async def handle(request: web.Request) -> web.StreamResponse:
            if not origin_ok(request):
                return web.Response(status=403, headers=_NO_STORE,
                                    text="plcrt panel: refused: a request of another origin\n")
            try:
                body = await read_body(request, fields)
                async with busy:   # one at a time, off the event loop
                    answer = await asyncio.get_running_loop().run_in_executor(None, fn, body)
            except PlcError as e:
                return json_answer({"ok": False, "message": printable(e.message)}, status=400)
            return json_answer(answer)
        return handle

    def where(body: dict[str, Any]) -> tuple[str, int]:
        block, number = body.get("block"), body.get("number")
        if not isinstance(block, str) or len(block) > 100:
            raise PlcConfigError("block must be a block's id (OB1, SBR0 ...)")
        if isinstance(number, bool) or not isinstance(number, int) or not 0 <= number < 100000:
            raise PlcConfigError("number must be a network's number")
        return block, number

    app.router.add_post("/ladder/networks", guarded(
        ("text",), lambda b: {"ok": True, "networks": networks(text_of(b))}))
    app.router.add_post("/ladder/new", guarded(
        ("text", "block"), lambda b: new_network(text_of(b), where(dict(b, number=0))[0])))
    app.router.add_post("/ladder/open", guarded(
        ("text", "block", "number"), lambda b: drawings.open(text_of(b), *where(b))))
    app.router.add_post("/ladder/edit", guarded(
        ("id", "text", "op"), lambda b: drawings.step(b.get("id"), text_of(b), "edit",
                                                      b.get("op"))))
    for what in ("undo", "redo"):
        app.router.add_post(f"/ladder/{what}", guarded(
            ("id", "text"), lambda b, w=what: drawings.step(b.get("id"), text_of(b), w)))


__all__ = ["Drawing", "Drawings", "MAX_DRAWINGS", "add_routes", "networks", "new_network"]
