"""Shared test set-up: makes the helper modules in ``tests/`` importable
(``stl_helpers``, ``reference_interp``) from the mirrored sub-folders, says
in the report header and the summary when the tests of the shared real-file
corpus were skipped because the corpus is not there (and, on a line of its
own, every other reason a test skipped for, so that the lines account for
pytest's count), and makes the property tests deterministic under CI.

Property tests (hypothesis) explore new random examples on every developer
run and keep the failures they find in ``.hypothesis/``.  Under CI (the
``CI`` environment variable set) they draw the same examples every time
(``derandomize``), so a submission is judged on a fixed set of cases
rather than on a fresh draw; ``PLCRT_PROPERTY_EXAMPLES`` still scales them.

A test session keeps plcrt's disk cache (native machine code and the marks
of programs the default backend compiled, docs/native.md "Tiers") in a
directory of its own unless ``PLCRT_CACHE_DIR`` names one: what earlier
runs left in the user's cache must not change which backend a test's PLC
starts on.
"""

from __future__ import annotations

import atexit
import os
import shutil
import sys
import tempfile
from pathlib import Path

import pytest
from hypothesis import settings

if "PLCRT_CACHE_DIR" not in os.environ:      # inherited by pytest-xdist's workers
    os.environ["PLCRT_CACHE_DIR"] = tempfile.mkdtemp(prefix="plcrt-test-cache-")
    atexit.register(shutil.rmtree, os.environ["PLCRT_CACHE_DIR"], True)

settings.register_profile("ci", derandomize=True, database=None)
if os.environ.get("CI"):
    settings.load_profile("ci")

_TESTS = str(Path(__file__).resolve().parent)
if _TESTS not in sys.path:
    sys.path.insert(0, _TESTS)

# The corpus of real Micro/WIN exports is read where the test modules look for
# it: ../shared/corpus beside the repository (read-only, never copied in).
CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "corpus"


def corpus_note() -> str | None:
    """Why corpus tests skip, or None when the corpus is there."""
    if CORPUS.is_dir():
        return None
    return (f"the real-file corpus is not at {CORPUS} "
            f"(README.md, 'Running the tests', says how to get them run)")


def pytest_report_header(config: pytest.Config) -> str | None:
    note = corpus_note()
    return None if note is None else f"corpus tests will skip: {note}"


def pytest_terminal_summary(terminalreporter, exitstatus: int,  # noqa: ANN001
                            config: pytest.Config) -> None:
    for line in skip_lines(terminalreporter.stats.get("skipped", []), corpus_note()):
        terminalreporter.write_line(line)


def skip_lines(reports: list, note: str | None) -> list[str]:
    """One line per reason that accounts for every skipped test: the corpus
    tests with ``note`` (where the corpus is looked for), then each other
    reason with the files of its tests, so that the lines add up to
    pytest's count of skipped tests."""
    # with the corpus in place, a corpus test that skips has its own reason
    corpus = [r for r in reports if note is not None and "corpus" in _skip_reason(r)]
    others: dict[str, list] = {}
    for r in reports:
        if r not in corpus:
            others.setdefault(_skip_reason(r).removeprefix("Skipped: "), []).append(r)
    lines = []
    if corpus:
        lines.append(f"{len(corpus)} corpus tests skipped: {note}")
    for reason, reps in others.items():
        files = sorted({r.nodeid.split("::")[0] for r in reps})
        lines.append(f"{len(reps)} other test{'s' if len(reps) != 1 else ''} skipped: "
                     f"{reason} ({', '.join(files[:3])}{', ...' if len(files) > 3 else ''})")
    return lines


def _skip_reason(report: pytest.TestReport) -> str:
    longrepr = report.longrepr
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2])
    return str(longrepr)
