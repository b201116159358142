"""README.md, "Your first ladder test": its three commands lead from a clone
to a passing pytest run of a ladder program.

The commands are taken from the README itself and run with bash in a
temporary folder that shows the repository's files.  Two substitutions keep
the test from building a new virtualenv: ``make setup`` is dropped (this
interpreter already has plcrt, pytest and the plugin installed, as the
README's .venv would) and ``.venv/bin/pytest`` becomes
``sys.executable -m pytest``.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from doc_blocks import ROOT, blocks, mirror

SECTION = "## Your first ladder test"


def _first_test_script() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    start = text.index(SECTION)
    line = text.count("\n", 0, start) + 1
    block = next(b for b in blocks(ROOT / "README.md") if b.line > line and b.lang == "sh")
    assert block.lines[0].startswith("make setup"), block.where
    assert block.lines[-1] == ".venv/bin/pytest mytests", block.where
    return "\n".join(block.lines[1:-1] + (f'"{sys.executable}" -m pytest -p no:cacheprovider '
                                          f"mytests",))


def test_first_ladder_test_passes_in_a_fresh_folder(tmp_path: Path) -> None:
    mirror(tmp_path)
    if (tmp_path / "mytests").is_symlink():
        (tmp_path / "mytests").unlink()     # a mytests/ of the clone is not the README's
    result = subprocess.run(["bash", "-e", "-c", _first_test_script()], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stdout
    assert "2 passed" in result.stdout, result.stdout
    assert (tmp_path / "mytests" / "test_seal_in.py").is_file()
