"""The Python examples of README.md and docs/*.md run as written and print
what they say.

The ``python`` blocks of one file run in order in one namespace (a later
block may use what an earlier one imported), in a folder that shows the
repository's files (``doc_blocks.mirror``), so files they write stay out
of the clone.  A ``print(...)`` line with a comment states its output: the
comment is the printed text, up to two spaces and a ``(`` that start a
note (``# 9 0   (100 ms ticks ...)`` expects ``9 0``).  A comment that is
all in parentheses (``# (the watched values)``) only describes the output.
A block marked ``<!-- pytest module -->`` is a test module: pytest runs it
and its tests must pass.  ``<!-- not run: REASON -->`` leaves a block out.
"""

from __future__ import annotations

import builtins
import io
import re
import subprocess
import sys
import tokenize
from collections import defaultdict
from pathlib import Path

import pytest
from doc_blocks import ROOT, Block, blocks, mirror

FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
PYTHON = {path: [b for b in blocks(path) if b.lang == "python"] for path in FILES}
README_BLOCKS = PYTHON[ROOT / "README.md"]
RUN_FILES = [p for p, bs in PYTHON.items() if any(b.marker is None for b in bs)]
MODULES = [b for bs in PYTHON.values() for b in bs if b.marker == "pytest module"]
_NOTE = re.compile(r"\s{2,}\(.*$")


def stated_outputs(block: Block) -> dict[int, str]:
    """line in the block (1-based) -> the output its comment states."""
    source = "\n".join(block.lines) + "\n"
    out: dict[int, str] = {}
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type != tokenize.COMMENT:
            continue
        code = tok.line[:tok.start[1]].strip()
        text = tok.string[1:].strip()
        if code.startswith("print(") and not text.startswith("("):
            out[tok.start[0]] = _NOTE.sub("", text)
    return out


def run_blocks(run: list[Block]) -> dict[tuple[int, int], str]:
    """Execute the blocks; (block index, line) -> what print wrote there."""
    printed: dict[tuple[int, int], str] = defaultdict(str)
    names = {f"<{b.where}>": i for i, b in enumerate(run)}

    def recording_print(*args: object, sep: str | None = " ", end: str | None = "\n",
                        file: object = None, flush: bool = False) -> None:
        if file not in (None, sys.stdout):
            builtins.print(*args, sep=sep, end=end, file=file,  # type: ignore[call-overload]
                           flush=flush)
            return
        frame = sys._getframe(1)
        key = (names.get(frame.f_code.co_filename, -1), frame.f_lineno)
        printed[key] += (" " if sep is None else sep).join(map(str, args)) + (
            "\n" if end is None else end)

    namespace: dict[str, object] = {"__name__": "__readme__", "print": recording_print}
    for b in run:
        exec(compile("\n".join(b.lines) + "\n", f"<{b.where}>", "exec"), namespace)
    return printed


def test_readme_has_python_examples_with_stated_output() -> None:
    assert len(README_BLOCKS) >= 3
    assert sum(len(stated_outputs(b)) for b in README_BLOCKS) >= 6


@pytest.mark.parametrize("path", RUN_FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_python_examples_print_what_their_comments_say(
        path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(mirror(tmp_path))
    # a machine where no run has left machine code (a marked program is
    # native from its first scan: docs/native.md, "Tiers")
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path / "plcrt-cache"))
    run = [b for b in PYTHON[path] if b.marker is None]
    printed = run_blocks(run)
    for i, block in enumerate(run):
        for line, expected in stated_outputs(block).items():
            got = printed.get((i, line))
            assert got is not None, f"{block.where}, line {line}: nothing printed"
            assert got.rstrip("\n") == expected, (
                f"{block.where}, line {line} of the block: printed {got!r}, "
                f"the comment says {expected!r}")


@pytest.mark.parametrize("block", MODULES, ids=lambda b: b.where)
def test_pytest_module_examples_pass(block: Block, tmp_path: Path) -> None:
    work = mirror(tmp_path)
    (work / "test_doc_example.py").write_text("\n".join(block.lines) + "\n", encoding="utf-8")
    result = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                             "test_doc_example.py"], cwd=work, text=True, timeout=300,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    assert result.returncode == 0, f"{block.where}\n{result.stdout}"
    assert re.search(r"\b\d+ passed\b", result.stdout) and "skipped" not in result.stdout


def test_every_python_block_is_run_or_says_why() -> None:
    for blocks_of_file in PYTHON.values():
        for block in blocks_of_file:
            assert block.marker in (None, "pytest module", "not run"), block.where


def test_a_wrong_comment_fails(monkeypatch: pytest.MonkeyPatch) -> None:
    """The check compares: a block whose comment states another value fails."""
    monkeypatch.chdir(ROOT)
    block = Block(Path(ROOT / "README.md"), 0, "python",
                  ("x = 6 * 7", "print(x)   # 41  (a wrong answer)"), None, "")
    assert stated_outputs(block) == {2: "41"}
    assert run_blocks([block])[(0, 2)] == "42\n"
