"""The import graph of plcrt.lang: one way only, and no module over 500 lines.

plcrt.lang is the front end, below the compiler: its modules import each
other and the ground below them (plcrt.errors, plcrt.safetext and
plcrt.paths, the checks of file names), and nothing else of plcrt.  Among
themselves they form no cycle (the two parsers share their tables through
plcrt.lang.stltext, below both).  Every import counts, also one inside a
function or under TYPE_CHECKING: the graph is read from the source with ast.
"""

from __future__ import annotations

import ast
from pathlib import Path

LANG = Path(__file__).resolve().parents[2] / "plcrt" / "lang"
BELOW = {"plcrt.errors", "plcrt.safetext", "plcrt.paths"}


def _imports(path: Path, package: bool) -> set[str]:
    """The plcrt modules (or packages) that the file at ``path`` imports;
    ``from . import x`` names the submodule ``x``."""
    mod = "plcrt.lang" if package else f"plcrt.lang.{path.stem}"
    base = mod.split(".") if package else mod.split(".")[:-1]
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("plcrt"))
        elif isinstance(node, ast.ImportFrom):
            src = node.module or ""
            if node.level:
                src = ".".join(base[:len(base) - node.level + 1] + ([src] if src else []))
            if src.startswith("plcrt"):
                out.update(f"{src}.{a.name}" if src == "plcrt.lang" else src
                           for a in node.names)
    out.discard(mod)
    return out


def _graph() -> dict[str, set[str]]:
    graph = {}
    for path in sorted(LANG.glob("*.py")):
        package = path.name == "__init__.py"
        graph["plcrt.lang" if package else f"plcrt.lang.{path.stem}"] = _imports(path, package)
    return graph


def _on_a_cycle(graph: dict[str, set[str]]) -> set[str]:
    """The modules from which an import path leads back to themselves."""
    def reach(start: str) -> set[str]:
        seen: set[str] = set()
        todo = list(graph.get(start, ()))
        while todo:
            m = todo.pop()
            if m not in seen:
                seen.add(m)
                todo.extend(graph.get(m, ()))
        return seen

    return {m for m in graph if m in reach(m)}


def test_lang_imports_only_itself_and_the_ground() -> None:
    graph = _graph()
    up = sorted(f"{m} -> {t}" for m, ts in graph.items() for t in ts
                if t not in BELOW and not t.startswith("plcrt.lang"))
    assert up == []


def test_no_import_cycle_in_lang() -> None:
    assert _on_a_cycle(_graph()) == set()


def test_the_parsers_share_their_tables_from_below() -> None:
    graph = _graph()
    assert "plcrt.lang.stl" not in graph["plcrt.lang.fastparse"]
    assert "plcrt.lang.stltext" in graph["plcrt.lang.fastparse"]
    assert "plcrt.lang.stltext" in graph["plcrt.lang.stl"]


def test_the_cycle_finder_finds_a_cycle() -> None:
    # the helper the test above relies on, on a graph with one cycle and a tail
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set()}
    assert _on_a_cycle(graph) == {"a", "b", "c"}


def test_lang_modules_stay_under_500_lines() -> None:
    long = {}
    for path in LANG.rglob("*.py"):
        lines = sum(1 for line in path.read_text(encoding="utf-8").splitlines()
                    if line.strip())
        if lines > 500:
            long[path.name] = lines
    assert long == {}
