"""The plant's machines in the page (static/machines.js), in headless
Chromium: the conveyor example served as ``plcrt serve
examples/machines/conveyor.awl --plant examples/machines/conveyor.toml``
starts it; the parts move, a button of the machine reaches the PLC, a
teacher's fault switch shows on the drawing, and a stopped conveyor at a
fixed simulated time looks like golden/conveyor.png.

Also the server side without a browser: what a frame carries of a
machine's state (cleaned: numbers, booleans, short names) and the
``machine`` message's checks.
"""

from __future__ import annotations

import json
import time

import pytest

import plcrt
from plcrt.web.machines import MAX_ITEMS, clean
from plcrt.web.protocol import ProtocolError, validate
from plcrt.web.session import PanelSession

from .conftest import REPO, matches_golden

AWL = REPO / "examples" / "machines" / "conveyor.awl"
TOML = REPO / "examples" / "machines" / "conveyor.toml"


def conveyor() -> plcrt.Plc:
    return plcrt.load(str(AWL), plant=str(TOML))


def open_machines(page, served) -> None:
    page.goto(served.url)
    page.wait_for_selector("[data-machine=conveyor] svg.machine-svg")
    page.wait_for_function("() => window.plcrtPanel.frame !== null && "
                           "window.plcrtPanel.frame.machines.length === 1")


def machine_frame(page) -> dict:
    return page.evaluate("() => window.plcrtPanel.frame.machines[0]")


# ---------------------------------------------------------------- no browser
def test_the_frame_carries_the_machine_state_and_the_hello_its_buttons_and_faults() -> None:
    plc = conveyor()
    s = PanelSession(plc)
    info = s.hello()["machines"]
    assert info[0]["name"] == "conveyor" and info[0]["buttons"] == ["start", "stop"]
    assert "jam" in info[0]["faults"] and "stuck_on:eye_entry" in info[0]["faults"]
    s.apply(validate({"type": "machine", "machine": "conveyor", "action": "press",
                      "name": "start"}))
    plc.run(seconds=2)
    st = s.frame()["machines"][0]
    assert st == json.loads(json.dumps(plc.machine("conveyor").state()))
    assert st["outputs"]["motor"] == 1 and st["parts"]


def test_clean_keeps_only_numbers_booleans_and_short_names() -> None:
    hostile = {"ok": 1, "<b>x</b>": 2, "name": "<script>", "f": float("nan"),
               "list": list(range(MAX_ITEMS + 10)), "deep": [[[[[1]]]]], "big": 2 ** 60,
               "obj": object(), "fine": ["stuck_on:eye_entry", True, None, 1.5]}
    out = clean(hostile)
    assert "<b>x</b>" not in out and out["ok"] == 1
    assert out["name"] is None and out["f"] is None and out["big"] is None and out["obj"] is None
    assert len(out["list"]) == MAX_ITEMS and out["deep"] == [[[None]]]
    assert out["fine"] == ["stuck_on:eye_entry", True, None, 1.5]


@pytest.mark.parametrize("msg", [
    {"type": "machine", "machine": "conveyor", "action": "explode", "name": "start"},
    {"type": "machine", "machine": "conveyor", "action": "press"},
    {"type": "machine", "machine": "x" * 500, "action": "press", "name": "start"},
    {"type": "machine", "machine": "conveyor", "action": "press", "name": 3},
])
def test_a_bad_machine_message_is_refused(msg) -> None:
    with pytest.raises(ProtocolError):
        validate(msg)


def test_an_unknown_machine_button_or_fault_is_an_error_for_the_page() -> None:
    s = PanelSession(conveyor())
    for machine, action, name in (("belt", "press", "start"), ("conveyor", "press", "go"),
                                  ("conveyor", "fault_on", "melt")):
        s.last_error = None
        s.apply(validate({"type": "machine", "machine": machine, "action": action,
                          "name": name}))
        assert s.last_error is not None and s.last_error["request"] == "machine"


# ---------------------------------------------------------------- browser
def test_the_conveyor_animates_and_its_start_button_reaches_the_plc(serve, page) -> None:
    served = serve(conveyor())
    open_machines(page, served)
    assert machine_frame(page)["outputs"]["motor"] == 0
    page.click("[data-machine=conveyor] button[data-button=start]")
    page.click("#run")
    # the program latches the motor on start (Q0.0), as the PLC sees it
    page.wait_for_function("() => window.plcrtPanel.frame.io['Q0.0'] === 1 && "
                           "window.plcrtPanel.frame.machines[0].outputs.motor === 1")
    page.wait_for_selector("[data-machine=conveyor] rect[data-part]")
    part = page.locator("[data-machine=conveyor] rect[data-part]").first
    pid = part.get_attribute("data-part")
    x0 = float(part.get_attribute("x"))
    page.wait_for_function(
        "([id, x0]) => { const r = document.querySelector("
        "'[data-machine=conveyor] rect[data-part=\"' + id + '\"]');"
        " return r && parseFloat(r.getAttribute('x')) > x0 + 5; }", arg=[pid, x0])
    assert page.errors == []


def test_the_machines_are_drawn_when_the_hello_comes_before_machines_js(serve, page) -> None:
    """machines.js is a deferred script: a hello (and frames) handled by
    panel.js before it runs are drawn when it does (the script is held
    back here until the hello has certainly come)."""
    served = serve(conveyor())
    # notes, as machines.js starts, whether panel.js already had the hello
    page.add_init_script("""Object.defineProperty(window, 'plcrtMachines', {
        configurable: true, get() { return this._m; },
        set(v) { this._m = v; this.helloFirst = !!(window.plcrtPanel && window.plcrtPanel.hello); }
    });""")
    page.route("**/static/machines.js", lambda route: (time.sleep(1.5), route.continue_()))
    open_machines(page, served)
    assert page.evaluate("() => window.helloFirst") is True
    assert machine_frame(page)["outputs"]["motor"] == 0
    assert page.errors == []


