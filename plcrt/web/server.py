"""The panel's web server: the page, its static files and the websocket.

aiohttp gives the HTTP server, the websocket and a test client in one
well-kept package, so no separate ASGI server is needed.  This module is
thin: it answers only requests whose ``Host`` names this server (a page of
another site whose name resolves to this address, DNS rebinding, gets
nothing), checks the websocket's ``Origin`` against the ``Host`` (a page
of another site cannot drive the PLC), parses every message with
:mod:`plcrt.web.protocol` (a bad one gets an ``error`` back, the
connection stays), hands the rest to the :class:`~plcrt.web.session.
PanelSession`, and sends each client what its mailbox holds.  Loading a
lesson, reloading it when its files change on disk, and "check my
program" are done here, off the event loop.
"""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
from collections.abc import Awaitable, Callable, Iterable
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from aiohttp import WSMsgType, web

from ..errors import PlcError, capped
from ..safetext import excerpt, printable
from . import course as course_mod
from .editor import ProgramSource, SourceOf
from .editroutes import add_routes as add_editor_routes
from .ladderroutes import add_routes as add_ladder_routes
from .protocol import MAX_MESSAGE, ProtocolError, dumps, parse
from .session import Client, PanelSession

STATIC = Path(__file__).parent / "static"

#: builds the session of a lesson (the CLI passes one that loads with its options)
LessonLoader = Callable[[course_mod.Lesson], PanelSession]

#: wall seconds between two looks at the current lesson's files
WATCH_S = 0.5
#: diagnostics of a lesson that does not load carried to the page
MAX_LOAD_ERRORS = 20
#: a websocket message larger than this closes the connection (aiohttp);
#: one between MAX_MESSAGE and this gets an ``error`` and the connection stays
MAX_FRAME = 4 * MAX_MESSAGE

_EMPTY = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nEND_ORGANIZATION_BLOCK\n"


class Panel:
    """What the server serves: the session, and the course if there is one.

    Args:
        hosts: host names the page may be opened under besides this
            server's own address and ``localhost`` (``plcrt serve --host
            NAME``, ``--allow-host NAME``); see :func:`host_ok`.
        watch_s: seconds between two looks at the current lesson's files.
        source_of: the program file the editor edits, and how a text of it
            is loaded, for the current lesson (or None); without it the
            editor has nothing to edit.
    """

    def __init__(self, session: PanelSession, *, lessons: list[course_mod.Lesson] | None = None,
                 current: course_mod.Lesson | None = None,
                 load_lesson: LessonLoader | None = None,
                 hosts: Iterable[str] = (), watch_s: float = WATCH_S,
                 source_of: SourceOf | None = None) -> None:
        self.session = session
        self.source_of = source_of
        self.lessons = lessons or []
        self.current = current
        self.load_lesson = load_lesson
        self.hosts = frozenset(h.strip().lower().strip("[]") for h in hosts if h.strip())
        self.watch_s = watch_s
        self.conns: set[_Conn] = set()
        self.checking = False
        #: why the current lesson's program is not loaded (None: it is)
        self.load_error: dict[str, Any] | None = None
        #: the lesson files' state when the program on screen was loaded
        self.stamp = current.stamp() if current is not None else ()
        self.switching = asyncio.Lock()

    def source(self) -> ProgramSource | None:
        """What the editor edits now (:mod:`plcrt.web.editor`)."""
        return None if self.source_of is None else self.source_of(self.current)

    def hello(self) -> dict[str, Any]:
        msg = dict(self.session.hello())
        msg["lessons"] = [le.to_dict() for le in self.lessons]
        msg["lesson"] = None if self.current is None else {
            **self.current.to_dict(), "doc": self.current.page(),
            "checkable": bool(self.current.tests)}
        msg["load_error"] = self.load_error
        src = self.source() if self.source_of is not None else None
        msg["editable"] = src is not None
        if src is not None:   # a downloaded program was loaded from the editor's text
            msg["files"] = [str(src.path) if f == "<string>" else f for f in msg["files"]]
        if self.load_error is not None and self.current is not None:
            msg["files"] = [str(self.current.program)]   # not the empty stand-in's
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


