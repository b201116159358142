"""The summary lines of ``make test`` account for every skipped test: the
corpus tests on the corpus line, every other reason on a line of its own
with the files of its tests (a test of the EM253 audit skips without the
manual's text, and was counted by pytest but explained nowhere)."""

from __future__ import annotations

from dataclasses import dataclass

from conftest import skip_lines


@dataclass
class _Report:
    nodeid: str
    longrepr: tuple[str, int, str]


def _skipped(nodeid: str, reason: str) -> _Report:
    return _Report(nodeid, ("file.py", 1, f"Skipped: {reason}"))


def test_every_skip_is_on_a_line_and_the_counts_add_up() -> None:
    reports = [_skipped("tests/programs/test_corpus_roundtrip.py::test_a",
                        "shared/corpus not available"),
               _skipped("tests/lang/test_fastparse.py::test_b[None]", "no corpus files"),
               _skipped("tests/devices/test_em253_audit.py::test_c",
                        "the manual's text is not available"),
               _skipped("tests/lang/test_limits.py::test_d", "no FIFOs here"),
               _skipped("tests/lang/test_limits.py::test_e", "no FIFOs here")]
    lines = skip_lines(reports, "the real-file corpus is not at /x/shared/corpus")
    assert lines == [
        "2 corpus tests skipped: the real-file corpus is not at /x/shared/corpus",
        "1 other test skipped: the manual's text is not available "
        "(tests/devices/test_em253_audit.py)",
        "2 other tests skipped: no FIFOs here (tests/lang/test_limits.py)",
    ]
    assert sum(int(line.split()[0]) for line in lines) == len(reports)


def test_with_the_corpus_a_skip_gives_its_own_reason() -> None:
    reports = [_skipped("tests/lang/test_fastparse.py::test_b[None]", "no corpus files")]
    assert skip_lines(reports, None) == [
        "1 other test skipped: no corpus files (tests/lang/test_fastparse.py)"]


def test_no_skip_no_line() -> None:
    assert skip_lines([], "the real-file corpus is not at /x") == []
