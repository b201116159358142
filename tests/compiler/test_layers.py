"""The compiler's three layers import only downwards (docs/architecture.md,
"The instruction registry"): ``plcrt.compiler`` -> ``plcrt.isa`` ->
``plcrt.gen`` -> ``plcrt.lang`` / ``plcrt.memory`` -> ``plcrt.errors`` /
``plcrt.safetext``, and none of their modules is over 500 non-blank lines.

Every import statement counts, also those inside functions and under
``TYPE_CHECKING``: the test reads the source, it does not import it.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2] / "plcrt"

#: package -> the plcrt packages (and top-level modules) its modules may import
ALLOWED = {
    "compiler": {"compiler", "isa", "gen", "lang", "memory", "errors", "safetext"},
    "isa": {"isa", "gen", "lang", "memory", "errors", "safetext"},
    "gen": {"gen", "lang", "memory", "errors", "safetext"},
    "memory": {"memory", "errors", "safetext"},
}


def _modules(package: str) -> list[Path]:
    return sorted((ROOT / package).rglob("*.py"))


def _imported(path: Path) -> set[str]:
    """The plcrt packages (first name below ``plcrt``) that *path* imports."""
    rel = path.relative_to(ROOT.parent).with_suffix("").parts
    base = list(rel[:-1])          # the package the module is in
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = base[:len(base) - (node.level - 1)]
                full = ".".join(parts + ([node.module] if node.module else []))
            else:
                full = node.module or ""
            # ``from . import cache``, ``from .. import isa``: the names are modules
            names = [full] if node.module else [f"{full}.{a.name}" for a in node.names]
        else:
            continue
        for name in names:
            parts = name.split(".")
            if parts[0] == "plcrt" and len(parts) > 1:
                out.add(parts[1])
    return out


@pytest.mark.parametrize("package", sorted(ALLOWED))
def test_layers_import_only_downwards(package: str) -> None:
    wrong = {f"{p.relative_to(ROOT.parent)}: {sorted(_imported(p) - ALLOWED[package])}"
             for p in _modules(package) if _imported(p) - ALLOWED[package]}
    assert sorted(wrong) == []


@pytest.mark.parametrize("package", ["compiler", "isa", "gen"])
def test_no_module_is_over_500_lines(package: str) -> None:
    long = {str(p.relative_to(ROOT.parent)): n for p in _modules(package)
            if (n := sum(1 for line in p.read_text(encoding="utf-8").splitlines()
                         if line.strip())) > 500}
    assert long == {}


def test_the_registry_is_full_after_importing_it_alone() -> None:
    """The families register when the package is imported; the registry
    imports none of them (no cycle inside plcrt.isa)."""
    import subprocess
    import sys
    code = ("from plcrt.isa.registry import lookup, REGISTRY; "
            "print(lookup('INCW') is not None, len(REGISTRY) > 200)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.split() == ["True", "True"]
    registry = ROOT / "isa" / "registry.py"
    imported = {n.module for n in ast.walk(ast.parse(registry.read_text(encoding="utf-8")))
                if isinstance(n, ast.ImportFrom)}
    assert "families" not in imported and None not in imported
