"""The STL editor in a real headless browser: a typed error marked at its
line, fixed, downloaded, and the PLC running the new program; completion
and hover help; Save writing the file; a file changed on disk loaded
again (asking first when the page holds edits); untrusted text inert; a
page of another origin refused."""

from __future__ import annotations

import time

import plcrt
from plcrt.web.editor import ProgramSource
from plcrt.web.server import Panel
from plcrt.web.session import PanelSession

from .conftest import (editor_download, editor_download_refused, editor_end_of_line,
                       editor_no_errors, editor_text, posts_from_another_origin)

PROGRAM = """\
ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1 // <img src=x onerror="window.pwned=1">
LD     I0.0
=      Q0.0
END_ORGANIZATION_BLOCK
"""

SYMBOLS = "Start\tI0.0\tstart switch\nLamp\tQ0.1\tthe <b>new</b> lamp\n"


def _panel(tmp_path) -> tuple[Panel, object]:
    path = tmp_path / "prog.awl"
    path.write_text(PROGRAM)
    sym = tmp_path / "symbols.txt"
    sym.write_text(SYMBOLS)
    source = ProgramSource(path, (), {"backend": "python", "symbols": sym})
    plc = plcrt.load(path, symbols=sym, backend="python")
    return Panel(PanelSession(plc), source_of=lambda les: source), path


def _open_editor(page, served) -> None:
    page.goto(served.url)
    page.wait_for_function("() => window.plcrtPanel.frame !== null")
    page.click("#edit-toggle")
    page.wait_for_function("() => window.plcrtEditor.loaded")


