"""The block registry (plcrt.blocks) and the loader it is handed.

The registry sits below the devices that implement the library blocks: it
never imports them, ``import plcrt`` hands it the import of
plcrt.devices.libraries as a loader, and the loader runs when a call first
needs the table (not with ``import plcrt``).
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

from plcrt import blocks

ROOT = Path(__file__).resolve().parents[2]

_PROBE = """
import json, sys
import plcrt
from plcrt.blocks import BLOCK_FACTORIES, PROTECTED, load_libraries
from plcrt.blocks.interface import interfaces
before = sorted(m for m in sys.modules if m.startswith("plcrt.devices"))
load_libraries()
print(json.dumps({"before": before,
                  "missing": sorted(set(interfaces()) - set(BLOCK_FACTORIES)),
                  "unknown": sorted(set(BLOCK_FACTORIES) - set(interfaces())),
                  "protected": sorted(PROTECTED),
                  "loaded": sorted(m for m in sys.modules if m.startswith("plcrt.devices"))}))
"""


@pytest.fixture(scope="module")
def fresh() -> dict:
    """What a new process sees before and after load_libraries()."""
    out = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True,
                         cwd=ROOT, timeout=120, check=True)
    return json.loads(out.stdout)


def test_import_plcrt_does_not_import_the_devices(fresh: dict) -> None:
    assert fresh["before"] == []


def test_the_loader_import_plcrt_hands_over_registers_every_library_block(fresh: dict) -> None:
    assert fresh["missing"] == [] and fresh["unknown"] == []
    assert {"MBUS_CTRL", "MBUS_SLAVE", "USS_INIT", "PTO0_CTRL"} <= set(fresh["protected"])


def test_every_module_that_registers_blocks_is_loaded(fresh: dict) -> None:
    # a module of plcrt.devices that calls register_block / register_protected
    # must be reached from plcrt.devices.libraries, or its blocks are missing
    registering = set()
    for path in (ROOT / "plcrt" / "devices").rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        if any(isinstance(n, ast.Name) and n.id in ("register_block", "register_protected")
               for n in ast.walk(tree)):
            parts = path.relative_to(ROOT).with_suffix("").parts
            registering.add(".".join(parts))
    assert "plcrt.devices.em253.pos_run" in registering
    assert sorted(registering - set(fresh["loaded"])) == []


def test_a_loader_runs_once_and_again_after_it_raised(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(blocks, "_PENDING", [])
    calls: list[str] = []

    def good() -> None:
        calls.append("good")

    def flaky() -> None:
        calls.append("flaky")
        if calls.count("flaky") == 1:
            raise RuntimeError("not yet")

    blocks.add_library_loader(good)
    blocks.add_library_loader(flaky)
    with pytest.raises(RuntimeError):
        blocks.load_libraries()
    blocks.load_libraries()
    blocks.load_libraries()
    assert calls == ["good", "flaky", "flaky"]
