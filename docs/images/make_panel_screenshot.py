"""Take the README's picture of the panel: ``python docs/images/make_panel_screenshot.py``.

Serves lesson 5 of the course (jogging and an exact move on the EM253) with
``plcrt serve``'s application on a free loopback port, drives it in
Debian's Chromium through Playwright (as tests/web does), starts the
relative move, and saves ``docs/images/panel.png`` while the axis is on
its way.  Needs ``apt-get install chromium`` and the test extra.
"""

from __future__ import annotations

import sys
from pathlib import Path

from shoot import shoot   # first: it puts the checkout on sys.path

from plcrt.web import course
from plcrt.web.server import Panel
from plcrt.web.session import PanelSession
import plcrt


def drive(page) -> None:
    page.wait_for_function("() => window.plcrtPanel && window.plcrtPanel.frame")
    page.fill("#watch-spec", "VD300")
    page.click("#watch-add")
    page.fill("#watch-spec", "VD208")
    page.click("#watch-add")
    page.fill("#trend-signals", "M11.0 Q0.0")
    page.click("#trend-form button")
    page.click("#run")
    go = page.locator('[data-input="I0.2"]')
    go.click()
    page.wait_for_timeout(300)
    go.click()
    page.wait_for_function("() => Math.abs(window.plcrtPanel.frame.axes[0].position)"
                           " > 3000", timeout=30000)
    page.click("#stop")
    page.wait_for_timeout(300)


def main() -> int:
    les = course.lesson(Path("examples/course/05-jog-and-position"))
    plc = plcrt.load(Path("examples/course/05-jog-and-position/lesson.awl"),
                     plant=Path("examples/course/05-jog-and-position/plant.toml"))
    panel = Panel(PanelSession(plc), lessons=course.lessons(les.dir.parent), current=les)
    return shoot(panel, "panel.png", 1400, drive)


if __name__ == "__main__":
    sys.exit(main())
