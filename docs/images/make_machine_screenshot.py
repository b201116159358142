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

import sys
from pathlib import Path

from shoot import shoot   # first: it puts the checkout on sys.path

from plcrt.web.server import Panel
from plcrt.web.session import PanelSession
import plcrt


def drive(page) -> None:
    page.wait_for_selector("[data-machine=conveyor] svg")
    page.select_option("#speed", "10")
    page.click("[data-machine=conveyor] button[data-button=start]")
    page.click("#run")
    page.wait_for_function("() => window.plcrtPanel.frame.t > 9", timeout=60000)
    page.click("#stop")
    page.wait_for_timeout(500)


def main() -> int:
    plc = plcrt.load(Path("examples/machines/conveyor.awl"),
                     plant=Path("examples/machines/conveyor.toml"))
    return shoot(Panel(PanelSession(plc)), "machine.png", 1000, drive)


if __name__ == "__main__":
    sys.exit(main())
