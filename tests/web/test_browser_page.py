"""The panel's page in headless Chromium: the program's diagnostics and a
click that shows their network, readable compare contacts and coil
letters, the force marker without an emoji font, a narrow screen, the
accessible names and states of inputs and lamps, the page after the
server stopped, and the trends after a power-up reset."""

from __future__ import annotations

import pytest

import plcrt
from plcrt.errors import Diagnostic, SourceLoc
from plcrt.web import course
from plcrt.web.server import Panel
from plcrt.web.session import PanelSession

from .conftest import REPO
from .test_hostile import EVIL
from .test_browser import force_in_watch, frame, open_panel

#: a subroutine that calls itself: a warning at load (recursion) and one
#: while running (the ninth nesting level is not called), both in SBR0/2
RECURSION = """\
ORGANIZATION_BLOCK MAIN:OB1
TITLE=Recursion
BEGIN
Network 1 // Call the subroutine
LD     SM0.0
CALL   SBR0
Network 2 // Lamp
LD     I0.0
=      Q0.0
END_ORGANIZATION_BLOCK
SUBROUTINE_BLOCK SBR_0:SBR0
TITLE=Calls itself
BEGIN
Network 1 // Count the depth
LD     SM0.0
INCW   VW0
Network 2 // Again
LD     SM0.0
CALL   SBR0
END_SUBROUTINE_BLOCK
"""

#: compare contacts of every type with both operands shown, and coils with
#: letters (R, S, SCRE), all powered after one scan
COMPARE = """\
ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1 // Compare
LDW>=  VW0, VW2
AD<    VD4, VD8
LPS
R      Q0.0, 1
LPP
S      Q0.1, 1
Network 2 // Real and byte
LDR>   VD20, VD24
AB<>   VB30, VB31
=      Q0.2
Network 3 // Step
LSCR   S0.1
Network 4 // In the step
LD     SM0.0
=      Q0.3
Network 5 // End of the step
SCRE
END_ORGANIZATION_BLOCK
"""


def _lesson5(plc_setup=None) -> Panel:
    les = course.lesson(REPO / "examples/course/05-jog-and-position")
    plc = plcrt.load(les.program, plant=les.plant)
    if plc_setup is not None:
        plc_setup(plc)
    return Panel(PanelSession(plc))


def test_a_run_time_diagnostic_of_lesson_5_appears_and_shows_its_network(serve, page) -> None:
    """Go pressed while jogging: POS_GOTO_R refuses the Run edge with the
    warning `plcrt run` prints; the page lists it with its network, and a
    click scrolls to network 5 and outlines it."""
    def jog_and_go(plc: plcrt.Plc) -> None:
        plc.write("I0.0", 1)
        plc.write("M11.0", 1)
    served = serve(panel=_lesson5(jog_and_go))
    page.set_viewport_size({"width": 1400, "height": 500})
    open_panel(page, served)
    assert page.locator("#diags li").count() == 0
    page.click("#stepn")        # 10 scans
    item = page.locator('#diags button[data-shows="OB1/5"]')
    item.wait_for()
    text = item.inner_text()
    assert "the axis is already moved by another instruction" in text
    assert text.startswith("OB1 network 5: warning: POS_GOTO_R: ") and "lesson.awl:42:1" in text
    assert not page.locator('.net[data-net="OB1/5"]').evaluate(
        "e => { const r = e.getBoundingClientRect(); return r.top < innerHeight && r.bottom > 0; }")
    item.click()
    net = page.locator('.net[data-net="OB1/5"]')
    assert "flash" in net.get_attribute("class")
    page.wait_for_function(
        "() => { const r = document.querySelector('.net[data-net=\"OB1/5\"]')"
        ".getBoundingClientRect(); return r.top >= 0 && r.top < innerHeight; }")
    assert page.locator(".net.flash").count() == 1
    assert page.errors == []


