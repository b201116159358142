"""The panel's modules: each one part, none over 500 non-blank lines, imports
one way only.

The runner's parts (run modes, pacing, builds and breakpoints, watch table,
trend, the program's drawing) import nothing of the session that composes
them, of the server or of each other (the pacing, shared with the network
servers' runner, lives in plcrt.net);
no module of plcrt.web is on an import cycle; the panel never imports the
debugger.  Every import counts, also one inside a function or under
TYPE_CHECKING (the graph is read from the source with ast).
"""

from __future__ import annotations

from import_graph import PLCRT, cycles, graph, long_modules

WEB = PLCRT / "web"

#: the parts PanelSession composes -> the modules of plcrt.web each may import
PARTS = {
    "running": set(),
    "builds": set(),
    "watch": {"present", "protocol"},
    "trend": {"protocol"},
    "program": {"present", "svg"},
}


def test_no_module_of_the_panel_is_over_500_lines() -> None:
    assert long_modules(WEB) == {}


def test_the_runners_parts_import_only_what_lies_below_them() -> None:
    g = graph()
    wrong = {}
    for part, allowed in PARTS.items():
        web = {t.removeprefix("plcrt.web.") for t in g[f"plcrt.web.{part}"]
               if t.startswith("plcrt.web.")}
        if web - allowed:
            wrong[part] = sorted(web - allowed)
    assert wrong == {}


def test_no_module_of_the_panel_is_on_an_import_cycle() -> None:
    on_cycle = sorted(m for c in cycles(graph()) for m in c if m.startswith("plcrt.web"))
    assert on_cycle == []


def test_the_panel_never_imports_the_debugger() -> None:
    g = graph()
    up = sorted(f"{m} -> {t}" for m, ts in g.items() if m.startswith("plcrt.web")
                for t in ts if t == "plcrt.debug" or t.startswith("plcrt.debug."))
    assert up == []


def test_the_graph_sees_imports_inside_functions() -> None:
    # the checks above rely on it: plcrt.web.cli imports the command-line
    # options (plcrt.term.options) only inside its functions (the command
    # line starts without the panel)
    assert "plcrt.term.options" in graph()["plcrt.web.cli"]