def test_type_an_error_see_it_fix_it_download_and_run(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    _open_editor(page, served)
    assert "Network 1" in editor_text(page)
    # a second network typed with the keyboard, with an error on line 6
    editor_end_of_line(page, 5)
    page.keyboard.press("Enter")
    page.keyboard.type("Network 2\nLD     Start\n=      Q0.9")
    assert editor_text(page).splitlines()[7] == "=      Q0.9"
    page.wait_for_selector(".cm-lintRange-error")
    first = page.locator("#editor-diags li.error").first
    assert first.text_content().startswith("line 8:8: error:")
    assert "Q0.9" in page.locator(".cm-lintRange-error").first.text_content()
    assert page.locator(".cm-gutter-lint .cm-lint-marker-error").count() == 1
    # a download with the error is refused: the ladder keeps one network
    editor_download_refused(page)
    assert page.locator("#networks .net").count() == 1
    # fix it: Q0.9 -> Q0.1
    editor_end_of_line(page, 8)
    page.keyboard.press("Backspace")
    page.keyboard.type("1")
    editor_no_errors(page)
    assert page.locator(".cm-lintRange-error").count() == 0
    assert editor_download(page).startswith("downloaded in STOP")
    # the ladder shows the new program; running it, I0.0 lights Q0.1
    page.wait_for_function("() => document.querySelectorAll('#networks .net').length === 2")
    page.click("#run")
    page.locator('[data-input="I0.0"]').click()
    page.wait_for_function("() => window.plcrtPanel.frame.io['Q0.1'] === 1")
    assert page.evaluate("() => window.plcrtPanel.frame.io['Q0.0']") == 1
    assert panel.session.plc.read("Q0.1") == 1
    # program and symbol text stay text
    assert page.evaluate("() => window.pwned") is None
    assert page.locator("#editor img, #editor b").count() == 0
    assert page.errors == []


def test_completion_and_hover_help_come_from_the_registry_and_symbols(serve, page,
                                                                      tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    _open_editor(page, served)
    editor_end_of_line(page, 5)
    page.keyboard.press("Enter")
    page.keyboard.type("TO")
    page.wait_for_selector(".cm-tooltip-autocomplete")
    labels = page.locator(".cm-tooltip-autocomplete li").all_text_contents()
    assert any(t.startswith("TON") for t in labels) and any(t.startswith("TOF") for t in labels)
    page.keyboard.press("Escape")
    page.keyboard.type("N    T37, 10\nLD     La")
    page.wait_for_selector(".cm-tooltip-autocomplete")
    labels = page.locator(".cm-tooltip-autocomplete li").all_text_contents()
    assert any(t.startswith("Lamp") for t in labels)
    page.keyboard.press("Escape")
    page.keyboard.type("mp\nA      T3")   # an address the text uses
    page.wait_for_selector(".cm-tooltip-autocomplete")
    assert "T37" in page.locator(".cm-tooltip-autocomplete li").all_text_contents()
    page.keyboard.press("Escape")
    # hover over TON: its summary and operands
    box = page.locator(".cm-line", has_text="TON").bounding_box()
    page.mouse.move(box["x"] + 8, box["y"] + box["height"] / 2)
    help_ = page.wait_for_selector(".stl-help")
    assert "on-delay" in help_.text_content() and "timer (T0..T255)" in help_.text_content()
    assert page.locator(".stl-help b").count() == 0
    assert page.errors == []


def test_save_writes_the_file(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    _open_editor(page, served)
    editor_end_of_line(page, 5)
    page.keyboard.type("\nNetwork 2\nLD     I0.1\n=      Q0.2")
    assert page.locator("#editor-name.dirty").count() == 1
    page.click("#editor-save")
    page.wait_for_function("() => document.querySelector('#editor-status')"
                           ".textContent === 'saved prog.awl'")
    assert path.read_text().replace("\r\n", "\n") == PROGRAM.replace(
        "=      Q0.0\n", "=      Q0.0\nNetwork 2\nLD     I0.1\n=      Q0.2\n")
    assert page.locator("#editor-name.dirty").count() == 0


def test_a_file_changed_on_disk_is_loaded_again(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    _open_editor(page, served)
    # no edits in the page: loaded without asking
    path.write_text(PROGRAM.replace("Q0.0", "Q0.3"))
    page.wait_for_function("() => window.plcrtEditor.view.state.doc.toString()"
                           ".includes('Q0.3')", timeout=10000)
    # edits in the page: asked first; declining keeps them
    asked: list[str] = []

    def answer(dialog, accept: bool) -> None:
        asked.append(dialog.message)
        dialog.accept() if accept else dialog.dismiss()

    page.once("dialog", lambda d: answer(d, False))
    editor_end_of_line(page, 5)
    page.keyboard.type(" // mine")
    time.sleep(0.05)
    path.write_text(PROGRAM.replace("Q0.0", "Q0.4"))
    page.wait_for_function("() => document.querySelector('#editor-status')"
                           ".textContent.startsWith('kept your edits')", timeout=10000)
    assert "changed on disk" in asked[0] and "// mine" in editor_text(page)
    # accepting loads the file
    page.once("dialog", lambda d: answer(d, True))
    path.write_text(PROGRAM.replace("Q0.0", "Q0.5"))
    page.wait_for_function("() => window.plcrtEditor.view.state.doc.toString()"
                           ".includes('Q0.5')", timeout=10000)
    assert len(asked) == 2 and "// mine" not in editor_text(page)


def test_a_page_of_another_origin_cannot_save_or_download(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    before = panel.session
    seen = posts_from_another_origin(page, served.url,
                                     ["editor/save", "editor/download", "editor/check"])
    assert seen == {"save": 403, "download": 403, "check": 403}
    assert path.read_text() == PROGRAM and panel.session is before


def test_stl_is_highlighted_by_kind(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    _open_editor(page, served)
    editor_end_of_line(page, 5)
    page.keyboard.type("\nNetwork 2\nLD     Start\nTON    T37, 16#0A\n")
    colors = page.evaluate("""() => {
        const root = document.querySelector('#editor-host').shadowRoot;
        const out = {};
        for (const s of root.querySelectorAll('.cm-line span')) {
          out[s.textContent] = getComputedStyle(s).color;
        }
        return out;
    }""")
    assert colors["LD"] == colors["TON"] == "rgb(13, 71, 161)"            # instructions
    assert colors["I0.0"] == colors["T37"] == "rgb(0, 105, 92)"          # addresses
    assert colors["16#0A"] == "rgb(230, 81, 0)"                          # constants
    assert colors["Start"] == "rgb(173, 20, 87)"                         # symbols
    assert colors["Network"] == colors["ORGANIZATION_BLOCK"] == "rgb(106, 27, 154)"
    assert colors['// <img src=x onerror="window.pwned=1">'] == "rgb(117, 117, 117)"


def test_a_download_while_running_goes_on_with_the_memory(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    _open_editor(page, served)
    page.click("#run")
    page.locator('[data-input="I0.0"]').click()
    page.wait_for_function("() => window.plcrtPanel.frame.io['Q0.0'] === 1")
    # Q0.0 -> Q0.1: the new program no longer drives Q0.0
    page.evaluate("() => { const v = window.plcrtEditor.view; const t = v.state.doc.toString(); "
                  "const i = t.indexOf('Q0.0'); "
                  "v.dispatch({changes: {from: i, to: i + 4, insert: 'Q0.1'}}); }")
    editor_no_errors(page)
    assert editor_download(page).startswith("downloaded in RUN")
    # still running; the switch stayed on; Q0.1 follows it, Q0.0 kept its state
    page.wait_for_function("() => window.plcrtPanel.frame.io['Q0.1'] === 1")
    assert page.evaluate("() => window.plcrtPanel.frame.run") == "running"
    assert page.evaluate("() => window.plcrtPanel.frame.io['I0.0']") == 1
    assert panel.session.plc.read("Q0.0") == 1   # no longer shown: the program does not use it
    assert page.errors == []


def test_switching_lessons_asks_before_unsaved_edits_go(serve, page, tmp_path) -> None:
    import shutil

    from .test_browser_lessons import COURSE, lesson_panel
    course = tmp_path / "course"
    for name in ("01-seal-in", "02-timers"):
        shutil.copytree(COURSE / name, course / name)
    served = serve(panel=lesson_panel(course / "01-seal-in"))
    _open_editor(page, served)
    assert editor_text(page) == (course / "01-seal-in" / "lesson.awl").read_text()
    editor_end_of_line(page, 1)
    page.keyboard.type(" // mine")
    page.once("dialog", lambda d: d.dismiss())
    page.select_option("#lessons", "02-timers")
    assert page.locator("#lessons").input_value() == "01-seal-in"
    assert "// mine" in editor_text(page)
    page.once("dialog", lambda d: d.accept())
    page.select_option("#lessons", "02-timers")
    page.wait_for_function("() => window.plcrtEditor.view.state.doc.toString()"
                           ".includes('T37')")
    assert editor_text(page) == (course / "02-timers" / "lesson.awl").read_text()
    assert "// mine" not in (course / "01-seal-in" / "lesson.awl").read_text()