def test_load_and_run_time_diagnostics_open_the_block_of_their_network(serve, page) -> None:
    """A warning at load is listed as soon as the page opens, one while
    running after the scan that raised it; a click opens SBR0's tab."""
    served = serve(plcrt.load(RECURSION))
    open_panel(page, served)
    items = page.locator("#diags li")
    assert items.count() == 1
    assert "recursion: SBR0 -> SBR0" in items.first.inner_text()
    assert "warning" in items.first.get_attribute("class")
    page.click("#step")
    page.wait_for_function("() => document.querySelectorAll('#diags li').length === 2")
    assert "CALL not executed" in items.nth(1).inner_text()
    assert page.locator('#tabs button.active').inner_text().startswith("OB1")
    items.nth(1).locator("button").click()
    assert page.locator('#tabs button.active').inner_text().startswith("SBR0")
    page.wait_for_selector('.net.flash[data-net="SBR0/2"]')
    # a power-up reset and the same warning again: still listed once
    page.click("#reset")
    page.click("#step")
    page.wait_for_function("() => window.plcrtPanel.frame.scans === 1")
    page.wait_for_timeout(200)
    assert items.count() == 2


def test_diagnostic_text_is_shown_as_text(serve, page) -> None:
    """Program text quoted by a diagnostic (as a library block quotes an
    operand) is shown as text, never as markup."""
    served = serve()
    open_panel(page, served)
    loc = SourceLoc("<string>", 6, 1, "OB1", 1)
    served.panel.session.plc.diagnostics.append(Diagnostic("warning", EVIL, loc, "runtime"))
    page.click("#step")
    page.wait_for_selector("#diags li")
    assert EVIL in page.locator("#diags").inner_text()
    assert page.locator("#diags img, #diags script").count() == 0
    assert page.evaluate("() => window.__pwned") is None
    assert page.errors == []


def _rects(page, selector: str) -> list[dict]:
    return page.evaluate(
        "(sel) => [...document.querySelectorAll(sel)].filter(t => t.textContent.trim())"
        ".map(t => { const r = t.getBoundingClientRect();"
        " return {text: t.textContent, l: r.left, r: r.right, t: r.top, b: r.bottom}; })",
        selector)


def _compare_page(serve, page):
    plc = plcrt.load(COMPARE)
    for addr, v in [("VW0", 12000), ("VW2", -32000), ("VD4", -2000000000), ("VD8", 5),
                    ("VD20", 2.5), ("VD24", -1.234567e+38), ("VB30", 200), ("VB31", 7),
                    ("S0.1", 1)]:
        plc.write(addr, v)
    served = serve(plc)
    open_panel(page, served)
    page.click("#step")
    page.wait_for_function("() => window.plcrtPanel.frame.scans === 1")
    page.wait_for_function("() => document.querySelector('[data-net=\"OB1/1\"] text.val')"
                           ".textContent !== ''")


def test_compare_contact_texts_do_not_overlap(serve, page) -> None:
    """Operands, their values and the operator (``>=I``) of each compare
    contact: no two text boxes of a rung overlap."""
    _compare_page(serve, page)
    for net in ("OB1/1", "OB1/2"):
        rects = _rects(page, f'[data-net="{net}"] svg text')
        texts = [r["text"] for r in rects]
        assert any(t in (">=I", "<D", ">R", "<>B") for t in texts), texts
        for i, a in enumerate(rects):
            for b in rects[i + 1:]:
                overlap = min(a["r"], b["r"]) - max(a["l"], b["l"]) > 0.5 and \
                    min(a["b"], b["b"]) - max(a["t"], b["t"]) > 0.5
                assert not overlap, (net, a, b)


def _contrast(fg: str, bg: str) -> float:
    """WCAG contrast ratio of two ``rgb(r, g, b)`` colours."""
    def lum(c: str) -> float:
        parts = [int(x) / 255 for x in c[c.index("(") + 1:c.index(")")].split(",")[:3]]
        lin = [p / 12.92 if p <= 0.03928 else ((p + 0.055) / 1.055) ** 2.4 for p in parts]
        return 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]
    hi, lo = sorted((lum(fg), lum(bg)), reverse=True)
    return (hi + 0.05) / (lo + 0.05)


