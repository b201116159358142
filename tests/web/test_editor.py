"""The editor's endpoints (plcrt/web/editroutes.py over plcrt/web/editor.py):
the check of a text with its lines, downloads in STOP and in RUN (and
their refusals), the save to the file, and the origin and size limits."""

from __future__ import annotations

import asyncio
import time
from pathlib import Path

import pytest

import plcrt
from plcrt.web.editor import MAX_TEXT, ProgramSource
from plcrt.web.server import Panel
from plcrt.web.session import PanelSession

from .test_server import _client, _in_thread

GOOD = """\
ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1 // Selbsthaltung für den Motor
LD     I0.0
O      Q0.0
AN     I0.1
=      Q0.0
Network 2
LD     SM0.1
MOVW   7, VW10
END_ORGANIZATION_BLOCK
"""

#: Q0.1 follows I0.0 (the old program drives Q0.0); VW10 counts scans
NEW = """\
ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     I0.0
=      Q0.1
Network 2
LD     SM0.1
MOVW   100, VW10
Network 3
LD     SM0.0
INCW   VW10
END_ORGANIZATION_BLOCK
"""

BAD = GOOD.replace("AN     I0.1", "AN     I0.9")   # line 6: bit number 0..7

ORIGIN = {"Content-Type": "application/json"}


def _panel(path: Path) -> Panel:
    source = ProgramSource(path, (), {"backend": "python"})
    return Panel(PanelSession(plcrt.load(path, backend="python")),
                 source_of=lambda les: source)


def _run(tmp_path: Path, body, text: str = GOOD, crlf: bool = True) -> None:
    path = tmp_path / "prog.awl"
    path.write_bytes(text.replace("\n", "\r\n" if crlf else "\n").encode("cp1252"))

    async def main():
        panel = _panel(path)
        panel.session.start()
        client = await _client(panel)
        try:
            await body(client, panel, path)
        finally:
            await client.close()
            panel.session.close()
    _in_thread(main)


async def _post(client, route: str, **body):
    r = await client.post(route, json=body)
    return r.status, await r.json()


async def _until(pred, timeout: float = 10.0) -> None:
    end = time.monotonic() + timeout
    while not pred():
        assert time.monotonic() < end, "timed out"
        await asyncio.sleep(0.02)


def test_check_gives_each_error_at_its_line_and_column(tmp_path) -> None:
    async def body(client, panel, path):
        status, ans = await _post(client, "/editor/check", text=BAD)
        assert status == 200 and ans["ok"] is False
        [d] = [d for d in ans["diagnostics"] if d["severity"] == "error"]
        assert (d["line"], d["column"]) == (6, 8)
        assert "I0.9" in d["message"] and d["where"] == "OB1 network 1"
        status, ans = await _post(client, "/editor/check", text=GOOD)
        assert ans == {"ok": True, "diagnostics": [], "more": None}
    _run(tmp_path, body)


def test_source_gives_the_files_text_decoded_and_a_stamp(tmp_path) -> None:
    async def body(client, panel, path):
        r = await client.get("/editor/source")
        ans = await r.json()
        assert ans["text"].replace("\r\n", "\n") == GOOD   # decoded from CP1252
        assert ans["name"] == "prog.awl" and ans["writable"] is True
        r = await client.get("/editor/stamp")
        assert (await r.json())["stamp"] == ans["stamp"]
    _run(tmp_path, body)


def test_words_lists_the_registrys_instructions_with_summary_and_operands(tmp_path) -> None:
    async def body(client, panel, path):
        ans = await (await client.get("/editor/words")).json()
        ton = {i["m"]: i for i in ans["instructions"]}["TON"]
        assert ton["family"] == "timer" and "on-delay" in ton["summary"]
        assert ton["operands"][0].startswith("timer")
    _run(tmp_path, body)


