"""A machine exercise graded in a real headless browser: *Check my
program* on the conveyor exercise lists each requirement; the starter
fails the one it misses and the page says why, the reference solution
gets every requirement green."""

from __future__ import annotations

import shutil

from .conftest import (REPO, editor_download, editor_download_refused, editor_end_of_line,
                       editor_no_errors, editor_text)
from .test_browser_lessons import lesson_panel, open_panel

COURSE = REPO / "examples/course"


def _check(page) -> None:
    page.click("#check")
    page.wait_for_selector("#check-results li[data-test]", timeout=120000)


def test_the_conveyor_exercise_is_graded_requirement_by_requirement(serve, page, tmp_path) -> None:
    folder = tmp_path / "course" / "08-conveyor-sort"
    shutil.copytree(COURSE / "08-conveyor-sort", folder)
    served = serve(panel=lesson_panel(folder, watch_s=0.2))
    open_panel(page, served)
    _check(page)
    failed = page.locator("#check-results li.failed[data-test]")
    assert failed.count() == 1
    assert failed.get_attribute("data-test") == "test_a_tall_part_goes_to_the_diverted_bin"
    text = failed.inner_text()
    assert "A tall part goes to the diverted bin, never straight on." in text
    assert "4 tall part(s) went straight on" in text and "'straight_tall': 4" in text
    assert "Pressing start runs the belt" in page.locator("#check-results li.passed").first.inner_text()
    # the first failure's scan trace is under the list
    assert "PLC trace" in page.locator("#check-output").text_content()

    # the student's program becomes the reference solution: every requirement green
    (folder / "lesson.awl").write_bytes((COURSE / "solutions" / "08.awl").read_bytes())
    page.wait_for_function(
        "() => (window.plcrtPanel.hello && JSON.stringify(window.plcrtPanel.hello)"
        ".includes('Exercise 8, a solution')) || document.body.innerText.includes('Exercise 8, a solution')",
        timeout=30000)
    _check(page)
    page.wait_for_selector("#check-results li.passed >> text=5 passed, 0 failed", timeout=120000)
    assert page.locator("#check-results li.passed[data-test]").count() == 5
    assert page.locator("#check-results li.failed").count() == 0


def test_a_student_edits_the_conveyor_exercise_downloads_it_and_the_machine_reacts(
        serve, page, tmp_path) -> None:
    """The whole flow in the page: the exercise opens with its goal text, its
    program and the conveyor; a network typed with an error is marked at its
    line and refused by Download; fixed and downloaded, it runs: start on
    the machine runs the belt, the parts move, and the new network's output
    (the diverter, which the starter never drives) reaches the machine."""
    folder = tmp_path / "course" / "08-conveyor-sort"
    shutil.copytree(COURSE / "08-conveyor-sort", folder)
    served = serve(panel=lesson_panel(folder, watch_s=0.2))
    open_panel(page, served)
    page.wait_for_selector("[data-machine=conveyor] svg.machine-svg")
    assert "sort the parts" in page.locator("body").inner_text()
    page.click("#edit-toggle")
    page.wait_for_function("() => window.plcrtEditor.loaded")
    lines = editor_text(page).splitlines()
    assert lines[19] == "=      Q0.1" and lines[20] == "END_ORGANIZATION_BLOCK"
    # a fourth network typed after line 20, with an error on line 23 (Q0.9)
    editor_end_of_line(page, 20)
    page.keyboard.press("Enter")
    page.keyboard.type("Network 4 // divert while running\nLD     M0.0\n=      Q0.9")
    assert editor_text(page).splitlines()[22] == "=      Q0.9"
    page.wait_for_selector(".cm-lintRange-error")
    assert page.locator("#editor-diags li.error").first.text_content().startswith("line 23:")
    assert "Q0.9" in page.locator(".cm-lintRange-error").first.text_content()
    editor_download_refused(page)
    assert page.locator("#networks .net").count() == 3
    # fixed: Q0.9 -> Q0.2, the diverter
    editor_end_of_line(page, 23)
    page.keyboard.press("Backspace")
    page.keyboard.type("2")
    editor_no_errors(page)
    assert page.locator(".cm-lintRange-error").count() == 0
    editor_download(page)
    page.wait_for_function("() => document.querySelectorAll('#networks .net').length === 4")
    # the machine reacts: start on the drawing, Run, the belt runs and the
    # diverter follows the new network
    m = "window.plcrtPanel.frame.machines[0]"
    page.wait_for_function(f"() => {m}.outputs.motor === 0 && {m}.outputs.divert === 0")
    page.click("[data-machine=conveyor] button[data-button=start]")
    page.click("#run")
    page.wait_for_function(f"() => {m}.outputs.motor === 1 && {m}.outputs.divert === 1 && "
                           "window.plcrtPanel.frame.io['Q0.2'] === 1")
    page.wait_for_selector("[data-machine=conveyor] rect[data-part]")
    part = page.locator("[data-machine=conveyor] rect[data-part]").first
    pid, x0 = part.get_attribute("data-part"), float(part.get_attribute("x"))
    page.wait_for_function(
        "([id, x0]) => { const r = document.querySelector("
        "'[data-machine=conveyor] rect[data-part=\"' + id + '\"]');"
        " return r && parseFloat(r.getAttribute('x')) > x0 + 5; }", arg=[pid, x0])
    assert page.errors == []
