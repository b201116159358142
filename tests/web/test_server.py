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
                                      "comment": "Start_PB = I0.0: start push button",
                                      "kind": "button"}
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


# ---------------------------------------------------------------- Host names
_WS = {"Connection": "Upgrade", "Upgrade": "websocket", "Sec-WebSocket-Version": "13",
       "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="}


@pytest.mark.parametrize("host", ["evil.example:{port}", "rebind.127.0.0.1.nip.io:{port}",
                                  "127.0.0.1:1", "127.0.0.2:{port}", "[::1]:{port}",
                                  "localhost.evil.example:{port}", "user@127.0.0.1:{port}",
                                  ""])
def test_a_foreign_host_name_is_refused_on_every_route(host: str) -> None:
    """DNS rebinding: a page of another site whose name resolves to this
    address sends its own name in Host; the page, the static files and
    the websocket all answer 403 to it."""
    async def body(client, panel):
        h = host.format(port=client.port)
        for path, extra in (("/", {}), ("/static/panel.js", {}), ("/ws", _WS),
                            ("/lesson/lesson.awl", {})):
            r = await client.get(path, headers={"Host": h, **extra})
            assert r.status == 403, (path, r.status)
            assert "not this server's name" in await r.text()
        assert not panel.session.clients
    _run(body)


@pytest.mark.parametrize("host", ["127.0.0.1:{port}", "localhost:{port}", "LOCALHOST:{port}"])
def test_the_servers_own_names_are_served(host: str) -> None:
    async def body(client, panel):
        h = host.format(port=client.port)
        r = await client.get("/", headers={"Host": h})
        assert r.status == 200
        ws = await client.ws_connect("/ws", headers={"Host": h, "Origin": f"http://{h}"})
        await _next(ws, "hello")
        await ws.close()
    _run(body)


def test_a_name_allowed_by_the_user_is_served() -> None:
    async def main():
        panel = Panel(PanelSession(load_sample()), hosts=["Panel.LAN"])
        client = await _client(panel)
        try:
            r = await client.get("/", headers={"Host": f"panel.lan:{client.port}"})
            assert r.status == 200
            r = await client.get("/", headers={"Host": f"other.lan:{client.port}"})
            assert r.status == 403
        finally:
            await client.close()
            panel.session.close()
    _in_thread(main)


# ---------------------------------------------------------------- hostile messages
@pytest.mark.parametrize("raw, message", [
    ("[" * 1000 + "]" * 1000, "deep at most"),
    ('{"type": "view", "block": "OB1", "networks": ' + "[" * 3000, "deep at most"),
    ('{"type": "unwatch", "spec": "' + "x" * 30000 + '"}', "message too long"),
])
def test_hostile_json_gets_an_error_and_the_connection_stays(raw: str, message: str) -> None:
    """A deeply nested message used to drop the connection with a
    RecursionError in the server; a message over 16 KiB used to close it."""
    async def body(client, panel):
        ws = await client.ws_connect("/ws")
        await _next(ws, "hello")
        await ws.send_str(raw)
        err = await _next(ws, "error")
        assert message in err["message"] and err["request"] is None
        await ws.send_json({"type": "step"})
        await _next(ws, "frame", lambda m: m["scans"] == 1)
        await ws.close()
    _run(body)


# ---------------------------------------------------------------- lessons
BROKEN = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1 // fine\nLD I0.0\n= Q0.0\n"
          "Network 2 // broken\nLD Q9999.9\n= Q0.1\nEND_ORGANIZATION_BLOCK\n")


def _course(tmp_path):
    """A course of two lessons: lesson 1 of examples/course and a copy of it
    whose program does not load."""
    import shutil

    from .conftest import REPO
    course = tmp_path / "course"
    good = course / "01-seal-in"
    shutil.copytree(REPO / "examples/course/01-seal-in", good)
    bad = course / "02-broken"
    shutil.copytree(good, bad)
    (bad / "lesson.awl").write_text(BROKEN)
    return good, bad


def _lesson_panel(folder) -> Panel:
    import argparse

    from plcrt.web.cli import build_panel
    args = argparse.Namespace(
        programs=[str(folder)], symbols=None, encoding=None, data=None, cpu=None, plant=None,
        auto_symbols=False, backend="python", max_file_mb=None, scan_ms=10.0, clock=None,
        no_breakpoints=False, host="127.0.0.1", allow_host=[])
    panel = build_panel(args)
    panel.watch_s = 0.05
    return panel


def _run_panel(panel: Panel, coro_fn) -> None:
    async def main():
        panel.session.start()
        client = await _client(panel)
        try:
            await coro_fn(client, panel)
        finally:
            await client.close()
            panel.session.close()
    _in_thread(main)


