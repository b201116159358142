"""README.md's Python examples run as written and print what they say.

The ``python`` blocks of the README run in order in one namespace (a later
block may use what an earlier one imported), from the repository root.  A
``print(...)`` line with a comment states its output: the comment is the
printed text, up to two spaces and a ``(`` that start a note
(``# 9 0   (100 ms ticks ...)`` expects ``9 0``).  A comment that is all
in parentheses (``# (the watched values)``) only describes the output.
"""

from __future__ import annotations

import builtins
import io
import re
import sys
import tokenize
from collections import defaultdict
from pathlib import Path

import pytest
from doc_blocks import ROOT, Block, blocks

README_BLOCKS = [b for b in blocks(ROOT / "README.md") if b.lang == "python"]
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
            builtins.print(*args, sep=sep, end=end, file=file, flush=flush)  # type: ignore[call-overload]
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


def test_readme_python_prints_what_its_comments_say(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    run = [b for b in README_BLOCKS if b.marker != "not run"]
    printed = run_blocks(run)
    for i, block in enumerate(run):
        for line, expected in stated_outputs(block).items():
            got = printed.get((i, line))
            assert got is not None, f"{block.where}, line {line}: nothing printed"
            assert got.rstrip("\n") == expected, (
                f"{block.where}, line {line} of the block: printed {got!r}, "
                f"the comment says {expected!r}")


def test_a_wrong_comment_fails(monkeypatch: pytest.MonkeyPatch) -> None:
    """The check compares: a block whose comment states another value fails."""
    monkeypatch.chdir(ROOT)
    block = Block(Path(ROOT / "README.md"), 0, "python",
                  ("x = 6 * 7", "print(x)   # 41  (a wrong answer)"), None, "")
    assert stated_outputs(block) == {2: "41"}
    assert run_blocks([block])[(0, 2)] == "42\n"
