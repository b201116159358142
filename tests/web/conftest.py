"""Fixtures of the panel's tests: sample programs, a panel server on a free
loopback port in a thread, and a headless Chromium page.

Browser tests skip when Debian's chromium (``/usr/bin/chromium`` or
``$PLCRT_CHROMIUM``) or the playwright package is missing, unless
``PLCRT_REQUIRE_BROWSER=1`` (CI), where they fail instead.  Nothing here
uses a fixed port or a shared file, so the tests run under pytest-xdist.
"""

from __future__ import annotations

import asyncio
import os
import shutil
import threading
from collections.abc import Callable, Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest

import plcrt

PROGRAM = """\
ORGANIZATION_BLOCK MAIN:OB1
TITLE=Panel sample
BEGIN
Network 1 // Seal-in
// start latches, stop wins
LD     I0.0
O      Q0.0
AN     I0.1
=      Q0.0
Network 2 // Timer: 5 s after the motor starts
LD     Q0.0
TON    T37, 50
Network 3 // Lamp after the timer
LD     T37
=      Q0.1
Network 4 // Copy
LD     SM0.0
MOVW   VW0, VW2
END_ORGANIZATION_BLOCK
"""

SYMBOLS = "Start_PB\tI0.0\tstart push button\nStop_PB\tI0.1\tstop push button\n" \
          "Motor\tQ0.0\tmotor contactor\n"

CHROME_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
               "--no-first-run", "--disable-background-networking",
               "--disable-component-update", "--disable-sync"]

REPO = Path(__file__).resolve().parents[2]


def editor_text(page: Any) -> str:
    """The text in the panel's STL editor (CodeMirror's document)."""
    return page.evaluate("() => window.plcrtEditor.view.state.doc.toString()")


def editor_end_of_line(page: Any, n: int) -> None:
    """Put the editor's cursor at the end of line *n* (1-based) and focus it."""
    page.evaluate(f"() => {{ const v = window.plcrtEditor.view; const l = v.state.doc.line({n});"
                  f" v.dispatch({{selection: {{anchor: l.to}}}}); v.focus(); }}")


#: reference screenshots of the page (golden/NAME.png)
GOLDEN = Path(__file__).parent / "golden"


def matches_golden(locator: Any, name: str) -> None:
    """The element's screenshot against golden/NAME.png: mean absolute
    difference under 0.01 and under 1 % of the pixels off by more than 0.1;
    PLCRT_UPDATE_GOLDEN=1 writes the reference."""
    import matplotlib.image as mpimg
    import numpy as np
    out = GOLDEN.parent / f"_shot_{name}_{os.getpid()}.png"
    try:
        locator.screenshot(path=str(out), animations="disabled")
        ref = GOLDEN / f"{name}.png"
        if os.environ.get("PLCRT_UPDATE_GOLDEN") == "1" or not ref.exists():
            if os.environ.get("PLCRT_UPDATE_GOLDEN") != "1":
                pytest.fail(f"{ref} is missing: run with PLCRT_UPDATE_GOLDEN=1")
            ref.write_bytes(out.read_bytes())
        a, b = (mpimg.imread(str(path))[..., :3] for path in (out, ref))
        assert a.shape == b.shape, f"size {a.shape} != reference {b.shape}"
        diff = np.abs(a - b)
        assert diff.mean() < 0.01
        assert (diff.max(axis=2) > 0.1).mean() < 0.01
    finally:
        out.unlink(missing_ok=True)


def editor_no_errors(page: Any) -> None:
    """Wait until the editor's check of its text finds no error."""
    page.wait_for_function("() => document.querySelector('#editor-count')"
                           ".textContent === 'no errors'")


def editor_download(page: Any) -> str:
    """Click Download and wait for it to be done; the status line."""
    page.click("#editor-download")
    page.wait_for_function("() => document.querySelector('#editor-status')"
                           ".textContent.startsWith('downloaded')")
    return page.locator("#editor-status").text_content()


def editor_download_refused(page: Any) -> None:
    """Click Download and wait for the refusal of a text with errors."""
    page.click("#editor-download")
    page.wait_for_function("() => document.querySelector('#editor-status')"
                           ".textContent.includes('has errors')")


