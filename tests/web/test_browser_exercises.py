"""A machine exercise graded in a real headless browser: *Check my
program* on the conveyor exercise lists each requirement; the starter
fails the one it misses and the page says why, the reference solution
gets every requirement green."""

from __future__ import annotations

import shutil

from .conftest import REPO
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
