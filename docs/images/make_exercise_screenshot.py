"""Take the README's picture of a machine exercise: ``python docs/images/make_exercise_screenshot.py``.

Serves the course's conveyor exercise (``examples/course/08-conveyor-sort``)
as ``plcrt serve examples/course/08-conveyor-sort`` does, on a free
loopback port; presses the conveyor's start button, runs the starter
program in the page until parts are on the belt, stops, and saves
``docs/images/exercise.png``: the exercise's goal text, its program and the
conveyor.  Drives Debian's Chromium through Playwright (as tests/web does);
needs ``apt-get install chromium`` and the test extra.
"""

from __future__ import annotations

import argparse
import sys

from shoot import shoot   # first: it puts the checkout on sys.path

from plcrt.web.cli import build_panel

FOLDER = "examples/course/08-conveyor-sort"


def drive(page) -> None:
    page.wait_for_selector("[data-machine=conveyor] svg")
    page.click("#edit-toggle")
    page.wait_for_function("() => window.plcrtEditor.loaded")
    page.select_option("#speed", "10")
    page.click("[data-machine=conveyor] button[data-button=start]")
    page.click("#run")
    page.wait_for_function("() => window.plcrtPanel.frame.t > 7.3", timeout=60000)
    page.click("#stop")
    # the page names the lesson by its absolute path, this clone's: the
    # picture shows it as the README's command gives it
    page.evaluate(f"() => {{ document.getElementById('files').textContent = "
                  f"'{FOLDER}/lesson.awl'; window.scrollTo(0, 0); }}")
    page.wait_for_timeout(500)


def main() -> int:
    args = argparse.Namespace(
        programs=[FOLDER], symbols=None, encoding=None, data=None, cpu=None, plant=None,
        auto_symbols=False, backend="python", max_file_mb=None, scan_ms=10.0, clock=None,
        no_breakpoints=False, host="127.0.0.1", allow_host=[])
    return shoot(build_panel(args), "exercise.png", 1450, drive)


if __name__ == "__main__":
    sys.exit(main())
