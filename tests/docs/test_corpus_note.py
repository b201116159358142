"""Without the shared corpus, pytest says in one line that (and why) the
corpus tests skipped, as README.md ("Running the tests") shows; with the
corpus, it says nothing.  The project's tests/conftest.py runs in a copy of
the layout: clone/tests/ beside shared/corpus.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

from doc_blocks import ROOT

TESTS = '''
import pytest

def test_reads_the_corpus():
    pytest.skip("corpus not found at ../shared/corpus")

def test_other_skip():
    pytest.skip("needs something else")

def test_plain():
    pass
'''
LINE = re.compile(r"^(\d+) corpus tests skipped: the real-file corpus is not at (\S+) "
                  r"\(README.md, 'Running the tests', says how to get them run\)$", re.M)


def _pytest(tmp_path: Path) -> str:
    clone = tmp_path / "clone"
    (clone / "tests").mkdir(parents=True)
    shutil.copy(ROOT / "tests" / "conftest.py", clone / "tests" / "conftest.py")
    (clone / "tests" / "test_x.py").write_text(TESTS, encoding="utf-8")
    result = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                             "--rootdir", str(clone), "tests"], cwd=clone, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=120)
    assert result.returncode == 0, result.stdout
    return result.stdout


def test_one_line_says_the_corpus_tests_skipped(tmp_path: Path) -> None:
    out = _pytest(tmp_path)
    found = LINE.findall(out)
    assert found == [("1", str(tmp_path / "shared" / "corpus"))], out
    assert "1 passed, 2 skipped" in out


def test_no_line_when_the_corpus_is_there(tmp_path: Path) -> None:
    (tmp_path / "shared" / "corpus").mkdir(parents=True)
    out = _pytest(tmp_path)
    assert "corpus tests skipped" not in out, out


def test_readme_shows_that_line() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert LINE.search(readme)
    assert "../shared/corpus" in readme
