"""The engine stays below the devices and the library blocks, and in modules
of a readable size.

Every import is counted, also those inside functions and under
TYPE_CHECKING: the engine reaches what the layers above supply only
through plcrt.parts (docs/architecture.md, "The load path").
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ENGINE = Path(__file__).resolve().parents[2] / "plcrt" / "engine"

#: packages and modules above the engine (or the composition root over all)
ABOVE = ("plcrt.devices", "plcrt.blocks", "plcrt.loader", "plcrt.testing", "plcrt.web",
         "plcrt.debug", "plcrt.cli", "plcrt.view", "plcrt.trace", "plcrt.cia402")


def _imports(path: Path) -> list[tuple[int, str]]:
    """(line, absolute module) of every import in *path*, wherever it is."""
    package = "plcrt.engine"
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            found += [(node.lineno, f"{module}.{a.name}") for a in node.names]
    return found


@pytest.mark.parametrize("path", sorted(ENGINE.glob("*.py")), ids=lambda p: p.name)
def test_the_engine_imports_nothing_above_it(path: Path) -> None:
    climbing = [(line, name) for line, name in _imports(path)
                if any(name == a or name.startswith(a + ".") for a in ABOVE)]
    assert climbing == [], f"{path.name} imports from above the engine: {climbing}"


@pytest.mark.parametrize("path", sorted(ENGINE.glob("*.py")), ids=lambda p: p.name)
def test_every_engine_module_is_at_most_500_lines(path: Path) -> None:
    lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip()]
    assert len(lines) <= 500, f"{path.name}: {len(lines)} non-blank lines"


def test_a_plc_built_by_the_engine_alone_is_fitted_with_devices_and_library_blocks() -> None:
    """Plc() straight from plcrt.engine.runtime, in a fresh interpreter that
    never touched plcrt.load: the parts come from the loader plcrt/__init__
    hands plcrt.parts (an EM253 module from the plant, a library block's CALL)."""
    root = ENGINE.parents[1]
    code = f"""
import plcrt.engine.runtime as rt
from plcrt.devices.plant import load_plant
prog = rt.parse_sources({str(root / "programs/em253/pos_goto_r.awl")!r})
plc = rt.Plc(prog, plant=load_plant({str(root / "programs/em253/plant.toml")!r}))
plc.scan(3)
print(type(plc.module(0)).__name__, len(plc.axes()), plc.diagnostics == [])
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["EM253Module", "2", "True"]
