"""What the README's picture scripts share (``make_*_screenshot.py``).

:func:`shoot` serves a panel on a free loopback port, opens it in Debian's
Chromium through Playwright (as tests/web does), lets the script drive the
page, and saves the picture under ``docs/images/``.  Needs
``apt-get install chromium`` and the test extra.  Importing it puts the
checkout and its ``tests/`` folder on ``sys.path`` and makes the checkout
the working directory: the page names a program as it was given, relative.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
os.chdir(ROOT)

from playwright.sync_api import sync_playwright  # noqa: E402

from web.conftest import CHROME_ARGS, Served, _chromium  # noqa: E402


def shoot(panel: Any, name: str, height: int, drive: Callable[[Any], None]) -> int:
    """Serve *panel*, run ``drive(page)`` in a 1400 x *height* window and
    save ``docs/images/<name>``; 0 for ``sys.exit``."""
    served = Served(panel)
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=_chromium(), args=CHROME_ARGS)
            page = browser.new_page(viewport={"width": 1400, "height": height})
            page.goto(served.url)
            drive(page)
            out = ROOT / "docs/images" / name
            page.screenshot(path=str(out))
            browser.close()
            print(out)
    finally:
        served.close()
    return 0
