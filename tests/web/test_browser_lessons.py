"""The course in a real headless browser: lesson 1 done with clicks only
(a normally-closed stop button), input kinds that do not carry over to the
next lesson, the lesson text's emphasis and links, a lesson that does not
load, and a page of another site name (DNS rebinding) refused."""

from __future__ import annotations

import argparse
import shutil
from collections.abc import Iterator
from typing import Any

import pytest

from .conftest import CHROME_ARGS, REPO, _chromium

COURSE = REPO / "examples/course"


def lesson_panel(folder, watch_s: float = 0.5) -> Any:
    """The panel ``plcrt serve FOLDER`` builds (Python backend)."""
    from plcrt.web.cli import build_panel
    args = argparse.Namespace(
        programs=[str(folder)], symbols=None, encoding=None, data=None, cpu=None, plant=None,
        auto_symbols=False, backend="python", max_file_mb=None, scan_ms=10.0, clock=None,
        no_breakpoints=False, host="127.0.0.1", allow_host=[])
    panel = build_panel(args)
    panel.watch_s = watch_s
    return panel


def open_panel(page, served) -> None:
    page.goto(served.url)
    page.wait_for_function("() => window.plcrtPanel.frame !== null")


def io(page, addr: str) -> int:
    return page.evaluate(f"() => window.plcrtPanel.frame.io['{addr}']")


def hold(page, addr: str) -> None:
    page.locator(f'[data-input="{addr}"]').hover()
    page.mouse.down()


def lamp_on(page, addr: str) -> bool:
    return "on" in (page.locator(f'[data-lamp="{addr}"]').get_attribute("class") or "")


def test_lesson_1_is_done_with_clicks_only(serve, page) -> None:
    """Stop_PB_NC is a normally-closed push-button: it rests at 1, so Start
    starts the motor; holding Stop gives 0 and stops it."""
    served = serve(panel=lesson_panel(COURSE / "01-seal-in"))
    open_panel(page, served)
    kind = page.locator('[data-input="I0.1"] ~ .kind')
    assert kind.inner_text() == "NC push-button"
    assert page.locator('[data-input="I0.0"] ~ .kind').inner_text() == "push-button"
    assert io(page, "I0.1") == 1 and io(page, "I0.2") == 1
    assert "on" in page.locator('[data-input="I0.1"]').get_attribute("class")
    page.click("#run")
    hold(page, "I0.0")                                   # Start
    page.wait_for_selector('[data-lamp="Q0.0"].on')
    page.mouse.up()
    page.wait_for_function("() => window.plcrtPanel.frame.io['I0.0'] === 0")
    page.wait_for_timeout(300)
    assert lamp_on(page, "Q0.0") and lamp_on(page, "Q0.1")      # sealed in
    assert not lamp_on(page, "Q0.2")
    hold(page, "I0.1")                                   # Stop: held, it reads 0
    page.wait_for_function("() => window.plcrtPanel.frame.io['I0.1'] === 0")
    page.wait_for_selector('[data-lamp="Q0.0"]:not(.on)')
    page.mouse.up()
    page.wait_for_function("() => window.plcrtPanel.frame.io['I0.1'] === 1")
    page.wait_for_timeout(300)
    assert not lamp_on(page, "Q0.0") and not lamp_on(page, "Q0.1")
    page.click('[data-input="I0.2"]')                    # trip the overload relay
    page.wait_for_selector('[data-lamp="Q0.2"].on')
    assert page.errors == []


def test_input_kinds_do_not_carry_over_to_the_next_lesson(serve, page) -> None:
    """I0.0 is lesson 1's Start push-button and lesson 2's run switch."""
    served = serve(panel=lesson_panel(COURSE / "01-seal-in"))
    open_panel(page, served)
    assert "momentary" in page.locator('[data-input="I0.0"]').get_attribute("class")
    page.select_option("#lessons", "02-timers")
    page.wait_for_function("() => window.plcrtPanel.hello.lesson.id === '02-timers'")
    page.wait_for_selector('[data-input="I0.3"]')
    assert "momentary" not in page.locator('[data-input="I0.0"]').get_attribute("class")
    assert page.locator('[data-input="I0.0"] ~ .kind').inner_text() == "switch"
    assert page.locator('[data-input="I0.3"] ~ .kind').inner_text() == "push-button"
    page.select_option("#lessons", "01-seal-in")
    page.wait_for_function("() => window.plcrtPanel.hello.lesson.id === '01-seal-in'")
    page.wait_for_function("() => window.plcrtPanel.frame.io['I0.1'] === 1")
    assert page.locator('[data-input="I0.1"] ~ .kind').inner_text() == "NC push-button"


