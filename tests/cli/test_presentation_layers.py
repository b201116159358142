"""The presentation packages import each other only downwards.

``plcrt.cli`` (with ``plcrt.cli_commands``) is the top: it dispatches to
the subcommands.  Below it the front ends ``plcrt.debug`` and ``plcrt.web``
are independent of each other; below them ``plcrt.testing``, then
``plcrt.view`` and ``plcrt.trace`` (independent of each other); and
``plcrt.term``, what every command-line front end shares, is below all of
them (docs/architecture.md, "Presentation").  Every import counts, also
one inside a function or under ``TYPE_CHECKING``; the package's ``cli``
modules count as part of their package.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2] / "plcrt"

#: presentation tiers, top first; packages in one tier do not import each other
TIERS = (("cli",), ("debug", "web"), ("testing",), ("view", "trace"), ("term",))
_TIER = {name: k for k, tier in enumerate(TIERS) for name in tier}


def _top(module: str) -> str | None:
    """The presentation package (or module) of ``plcrt.X...``, or None."""
    parts = module.split(".")
    if len(parts) < 2 or parts[0] != "plcrt":
        return None
    name = "cli" if parts[1].startswith("cli_") else parts[1]   # cli_commands is the CLI's
    return name if name in _TIER else None


def _imports(path: Path) -> list[tuple[str, int]]:
    """(imported plcrt module, line) of every import in the file."""
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    package = parts[:-1]   # of a package's __init__ too: the package itself
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(a.name, node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - (node.level - 1)]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            found.append((name, node.lineno))
            if name == "plcrt":   # from plcrt import cli
                found += [(f"plcrt.{a.name}", node.lineno) for a in node.names]
    return found


def _edges() -> list[tuple[str, str, str]]:
    out = []
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT.parent).with_suffix("")
        source = _top(".".join(rel.parts))
        if source is None:
            continue
        for name, line in _imports(path):
            target = _top(name)
            if target is not None and target != source:
                out.append((source, target, f"{'/'.join(rel.parts)}.py:{line} imports {name}"))
    return out


def test_the_tiers_name_existing_packages() -> None:
    for name in _TIER:
        assert (ROOT / name).is_dir() or (ROOT / f"{name}.py").is_file(), name


@pytest.mark.parametrize("tier", TIERS, ids=lambda t: "|".join(t))
def test_presentation_imports_go_down_only(tier: tuple[str, ...]) -> None:
    upward_or_sideways = [where for source, target, where in _edges()
                          if source in tier and _TIER[target] <= _TIER[source]]
    assert upward_or_sideways == []


def test_the_debugger_modules_form_no_import_cycle() -> None:
    """session (the interpreter) imports the commands; the commands act on
    debug.state and never import the session, directly or through base."""
    graph: dict[str, set[str]] = {}
    for path in (ROOT / "debug").glob("*.py"):
        graph[path.stem] = {name.rsplit(".", 1)[-1] for name, _ in _imports(path)
                            if name.startswith("plcrt.debug.")}

    def reaches(start: str, goal: str, seen: set[str]) -> bool:
        for nxt in graph.get(start, ()):
            if nxt == goal or (nxt not in seen and reaches(nxt, goal, seen | {nxt})):
                return True
        return False

    assert [m for m in graph if reaches(m, m, {m})] == []
