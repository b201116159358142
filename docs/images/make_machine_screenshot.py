"""Take the README's picture of a machine: ``python docs/images/make_machine_screenshot.py``.

Serves the conveyor example (``examples/machines/conveyor.awl`` with its
plant file) with ``plcrt serve``'s application on a free loopback port,
presses the conveyor's start button, runs it in the page until parts are
on the belt and at the gate, stops, and saves
``docs/images/machine.png``: the ladder beside the animated conveyor.
Drives Debian's Chromium through Playwright (as tests/web does); needs
``apt-get install chromium`` and the test extra.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from playwright.sync_api import sync_playwright  # noqa: E402

from plcrt.web.server import Panel  # noqa: E402
from plcrt.web.session import PanelSession  # noqa: E402
import plcrt  # noqa: E402
from web.conftest import CHROME_ARGS, Served, _chromium  # noqa: E402


def main() -> int:
    os.chdir(ROOT)   # the page names the program as it was given: relative
    plc = plcrt.load(Path("examples/machines/conveyor.awl"),
                     plant=Path("examples/machines/conveyor.toml"))
    served = Served(Panel(PanelSession(plc)))
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=_chromium(), args=CHROME_ARGS)
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            page.goto(served.url)
            page.wait_for_selector("[data-machine=conveyor] svg")
            page.select_option("#speed", "10")
            page.click("[data-machine=conveyor] button[data-button=start]")
            page.click("#run")
            page.wait_for_function("() => window.plcrtPanel.frame.t > 9", timeout=60000)
            page.click("#stop")
            page.wait_for_timeout(500)
            out = ROOT / "docs/images/machine.png"
            page.screenshot(path=str(out))
            browser.close()
            print(out)
    finally:
        served.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