def test_a_program_with_an_error_is_never_downloaded(tmp_path) -> None:
    async def body(client, panel, path):
        old = panel.session
        status, ans = await _post(client, "/editor/download", text=BAD)
        assert ans["ok"] is False and "errors" in ans["message"]
        assert ans["diagnostics"][0]["line"] == 6
        assert panel.session is old
    _run(tmp_path, body)


def test_download_in_stop_starts_the_new_program_from_power_up(tmp_path) -> None:
    async def body(client, panel, path):
        old = panel.session
        old.plc.write("VW20", 55)
        old.plc.force("I0.0", 1)
        status, ans = await _post(client, "/editor/download", text=NEW)
        assert (status, ans["ok"], ans["mode"]) == (200, True, "stop")
        new = panel.session
        assert new is not old and new.state == "stopped"
        assert new.plc.read("VW20") == 0            # power-up memory
        assert new.plc.forces == {"I0.0": 1}         # forces stay, as in the CPU
        new.submit(None, {"type": "step", "scans": 2})
        await _until(lambda: new.plc.scans == 2)
        assert new.plc.read("Q0.1") == 1 and new.plc.read("Q0.0") == 0
        assert new.plc.read("VW10") == 102           # first scan: 100 + 1, then +1
        assert path.read_bytes().decode("cp1252").replace("\r\n", "\n") == GOOD  # not saved
    _run(tmp_path, body)


def test_download_in_run_keeps_the_memory_and_is_no_first_scan(tmp_path) -> None:
    async def body(client, panel, path):
        old = panel.session
        old.plc.write("I0.0", 1)
        old.submit(None, {"type": "run"})
        await _until(lambda: old.plc.scans > 3)
        status, ans = await _post(client, "/editor/download", text=NEW)
        assert (ans["ok"], ans["mode"]) == (True, "run"), ans
        new = panel.session
        assert new.state == "running"
        await _until(lambda: new.plc.scans > old.plc.scans + 2)
        new.submit(None, {"type": "stop"})
        await _until(lambda: new.state == "stopped")
        # Q0.0 was sealed in by the old program and nothing drives it now:
        # it keeps its state; VW10 went on from 7 (no first scan: no MOVW 100)
        assert new.plc.read("Q0.0") == 1 and new.plc.read("Q0.1") == 1
        v = new.plc.read("VW10")
        assert 7 < v < 100 and v - 7 == new.plc.scans - old.plc.scans
    _run(tmp_path, body)


def test_download_in_run_is_refused_when_state_lives_outside_memory(tmp_path) -> None:
    with_irq = NEW.replace("MOVW   100, VW10", "ATCH   INT0, 10\nENI").replace(
        "END_ORGANIZATION_BLOCK",
        "END_ORGANIZATION_BLOCK\nINTERRUPT_BLOCK INT_0:INT0\nBEGIN\nNetwork 1\n"
        "LD SM0.0\nINCW VW30\nEND_INTERRUPT_BLOCK")

    async def body(client, panel, path):
        old = panel.session
        old.submit(None, {"type": "run"})
        await _until(lambda: old.plc.scans > 1)
        status, ans = await _post(client, "/editor/download", text=with_irq, mode="run")
        assert ans["ok"] is False
        assert "ATCH" in ans["message"] and "download in STOP" in ans["message"]
        assert panel.session is old and old.state == "running"
        status, ans = await _post(client, "/editor/download", text=with_irq, mode="stop")
        assert (ans["ok"], ans["mode"]) == (True, "stop")
    _run(tmp_path, body)


def test_save_writes_the_file_in_its_encoding_and_line_ends(tmp_path) -> None:
    async def body(client, panel, path):
        src = await (await client.get("/editor/source")).json()
        text = NEW.replace("Network 3", "Network 3 // Zähler")
        status, ans = await _post(client, "/editor/save", text=text, stamp=src["stamp"])
        assert ans["ok"] is True and ans["stamp"] != src["stamp"], ans
        assert path.read_bytes() == text.replace("\n", "\r\n").encode("cp1252")
        # the old stamp is stale now: a second save from it is refused
        status, ans = await _post(client, "/editor/save", text=GOOD, stamp=src["stamp"])
        assert status == 400 and "changed on disk" in ans["message"]
        status, ans = await _post(client, "/editor/save", text="// 漢字\n" + GOOD)
        assert status == 400 and "CP1252" in ans["message"]
        assert path.read_bytes() == text.replace("\n", "\r\n").encode("cp1252")
    _run(tmp_path, body)