class _OtherSite(BaseHTTPRequestHandler):
    """A page of another site: no policy of its own."""

    def do_GET(self) -> None:   # noqa: N802 - http.server's name
        body = b"<!DOCTYPE html><title>another site</title>"
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args: object) -> None:
        pass


def posts_from_another_origin(page: Any, base: str, routes: list[str]) -> dict[str, int]:
    """The HTTP status of each of ``routes`` (below ``base``, the panel's
    URL) posted by a page of another origin (another port) as a simple
    request (no preflight: the browser sends it, with Origin), by the
    route's last part."""
    other = ThreadingHTTPServer(("127.0.0.1", 0), _OtherSite)
    threading.Thread(target=other.serve_forever, daemon=True).start()
    try:
        page.goto(f"http://127.0.0.1:{other.server_address[1]}/")
        seen: dict[str, int] = {}
        page.on("response", lambda r: seen.__setitem__(r.url.rsplit("/", 1)[1], r.status))
        page.evaluate("""async ([base, routes]) => {
            for (const route of routes) {
              await fetch(base + route, {method: 'POST', mode: 'no-cors',
                headers: {'Content-Type': 'text/plain'}, body: '{"text": "x"}'});
            }
        }""", [base, routes])
        return seen
    finally:
        other.shutdown()
        other.server_close()


def load_sample(text: str = PROGRAM, symbols: str | None = SYMBOLS, **kw: Any) -> plcrt.Plc:
    return plcrt.load(text, symbols=symbols, **kw)


class Served:
    """A panel server running in a thread of its own."""

    def __init__(self, panel: Any) -> None:
        from aiohttp import web

        from plcrt.web.server import make_app
        self.panel = panel
        self.loop = asyncio.new_event_loop()
        self.ready = threading.Event()
        self.port = 0

        async def start() -> None:
            self.runner = web.AppRunner(make_app(panel))
            await self.runner.setup()
            site = web.TCPSite(self.runner, "127.0.0.1", 0)
            await site.start()
            self.port = site._server.sockets[0].getsockname()[1]  # type: ignore[union-attr]

        def run() -> None:
            asyncio.set_event_loop(self.loop)
            self.loop.run_until_complete(start())
            self.ready.set()
            self.loop.run_forever()

        self.thread = threading.Thread(target=run, daemon=True)
        self.thread.start()
        assert self.ready.wait(20), "the panel server did not start"
        panel.session.start()

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}/"

    def close(self) -> None:
        """Stop the session and the server (again: nothing)."""
        if not self.thread.is_alive():
            return
        self.panel.session.close()
        fut = asyncio.run_coroutine_threadsafe(self.runner.cleanup(), self.loop)
        try:
            fut.result(10)
        finally:
            self.loop.call_soon_threadsafe(self.loop.stop)
            self.thread.join(10)


@pytest.fixture
def serve() -> Iterator[Callable[..., Served]]:
    """``serve(plc)`` or ``serve(panel=...)``: a running panel server."""
    from plcrt.web.server import Panel
    from plcrt.web.session import PanelSession
    started: list[Served] = []

    def make(plc: plcrt.Plc | None = None, *, panel: Any = None) -> Served:
        if panel is None:
            panel = Panel(PanelSession(plc if plc is not None else load_sample()))
        s = Served(panel)
        started.append(s)
        return s

    yield make
    for s in started:
        s.close()


def _chromium() -> str | None:
    path = os.environ.get("PLCRT_CHROMIUM") or "/usr/bin/chromium"
    return path if shutil.which(path) or os.path.isfile(path) else None


@pytest.fixture(scope="session")
def browser() -> Iterator[Any]:
    required = os.environ.get("PLCRT_REQUIRE_BROWSER") == "1"
    path = _chromium()
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        sync_playwright = None
    if path is None or sync_playwright is None:
        why = "chromium not found" if path is None else "playwright is not installed"
        if required:
            pytest.fail(f"PLCRT_REQUIRE_BROWSER=1 but {why}")
        pytest.skip(why)
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=path, args=CHROME_ARGS)
        yield b
        b.close()


@pytest.fixture
def page(browser: Any) -> Iterator[Any]:
    ctx = browser.new_context(viewport={"width": 1400, "height": 900}, accept_downloads=True)
    pg = ctx.new_page()
    pg.errors = []
    pg.on("pageerror", lambda e: pg.errors.append(str(e)))
    pg.set_default_timeout(15000)
    yield pg
    ctx.close()