def test_letters_stay_readable_on_a_powered_coil_and_a_closed_compare(serve, page) -> None:
    """R, S and SCRE in a powered coil and the operator of a closed compare
    contact: their colour contrasts with the filled background (WCAG AA)."""
    _compare_page(serve, page)
    # the filled shape under each letter: the .cf of its group that holds
    # the middle of the letter's box
    pairs = page.evaluate(
        "() => [...document.querySelectorAll('svg.rung text.in')].map(t => {"
        " const b = t.getBBox(), x = b.x + b.width / 2, y = b.y + b.height / 2;"
        " const fill = [...t.parentNode.querySelectorAll('.cf')].find(f => {"
        "   const r = f.getBBox();"
        "   return r.x <= x && x <= r.x + r.width && r.y <= y && y <= r.y + r.height; });"
        " return {text: t.textContent, fg: getComputedStyle(t).fill,"
        " on: !!fill && fill.classList.contains('on'),"
        " bg: fill ? getComputedStyle(fill).fill : ''}; })")
    letters = {p["text"] for p in pairs if p["on"]}
    assert {"R", "S", "SCRE", ">=I", "<D", ">R", "<>B"} <= letters, pairs
    for p in pairs:
        if p["on"]:
            assert _contrast(p["fg"], p["bg"]) >= 4.5, p


def test_the_force_marker_needs_no_emoji_font(serve, page) -> None:
    """The padlock of a forced row is drawn (an SVG image), not a character
    from an emoji font, and it takes room beside the value."""
    served = serve()
    open_panel(page, served)
    force_in_watch(page, "VW0", "7")
    marker = page.evaluate(
        "() => { const s = getComputedStyle("
        "document.querySelector('tr[data-watch=\"VW0\"] .value'), '::before');"
        " return {content: s.content, image: s.backgroundImage, width: s.width}; }")
    assert not any(ord(ch) > 0x2FFF for ch in marker["content"]), marker
    assert marker["image"].startswith('url("data:image/svg+xml'), marker
    assert float(marker["width"].removesuffix("px")) > 4


def _outside(page) -> list[dict]:
    """The visible controls, lamps and canvases not inside the screen's width."""
    return page.evaluate(
        "() => [...document.querySelectorAll('button, input, select, [data-lamp], canvas')]"
        ".filter(e => e.offsetParent !== null).map(e => { const r = e.getBoundingClientRect();"
        " return {what: e.outerHTML.slice(0, 60), l: r.left, r: r.right}; })"
        ".filter(x => x.l < 0 || x.r > innerWidth)")


def test_a_600_px_screen_reaches_every_control(serve, page) -> None:
    """At 600 px every button, field and lamp lies inside the width of the
    screen (the page scrolls down, never sideways)."""
    page.set_viewport_size({"width": 600, "height": 800})
    served = serve()
    open_panel(page, served)
    force_in_watch(page, "VW0", "7")
    assert _outside(page) == []
    assert page.evaluate("() => document.documentElement.scrollWidth") <= 600
    page.locator('[data-input="I0.1"]').scroll_into_view_if_needed()
    page.locator('[data-input="I0.1"]').click()     # Stop_PB: a push-button, reachable


def test_a_phone_screen_shows_a_lesson_in_one_column(serve, page) -> None:
    """360 px with a lesson open (its list of lessons, text, axis slide and
    trends): still nothing beyond the right edge."""
    les = course.lesson(REPO / "examples/course/05-jog-and-position")
    plc = plcrt.load(les.program, plant=les.plant)
    served = serve(panel=Panel(PanelSession(plc), lessons=course.lessons(les.dir.parent),
                               current=les))
    page.set_viewport_size({"width": 360, "height": 740})
    open_panel(page, served)
    assert page.locator("#lessons").is_visible() and page.locator(".axis canvas").is_visible()
    assert _outside(page) == []
    assert page.evaluate("() => document.documentElement.scrollWidth") <= 360