def test_save_refuses_a_read_only_file(tmp_path) -> None:
    async def body(client, panel, path):
        path.chmod(0o444)
        try:
            status, ans = await _post(client, "/editor/save", text=NEW)
        finally:
            path.chmod(0o644)
        assert status == 400 and "read-only" in ans["message"]
        assert path.read_bytes().decode("cp1252").replace("\r\n", "\n") == GOOD
    import os
    if os.geteuid() == 0:
        pytest.skip("root writes read-only files")
    _run(tmp_path, body)


@pytest.mark.parametrize("route", ["/editor/check", "/editor/download", "/editor/save"])
def test_another_origin_is_refused(tmp_path, route) -> None:
    async def body(client, panel, path):
        old = panel.session
        r = await client.post(route, json={"text": NEW},
                              headers={"Origin": "http://evil.example"})
        assert r.status == 403
        r = await client.get("/editor/source", headers={"Origin": "http://evil.example"})
        assert r.status == 403
        assert panel.session is old
        assert path.read_bytes().decode("cp1252").replace("\r\n", "\n") == GOOD
    _run(tmp_path, body)


@pytest.mark.parametrize("data, ctype, message", [
    ("text=x", "application/x-www-form-urlencoded", "application/json"),
    ("[1]", "application/json", "JSON object"),
    ('{"text": 5}', "application/json", "text must be"),
    ('{"text": "x", "evil": 1}', "application/json", "unknown field"),
    ("[" * 100000, "application/json", "not JSON"),
])
def test_bad_requests_get_a_message(tmp_path, data, ctype, message) -> None:
    async def body(client, panel, path):
        r = await client.post("/editor/check", data=data, headers={"Content-Type": ctype})
        ans = await r.json()
        assert r.status == 400 and message in ans["message"]
    _run(tmp_path, body)


def test_a_text_over_the_limit_is_refused_unread(tmp_path) -> None:
    async def body(client, panel, path):
        status, ans = await _post(client, "/editor/check", text="x" * (MAX_TEXT + 1))
        assert status == 400 and str(MAX_TEXT) in ans["message"]
        r = await client.post("/editor/check", data=b"{" + b" " * (7 * MAX_TEXT) + b"}",
                              headers={"Content-Type": "application/json"})
        assert r.status == 400 and "larger than" in (await r.json())["message"]
    _run(tmp_path, body)


# ---------------------------------------------------------------- lessons
def _lesson(tmp_path: Path, program: str | None = None) -> tuple[Path, Panel]:
    import shutil

    from .test_browser_lessons import COURSE, lesson_panel
    folder = tmp_path / "course" / "01-seal-in"
    shutil.copytree(COURSE / "01-seal-in", folder)
    if program is not None:
        (folder / "lesson.awl").write_text(program)
    return folder, lesson_panel(folder, watch_s=0.05)


def _run_lesson(panel: Panel, body) -> None:
    async def main():
        client = await _client(panel)   # starts the lesson watcher
        panel.session.start()
        try:
            await body(client, panel)
        finally:
            await client.close()
            panel.session.close()
    _in_thread(main)


