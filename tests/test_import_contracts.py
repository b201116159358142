"""The one-way house: the import contracts in pyproject.toml hold.

``lint-imports`` (import-linter) reads the contracts under
``[tool.importlinter]`` in pyproject.toml: plcrt is a stack of layers, each
module may import only what lies on a lower line, and packages on one line
(``plcrt.debug | plcrt.web``) do not import each other.  Every import
counts, also those inside functions.  docs/architecture.md, "Layers", says
why the layers are in this order.

The second test shows that the contracts can fail: the same contracts run
over a copy of plcrt in which the engine imports the browser panel.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT = Path(sys.executable).parent / "lint-imports"

pytestmark = pytest.mark.skipif(not LINT.exists(), reason="import-linter is not installed "
                                "(it comes with the test extra: make test)")


def _lint(root: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=str(root))
    return subprocess.run([str(LINT), "--no-cache", "--config", str(root / "pyproject.toml")],
                          cwd=root, env=env, capture_output=True, text=True, timeout=120)


def test_the_import_contracts_hold() -> None:
    done = _lint(ROOT)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    assert "0 broken" in done.stdout


def test_an_import_that_climbs_breaks_the_contracts(tmp_path: Path) -> None:
    shutil.copytree(ROOT / "plcrt", tmp_path / "plcrt",
                    ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    clock = tmp_path / "plcrt" / "engine" / "clock.py"
    clock.write_text(clock.read_text(encoding="utf-8") + "\nfrom ..web import server  # noqa\n",
                     encoding="utf-8")
    done = _lint(tmp_path)
    assert done.returncode != 0
    assert "plcrt.engine is not allowed to import plcrt.web" in done.stdout
    assert "plcrt.engine.clock -> plcrt.web.server" in done.stdout