def test_inputs_and_lamps_have_accessible_names_and_states(serve, page) -> None:
    served = serve()
    open_panel(page, served)
    page.click("#run")
    start = page.get_by_role("button", name="I0.0 Start_PB")
    assert start.get_attribute("aria-pressed") == "false"
    lamp = page.get_by_role("img", name="Q0.0 Motor: off")
    assert lamp.count() == 1
    start.hover()
    page.mouse.down()
    page.get_by_role("button", name="I0.0 Start_PB", pressed=True).wait_for()
    page.get_by_role("img", name="Q0.0 Motor: on").wait_for()
    page.mouse.up()
    page.get_by_role("button", name="I0.0 Start_PB", pressed=False).wait_for()
    # Stop_PB made a switch: a switch role whose checked state is the input
    page.locator('[data-input="I0.1"] + .name + span + .kind').click()
    stop = page.get_by_role("switch", name="I0.1 Stop_PB")
    assert stop.get_attribute("aria-checked") == "false"
    stop.click()
    page.get_by_role("switch", name="I0.1 Stop_PB", checked=True).wait_for()
    page.get_by_role("img", name="Q0.0 Motor: off").wait_for()
    assert page.get_by_role("img", name="Q0.1: off").count() == 1   # no symbol: the address


def test_the_page_says_disconnected_when_the_server_stops(serve, page) -> None:
    served = serve()
    open_panel(page, served)
    page.click("#run")
    page.wait_for_function("() => document.getElementById('runstate').textContent === 'running'")
    served.close()
    page.wait_for_function(
        "() => document.getElementById('runstate').textContent === 'disconnected'")
    assert page.locator("#conn").inner_text() == "disconnected"
    assert "disconnected" in page.locator("#log").inner_text()


#: records the points each canvas is drawn through since it was last cleared
CANVAS_SPY = """
(() => {
  const C = CanvasRenderingContext2D.prototype;
  window.__plots = {};
  for (const name of ["moveTo", "lineTo"]) {
    const orig = C[name];
    C[name] = function (x, y) {
      (window.__plots[this.canvas.id] ||= []).push([x, y]);
      return orig.call(this, x, y);
    };
  }
  const fill = C.fillRect;
  C.fillRect = function (x, y, w, h) {
    if (x === 0 && y === 0 && w === this.canvas.width && h === this.canvas.height)
      window.__plots[this.canvas.id] = [];
    return fill.call(this, x, y, w, h);
  };
})();
"""


def _inside(page, canvas: str) -> None:
    size = page.evaluate("(id) => [document.getElementById(id).width,"
                         " document.getElementById(id).height]", canvas)
    pts = page.evaluate("(id) => window.__plots[id] || []", canvas)
    assert pts, canvas
    bad = [p for p in pts if not (0 <= p[0] <= size[0] and 0 <= p[1] <= size[1])]
    assert bad == [], (canvas, size, bad[:5])


def test_trends_stay_inside_their_canvas_after_a_power_up_reset(serve, page) -> None:
    """The axis trend and the signal trend start again after a power-up
    reset (the simulated time went back): every point drawn lies inside
    its canvas."""
    def jog(plc: plcrt.Plc) -> None:
        plc.force("I0.0", 1)
    served = serve(panel=_lesson5(jog))
    page.add_init_script(CANVAS_SPY)
    open_panel(page, served)
    page.fill("#trend-signals", "M10.0 VD300")
    page.click("#trend-form button")
    page.fill("#nscans", "100")
    page.click("#stepn")
    page.wait_for_function("() => window.plcrtPanel.frame.scans === 100"
                           " && window.plcrtPanel.frame.run === 'stopped'")
    page.click("#reset")
    page.wait_for_function("() => window.plcrtPanel.frame.scans === 0")
    page.fill("#nscans", "40")      # shorter than before: the old points lie beyond
    page.click("#stepn")
    page.wait_for_function("() => window.plcrtPanel.frame.scans === 40"
                           " && window.plcrtPanel.frame.run === 'stopped'")
    page.wait_for_timeout(300)
    assert frame(page)["t"] == pytest.approx(0.4)
    _inside(page, "axis-trend")
    _inside(page, "trend")
    trend = page.evaluate("() => window.plcrtPanel.trend")
    assert trend["t"][0] == 0 and len(trend["t"]) == 41 and trend["t"] == sorted(trend["t"])