def test_a_lessons_editor_edits_lesson_awl_and_saving_does_not_reload_it(tmp_path) -> None:
    folder, panel = _lesson(tmp_path)

    async def body(client, panel):
        src = await (await client.get("/editor/source")).json()
        assert src["name"] == "lesson.awl"
        assert src["text"] == (folder / "lesson.awl").read_text()
        before = panel.session
        before.plc.write("VW100", 1234)
        status, ans = await _post(client, "/editor/save", text=NEW, stamp=src["stamp"])
        assert ans["ok"] is True
        assert (folder / "lesson.awl").read_bytes() == NEW.encode()   # LF as it was
        await asyncio.sleep(0.5)          # ten looks of the watcher
        # saving is not downloading: the PLC runs what it ran, with its memory
        assert panel.session is before and before.plc.read("VW100") == 1234
        # a change by another program reloads the lesson (from power-up)
        (folder / "lesson.awl").write_text(GOOD)
        await _until(lambda: panel.session is not before)
        ans = await (await client.get("/editor/source")).json()
        assert ans["text"] == GOOD and ans["stamp"] != src["stamp"]
    _run_lesson(panel, body)


def test_a_lesson_that_does_not_load_is_mended_by_a_download(tmp_path) -> None:
    folder, panel = _lesson(tmp_path)

    async def body(client, panel):
        (folder / "lesson.awl").write_text(BAD)
        await _until(lambda: panel.load_error is not None)
        status, ans = await _post(client, "/editor/check",
                                  text=(folder / "lesson.awl").read_text())
        assert [d["line"] for d in ans["diagnostics"] if d["severity"] == "error"] == [6]
        status, ans = await _post(client, "/editor/download", text=GOOD)
        assert (ans["ok"], ans["mode"]) == (True, "stop")
        assert panel.load_error is None
        hello = panel.hello()
        assert hello["files"] == [str(folder / "lesson.awl")] and hello["editable"] is True
        assert [n["number"] for n in hello["blocks"][0]["networks"]] == [1, 2]
    _run_lesson(panel, body)


def test_a_project_file_is_not_edited_as_text(tmp_path) -> None:
    import argparse

    from plcrt.web.cli import build_panel
    prog = tmp_path / "prog.awl"
    prog.write_text(GOOD)
    args = argparse.Namespace(
        programs=[str(prog)], symbols=None, encoding=None, data=None, cpu=None, plant=None,
        auto_symbols=False, backend="python", max_file_mb=None, scan_ms=10.0, clock=None,
        no_breakpoints=False, host="127.0.0.1", allow_host=[])
    panel = build_panel(args)
    src = panel.source()
    assert src is not None and src.path == prog and src.options["backend"] == "python"
    assert panel.hello()["editable"] is True
    # the same options naming a project file: nothing to edit as text
    args.programs = [str(tmp_path / "project.mwp")]
    assert panel.source() is None and panel.hello()["editable"] is False


def test_save_refuses_a_file_it_may_not_write(tmp_path) -> None:
    from plcrt.errors import PlcConfigError
    from plcrt.web.editor import save

    class ReadOnly(ProgramSource):
        def writable(self) -> bool:   # as os.access says of a file of another user
            return False

    path = tmp_path / "prog.awl"
    path.write_text(GOOD)
    with pytest.raises(PlcConfigError, match="read-only: nothing was saved"):
        save(ReadOnly(path), NEW, None)
    assert path.read_text() == GOOD


def test_a_download_is_given_up_when_the_plc_reaches_no_scan_boundary(tmp_path,
                                                                         monkeypatch) -> None:
    from plcrt.web import editor
    monkeypatch.setattr(editor, "SWAP_TIMEOUT", 0.2)
    path = tmp_path / "prog.awl"
    path.write_text(GOOD)

    async def main():
        panel = _panel(path)      # its runner thread is not started: no scan boundary
        client = await _client(panel)
        try:
            old = panel.session
            old.control.run(old.plc)
            status, ans = await _post(client, "/editor/download", text=NEW)
            assert status == 400 and "did not reach a scan boundary" in ans["message"]
            assert panel.session is old
            old.tick(wait=False)   # the job runs late: it changes nothing
            assert old.state == "running" and old.plc.read("VW10") == 7
        finally:
            await client.close()
            panel.session.close()
    _in_thread(main)
