"""The import graph of the library blocks and the devices: one way only.

plcrt.blocks sits below plcrt.devices: the registry reads a table the
device libraries fill and never imports them; no module of plcrt.blocks,
plcrt.devices or the plcrt.cia402 facade is on an import cycle; nothing in
plcrt imports the facade; no module of either package is longer than 500
non-blank lines.  Every import counts, also one inside a function or under
TYPE_CHECKING (the graph is read from the source with ast).
"""

from __future__ import annotations

import ast
from pathlib import Path

PLCRT = Path(__file__).resolve().parents[2] / "plcrt"


def _modules() -> dict[str, tuple[Path, bool]]:
    """Module name -> (file, is a package)."""
    out = {}
    for path in PLCRT.rglob("*.py"):
        parts = list(path.relative_to(PLCRT.parent).with_suffix("").parts)
        package = parts[-1] == "__init__"
        if package:
            parts.pop()
        out[".".join(parts)] = (path, package)
    return out


def _graph() -> dict[str, set[str]]:
    """Module -> the plcrt modules it imports (relative imports resolved;
    ``from package import name`` is the submodule when there is one)."""
    mods = _modules()

    def known(name: str) -> str | None:
        parts = name.split(".")
        while parts and ".".join(parts) not in mods:
            parts.pop()
        return ".".join(parts) or None

    graph: dict[str, set[str]] = {}
    for mod, (path, package) in mods.items():
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


def _cycles(graph: dict[str, set[str]]) -> list[set[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out: list[set[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = set()
            while True:
                w = stack.pop()
                comp.add(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(comp)

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def _ours(mod: str) -> bool:
    return mod == "plcrt.cia402" or mod.split(".")[:2] in (["plcrt", "blocks"],
                                                           ["plcrt", "devices"])


def test_blocks_import_nothing_from_devices() -> None:
    graph = _graph()
    up = sorted(f"{m} -> {t}" for m, ts in graph.items() if m.startswith("plcrt.blocks")
                for t in ts if t.startswith("plcrt.devices") or t == "plcrt.cia402")
    assert up == []


def test_no_import_cycle_through_blocks_devices_or_the_cia402_facade() -> None:
    cycles = [sorted(c) for c in _cycles(_graph()) if any(_ours(m) for m in c)]
    assert cycles == []


def test_nothing_in_plcrt_imports_the_cia402_facade() -> None:
    graph = _graph()
    assert sorted(m for m, ts in graph.items() if "plcrt.cia402" in ts) == []


def test_the_cycle_finder_finds_a_cycle() -> None:
    # the helper the tests above rely on, on a graph with one cycle and a tail
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set()}
    assert _cycles(graph) == [{"a", "b", "c"}]


def test_modules_of_blocks_and_devices_stay_under_500_lines() -> None:
    long = {}
    for sub in ("blocks", "devices"):
        for path in (PLCRT / sub).rglob("*.py"):
            lines = sum(1 for line in path.read_text(encoding="utf-8").splitlines()
                        if line.strip())
            if lines > 500:
                long[str(path.relative_to(PLCRT))] = lines
    assert long == {}
