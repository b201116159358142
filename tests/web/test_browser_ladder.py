"""Drawing ladder in a real headless browser: a seal-in rung drawn into an
empty network with the mouse and the keyboard, written into the editor's
text and saved to the file; undo and redo; a network without ladder form
shown as STL with its reason; a new network drawn; operands with markup stay text; a page of
another origin refused on the drawing's endpoints."""

from __future__ import annotations


import plcrt
from plcrt.web.editor import ProgramSource
from plcrt.web.server import Panel
from plcrt.web.session import PanelSession

from .conftest import editor_no_errors, editor_text, posts_from_another_origin

PROGRAM = """\
ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1 // Seal-in
Network 2 // Stays STL
LD     I0.2
=      Q0.1
LD     I0.3
=      Q0.2
END_ORGANIZATION_BLOCK
"""

SYMBOLS = "Start\tI0.0\tstart button\nStop\tI0.1\tstop button\nMotor\tQ0.0\tmotor\n"

SEAL_IN = "LD     Start\nO      Motor\nAN     Stop\n=      Motor\n"


def _panel(tmp_path):
    path = tmp_path / "prog.awl"
    path.write_text(PROGRAM)
    sym = tmp_path / "symbols.txt"
    sym.write_text(SYMBOLS)
    source = ProgramSource(path, (), {"backend": "python", "symbols": sym})
    plc = plcrt.load(path, symbols=sym, backend="python")
    return Panel(PanelSession(plc), source_of=lambda les: source), path


def _open_drawing(page, served, network: str) -> None:
    page.goto(served.url)
    page.wait_for_function("() => window.plcrtPanel.frame !== null")
    page.click("#edit-toggle")
    page.wait_for_function("() => window.plcrtEditor.loaded")
    page.click("#draw-toggle")
    page.wait_for_function("() => document.querySelectorAll('#draw-net option').length === 2")
    page.select_option("#draw-net", network)
    page.click("#draw-open")
    page.wait_for_function("() => !document.querySelector('#draw').hidden")


def _type_in_place(page, text: str) -> None:
    page.wait_for_selector("#draw-rung input.lad-input")
    assert page.evaluate("() => document.activeElement.className") == "lad-input"
    page.keyboard.type(text)
    page.keyboard.press("Enter")


def _wait_stl(page, stl: str) -> None:
    page.wait_for_function("(s) => document.querySelector('#draw-stl').textContent === s", arg=stl)


def _selected(page) -> str:
    return page.locator("#draw-rung .lad-el.selected").get_attribute("aria-label")


