"""plcrt's import graph read from its source, for the tests that pin the
layers of one package (no cycle, nothing imported from above, no module
over 500 non-blank lines).

Every import counts, also one inside a function or under
``TYPE_CHECKING``: the graph is read with :mod:`ast`, relative imports
resolved, and ``from package import name`` is the submodule when there is
one.  The whole stack is checked by the import-linter contract
(tests/test_import_contracts.py); these helpers serve the finer rules of
single packages.
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

PLCRT = Path(__file__).resolve().parents[1] / "plcrt"


def _module(path: Path) -> str:
    parts = list(path.relative_to(PLCRT.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@cache
def graph() -> dict[str, frozenset[str]]:
    """Module -> the plcrt modules it imports; read once (the tests do not
    change the source)."""
    paths = {_module(p): p for p in PLCRT.rglob("*.py")}

    def known(name: str) -> str | None:
        parts = name.split(".")
        while parts and ".".join(parts) not in paths:
            parts.pop()
        return ".".join(parts) or None

    out: dict[str, frozenset[str]] = {}
    for mod, path in paths.items():
        base = mod.split(".") if path.name == "__init__.py" else mod.split(".")[:-1]
        edges: set[str] = set()
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
        out[mod] = frozenset(edges)
    return out


def cycles(edges: dict[str, frozenset[str]] | dict[str, set[str]]) -> list[set[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out: list[set[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in edges.get(v, ()):
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

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def long_modules(folder: Path, limit: int = 500) -> dict[str, int]:
    """The modules under ``folder`` with more than ``limit`` non-blank lines,
    by their path inside plcrt."""
    long = {}
    for path in folder.rglob("*.py"):
        lines = sum(1 for line in path.read_text(encoding="utf-8").splitlines() if line.strip())
        if lines > limit:
            long[str(path.relative_to(PLCRT))] = lines
    return long
