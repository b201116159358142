"""The course in the panel: lessons of ``examples/course/`` and "check my
program".

A lesson is a folder with ``lesson.awl`` and ``README.md`` (and optionally
``symbols.txt``, ``plant.toml`` and ``test_NN_*.py``); its course is the
folder holding it.  :func:`check` runs the lesson's test file with pytest
in a subprocess, with a timeout, and reads each test's outcome from a
JUnit XML report written into a temporary folder.

This module neither serves nor draws anything.
"""

from __future__ import annotations

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

#: wall seconds a check may take
CHECK_TIMEOUT = 120.0
#: characters of pytest's output kept for the page
OUTPUT_CHARS = 20000


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
        """The lesson's README (Markdown, shown as text by the page)."""
        return (self.dir / "README.md").read_text(encoding="utf-8", errors="replace")

    def to_dict(self) -> dict[str, Any]:
        return {"id": self.id, "title": self.title}


def is_lesson(path: Path) -> bool:
    return path.is_dir() and (path / "lesson.awl").is_file() and (path / "README.md").is_file()


def lesson(path: Path) -> Lesson:
    """The lesson in folder ``path``."""
    if not is_lesson(path):
        raise PlcConfigError(f"{path} is not a lesson folder (lesson.awl and README.md)")
    title = path.name
    for line in (path / "README.md").read_text(encoding="utf-8", errors="replace").splitlines():
        if line.startswith("#"):
            title = line.lstrip("#").strip()
            break
    return Lesson(path.name, title, path.resolve())


def lessons(course: Path) -> list[Lesson]:
    """The lessons of a course folder, in folder-name order."""
    if not course.is_dir():
        return []
    return [lesson(p) for p in sorted(course.iterdir()) if is_lesson(p)]


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
        tests = _junit(report) if report.is_file() else []
    output = (proc.stdout + proc.stderr)[-OUTPUT_CHARS:]
    passed = sum(t["outcome"] == "passed" for t in tests)
    failed = sum(t["outcome"] in ("failed", "error") for t in tests)
    return {"type": "check", "lesson": les.id, "ok": proc.returncode == 0 and failed == 0,
            "passed": passed, "failed": failed, "tests": tests, "output": output}


def _junit(path: Path) -> list[dict[str, str]]:
    """Each test case of a JUnit XML report (written by our own pytest)."""
    out = []
    for case in ET.parse(path).getroot().iter("testcase"):
        outcome, text = "passed", ""
        for tag in ("failure", "error", "skipped"):
            el = case.find(tag)
            if el is not None:
                outcome = {"failure": "failed", "error": "error", "skipped": "skipped"}[tag]
                text = (el.get("message") or "")[:500]
                break
        name = case.get("name", "")
        out.append({"name": name, "doc": _words(name), "outcome": outcome, "message": text})
    return out


def _words(name: str) -> str:
    """``test_stop_breaks_the_seal`` -> ``stop breaks the seal``."""
    return re.sub(r"^test_", "", name.split("[")[0]).replace("_", " ")


__all__ = ["CHECK_TIMEOUT", "Lesson", "check", "find", "is_lesson", "lesson", "lessons"]