def test_draw_a_seal_in_rung_with_mouse_and_keyboard_and_save(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    _open_drawing(page, served, "OB1/1")
    assert "empty network" in page.locator("#draw-rung").text_content()
    # with the mouse: a contact, then the coil that makes it a rung
    page.click("#draw-palette [data-add=NO]")
    _type_in_place(page, "Start")
    assert page.locator("#draw-status").text_content().startswith("add an output")
    page.click("#draw-palette [data-add='=']")
    _type_in_place(page, "Motor")
    _wait_stl(page, "LD     Start\n=      Motor\n")
    # the editor holds the network as STL at once
    assert "Network 1 // Seal-in\nLD     Start\n=      Motor\nNetwork 2" in editor_text(page)
    # with the keyboard: select Start (arrows), a normally closed contact
    # after it ('/'), then a parallel branch around Start ('o')
    page.focus("#draw-rung")
    page.keyboard.press("ArrowLeft")
    page.keyboard.press("ArrowLeft")
    assert _selected(page) == "NO Start"
    page.keyboard.press("/")
    _type_in_place(page, "Stop")
    _wait_stl(page, "LD     Start\nAN     Stop\n=      Motor\n")
    assert _selected(page) == "NC Stop"
    page.keyboard.press("ArrowLeft")
    assert _selected(page) == "NO Start"
    page.keyboard.press("o")
    _type_in_place(page, "Motr")          # a typo, fixed in place below
    _wait_stl(page, "LD     Start\nO      Motr\nAN     Stop\n=      Motor\n")
    assert _selected(page) == "NO Motr"
    page.keyboard.press("Enter")
    page.wait_for_selector("#draw-rung input.lad-input")
    page.keyboard.press("Control+a")
    page.keyboard.type("Motor")
    page.keyboard.press("Enter")
    _wait_stl(page, SEAL_IN)
    # the drawing: the branch under Start, Stop after them, the coil
    labels = page.locator("#draw-rung .lad-el").evaluate_all("els => els.map(e => e.getAttribute('aria-label'))")
    assert labels == ["NO Start", "NO Motor", "NC Stop", "= Motor"]
    top = page.locator("#draw-rung .lad-el").nth(0).bounding_box()
    below = page.locator("#draw-rung .lad-el").nth(1).bounding_box()
    assert below["y"] > top["y"] and abs(below["x"] - top["x"]) < 2
    # undo goes back a step, in the drawing and in the editor; redo again
    page.focus("#draw-rung")
    page.keyboard.press("Control+z")
    _wait_stl(page, "LD     Start\nO      Motr\nAN     Stop\n=      Motor\n")
    assert "O      Motr" in editor_text(page)
    page.keyboard.press("Control+y")
    _wait_stl(page, SEAL_IN)
    # Delete removes the selected element, undo brings it back
    page.locator("#draw-rung .lad-el[aria-label='NC Stop']").click()
    page.keyboard.press("Delete")
    _wait_stl(page, "LD     Start\nO      Motor\n=      Motor\n")
    page.click("#draw-undo")
    _wait_stl(page, SEAL_IN)
    # the editor's check accepts it; Save writes the file
    editor_no_errors(page)
    page.click("#editor-save")
    page.wait_for_function("() => document.querySelector('#editor-status')"
                           ".textContent.startsWith('saved')")
    assert path.read_text() == PROGRAM.replace("Network 1 // Seal-in\n",
                                               "Network 1 // Seal-in\n" + SEAL_IN)
    # and the file reads back as the same ladder
    _open_drawing(page, served, "OB1/1")
    _wait_stl(page, SEAL_IN)
    assert page.errors == []


def test_a_network_without_ladder_form_stays_stl_and_a_new_one_is_drawn(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    _open_drawing(page, served, "OB1/2")
    page.wait_for_function("() => document.querySelector('#draw-status').textContent"
                           ".startsWith('this network stays STL')")
    assert "rung" in page.locator("#draw-status").text_content()
    assert page.locator("#draw-stl").text_content() == ("LD     I0.2\n=      Q0.1\n"
                                                         "LD     I0.3\n=      Q0.2\n")
    assert page.locator("#draw-palette").is_hidden()
    # New network: an empty network 3 after it, drawn at once
    page.click("#draw-new")
    page.wait_for_function("() => document.querySelector('#draw-status').textContent "
                           "=== 'drawing OB1 network 3'")
    page.click("#draw-palette [data-add=NO]")
    _type_in_place(page, "I0.5")
    page.click("#draw-palette [data-add='=']")
    _type_in_place(page, "Q0.5")
    _wait_stl(page, "LD     I0.5\n=      Q0.5\n")
    assert editor_text(page).endswith("=      Q0.2\nNetwork 3\nLD     I0.5\n=      Q0.5\n"
                                "END_ORGANIZATION_BLOCK\n")
    assert page.errors == []


def test_operands_with_markup_stay_text(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    _open_drawing(page, served, "OB1/1")
    page.click("#draw-palette [data-add=NO]")
    _type_in_place(page, "<img src=x onerror=window.pwned=1>")
    page.click("#draw-palette [data-add='=']")
    _type_in_place(page, "Q0.0")
    # refused by the model (no such operand), said as text
    page.wait_for_function("() => document.querySelector('#draw-status').className === 'error'")
    assert page.evaluate("() => window.pwned") is None
    assert page.locator("#draw img").count() == 0
    assert path.read_text() == PROGRAM
    assert page.errors == []


def test_a_page_of_another_origin_cannot_draw(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    served = serve(panel=panel)
    seen = posts_from_another_origin(page, served.url, [
        "ladder/" + route for route in ("networks", "open", "edit", "undo", "redo")])
    assert seen == {"networks": 403, "open": 403, "edit": 403, "undo": 403, "redo": 403}


def test_change_move_and_add_a_box_with_the_keyboard(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    path.write_text(PROGRAM.replace("Network 1 // Seal-in\n",
                                    "Network 1 // Seal-in\nLD     Start\nA      Stop\n"
                                    "=      Motor\n"))
    served = serve(panel=panel)
    _open_drawing(page, served, "OB1/1")
    _wait_stl(page, "LD     Start\nA      Stop\n=      Motor\n")
    page.locator("#draw-rung .lad-el[aria-label='NO Stop']").click()
    page.keyboard.press("Shift+?")          # Shift with a palette key: change the kind
    _wait_stl(page, "LD     Start\nAN     Stop\n=      Motor\n")
    assert _selected(page) == "NC Stop"
    page.keyboard.press("Alt+ArrowLeft")    # move it before Start
    _wait_stl(page, "LDN    Stop\nA      Start\n=      Motor\n")
    assert _selected(page) == "NC Stop"
    page.keyboard.press("ArrowRight")
    page.keyboard.press("ArrowRight")
    assert _selected(page) == "= Motor"
    page.keyboard.press("Shift+S")          # the coil becomes a set coil, one bit
    _wait_stl(page, "LDN    Stop\nA      Start\nS      Motor, 1\n")
    page.select_option("#draw-box", "TON")
    page.focus("#draw-rung")
    page.keyboard.press("b")
    _type_in_place(page, "T37, +50")
    _wait_stl(page, "LDN    Stop\nA      Start\nS      Motor, 1\nTON    T37, +50\n")
    assert page.locator("#draw-rung .lad-el.box .lad-pin").all_text_contents() == [
        "T37", "PT +50"]
    # a refused operand says why and changes nothing
    page.keyboard.press("Enter")
    page.wait_for_selector("#draw-rung input.lad-input")
    page.keyboard.press("Control+a")
    page.keyboard.type("T37, VW1, VW2")
    page.keyboard.press("Enter")
    page.wait_for_function("() => document.querySelector('#draw-status').className === 'error'")
    assert "TON    T37, +50" in editor_text(page)
    page.focus("#draw-rung")
    for _ in range(4):
        page.keyboard.press("Control+z")
    _wait_stl(page, "LD     Start\nA      Stop\n=      Motor\n")
    assert page.locator("#draw-undo").is_disabled()
    assert page.errors == []


def test_elements_are_moved_with_the_mouse(serve, page, tmp_path) -> None:
    panel, path = _panel(tmp_path)
    path.write_text(PROGRAM.replace("Network 1 // Seal-in\n",
                                    "Network 1 // Seal-in\nLD     Start\nA      Stop\n"
                                    "A      I0.2\n=      Motor\nS      Q0.3, 1\n"))
    served = serve(panel=panel)
    _open_drawing(page, served, "OB1/1")
    _wait_stl(page, "LD     Start\nA      Stop\nA      I0.2\n=      Motor\nS      Q0.3, 1\n")
    el = "#draw-rung .lad-el[aria-label='{}']"
    # Start onto the right half of I0.2: after it
    box = page.locator(el.format("NO I0.2")).bounding_box()
    page.drag_and_drop(el.format("NO Start"), el.format("NO I0.2"),
                       target_position={"x": box["width"] - 3, "y": box["height"] / 2})
    _wait_stl(page, "LD     Stop\nA      I0.2\nA      Start\n=      Motor\nS      Q0.3, 1\n")
    # the set coil onto the left half of the output coil: before it
    page.drag_and_drop(el.format("S Q0.3, 1"), el.format("= Motor"),
                       target_position={"x": 3, "y": 5})
    _wait_stl(page, "LD     Stop\nA      I0.2\nA      Start\nS      Q0.3, 1\n=      Motor\n")
    assert _selected(page) == "S Q0.3, 1"
    # a coil dropped among contacts is refused, nothing changes
    page.drag_and_drop(el.format("= Motor"), el.format("NO Stop"))
    page.wait_for_function("() => document.querySelector('#draw-status').className === 'warning'")
    assert "S      Q0.3, 1\n=      Motor" in editor_text(page)
    assert page.errors == []
