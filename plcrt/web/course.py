"""The course in the panel: lessons of ``examples/course/`` and "check my
program".

A lesson is a folder with ``lesson.awl`` and ``README.md`` (and optionally
``panel.md``, ``symbols.txt``, ``plant.toml`` and ``test_NN_*.py``); its
course is the folder holding it.  The README is the lesson for the
terminal; ``panel.md`` is the lesson for the page (steps to do with the
mouse), shown instead of the README when it exists, and its table of
inputs (``| input | kind | ... |``) says which input is a switch or a
push-button and whether it is normally closed.  :func:`check` runs the
lesson's test file with pytest in a subprocess, with a timeout, and reads
each test's outcome from a JUnit XML report written into a temporary
folder: it runs the lesson folder's Python code, so a lesson folder must
be trusted.

This module neither serves nor draws anything.
"""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import PlcConfigError
from . import markdown
from .present import KIND_WORDS

#: wall seconds a check may take
CHECK_TIMEOUT = 120.0
#: characters of pytest's output kept for the page
OUTPUT_CHARS = 20000
#: the files of a lesson folder the page may open (links of the lesson text)
SERVED_SUFFIXES = (".awl", ".txt", ".toml", ".md", ".py", ".dbg")
#: the files whose change reloads the lesson in the panel
WATCHED = ("lesson.awl", "symbols.txt", "plant.toml", "panel.md", "README.md")


@dataclass(frozen=True)
class Lesson:
    """One lesson folder."""

    id: str
    title: str
    dir: Path

    @property
    def program(self) -> Path:
        return self.dir / "lesson.awl"

    @property
    def symbols(self) -> Path | None:
        p = self.dir / "symbols.txt"
        return p if p.is_file() else None

    @property
    def plant(self) -> Path | None:
        p = self.dir / "plant.toml"
        return p if p.is_file() else None

    @property
    def tests(self) -> list[Path]:
        return sorted(self.dir.glob("test_*.py"))

    def text(self) -> str:
        """The lesson's text for the page: ``panel.md``, else the README
        (Markdown)."""
        page = self.dir / "panel.md"
        path = page if page.is_file() else self.dir / "README.md"
        try:
            return _read(path)
        except OSError as e:   # deleted or unreadable while the panel runs
            return f"*The lesson text {path.name} cannot be read: {e.strerror}.*"

    def page(self) -> list[dict[str, Any]]:
        """The page's lesson text as safe blocks (:mod:`plcrt.web.markdown`);
        relative links to the lesson's own files point at ``lesson/NAME``."""
        return markdown.parse(self.text(), self._link)

    def _link(self, url: str) -> str | None:
        name = url.split("#")[0].split("?")[0]
        return f"lesson/{name}" if self.file(name) is not None else None

    def file(self, name: str) -> Path | None:
        """A file of the lesson's folder the page may open (a plain name,
        one of :data:`SERVED_SUFFIXES`), or None."""
        if not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,99}", name) or \
                not name.endswith(SERVED_SUFFIXES):
            return None
        p = self.dir / name
        return p if p.is_file() else None

    def kinds(self) -> dict[str, str]:
        """The input kinds the lesson's page text declares: its table whose
        head starts ``| input | kind |``, e.g. ``| I0.1 | NC push-button |
        stop |`` (kinds: :data:`plcrt.web.present.KIND_WORDS`).

        Raises:
            PlcConfigError: a kind that is not one of them.
        """
        out: dict[str, str] = {}
        for b in self.page():
            table = b.get("table")
            if table is None:
                continue
            head = [_spans_text(c).lower() for c in table["head"]]
            if head[:2] != ["input", "kind"]:
                continue
            for row in table["rows"]:
                if len(row) < 2:
                    continue
                addr, kind = _spans_text(row[0]), _spans_text(row[1]).lower()
                if kind not in KIND_WORDS:
                    raise PlcConfigError(
                        f"{self.id}/panel.md: input {addr}: kind '{kind}' is not one of "
                        f"{', '.join(KIND_WORDS)}")
                out[addr] = KIND_WORDS[kind]
        return out

    def stamp(self) -> tuple[tuple[str, int, int], ...]:
        """The modification times and sizes of the :data:`WATCHED` files:
        a change means the lesson must be loaded again."""
        out = []
        for name in WATCHED:
            try:
                st = (self.dir / name).stat()
            except OSError:
                continue
            out.append((name, st.st_mtime_ns, st.st_size))
        return tuple(out)

    def to_dict(self) -> dict[str, Any]:
        return {"id": self.id, "title": self.title}


def is_lesson(path: Path) -> bool:
    return path.is_dir() and (path / "lesson.awl").is_file() and (path / "README.md").is_file()


def lesson(path: Path) -> Lesson:
    """The lesson in folder ``path``."""
    if not is_lesson(path):
        raise PlcConfigError(f"{path} is not a lesson folder (lesson.awl and README.md)")
    title = path.name
    for line in _read(path / "README.md").splitlines():
        if line.startswith("#"):
            title = line.lstrip("#").strip()
            break
    return Lesson(path.name, title, path.resolve())


