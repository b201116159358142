"""The panel's modules: each one part, none over 500 non-blank lines, imports
one way only.

The runner's parts (run modes, pacing, builds and breakpoints, watch table,
trend, the program's drawing) import nothing of the session that composes
them, of the server or of each other (except the run modes their pacing);
no module of plcrt.web is on an import cycle; the panel never imports the
debugger.  Every import counts, also one inside a function or under
TYPE_CHECKING (the graph is read from the source with ast).
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

PLCRT = Path(__file__).resolve().parents[2] / "plcrt"
WEB = PLCRT / "web"

#: the parts PanelSession composes -> the modules of plcrt.web each may import
PARTS = {
    "running": {"pacing"},
    "pacing": set(),
    "builds": set(),
    "watch": {"present", "protocol"},
    "trend": {"protocol"},
    "program": {"present", "svg"},
}


def _module(path: Path) -> str:
    parts = list(path.relative_to(PLCRT.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@cache
def _graph() -> dict[str, set[str]]:
    """Module -> the plcrt modules it imports (relative imports resolved;
    ``from package import name`` is the submodule when there is one); read
    once (the tests do not change it)."""
    paths = {_module(p): p for p in PLCRT.rglob("*.py")}

    def known(name: str) -> str | None:
        parts = name.split(".")
        while parts and ".".join(parts) not in paths:
            parts.pop()
        return ".".join(parts) or None

    graph: dict[str, set[str]] = {}
    for mod, path in paths.items():
        package = path.name == "__init__.py"
        base = mod.split(".") if package else mod.split(".")[:-1]
        edges = graph[mod] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [known(a.name) for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                src = node.module or ""
                if node.level:
                    src = ".".join(base[:len(base) - node.level + 1] + ([src] if src else []))
                targets = [known(f"{src}.{a.name}") or known(src) for a in node.names]
            else:
                continue
            edges.update(t for t in targets if t is not None and t != mod)
    return graph


def _reaches(graph: dict[str, set[str]], start: str) -> set[str]:
    seen: set[str] = set()
    todo = [start]
    while todo:
        for t in graph.get(todo.pop(), ()):
            if t not in seen:
                seen.add(t)
                todo.append(t)
    return seen


def test_no_module_of_the_panel_is_over_500_lines() -> None:
    long = {}
    for path in WEB.rglob("*.py"):
        lines = sum(1 for line in path.read_text(encoding="utf-8").splitlines() if line.strip())
        if lines > 500:
            long[path.name] = lines
    assert long == {}


def test_the_runners_parts_import_only_what_lies_below_them() -> None:
    graph = _graph()
    wrong = {}
    for part, allowed in PARTS.items():
        web = {t.removeprefix("plcrt.web.") for t in graph[f"plcrt.web.{part}"]
               if t.startswith("plcrt.web.")}
        if web - allowed:
            wrong[part] = sorted(web - allowed)
    assert wrong == {}


def test_no_module_of_the_panel_is_on_an_import_cycle() -> None:
    graph = _graph()
    on_cycle = sorted(m for m in graph if m.startswith("plcrt.web") and m in _reaches(graph, m))
    assert on_cycle == []


def test_the_panel_never_imports_the_debugger() -> None:
    graph = _graph()
    up = sorted(f"{m} -> {t}" for m, ts in graph.items() if m.startswith("plcrt.web")
                for t in ts if t == "plcrt.debug" or t.startswith("plcrt.debug."))
    assert up == []


def test_the_graph_sees_imports_inside_functions() -> None:
    # the checks above rely on it: plcrt.web.cli imports the command-line
    # options (plcrt.term.options) only inside its functions (the command
    # line starts without the panel)
    assert "plcrt.term.options" in _graph()["plcrt.web.cli"]
