"""The ladder pictures in the course READMEs are what ``plcrt show`` draws.

Every lesson README under ``examples/course/`` pastes the ladder view of
its program: its first ```text block must be exactly the output of
``plcrt show examples/course/<lesson>/lesson.awl``.  A README may also
show status pictures as ```console blocks whose first line is the command
(``$ plcrt show ... --status ...``, run from the repository root) and whose
other lines are its output; each of those is re-run and compared as well.
So a change of the program or of the view cannot leave a stale picture
behind.

To refresh the pictures after such a change, run from the repository root::

    .venv/bin/python tests/examples/test_course_pictures.py --update

and review the diff.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
COURSE = ROOT / "examples" / "course"
READMES = sorted(r for r in COURSE.glob("*/README.md") if (r.parent / "lesson.awl").is_file())

_FENCE_RE = re.compile(r"^```(\w*)[ \t]*\n(.*?)^```[ \t]*$", re.MULTILINE | re.DOTALL)
#: environment variables that would make rich style or wrap the output
_RICH_ENV = ("FORCE_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE", "COLUMNS", "LINES")


def blocks(text: str) -> list[tuple[str, str, int, int]]:
    """Fenced code blocks: (language, content, start, end of the content)."""
    return [(m.group(1), m.group(2), m.start(2), m.end(2)) for m in _FENCE_RE.finditer(text)]


def show(args: list[str]) -> str:
    """stdout of ``plcrt show ARGS`` run from the repository root."""
    from plcrt.cli import main

    out, err = io.StringIO(), io.StringIO()
    saved = {k: os.environ.pop(k) for k in _RICH_ENV if k in os.environ}
    cwd = os.getcwd()
    try:
        os.chdir(ROOT)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = main(["show", *args])
    finally:
        os.chdir(cwd)
        os.environ.update(saved)
    assert status == 0, f"plcrt show {shlex.join(args)} exited with {status}:\n{err.getvalue()}"
    return out.getvalue()


def lesson_program(readme: Path) -> str:
    return (readme.parent / "lesson.awl").relative_to(ROOT).as_posix()


def expected_pictures(readme: Path) -> list[tuple[int, int, str, str]]:
    """(start, end, what, rendered) for every picture of one README."""
    text = readme.read_text(encoding="utf-8")
    found = blocks(text)
    pictures = []
    first_text = next((b for b in found if b[0] == "text"), None)
    assert first_text is not None, f"{readme}: no ```text block with the ladder picture"
    program = lesson_program(readme)
    pictures.append((first_text[2], first_text[3], f"plcrt show {program}", show([program])))
    for lang, content, start, end in found:
        first, _, rest = content.partition("\n")
        if lang == "console" and first.startswith("$ plcrt show "):
            args = shlex.split(first[len("$ plcrt show "):])
            pictures.append((start + len(first) + 1, end, first[2:], show(args)))
    return pictures


def test_every_lesson_has_a_readme() -> None:
    """Six lessons and five machine exercises, each with a README next to
    its program."""
    lessons = sorted(p.parent.name for p in COURSE.glob("*/lesson.awl"))
    assert len(lessons) == 11
    assert lessons == sorted(p.parent.name for p in COURSE.glob("*/README.md")
                             if p.parent.name != "solutions")


@pytest.mark.parametrize("readme", READMES, ids=[r.parent.name for r in READMES])
def test_readme_pictures_are_current(readme: Path) -> None:
    """The first ```text block is `plcrt show lesson.awl`; every ```console
    block starting with `$ plcrt show` shows that command's output."""
    text = readme.read_text(encoding="utf-8")
    for start, end, what, rendered in expected_pictures(readme):
        pasted = text[start:end]
        assert pasted == rendered, (
            f"{readme.relative_to(ROOT)}: the picture of `{what}` is stale; refresh it with "
            f"`python tests/examples/test_course_pictures.py --update`")


def update() -> int:
    """Rewrite the pictures of every lesson README in place."""
    for readme in READMES:
        text = readme.read_text(encoding="utf-8")
        for start, end, _, rendered in sorted(expected_pictures(readme), reverse=True):
            text = text[:start] + rendered + text[end:]
        readme.write_text(text, encoding="utf-8")
        print(f"updated {readme.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    if sys.argv[1:] != ["--update"]:
        print("usage: python tests/examples/test_course_pictures.py --update", file=sys.stderr)
        sys.exit(2)
    sys.exit(update())