def lessons(course: Path) -> list[Lesson]:
    """The lessons of a course folder, in folder-name order."""
    if not course.is_dir():
        return []
    return [lesson(p) for p in sorted(course.iterdir()) if is_lesson(p)]


def _read(path: Path) -> str:
    """A lesson text, at most :data:`markdown.MAX_CHARS` characters' worth."""
    with open(path, "rb") as f:
        return f.read(4 * markdown.MAX_CHARS + 4).decode("utf-8", errors="replace")


def _spans_text(spans: list[dict[str, Any]]) -> str:
    return "".join(s["t"] for s in spans).strip()


def find(course: list[Lesson], ident: str) -> Lesson:
    for le in course:
        if le.id == ident:
            return le
    raise PlcConfigError(f"no lesson '{ident}' in the course")


def check(les: Lesson, timeout: float = CHECK_TIMEOUT) -> dict[str, Any]:
    """Run the lesson's tests; returns the ``check`` message: passed and
    failed counts, each test's name, outcome and failure text, and the
    end of pytest's output."""
    files = les.tests
    if not files:
        raise PlcConfigError(f"lesson {les.id} has no test file")
    with tempfile.TemporaryDirectory(prefix="plcrt-check-") as tmp:
        report = Path(tmp) / "report.xml"
        cmd = [sys.executable, "-m", "pytest", "-q", "-rA", "-p", "no:cacheprovider",
               "-o", "addopts=", "--rootdir", str(les.dir), f"--junitxml={report}",
               *[str(f) for f in files]]
        env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
        env.pop("PYTEST_XDIST_WORKER", None)
        try:
            proc = subprocess.run(cmd, cwd=les.dir, capture_output=True, text=True,
                                  timeout=timeout, env=env)
        except subprocess.TimeoutExpired:
            return {"type": "check", "lesson": les.id, "ok": False, "passed": 0,
                    "failed": 0, "tests": [],
                    "output": f"the tests did not finish within {timeout:g} s"}
        tests = _junit(report, _docs(files)) if report.is_file() else []
    output = _clip(proc.stdout + proc.stderr)
    passed = sum(t["outcome"] == "passed" for t in tests)
    failed = sum(t["outcome"] in ("failed", "error") for t in tests)
    return {"type": "check", "lesson": les.id, "ok": proc.returncode == 0 and failed == 0,
            "passed": passed, "failed": failed, "tests": tests, "output": output}


def _docs(files: list[Path]) -> dict[str, str]:
    """Test name -> the first paragraph of its docstring, read from the
    test files' syntax trees (nothing runs): an exercise states each
    requirement there, and the page lists the requirement rather than the
    function's name."""
    out: dict[str, str] = {}
    for f in files:
        try:
            tree = ast.parse(_read(f))
        except (OSError, SyntaxError, ValueError, RecursionError, MemoryError):
            continue
        for node in tree.body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and \
                    node.name.startswith("test"):
                doc = ast.get_docstring(node) or ""
                first = " ".join(doc.split("\n\n")[0].split())
                if first:
                    out[node.name] = first[:300]
    return out


def _junit(path: Path, docs: dict[str, str] | None = None) -> list[dict[str, str]]:
    """Each test case of a JUnit XML report (written by our own pytest);
    ``doc`` is the test's docstring (:func:`_docs`), else its name in
    words."""
    out = []
    for case in ET.parse(path).getroot().iter("testcase"):
        outcome, text = "passed", ""
        for tag in ("failure", "error", "skipped"):
            el = case.find(tag)
            if el is not None:
                outcome = {"failure": "failed", "error": "error", "skipped": "skipped"}[tag]
                text = _message(el.get("message") or "")
                break
        name = case.get("name", "")
        doc = (docs or {}).get(name.split("[")[0]) or _words(name)
        if "[" in name:
            doc += " [" + name.split("[", 1)[1]
        out.append({"name": name, "doc": doc, "outcome": outcome, "message": text})
    return out


def _message(text: str) -> str:
    """A failure's message for the page: an assertion's own message
    without pytest's ``assert ...`` explanation after it (which is kept
    when the assertion has no message of its own), at most 500
    characters."""
    if text.startswith("AssertionError: "):
        text = text[len("AssertionError: "):]
        if not text.startswith("assert "):
            text = text.split("\nassert ")[0]
    return text[:500]


def _clip(output: str) -> str:
    """pytest's output, at most :data:`OUTPUT_CHARS`: its start (the first
    failure with its PLC trace) and its end (the summary), the middle cut."""
    if len(output) <= OUTPUT_CHARS:
        return output
    half = OUTPUT_CHARS // 2
    return output[:half] + "\n[... output cut ...]\n" + output[-half:]


def _words(name: str) -> str:
    """``test_stop_breaks_the_seal`` -> ``stop breaks the seal``."""
    return re.sub(r"^test_", "", name.split("[")[0]).replace("_", " ")


__all__ = ["CHECK_TIMEOUT", "Lesson", "check", "find", "is_lesson", "lesson", "lessons"]
