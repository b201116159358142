"""The editor's HTTP endpoints: ``/editor/source``, ``/editor/stamp``,
``/editor/words``, ``/editor/check``, ``/editor/download`` and
``/editor/save``.

Each request passes the server's ``Host`` check (its middleware) and here
the websocket's ``Origin`` check (:func:`plcrt.web.server.origin_ok`): a
browser sends ``Origin`` with every POST and with a cross-site GET, so
another site's page is refused with 403.  A POST must be
``application/json`` (a cross-site form cannot send that without asking
first) and its body is read up to :data:`MAX_BODY` bytes, never more;
the text in it is at most :data:`plcrt.web.editor.MAX_TEXT` characters.
Answers are JSON; every text in them made printable.  Loading a text (a
check, a download) runs off the event loop, one at a time.

What it is: the HTTP side of :mod:`plcrt.web.editor`, and the swap of the
running session on a download.  What it is not: the loading and the
memory move themselves (:mod:`plcrt.web.editor`).
"""

from __future__ import annotations

import asyncio
import json
from collections.abc import Awaitable, Callable
from typing import Any

from aiohttp import web

from ..errors import PlcConfigError, PlcError
from ..safetext import printable
from . import editor
from .session import PanelSession

#: the largest request body (UTF-8 of the largest text, quoted, and the rest)
MAX_BODY = 6 * editor.MAX_TEXT + 4096
_NO_STORE = {"Cache-Control": "no-store"}

Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]
Replace = Callable[[Any, PanelSession, "str | None"], Awaitable[None]]


def add_routes(app: web.Application, panel: Any, replace: Replace,
               origin_ok: Callable[[web.Request], bool]) -> None:
    """Add the editor's endpoints to ``app`` (the panel's).  ``replace``
    makes a new session the one every page shows; ``origin_ok`` is the
    server's ``Origin`` check."""
    busy = asyncio.Lock()   # one load at a time (made in the server's loop: aiohttp >= 3.10)

    def guarded(fn: Callable[[web.Request], Awaitable[dict[str, Any]]]) -> Handler:
        async def handle(request: web.Request) -> web.StreamResponse:
            if not origin_ok(request):
                return web.Response(status=403, headers=_NO_STORE,
                                    text="plcrt panel: refused: a request of another origin\n")
            try:
                answer = await fn(request)
            except PlcError as e:
                return _json({"ok": False, "message": printable(e.message)}, status=400)
            return _json(answer)
        return handle

    def source() -> editor.ProgramSource:
        src = panel.source()
        if src is None:
            raise PlcConfigError("this panel has no program file to edit")
        return src

    async def get_source(request: web.Request) -> dict[str, Any]:
        src = source()
        text, stamp = await asyncio.get_running_loop().run_in_executor(None, src.read)
        return {"ok": True, "name": printable(src.path.name), "text": text, "stamp": stamp,
                "writable": src.writable()}

    async def get_stamp(request: web.Request) -> dict[str, Any]:
        return {"ok": True, "stamp": source().stamp()}

    async def get_words(request: web.Request) -> dict[str, Any]:
        return {"ok": True, **editor.words()}

    async def post_check(request: web.Request) -> dict[str, Any]:
        body = await _body(request)
        text = _text(body)
        src = source()
        async with busy:
            return await asyncio.get_running_loop().run_in_executor(
                None, editor.check_text, src, text)

    async def post_download(request: web.Request) -> dict[str, Any]:
        body = await _body(request, ("text", "mode"))
        text, mode = _text(body), body.get("mode", "auto")
        if mode not in ("auto", "run", "stop"):
            raise PlcConfigError("mode must be auto, run or stop")
        src = source()
        async with busy, panel.switching:
            return await _download(panel, src, text, mode, replace)

    async def post_save(request: web.Request) -> dict[str, Any]:
        body = await _body(request, ("text", "stamp"))
        text, stamp = _text(body), body.get("stamp")
        if stamp is not None and (not isinstance(stamp, str) or len(stamp) > 100):
            raise PlcConfigError("stamp must be the text /editor/source gave")
        src = source()
        async with panel.switching:   # the lesson watcher waits: this change is ours
            new = await asyncio.get_running_loop().run_in_executor(
                None, editor.save, src, text, stamp)
            les = panel.current
            if les is not None and les.program == src.path and panel.load_error is None:
                # the page saved the file: the running program stays what it was
                # (saving is not downloading), the watcher does not reload it
                panel.stamp = les.stamp()
        return {"ok": True, "stamp": new, "message": printable(f"saved {src.path.name}")}

    app.router.add_get("/editor/source", guarded(get_source))
    app.router.add_get("/editor/stamp", guarded(get_stamp))
    app.router.add_get("/editor/words", guarded(get_words))
    app.router.add_post("/editor/check", guarded(post_check))
    app.router.add_post("/editor/download", guarded(post_download))
    app.router.add_post("/editor/save", guarded(post_save))


