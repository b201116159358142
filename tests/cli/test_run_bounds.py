"""Runs the command line cannot finish or count: ``--max-wall`` holds at
real-time pace too (its sleeps end at the limit), a span longer than
2^63 µs of simulated time is refused before loading, and the wall-limit
message stays one readable line whatever the planned length."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from plcrt.cli import main
from plcrt.term.progress import MAX_RUN_US

SEAL_IN = str(Path(__file__).resolve().parents[2] / "programs" / "seal_in.awl")


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str, float]:
    start = time.monotonic()
    code = main(list(argv))
    took = time.monotonic() - start
    out, err = capsys.readouterr()
    return code, out, err, took


def test_max_wall_holds_at_realtime_pace(capsys: pytest.CaptureFixture[str]) -> None:
    """One-second scans at real-time pace: the old chunk of 100 scans slept
    100 s before the limit was looked at."""
    code, out, err, took = _run(capsys, "run", SEAL_IN, "--realtime", "--scan-ms", "1000",
                                "--seconds", "600", "--max-wall", "0.5")
    assert code == 3
    assert took < 5
    assert "stopped by --max-wall after 0.5 s of wall-clock time, at 1 s simulated " \
           "(1 of 600 scans run)" in err


def test_realtime_results_are_unchanged_by_the_pacing(
        capsys: pytest.CaptureFixture[str]) -> None:
    argv = ("run", SEAL_IN, "--scans", "5", "--scan-ms", "20", "--set", "I0.0=1",
            "--watch", "Q0.0", "--json")
    assert main([*argv, "--realtime", "--max-wall", "30"]) == 0
    paced = capsys.readouterr().out
    assert main(list(argv)) == 0
    assert capsys.readouterr().out == paced


@pytest.mark.parametrize("argv, option", [
    (("--seconds", "1e300"), "--seconds 1e+300"),
    (("--seconds", "1e16"), "--seconds 1e+16"),
    (("--scans", str(10**17)), "--scans 1e+17"),
    (("--scans", "9" * 300), "--scans 1e+300"),
])
def test_a_span_that_cannot_be_counted_is_refused(
        capsys: pytest.CaptureFixture[str], argv: tuple[str, str], option: str) -> None:
    code, out, err, took = _run(capsys, "run", SEAL_IN, *argv, "--max-wall", "2")
    assert code == 1
    assert took < 2
    assert err.startswith(f"plcrt: error: {option}")
    assert "is longer than a run can be counted: at most 9.22e+12 s of simulated time" in err
    assert len(err) < 300
    assert out == ""


def test_the_longest_countable_run_is_accepted(capsys: pytest.CaptureFixture[str]) -> None:
    """The limit is inclusive; such a run stops at the wall limit, and the
    message gives the planned count (9.2e17 scans of 10 µs) as a
    magnitude, not 18 digits."""
    seconds = str(MAX_RUN_US // 10**6)
    code, out, err, _ = _run(capsys, "run", SEAL_IN, "--seconds", seconds, "--scan-ms", "0.01",
                             "--max-wall", "0.2")
    assert code == 3
    assert " scans run); the results are those of that moment" in err
    assert "of 9.22e+17 scans run" in err
    assert len(err.splitlines()[0]) < 200