def test_a_lesson_that_does_not_load_is_switched_to_with_its_error(tmp_path) -> None:
    """The page shows the new lesson's text and no program (not the
    previous lesson's), and the error names the file, line and network."""
    good, bad = _course(tmp_path)

    async def body(client, panel):
        ws = await client.ws_connect("/ws")
        first = await _next(ws, "hello")
        assert first["lesson"]["id"] == "01-seal-in" and first["load_error"] is None
        await ws.send_json({"type": "lesson", "id": "02-broken"})
        hello = await _next(ws, "hello")
        assert hello["lesson"]["id"] == "02-broken" and hello["lesson"]["doc"]
        assert [n for b in hello["blocks"] for n in b["networks"]] == []
        assert hello["inputs"] == [] and hello["outputs"] == []
        assert hello["files"] == [str(bad.resolve() / "lesson.awl")]
        (diag,) = hello["load_error"]["diagnostics"]
        assert diag["file"] == "02-broken/lesson.awl" and diag["line"] == 7
        assert diag["block"] == "OB1" and diag["network"] == 2
        err = await _next(ws, "error")
        assert err["request"] == "lesson"
        assert "02-broken/lesson.awl:7:4: error:" in err["message"]
        assert "[OB1 network 2]" in err["message"] and "Q9999.9" in err["message"]
        # the program is not there: commands say why instead of acting
        await ws.send_json({"type": "run"})
        err = await _next(ws, "error")
        assert "no program is loaded" in err["message"]
        await ws.send_json({"type": "lesson", "id": "01-seal-in"})
        back = await _next(ws, "hello")
        assert back["load_error"] is None and back["blocks"][0]["networks"]
        await ws.close()
    _run_panel(_lesson_panel(good), body)


def test_a_lesson_file_edited_on_disk_is_loaded_again(tmp_path) -> None:
    """The student edits lesson.awl: the page gets the new ladder without
    switching lessons; a broken edit gives the load error, its fix the
    program again, all in the same lesson."""
    good, _ = _course(tmp_path)
    awl = good / "lesson.awl"
    text = awl.read_text()

    def nets(hello):
        return [n["title"] for b in hello["blocks"] for n in b["networks"]]

    async def body(client, panel):
        ws = await client.ws_connect("/ws")
        first = await _next(ws, "hello")
        assert len(nets(first)) == 3
        extra = "Network 4 // Added by the student\nLD I0.0\n= Q0.3\nEND_ORGANIZATION_BLOCK"
        awl.write_text(text.replace("END_ORGANIZATION_BLOCK", extra))
        hello = await _next(ws, "hello")
        assert hello["lesson"]["id"] == "01-seal-in"
        assert nets(hello)[-1] == "Added by the student"
        assert "Q0.3" in [o["addr"] for o in hello["outputs"]]
        note = await _next(ws, "notice")
        assert "loaded again" in note["message"]
        awl.write_text(text.replace("LD     I0.0", "LD     I0.9"))
        broken = await _next(ws, "hello")
        assert broken["load_error"]["diagnostics"][0]["file"] == "01-seal-in/lesson.awl"
        assert broken["lesson"]["id"] == "01-seal-in"
        awl.write_text(text)
        fixed = await _next(ws, "hello")
        assert fixed["load_error"] is None and len(nets(fixed)) == 3
        await ws.close()
    _run_panel(_lesson_panel(good), body)


def test_the_lesson_text_links_open_the_lessons_own_files_only() -> None:
    from .conftest import REPO

    async def body(client, panel):
        r = await client.get("/lesson/lesson.awl")
        assert r.status == 200 and r.headers["Content-Type"].startswith("text/plain")
        assert "Network 1" in await r.text()
        for name in ("..%2Flesson.awl", "missing.awl", "__pycache__", ".hidden.awl"):
            r = await client.get(f"/lesson/{name}")
            assert r.status == 404, name
    _run_panel(_lesson_panel(REPO / "examples/course/01-seal-in"), body)


def test_serve_passes_its_host_names_to_the_panel() -> None:
    """--host NAME and each --allow-host NAME are names the page may be
    opened under; an address given to --host is no name."""
    import argparse

    from plcrt.web.cli import build_panel
    from .conftest import REPO

    def hosts(host: str, allow: list[str]) -> frozenset[str]:
        args = argparse.Namespace(
            programs=[str(REPO / "examples/course/01-seal-in")], symbols=None, encoding=None,
            data=None, cpu=None, plant=None, auto_symbols=False, backend="python",
            max_file_mb=None, scan_ms=10.0, clock=None, no_breakpoints=False, host=host,
            allow_host=allow)
        panel = build_panel(args)
        panel.session.close()
        return panel.hosts

    assert hosts("0.0.0.0", []) == frozenset()
    assert hosts("::", ["Panel.LAN"]) == {"panel.lan"}
    assert hosts("teacher-pc", ["[fd00::1]"]) == {"teacher-pc", "fd00::1"}