async def _download(panel: Any, src: editor.ProgramSource, text: str, mode: str,
                    replace: Replace) -> dict[str, Any]:
    """Load ``text`` for running and put it in place of the running
    program (see :func:`plcrt.web.editor.run_obstacle` and
    :func:`~plcrt.web.editor.carry`)."""
    loop = asyncio.get_running_loop()
    editor.check_size(text)
    old: PanelSession = panel.session
    if panel.load_error is None and old.state == "paused":
        raise PlcConfigError("the PLC is paused at a breakpoint: continue or stop it, then "
                             "download")
    try:
        plc = await loop.run_in_executor(None, src.load, text)
    except PlcError as e:
        return {"ok": False, "mode": None,
                "message": "not downloaded: the program has errors (the PLC runs the "
                           "program it had)",
                **editor.diagnostics(list(e.diagnostics))}
    running = panel.load_error is None and old.control.busy
    if mode == "auto":
        mode = "run" if running else "stop"
    les = panel.current
    new = await loop.run_in_executor(None, lambda: PanelSession(
        plc, breakpoints=old.builds.breakable, kinds=les.kinds() if les is not None else None,
        door=old.door))

    given_up = False

    def job(cur: Any) -> str | None:
        # in the old session's thread, at a scan boundary: stop it there
        if given_up:
            return "the download was given up"
        why = editor.run_obstacle(cur, new.plc) if mode == "run" else None
        if why is None:
            old.control.stop()
            if mode == "run":
                editor.carry(cur, new.plc)
            else:
                for key, value in cur.forces.items():
                    new.plc.force(key, value)
        return why

    if panel.load_error is None:
        try:
            why = await asyncio.wait_for(asyncio.wrap_future(old.door.post(job)),
                                         editor.SWAP_TIMEOUT)
        except (asyncio.TimeoutError, PlcError):   # PlcError: the door is busy or closed
            given_up = True
            new.close()
            raise PlcConfigError("the PLC did not reach a scan boundary in "
                                 f"{editor.SWAP_TIMEOUT:g} s: nothing was downloaded") from None
    else:   # no program runs: nothing to stop or carry
        why, mode = None, "stop"
    if why is not None:
        new.close()
        return {"ok": False, "mode": "run",
                "message": printable(f"not downloaded in RUN: {why}. Stop the PLC and "
                                     f"download in STOP (from power-up)"),
                **editor.diagnostics(list(plc.diagnostics))}
    for w in old.watch_table.rows:
        new.apply({"type": "watch", "spec": w.spec, "format": w.format})
    if old.trend.signals:
        new.apply({"type": "trend", "signals": list(old.trend.signals)})
    new.pacer.set(old.pacer.mode, old.pacer.factor, plc.now_us)
    if mode == "run":
        new.control.run(new.plc)
        message = "downloaded in RUN: the new program goes on with the memory of the old one"
    else:
        message = "downloaded in STOP: the new program starts from power-up; click Run"
    panel.load_error = None
    await replace(panel, new, message)
    return {"ok": True, "mode": mode, "message": message,
            **editor.diagnostics(list(plc.diagnostics))}


async def _body(request: web.Request, fields: tuple[str, ...] = ("text",)) -> dict[str, Any]:
    """The request's JSON object, read up to :data:`MAX_BODY` bytes."""
    if request.content_type != "application/json":
        raise PlcConfigError("send the request as application/json")
    if request.content_length is not None and request.content_length > MAX_BODY:
        raise PlcConfigError(f"the request is larger than {MAX_BODY} bytes")
    chunks, size = [], 0
    while True:
        chunk = await request.content.readany()
        if not chunk:
            break
        size += len(chunk)
        if size > MAX_BODY:
            raise PlcConfigError(f"the request is larger than {MAX_BODY} bytes")
        chunks.append(chunk)
    try:
        body = json.loads(b"".join(chunks).decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        raise PlcConfigError("the request is not JSON") from None
    if not isinstance(body, dict):
        raise PlcConfigError("the request must be a JSON object")
    unknown = sorted(set(body) - set(fields))
    if unknown:
        raise PlcConfigError(f"unknown field {printable(str(unknown[0]))[:40]!r}")
    return body


def _text(body: dict[str, Any]) -> str:
    text = body.get("text")
    if not isinstance(text, str):
        raise PlcConfigError("text must be the program's text")
    editor.check_size(text)
    return text


def _json(answer: dict[str, Any], status: int = 200) -> web.Response:
    return web.Response(status=status, headers=_NO_STORE, content_type="application/json",
                        text=json.dumps(answer, ensure_ascii=True, allow_nan=False))


#: the body, text and answer helpers, for the panel's other endpoints
#: (:mod:`plcrt.web.ladderroutes`)
read_body, text_of, json_answer = _body, _text, _json

__all__ = ["MAX_BODY", "add_routes", "json_answer", "read_body", "text_of"]
