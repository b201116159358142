"""The view's modules: none over 500 non-blank lines, none on an import
cycle, and the editable ladder model imports one way: model <- STL <- checks
<- edits, and nothing of the drawing (rich, render) or of the running PLC
(status).  Every import counts (the graph is read with ast)."""

from __future__ import annotations

from import_graph import PLCRT, cycles, graph, long_modules

#: the editing model's modules -> the modules of plcrt.view each may import
EDITING = {
    "ladder_model": set(),
    "ladder_stl": {"ladder", "ladder_model"},
    "ladder_check": {"ladder_model", "ladder_stl"},
    "ladder_edit": {"ladder", "ladder_model", "ladder_stl", "ladder_check"},
}


def test_no_module_of_the_view_is_over_500_lines() -> None:
    assert long_modules(PLCRT / "view") == {}


def test_no_module_of_the_view_is_on_an_import_cycle() -> None:
    assert sorted(m for c in cycles(graph()) for m in c if m.startswith("plcrt.view")) == []


def test_the_editing_model_imports_one_way() -> None:
    g = graph()
    wrong = {}
    for module, allowed in EDITING.items():
        view = {t.removeprefix("plcrt.view.") for t in g[f"plcrt.view.{module}"]
                if t.startswith("plcrt.view.")}
        if view - allowed:
            wrong[module] = sorted(view - allowed)
    assert wrong == {}