def host_ok(request: web.Request, names: frozenset[str] = frozenset()) -> bool:
    """Whether the request's ``Host`` names this server: its port is the
    port the request came in on, and its name is the address the request
    came in on (an IP literal: the page was opened by address),
    ``localhost`` when that address is a loopback one, or one of
    ``names``.  Any other name, whatever address it resolves to, is
    another site's (DNS rebinding)."""
    host = request.headers.get("Host")
    sock = request.transport.get_extra_info("sockname") if request.transport else None
    if not host or not sock or len(host) > 300:
        return False
    try:
        parts = urlsplit("//" + host)
        name, port = (parts.hostname or "").lower(), parts.port
    except ValueError:
        return False
    if parts.username is not None or parts.password is not None or parts.path or not name:
        return False
    local = _address(str(sock[0]))
    if (port if port is not None else 80) != sock[1] or local is None:
        return False
    if name in names:
        return True
    if name == "localhost":
        return local.is_loopback
    return _address(name) == local


def _address(text: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    """An IP address (an IPv4-mapped IPv6 one as IPv4; no zone), or None."""
    try:
        a = ipaddress.ip_address(text.split("%")[0])
    except ValueError:
        return None
    if isinstance(a, ipaddress.IPv6Address) and a.ipv4_mapped is not None:
        return a.ipv4_mapped
    return a


def make_app(panel: Panel) -> web.Application:
    """The aiohttp application serving ``panel``."""

    @web.middleware
    async def only_this_host(request: web.Request,
                             handler: Callable[[web.Request], Awaitable[web.StreamResponse]]
                             ) -> web.StreamResponse:
        # every route: the page, /static/, /lesson/ and the websocket
        if not host_ok(request, panel.hosts):
            shown = printable(excerpt(request.headers.get("Host", "")))
            return web.Response(
                status=403, headers=_NO_STORE,
                text=f"plcrt panel: refused: host '{shown}' is not this server's name. Open "
                     f"the address plcrt serve printed, or start it with --allow-host NAME.\n")
        return await handler(request)

    app = web.Application(client_max_size=MAX_MESSAGE, middlewares=[only_this_host])

    async def index(request: web.Request) -> web.StreamResponse:
        return web.FileResponse(STATIC / "index.html", headers=_NO_STORE)

    async def lesson_file(request: web.Request) -> web.StreamResponse:
        # the files the lesson text links to (lesson.awl, symbols.txt ...)
        les = panel.current
        path = les.file(request.match_info["name"]) if les is not None else None
        if path is None:
            raise web.HTTPNotFound(text="no such file in this lesson\n")
        return web.FileResponse(path, headers={**_NO_STORE,
                                               "Content-Type": "text/plain; charset=utf-8"})

    async def ws_handler(request: web.Request) -> web.StreamResponse:
        if not origin_ok(request):
            return web.Response(status=403, text="websocket from another origin refused\n")
        ws = web.WebSocketResponse(max_msg_size=MAX_FRAME, heartbeat=20)
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

    async def on_startup(app: web.Application) -> None:
        if panel.current is not None and panel.load_lesson is not None:
            app[_WATCHER] = asyncio.create_task(_watch_lesson(panel))

    async def on_shutdown(app: web.Application) -> None:
        task = app.get(_WATCHER)
        if task is not None:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task
        for conn in list(panel.conns):
            await conn.ws.close()

    app.router.add_get("/", index)
    app.router.add_get("/ws", ws_handler)
    app.router.add_get("/lesson/{name}", lesson_file)
    app.router.add_static("/static/", STATIC, show_index=False)
    add_editor_routes(app, panel, replace_session, origin_ok)
    add_ladder_routes(app, origin_ok)
    app.on_startup.append(on_startup)
    app.on_shutdown.append(on_shutdown)
    app.on_response_prepare.append(_headers)
    return app


_NO_STORE = {"Cache-Control": "no-store"}
_WATCHER = web.AppKey("lesson watcher", asyncio.Task)


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
        elif panel.load_error is not None and kind not in ("view", "history"):
            raise ProtocolError(f"no program is loaded: {panel.load_error['message']}")
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
    await _install(panel, course_mod.find(panel.lessons, ident))


async def _install(panel: Panel, les: course_mod.Lesson, notice: str | None = None) -> None:
    """Load lesson ``les`` (off the event loop) and make it the one every
    page shows.  A program that does not load still switches: the page
    gets the lesson's text, no program (``load_error`` in the hello) and
    an ``error`` with the diagnostics' files, lines and networks."""
    assert panel.load_lesson is not None
    loop = asyncio.get_running_loop()
    async with panel.switching:
        stamp = les.stamp()
        try:
            new = await loop.run_in_executor(None, panel.load_lesson, les)
            error = None
        except PlcError as e:
            new = await loop.run_in_executor(None, _unloaded)
            error = load_error(les, e)
        panel.current, panel.load_error, panel.stamp = les, error, stamp
        await replace_session(panel, new, notice,
                              None if error is None else error["message"])


async def replace_session(panel: Panel, new: PanelSession, notice: str | None = None,
                          error: str | None = None) -> None:
    """Make ``new`` the session every page shows (each gets its ``hello``,
    then ``notice`` and ``error``), start it and close the old one."""
    old = panel.session
    panel.session = new
    for conn in panel.conns:
        if conn.client is not None:
            old.disconnect(conn.client)
        conn.attach(panel)
        assert conn.client is not None
        if notice is not None:
            conn.client.mailbox.put({"type": "notice", "level": "info", "message": notice})
        if error is not None:
            conn.client.mailbox.put({"type": "error", "request": "lesson", "message": error})
    new.start()
    await asyncio.get_running_loop().run_in_executor(None, old.close)


def load_error(les: course_mod.Lesson, e: PlcError) -> dict[str, Any]:
    """Why a lesson's program did not load, for the page: one line per
    diagnostic as ``plcrt check`` prints it (file relative to the course,
    line, column, block and network), and each as data."""
    course = les.dir.parent
    diags, more = capped([d for d in e.diagnostics if d.severity == "error"]
                         or list(e.diagnostics), MAX_LOAD_ERRORS, ordered=True)
    items, lines = [], []
    for d in diags:
        loc = d.loc
        file = ""
        if loc is not None:
            file = loc.file
            with contextlib.suppress(ValueError):
                file = str(Path(file).resolve().relative_to(course))
        items.append({"message": printable(d.message), "file": printable(file),
                      "line": loc.line if loc else None, "column": loc.column if loc else None,
                      "block": loc.block if loc else None,
                      "network": loc.network if loc else None})
        text = str(d)
        if loc is not None and file:
            text = text.replace(loc.file, file, 1)
        lines.append(text)
    if not lines:
        lines.append(printable(e.message))
    if more:
        lines.append(more)
    return {"message": f"lesson {les.id} does not load: " + "\n".join(lines),
            "diagnostics": items}


def _unloaded() -> PanelSession:
    """The session of a lesson whose program does not load: no network, no
    input, no output."""
    from .. import load
    return PanelSession(load(_EMPTY, backend="python"), breakpoints=False)


async def _watch_lesson(panel: Panel) -> None:
    """Reload the current lesson when one of its files changes on disk (a
    student editing ``lesson.awl``): the same lesson, its new program (or
    the load error), from power-up."""
    while True:
        await asyncio.sleep(panel.watch_s)
        les = panel.current
        if les is None or panel.switching.locked():
            continue
        if les.stamp() != panel.stamp:
            await _install(panel, les, notice=f"the files of lesson {les.id} changed: "
                                              f"loaded again")


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


__all__ = ["MAX_FRAME", "Panel", "STATIC", "WATCH_S", "host_ok", "load_error", "make_app",
           "origin_ok", "replace_session"]
