"""The fenced code blocks of the project's Markdown files, for the tests that
run the documentation's examples (``test_console_examples.py``,
``test_readme_python.py``, ``test_first_ladder_test.py``).

A block may be preceded (on the last non-blank line before its opening
fence) by an HTML comment that tells these tests how to treat it; a reader
of the rendered Markdown does not see it:

``<!-- not run: REASON -->``
    The block is not run, for the reason given (it needs a terminal, the
    network, a new virtualenv, ...).  The reason must not be empty.
``<!-- debug transcript: plcrt debug ARGS -->``
    A ``console`` block without ``$`` lines that shows a debugger session:
    the commands after its ``(plcrt...)`` prompts are fed to the command
    on stdin, and the whole output must equal the block.
``<!-- pytest module -->``
    A ``python`` block that is a test module: pytest runs it and its tests
    must pass.

This module only reads and splits the files; it runs nothing.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: The Markdown files whose examples are checked: the README, docs/ and the
#: READMEs of the sample programs and examples.
MARKDOWN = sorted([ROOT / "README.md", *(ROOT / "docs").glob("*.md"),
                   *(ROOT / "programs").rglob("README.md"),
                   *(ROOT / "examples").rglob("README.md")])

_FENCE = re.compile(r"^(?P<indent>\s*)```(?P<lang>[\w-]*)\s*$")
_MARKER = re.compile(
    r"^<!--\s*(?P<kind>not run|debug transcript|pytest module):?(?P<arg>.*?)-->\s*$")


@dataclass(frozen=True)
class Block:
    """One fenced block: where it is, its language and its lines (without
    the fences, de-indented like its opening fence)."""

    path: Path
    line: int                 # 1-based line of the opening fence
    lang: str
    lines: tuple[str, ...]
    marker: str | None        # "not run", "debug transcript" or "pytest module"
    marker_arg: str           # the reason, or the debugger command line

    @property
    def where(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def blocks(path: Path) -> list[Block]:
    """Every fenced block of a Markdown file, in order."""
    out: list[Block] = []
    lines = path.read_text(encoding="utf-8").splitlines()
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        start, indent, lang = i, m["indent"], m["lang"]
        body: list[str] = []
        i += 1
        while i < len(lines) and lines[i].strip() != "```":
            line = lines[i]
            body.append(line[len(indent):] if line.startswith(indent) else line.lstrip())
            i += 1
        marker, arg = _marker_before(lines, start)
        out.append(Block(path, start + 1, lang, tuple(body), marker, arg))
        i += 1
    return out


def _marker_before(lines: list[str], fence: int) -> tuple[str | None, str]:
    j = fence - 1
    while j >= 0 and not lines[j].strip():
        j -= 1
    m = _MARKER.match(lines[j].strip()) if j >= 0 else None
    return (m["kind"], m["arg"].strip()) if m else (None, "")


def mirror(folder: Path) -> Path:
    """``folder`` with a link to every top-level entry of the repository
    (but .git and .venv): relative paths of examples work there, and files
    an example writes land in ``folder``, not in the clone."""
    for entry in ROOT.iterdir():
        if entry.name not in (".git", ".venv"):
            (folder / entry.name).symlink_to(entry)
    return folder


def all_blocks(*langs: str) -> list[Block]:
    """The blocks of the given languages in every checked Markdown file."""
    return [b for path in MARKDOWN for b in blocks(path) if b.lang in langs]


def console_steps(block: Block) -> list[tuple[str, list[str]]]:
    """A console block as (command, expected output lines) pairs: a command
    is a ``$ `` line and the lines it continues with a trailing backslash
    (kept, for the shell); its output is every line up to the next ``$ ``."""
    steps: list[tuple[str, list[str]]] = []
    lines = list(block.lines)
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("$ "):
            command = line[2:]
            while command.endswith("\\") and i + 1 < len(lines):
                i += 1
                command += "\n" + lines[i]
            steps.append((command, []))
        elif steps:
            steps[-1][1].append(line)
        else:
            raise ValueError(f"{block.where}: output before the first '$ ' command")
        i += 1
    return steps


def output_pattern(expected: list[str]) -> re.Pattern[str]:
    """The documented output as a pattern for the real one.  Lines compare
    exactly, except that trailing spaces are ignored, a line that is just
    ``...`` stands for any number of lines (output left out), and a line
    ending in ``...`` for a line that starts with the text before it."""
    parts: list[str] = []
    for line in expected:
        line = line.rstrip()
        if line == "...":
            parts.append(r"(?:[^\n]*\n)*?")
        elif line.endswith("..."):
            parts.append(re.escape(line[:-3]) + r"[^\n]*\n")
        else:
            parts.append(re.escape(line) + r"\n")
    return re.compile("".join(parts))


def normalise_output(text: str) -> str:
    """Real output as compared: trailing spaces dropped, one newline at the end."""
    return "".join(line.rstrip() + "\n" for line in text.splitlines())


def matches(expected: list[str], actual: str) -> bool:
    return output_pattern(expected).fullmatch(normalise_output(actual)) is not None
