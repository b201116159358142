"""The panel in a real headless browser: buttons, lamps, coils, forcing,
stepping, a timer counting, an axis moving, the course's check, and a
screenshot compared with a stored reference."""

from __future__ import annotations

import pytest

from plcrt.web import course
from plcrt.web.server import Panel
from plcrt.web.session import PanelSession

from .conftest import REPO, load_sample, matches_golden


def open_panel(page, served) -> None:
    page.goto(served.url)
    page.wait_for_selector("svg.rung")
    page.wait_for_function("() => window.plcrtPanel.frame !== null")


def frame(page) -> dict:
    return page.evaluate("() => window.plcrtPanel.frame")


def force_in_watch(page, addr: str, value: str):
    """Add ``addr`` to the watch table, force it to ``value`` with the
    row's button and wait until the page shows it forced; the row."""
    page.fill("#watch-spec", addr)
    page.click('#watch-add button[type="submit"]')
    row = page.locator(f'tr[data-watch="{addr}"]')
    row.locator("input").fill(value)
    row.locator("button[title=force]").click()
    page.wait_for_selector(f'tr[data-watch="{addr}"].forced')
    return row


def test_push_button_turns_on_the_coil_and_the_lamp(serve, page) -> None:
    served = serve()
    open_panel(page, served)
    page.click("#run")
    btn = page.locator('[data-input="I0.0"]')
    assert "momentary" in btn.get_attribute("class")      # Start_PB: a push-button
    btn.hover()
    page.mouse.down()
    page.wait_for_selector('[data-lamp="Q0.0"].on')
    page.mouse.up()
    page.wait_for_function("() => window.plcrtPanel.frame.io['I0.0'] === 0")
    # sealed in: the lamp stays on, the coil of network 1 is drawn powered
    assert "on" in page.locator('[data-lamp="Q0.0"]').get_attribute("class")
    assert page.locator('[data-net="OB1/1"] path.co.on').count() == 1
    assert page.locator('[data-net="OB1/1"] path.ct.on').count() >= 2
    assert page.errors == []


def test_keyboard_toggles_a_switch(serve, page) -> None:
    served = serve()
    open_panel(page, served)
    page.locator('[data-input="I0.1"] + .name + span + .kind').click()   # push-button -> switch
    page.evaluate("() => document.activeElement.blur()")
    page.keyboard.press("2")                                            # the second input
    page.wait_for_selector('[data-input="I0.1"].on')


def test_force_a_value_and_step_one_scan(serve, page) -> None:
    served = serve()
    open_panel(page, served)
    row = force_in_watch(page, "VW0", "7")
    assert row.locator(".value").inner_text() == "7"
    assert frame(page)["scans"] == 0
    page.click("#step")
    page.wait_for_function("() => window.plcrtPanel.frame.scans === 1")
    # MOVW VW0, VW2 ran once: VW2's value is written beside the box
    page.wait_for_function(
        "() => [...document.querySelectorAll('[data-net=\"OB1/4\"] text.val')]"
        ".some(t => t.textContent === '+7')")
    # a click on an operand opens it in the watch table
    page.locator('[data-net="OB1/4"] text[data-op="VW2"]').click()
    page.wait_for_selector('tr[data-watch="VW2"]')
    assert page.locator('tr[data-watch="VW2"] .value').inner_text() == "7"


def test_timer_counts_in_run_until(serve, page) -> None:
    served = serve()
    open_panel(page, served)
    page.select_option("#speed", "max")
    force_in_watch(page, "I0.0", "1")
    page.fill("#cond", "T37 >= 20")
    page.click("#until")
    page.wait_for_function("() => window.plcrtPanel.frame.scans > 0 && "
                           "window.plcrtPanel.frame.run === 'stopped'")
    f = frame(page)
    assert f["t"] == pytest.approx(2.01, abs=0.011)
    assert page.locator('[data-net="OB1/2"] text.val').first.text_content() == "+20"
    assert "true" in page.locator("#log").inner_text()


def test_axis_moves_to_its_target(serve, page) -> None:
    les = course.lesson(REPO / "examples/course/05-jog-and-position")
    plc = load_sample(les.program.read_text(), symbols=None, plant=les.plant)
    served = serve(panel=Panel(PanelSession(plc)))
    open_panel(page, served)
    assert page.locator(".axis canvas.slide").count() == 1
    page.select_option("#speed", "10")
    page.click("#run")
    page.locator('[data-input="I0.2"]').hover()
    page.mouse.down()
    page.wait_for_timeout(200)
    page.mouse.up()
    page.wait_for_function(
        "() => { const a = window.plcrtPanel.frame.axes[0];"
        " return a.position === 10000 && a.status === 'stopped'; }", timeout=30000)
    page.wait_for_selector('.axis[data-position="10000"]')
    assert "position 10000" in page.locator(".axis .info").inner_text()


