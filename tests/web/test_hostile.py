"""A hostile program: titles, comments, symbol names and comments carrying
script and markup are shown as text and do nothing in the page."""

from __future__ import annotations

from plcrt.web.server import Panel
from plcrt.web.session import PanelSession

from .conftest import load_sample

EVIL = '<script>window.__pwned=1</script><img src=x onerror="window.__pwned=1">'

PROGRAM = f"""\
ORGANIZATION_BLOCK MAIN:OB1
TITLE={EVIL}
// {EVIL}
BEGIN
Network 1 // {EVIL}
// <svg onload="window.__pwned=1"></svg> "'><iframe src=javascript:window.__pwned=1>
LD     Evil
=      Q0.0
Network 2 // STL only: {EVIL}
LD     I0.1
LPS
A      I0.2
=      Q0.1 // {EVIL}
END_ORGANIZATION_BLOCK
"""

SYMBOLS = f'Evil\tI0.0\t{EVIL}\nLamp\tQ0.0\t"><svg/onload=window.__pwned=1>\n'


def test_program_text_cannot_run_script_or_inject_elements(serve, page) -> None:
    plc = load_sample(PROGRAM, symbols=SYMBOLS)
    served = serve(panel=Panel(PanelSession(plc)))
    page.goto(served.url)
    page.wait_for_selector("svg.rung")
    page.wait_for_function("() => window.plcrtPanel.frame !== null")
    page.locator('[data-input="I0.0"]').hover()       # tooltips, hovers
    page.click("#step")
    page.wait_for_function("() => window.plcrtPanel.frame.scans === 1")
    page.wait_for_timeout(300)
    assert page.evaluate("() => window.__pwned") is None
    # the page's own scripts only: the panel, the machines, the editor and
    # its CodeMirror bundle, the ladder drawing
    assert page.evaluate("() => [...document.scripts].map(s => new URL(s.src).pathname)") == [
        "/static/panel.js", "/static/machines.js", "/static/vendor/codemirror.min.js", "/static/editor.js",
        "/static/ladder_edit.js"]
    assert page.locator("img, iframe").count() == 0
    assert page.locator("#networks svg svg, #networks foreignObject").count() == 0
    assert page.evaluate("() => [...document.querySelectorAll('*')].filter(e => "
                         "[...e.attributes].some(a => a.name.startsWith('on'))).length") == 0
    text = page.locator("#networks").inner_text()
    assert "<script>window.__pwned=1</script>" in text              # shown, as text
    assert "<iframe src=javascript:" in text
    tips = page.evaluate("() => [...document.querySelectorAll('svg title')]"
                         ".map(t => t.textContent)")
    assert any(EVIL in t for t in tips)
    assert page.errors == []
