"""The aiohttp application: the page, the websocket's origin check, hello
and frames, bad messages answered with errors, several clients at once."""

from __future__ import annotations

import asyncio
import json

import pytest
from aiohttp.test_utils import TestClient, TestServer

from plcrt.web.server import Panel, make_app
from plcrt.web.session import PanelSession

from .conftest import load_sample


async def _client(panel: Panel) -> TestClient:
    client = TestClient(TestServer(make_app(panel)))
    await client.start_server()
    return client


async def _next(ws, kind: str, pred=lambda m: True, timeout: float = 10.0) -> dict:
    async def find() -> dict:
        while True:
            m = json.loads((await ws.receive()).data)
            if m["type"] == kind and pred(m):
                return m
    return await asyncio.wait_for(find(), timeout)


def _run(coro_fn):
    async def main():
        panel = Panel(PanelSession(load_sample()))
        panel.session.start()
        client = await _client(panel)
        try:
            await coro_fn(client, panel)
        finally:
            await client.close()
            panel.session.close()
    _in_thread(main)


def _in_thread(main) -> None:
    """``asyncio.run`` in a thread of its own: the browser tests' sync
    Playwright keeps an event loop running in this one."""
    import threading
    errors: list[BaseException] = []

    def target() -> None:
        try:
            asyncio.run(main())
        except BaseException as e:  # noqa: BLE001 - re-raised below
            errors.append(e)

    t = threading.Thread(target=target)
    t.start()
    t.join(120)
    if errors:
        raise errors[0]


def test_index_and_static_files_are_served_with_a_strict_policy() -> None:
    async def body(client, panel):
        r = await client.get("/")
        assert r.status == 200 and "panel.js" in await r.text()
        assert "script-src 'self'" in r.headers["Content-Security-Policy"]
        r = await client.get("/static/panel.js")
        assert r.status == 200
        r = await client.get("/static/../server.py")
        assert r.status in (403, 404)
    _run(body)


@pytest.mark.parametrize("origin", ["http://evil.example", "http://127.0.0.1:1", "null",
                                    "file://"])
def test_websocket_from_another_origin_is_refused(origin: str) -> None:
    async def body(client, panel):
        r = await client.get("/ws", headers={"Origin": origin, "Connection": "Upgrade",
                                             "Upgrade": "websocket",
                                             "Sec-WebSocket-Version": "13",
                                             "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="})
        assert r.status == 403
        assert not panel.session.clients
    _run(body)


def test_own_origin_gets_hello_then_frames() -> None:
    async def body(client, panel):
        host = f"{client.host}:{client.port}"
        ws = await client.ws_connect("/ws", headers={"Origin": f"http://{host}"})
        hello = await _next(ws, "hello")
        assert [b["id"] for b in hello["blocks"]] == ["OB1"]
        assert hello["inputs"][0] == {"addr": "I0.0", "name": "Start_PB:I0.0",
                                      "comment": "Start_PB = I0.0: start push button"}
        assert hello["blocks"][0]["networks"][0]["svg"].startswith("<svg")
        await ws.send_json({"type": "speed", "mode": "max"})
        await ws.send_json({"type": "set", "addr": "I0.0", "value": "1"})
        await ws.send_json({"type": "step", "scans": 3})
        f = await _next(ws, "frame", lambda m: m["scans"] == 3 and m["run"] == "stopped")
        assert f["io"]["Q0.0"] == 1 and "OB1/1" in f["nets"]
        await ws.close()
    _run(body)


@pytest.mark.parametrize("raw, message", [
    ("not json", "JSON object"),
    ('{"type": "explode"}', "unknown message type"),
    ('{"type": "step", "scans": -1}', "between 1"),
])
def test_bad_messages_get_an_error_and_the_connection_stays(raw: str, message: str) -> None:
    async def body(client, panel):
        ws = await client.ws_connect("/ws")
        await _next(ws, "hello")
        await ws.send_str(raw)
        err = await _next(ws, "error")
        assert message in err["message"]
        await ws.send_json({"type": "set", "addr": "VW99999", "value": "1", "id": 4})
        err = await _next(ws, "error")
        assert err["id"] == 4 and err["request"] == "set"
        await ws.send_json({"type": "step"})
        await _next(ws, "frame", lambda m: m["scans"] == 1)
        await ws.send_bytes(b"\x00\x01")
        await _next(ws, "error")
        await ws.close()
    _run(body)


def test_several_clients_watch_the_same_plc() -> None:
    async def body(client, panel):
        a = await client.ws_connect("/ws")
        b = await client.ws_connect("/ws")
        await _next(a, "hello")
        await _next(b, "hello")
        await a.send_json({"type": "force", "addr": "VW0", "value": "42"})
        await a.send_json({"type": "step", "scans": 2})
        fb = await _next(b, "frame", lambda m: m["scans"] == 2 and m["forces"])
        assert fb["forces"] == {"VW0": 42}
        await a.close()
        await b.send_json({"type": "step"})
        await _next(b, "frame", lambda m: m["scans"] == 3)
        await b.close()
    _run(body)


def test_check_without_a_lesson_is_an_error() -> None:
    async def body(client, panel):
        ws = await client.ws_connect("/ws")
        await _next(ws, "hello")
        await ws.send_json({"type": "check"})
        err = await _next(ws, "error")
        assert "no lesson" in err["message"]
        await ws.close()
    _run(body)


def test_serve_reports_a_bad_program_without_a_traceback(tmp_path, capsys) -> None:
    from plcrt.cli import main
    bad = tmp_path / "bad.awl"
    bad.write_text("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD Q9999.9\n"
                   "END_ORGANIZATION_BLOCK\n")
    assert main(["serve", str(bad), "--port", "0"]) == 1
    err = capsys.readouterr().err
    assert "bit number must be 0..7" in err and "Traceback" not in err
    assert main(["serve", str(tmp_path / "missing.awl")]) == 1
    assert "cannot read file" in capsys.readouterr().err


def test_serve_builds_a_lesson_panel_from_a_lesson_folder() -> None:
    import argparse

    from plcrt.web.cli import build_panel
    from .conftest import REPO
    args = argparse.Namespace(
        programs=[str(REPO / "examples/course/05-jog-and-position")], symbols=None,
        encoding=None, data=None, cpu=None, plant=None, auto_symbols=False, backend=None,
        max_file_mb=None, scan_ms=10.0, clock=None, no_breakpoints=False)
    panel = build_panel(args)
    hello = panel.hello()
    assert hello["lesson"]["id"] == "05-jog-and-position" and len(hello["lessons"]) >= 6
    assert hello["axes"][0]["limit_pos"] == 60000 and hello["breakable"] is True