def test_lesson_text_and_check_my_program(serve, page) -> None:
    les = course.lesson(REPO / "examples/course/01-seal-in")
    plc = load_sample(les.program.read_text(), symbols=les.symbols.read_text())
    panel = Panel(PanelSession(plc), lessons=course.lessons(les.dir.parent), current=les)
    served = serve(panel=panel)
    open_panel(page, served)
    assert page.locator("#lesson-title").inner_text() == "Lesson 1: the seal-in circuit"
    assert "seal" in page.locator("#lesson-text").inner_text()
    assert page.locator("#lessons option").count() >= 6
    page.click("#check")
    page.wait_for_selector("#check-results li[data-test]", timeout=120000)
    assert page.locator("#check-results li.passed[data-test]").count() == 5
    assert "5 passed, 0 failed" in page.locator("#check-results").inner_text()


def test_screenshot_matches_the_reference(serve, page) -> None:
    """A fixed program after 3 scans with start pressed, stopped: the
    ladder column compared with golden/ladder.png (mean absolute
    difference and the share of differing pixels)."""
    plc = load_sample()
    plc.write("I0.0", 1)
    served = serve(plc)
    open_panel(page, served)
    page.click("#stepn")   # 10 scans
    page.wait_for_function("() => window.plcrtPanel.frame.scans === 10 && "
                           "window.plcrtPanel.frame.run === 'stopped'")
    page.wait_for_timeout(200)
    matches_golden(page.locator("#networks"), "ladder")


def test_trend_exports_csv_and_png(serve, page, tmp_path) -> None:
    """A trend of a bit and a timer over 30 scans: the CSV holds one row per
    scan with the simulated time, the PNG is the plotted picture."""
    plc = load_sample()
    plc.force("I0.0", 1)
    served = serve(plc)
    open_panel(page, served)
    page.fill("#trend-signals", "Q0.0 T37")
    page.click("#trend-form button")
    page.fill("#nscans", "30")
    page.click("#stepn")
    page.wait_for_function("() => window.plcrtPanel.frame.scans === 30"
                           " && window.plcrtPanel.trend.t.length === 31")
    with page.expect_download() as dl:
        page.click("#trend-csv")
    csv = tmp_path / "trend.csv"
    dl.value.save_as(csv)
    rows = [r.split(",") for r in csv.read_text().splitlines()]
    assert rows[0] == ["t", "Q0.0", "T37"]
    assert len(rows) == 32 and float(rows[-1][0]) == pytest.approx(0.3)
    assert rows[1][1:] == ["0", "0"] and rows[-1][1] == "1" and int(rows[-1][2]) == 2
    with page.expect_download() as dl:
        page.click("#trend-png")
    png = tmp_path / "trend.png"
    dl.value.save_as(png)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 1000


def test_a_breakpoint_set_in_the_page_pauses_before_its_network(serve, page) -> None:
    """The circle of network 3 sets a breakpoint (the runner moves to the
    build with probes); a scan stops before network 3 and the bar says so;
    continue finishes the scan; clearing it moves back."""
    served = serve()
    open_panel(page, served)
    page.click('[data-net="OB1/3"] button.bp')
    page.wait_for_selector('[data-net="OB1/3"] button.bp.set')
    page.click("#step")
    page.wait_for_function("() => window.plcrtPanel.frame.run === 'paused'")
    assert frame(page)["paused_at"] == "OB1/3" and frame(page)["scans"] == 0
    assert "paused" in page.locator("#runstate").inner_text()
    page.click('[data-net="OB1/3"] button.bp')      # clear it while paused
    page.wait_for_selector('[data-net="OB1/3"] button.bp:not(.set)')
    page.click("#run")                               # continues the paused scan
    page.wait_for_function("() => window.plcrtPanel.frame.scans >= 1")
    page.click("#stop")
    page.wait_for_function("() => window.plcrtPanel.frame.run === 'stopped'")
    for _ in range(50):
        if served.panel.session.plc.coverage is None:
            break
        page.wait_for_timeout(100)
    assert served.panel.session.plc.coverage is None
