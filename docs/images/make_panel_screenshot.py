"""Take the README's picture of the panel: ``python docs/images/make_panel_screenshot.py``.

Serves lesson 5 of the course (jogging and an exact move on the EM253) with
``plcrt serve``'s application on a free loopback port, drives it in
Debian's Chromium through Playwright (as tests/web does), starts the
relative move, and saves ``docs/images/panel.png`` while the axis is on
its way.  Needs ``apt-get install chromium`` and the test extra.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from playwright.sync_api import sync_playwright  # noqa: E402

from plcrt.web import course  # noqa: E402
from plcrt.web.server import Panel  # noqa: E402
from plcrt.web.session import PanelSession  # noqa: E402
import plcrt  # noqa: E402
from web.conftest import CHROME_ARGS, Served, _chromium  # noqa: E402


def main() -> int:
    os.chdir(ROOT)   # the page names the program as it was given: relative
    les = course.lesson(Path("examples/course/05-jog-and-position"))
    plc = plcrt.load(Path("examples/course/05-jog-and-position/lesson.awl"),
                     plant=Path("examples/course/05-jog-and-position/plant.toml"))
    served = Served(Panel(PanelSession(plc), lessons=course.lessons(les.dir.parent),
                          current=les))
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=_chromium(), args=CHROME_ARGS)
            page = browser.new_page(viewport={"width": 1400, "height": 1400})
            page.goto(served.url)
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
            out = ROOT / "docs/images/panel.png"
            page.screenshot(path=str(out))
            browser.close()
            print(out)
    finally:
        served.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