def test_a_teacher_switches_on_a_stuck_eye_and_the_machine_shows_it(serve, page) -> None:
    served = serve(conveyor())
    open_machines(page, served)
    eye = page.locator("[data-machine=conveyor] circle[data-eye=eye_entry]")
    assert "lit" not in (eye.get_attribute("class") or "")
    page.click("[data-machine=conveyor] details.machine-teacher summary")
    page.check("[data-machine=conveyor] input[data-fault='stuck_on:eye_entry']")
    page.click("#step")
    page.wait_for_function("() => window.plcrtPanel.frame.machines[0].faults"
                           ".includes('stuck_on:eye_entry') && "
                           "window.plcrtPanel.frame.io['I0.0'] === 1")
    page.wait_for_function("() => { const c = document.querySelector("
                           "'[data-machine=conveyor] circle[data-eye=eye_entry]').classList;"
                           " return c.contains('lit') && c.contains('faulty'); }")
    assert "stuck_on:eye_entry" in page.locator(
        "[data-machine=conveyor] .machine-faults").inner_text()
    page.uncheck("[data-machine=conveyor] input[data-fault='stuck_on:eye_entry']")
    page.wait_for_function("() => window.plcrtPanel.frame.machines[0].faults.length === 0")


def test_the_conveyor_screenshot_matches_the_reference(serve, page) -> None:
    """Started and run 7.3 s of simulated time before the page opens, the
    PLC stopped: the drawing is a function of that state only (mean
    absolute difference and share of differing pixels, as the ladder's)."""
    plc = conveyor()
    plc.machine("conveyor").press("start")
    plc.run(seconds=7.3)
    served = serve(plc)
    open_machines(page, served)
    page.wait_for_selector("[data-machine=conveyor] rect[data-part]")
    page.wait_for_timeout(200)
    matches_golden(page.locator("[data-machine=conveyor] svg.machine-svg"), "conveyor")


# kind -> (buttons held / pressed before the page opens, a JS check of the
# drawing that holds only when the drawing follows that state)
OTHERS = {
    "tank": (["start"], "+document.querySelector('[data-machine=tank] rect.water')"
                        ".getAttribute('height') > 1"),
    "traffic": ([], "document.querySelector('[data-machine=traffic] "
                    "circle[data-lamp=main_green]').classList.contains('lit') && "
                    "document.querySelector('[data-machine=traffic] "
                    "circle[data-lamp=side_red]').classList.contains('lit') && "
                    "!document.querySelector('[data-machine=traffic] "
                    "circle[data-lamp=side_green]').classList.contains('lit')"),
    "garage": (["key", "button_open"],
               "+document.querySelector('[data-machine=garage] rect.door')"
               ".getAttribute('height') < 110"),
    "elevator": (["call_3"], "!document.querySelector('[data-machine=elevator] g.car')"
                             ".getAttribute('transform').includes('translate(0 100.00)')"),
}


@pytest.mark.parametrize("kind", sorted(OTHERS))
def test_each_machine_is_drawn_from_its_state(serve, page, kind) -> None:
    """Each example machine, run 4 s after its buttons, is drawn as its
    state says (the tank has water, the main road green and the side road
    red, the garage door up, the elevator car away from floor 1)."""
    plc = plcrt.load(str(REPO / "examples/machines" / f"{kind}.awl"),
                     plant=str(REPO / "examples/machines" / f"{kind}.toml"))
    m = plc.machine(kind)
    buttons, check = OTHERS[kind]
    for b in buttons:
        (m.hold if b == "key" else m.press)(b)
    plc.run(seconds=4)
    served = serve(plc)
    page.goto(served.url)
    page.wait_for_selector(f"[data-machine={kind}] svg.machine-svg")
    page.wait_for_function("() => window.plcrtPanel.frame && "
                           "window.plcrtPanel.frame.machines.length === 1")
    page.wait_for_function("() => " + check)
    assert page.errors == []


# kind -> (buttons held / pressed, simulated seconds run before the page
# opens): a state that shows the machine's moving parts away from rest
GOLDEN_STATES = {
    "tank": (["start"], 6.0),
    "traffic": ([], 4.0),
    "garage": (["key", "button_open"], 4.0),
    "elevator": (["call_3"], 4.0),
}


@pytest.mark.parametrize("kind", sorted(GOLDEN_STATES))
def test_each_machine_screenshot_matches_its_reference(serve, page, kind) -> None:
    """Each example machine after its buttons and a fixed simulated time,
    the PLC stopped, looks like golden/KIND.png (the conveyor's tolerance)."""
    plc = plcrt.load(str(REPO / "examples/machines" / f"{kind}.awl"),
                     plant=str(REPO / "examples/machines" / f"{kind}.toml"))
    m = plc.machine(kind)
    buttons, seconds = GOLDEN_STATES[kind]
    for b in buttons:
        (m.hold if b == "key" else m.press)(b)
    plc.run(seconds=seconds)
    served = serve(plc)
    page.goto(served.url)
    page.wait_for_selector(f"[data-machine={kind}] svg.machine-svg")
    page.wait_for_function("() => window.plcrtPanel.frame && "
                           "window.plcrtPanel.frame.machines.length === 1")
    page.wait_for_function("() => " + OTHERS[kind][1])
    page.wait_for_timeout(200)
    matches_golden(page.locator(f"[data-machine={kind}] svg.machine-svg"), kind)
    assert page.errors == []