def test_the_lesson_text_renders_emphasis_code_and_links(serve, page) -> None:
    served = serve(panel=lesson_panel(COURSE / "01-seal-in"))
    open_panel(page, served)
    text = page.locator("#lesson-text")
    assert text.locator("strong", has_text="normally closed").count() >= 1
    assert text.locator("em").count() >= 1
    assert text.locator("code", has_text="Start_PB").count() >= 1
    assert "**" not in text.inner_text() and "`" not in text.inner_text()
    assert "Run these from the repository root" not in text.inner_text()
    assert text.locator("ol li").first.inner_text().startswith("Click Run")


def test_a_link_of_the_lesson_text_opens_in_a_new_tab_without_opener(serve, page,
                                                                     tmp_path) -> None:
    folder = tmp_path / "01-seal-in"
    shutil.copytree(COURSE / "01-seal-in", folder)
    (folder / "panel.md").write_text(
        "See [the program](lesson.awl), [the manual](https://example.org/m) and "
        "[this](javascript:alert%281%29).\n")
    served = serve(panel=lesson_panel(folder))
    open_panel(page, served)
    links = page.locator("#lesson-text a")
    assert links.count() == 2
    assert links.nth(0).get_attribute("href") == "lesson/lesson.awl"
    assert links.nth(1).get_attribute("href") == "https://example.org/m"
    for i in range(2):
        assert links.nth(i).get_attribute("rel") == "noopener noreferrer"
        assert links.nth(i).get_attribute("target") == "_blank"
    with page.context.expect_page() as new:
        links.nth(0).click()
    assert "Network 1" in new.value.locator("body").inner_text()


def test_a_lesson_that_does_not_load_shows_its_text_and_the_error(serve, page,
                                                                   tmp_path) -> None:
    course = tmp_path / "course"
    shutil.copytree(COURSE / "01-seal-in", course / "01-seal-in")
    shutil.copytree(COURSE / "02-timers", course / "02-timers")
    (course / "02-timers" / "lesson.awl").write_text(
        "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\nNetwork 2\n"
        "LD Q0.0\nTON T37, +50\n= Q9999.9\nEND_ORGANIZATION_BLOCK\n")
    served = serve(panel=lesson_panel(course / "01-seal-in"))
    open_panel(page, served)
    assert page.locator("svg.rung").count() == 3
    page.select_option("#lessons", "02-timers")
    page.wait_for_selector("#lesson-text .load-error")
    assert page.locator("#lesson-title").inner_text() == "Lesson 2: timers"
    err = page.locator("#lesson-text .load-error").inner_text()
    assert "02-timers/lesson.awl:9:" in err and "[OB1 network 2]" in err
    assert page.locator("svg.rung").count() == 0          # lesson 1's ladder is gone
    assert page.locator("[data-input]").count() == 0
    assert "02-timers/lesson.awl:9:" in page.locator("#log").inner_text()


# ---------------------------------------------------------------- DNS rebinding
@pytest.fixture(scope="module")
def rebinding_browser(browser) -> Iterator[Any]:
    """A second Chromium (of the same Playwright) resolving ``rebind.test``
    to 127.0.0.1: what a DNS rebinding attack does to another site's name."""
    b = browser.browser_type.launch(executable_path=_chromium(), args=[
        *CHROME_ARGS, "--host-resolver-rules=MAP rebind.test 127.0.0.1"])
    yield b
    b.close()


def test_a_page_under_another_sites_name_is_refused(serve, rebinding_browser) -> None:
    """The browser reaches the panel under the name rebind.test (as after
    DNS rebinding): the page, the static files and the websocket are
    refused; the same browser under 127.0.0.1 gets the panel."""
    from .conftest import load_sample
    served = serve(load_sample())
    ctx = rebinding_browser.new_context()
    try:
        page = ctx.new_page()
        page.set_default_timeout(15000)
        foreign = f"http://rebind.test:{served.port}"
        r = page.goto(foreign + "/")
        assert r is not None and r.status == 403
        assert "not this server's name" in page.locator("body").inner_text()
        assert page.evaluate("() => window.plcrtPanel === undefined")
        r = page.goto(foreign + "/static/panel.js")
        assert r is not None and r.status == 403
        opened = page.evaluate(f"""() => new Promise((done) => {{
            const ws = new WebSocket("ws://rebind.test:{served.port}/ws");
            ws.onopen = () => done("open");
            ws.onerror = () => done("refused");
            setTimeout(() => done("timeout"), 5000);
        }})""")
        assert opened == "refused" and not served.panel.session.clients
        r = page.goto(served.url)
        assert r is not None and r.status == 200
        page.wait_for_function("() => window.plcrtPanel.frame !== null")
    finally:
        ctx.close()
