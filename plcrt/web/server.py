"""The panel's web server: the page, its static files and the websocket.

aiohttp gives the HTTP server, the websocket and a test client in one
well-kept package, so no separate ASGI server is needed.  This module is
thin: it checks the websocket's ``Origin`` against the ``Host`` (a page of
another site cannot drive the PLC), parses every message with
:mod:`plcrt.web.protocol` (a bad one gets an ``error`` back, the
connection stays), hands the rest to the :class:`~plcrt.web.session.
PanelSession`, and sends each client what its mailbox holds.  Loading a
lesson and "check my program" are done here, off the event loop.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from aiohttp import WSMsgType, web

from ..errors import PlcError
from ..safetext import printable
from . import course as course_mod
from .protocol import MAX_MESSAGE, ProtocolError, dumps, parse
from .session import Client, PanelSession

STATIC = Path(__file__).parent / "static"

#: builds the session of a lesson (the CLI passes one that loads with its options)
LessonLoader = Callable[[course_mod.Lesson], PanelSession]


class Panel:
    """What the server serves: the session, and the course if there is one."""

    def __init__(self, session: PanelSession, *, lessons: list[course_mod.Lesson] | None = None,
                 current: course_mod.Lesson | None = None,
                 load_lesson: LessonLoader | None = None) -> None:
        self.session = session
        self.lessons = lessons or []
        self.current = current
        self.load_lesson = load_lesson
        self.conns: set[_Conn] = set()
        self.checking = False

    def hello(self) -> dict[str, Any]:
        msg = dict(self.session.hello())
        msg["lessons"] = [le.to_dict() for le in self.lessons]
        msg["lesson"] = None if self.current is None else {
            **self.current.to_dict(), "text": self.current.text(),
            "checkable": bool(self.current.tests)}
        return msg


class _Conn:
    """One websocket: its client in the current session and its sender."""

    def __init__(self, ws: web.WebSocketResponse, loop: asyncio.AbstractEventLoop) -> None:
        self.ws = ws
        self.wake = asyncio.Event()
        self.loop = loop
        self.client: Client | None = None

    def notify(self) -> None:
        self.loop.call_soon_threadsafe(self.wake.set)

    def attach(self, panel: Panel) -> None:
        self.client = panel.session.connect(self.notify)
        self.client.mailbox.put(panel.hello())


def origin_ok(request: web.Request) -> bool:
    """A browser always sends ``Origin`` with a websocket: it must be this
    server's own (same host and port as ``Host``).  A client without
    ``Origin`` is not a web page (scripts, the bench) and is let in."""
    origin = request.headers.get("Origin")
    if origin is None:
        return True
    host = request.headers.get("Host", "")
    try:
        parts = urlsplit(origin)
    except ValueError:
        return False
    return parts.scheme in ("http", "https") and bool(host) and \
        parts.netloc.lower() == host.lower()


def make_app(panel: Panel) -> web.Application:
    """The aiohttp application serving ``panel``."""
    app = web.Application(client_max_size=MAX_MESSAGE)

    async def index(request: web.Request) -> web.StreamResponse:
        return web.FileResponse(STATIC / "index.html", headers=_NO_STORE)

    async def ws_handler(request: web.Request) -> web.StreamResponse:
        if not origin_ok(request):
            return web.Response(status=403, text="websocket from another origin refused\n")
        ws = web.WebSocketResponse(max_msg_size=MAX_MESSAGE, heartbeat=20)
        await ws.prepare(request)
        conn = _Conn(ws, asyncio.get_running_loop())
        conn.attach(panel)
        panel.conns.add(conn)
        sender = asyncio.create_task(_send_loop(conn))
        try:
            async for m in ws:
                if m.type != WSMsgType.TEXT:
                    if m.type in (WSMsgType.BINARY,):
                        await ws.send_str(dumps({"type": "error", "request": None,
                                                 "message": "send JSON text messages"}))
                    continue
                await _receive(panel, conn, m.data)
        finally:
            panel.conns.discard(conn)
            if conn.client is not None:
                panel.session.disconnect(conn.client)
            sender.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await sender
        return ws

    async def on_shutdown(app: web.Application) -> None:
        for conn in list(panel.conns):
            await conn.ws.close()

    app.router.add_get("/", index)
    app.router.add_get("/ws", ws_handler)
    app.router.add_static("/static/", STATIC, show_index=False)
    app.on_shutdown.append(on_shutdown)
    app.on_response_prepare.append(_headers)
    return app


_NO_STORE = {"Cache-Control": "no-store"}


async def _headers(request: web.Request, response: web.StreamResponse) -> None:
    # no script, style or connection from anywhere but this server
    response.headers.setdefault(
        "Content-Security-Policy",
        "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data: blob:; "
        "connect-src 'self'; object-src 'none'; base-uri 'none'; frame-ancestors 'none'")
    response.headers.setdefault("X-Content-Type-Options", "nosniff")


async def _send_loop(conn: _Conn) -> None:
    while not conn.ws.closed:
        await conn.wake.wait()
        conn.wake.clear()
        client = conn.client
        if client is None:
            continue
        for msg in client.mailbox.take():
            if conn.ws.closed:
                return
            await conn.ws.send_str(dumps(msg))


async def _receive(panel: Panel, conn: _Conn, data: str) -> None:
    try:
        msg = parse(data)
    except ProtocolError as e:
        await conn.ws.send_str(dumps({"type": "error", "request": None,
                                      "message": printable(e.message)}))
        return
    kind = msg["type"]
    try:
        if kind == "lesson":
            await _switch_lesson(panel, msg["id"])
        elif kind == "check":
            await _check(panel, conn, msg)
        else:
            panel.session.submit(conn.client, msg)
    except PlcError as e:
        err = {"type": "error", "request": kind, "message": printable(e.message)}
        if "id" in msg:
            err["id"] = msg["id"]
        await conn.ws.send_str(dumps(err))


async def _switch_lesson(panel: Panel, ident: str) -> None:
    if panel.load_lesson is None:
        raise ProtocolError("this panel has no course")
    les = course_mod.find(panel.lessons, ident)
    loop = asyncio.get_running_loop()
    new = await loop.run_in_executor(None, panel.load_lesson, les)
    old = panel.session
    panel.session, panel.current = new, les
    for conn in panel.conns:
        if conn.client is not None:
            old.disconnect(conn.client)
        conn.attach(panel)
    new.start()
    await loop.run_in_executor(None, old.close)


async def _check(panel: Panel, conn: _Conn, msg: dict[str, Any]) -> None:
    if panel.current is None:
        raise ProtocolError("no lesson is open: 'check my program' checks a lesson")
    if panel.checking:
        raise ProtocolError("a check is already running")
    panel.checking = True
    try:
        result = await asyncio.get_running_loop().run_in_executor(
            None, course_mod.check, panel.current)
    finally:
        panel.checking = False
    await conn.ws.send_str(dumps(result))


__all__ = ["Panel", "STATIC", "make_app", "origin_ok"]
