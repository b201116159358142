"""The compiler's three layers import only downwards (docs/architecture.md,
"The instruction registry"): ``plcrt.compiler`` -> ``plcrt.isa`` ->
``plcrt.gen`` -> ``plcrt.lang`` / ``plcrt.memory`` -> ``plcrt.errors`` /
``plcrt.safetext``, and none of their modules is over 500 non-blank lines.

Every import statement counts, also those inside functions and under
``TYPE_CHECKING``: the graph is read from the source (tests/import_graph.py).
"""

from __future__ import annotations

import ast

import pytest
from import_graph import PLCRT as ROOT
from import_graph import graph, long_modules

#: package -> the plcrt packages (and top-level modules) its modules may import
ALLOWED = {
    "compiler": {"compiler", "isa", "gen", "lang", "memory", "errors", "safetext"},
    "isa": {"isa", "gen", "lang", "memory", "errors", "safetext"},
    "gen": {"gen", "lang", "memory", "errors", "safetext"},
    "memory": {"memory", "errors", "safetext"},
}


def _packages_imported(package: str) -> dict[str, set[str]]:
    """Module of ``plcrt.<package>`` -> the plcrt packages (first name below
    ``plcrt``) it imports that it may not."""
    out = {}
    for mod, targets in graph().items():
        if mod == f"plcrt.{package}" or mod.startswith(f"plcrt.{package}."):
            wrong = {t.split(".")[1] for t in targets if "." in t} - ALLOWED[package]
            if wrong:
                out[mod] = wrong
    return out


@pytest.mark.parametrize("package", sorted(ALLOWED))
def test_layers_import_only_downwards(package: str) -> None:
    assert _packages_imported(package) == {}


@pytest.mark.parametrize("package", ["compiler", "isa", "gen"])
def test_no_module_is_over_500_lines(package: str) -> None:
    assert long_modules(ROOT / package) == {}


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
