"""The debugger's commands that run scans are bounded: a count or a
duration beyond :data:`~plcrt.debug.commands.MAX_COMMAND_SCANS` scans is
refused before anything runs, and ``--max-wall`` (``Session(max_wall=...)``)
stops a command between two scans after that much wall-clock time, with
exit status 3; time paused at a breakpoint does not count."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from plcrt.debug.commands import MAX_COMMAND_SCANS

from debug_helpers import ROOT, session, transcript

SEAL_IN = "programs/seal_in.awl"


@pytest.fixture(autouse=True)
def _in_root(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


@pytest.mark.parametrize("command", [
    "scan 99999999999",
    f"scan {MAX_COMMAND_SCANS + 1}",
    "scan " + "9" * 400,                      # never even converted to an int
    "run 100000000",                          # 10^10 scans of 10 ms
    "run until Q0.0 timeout 100000000",
    "pulse I0.0 99999999999",
])
def test_a_command_beyond_the_bound_is_refused_before_running(command: str) -> None:
    start = time.monotonic()
    text, status = transcript(SEAL_IN, command)
    assert time.monotonic() - start < 30
    assert status == 1
    assert "error: " in text and "at most" in text and str(MAX_COMMAND_SCANS) in text
    assert "scan 0  RUN" not in text and "t=0.000 s" not in text.split("error:")[0]


def test_max_scans_are_allowed() -> None:
    """The bound itself is a count the debugger takes (checked without
    running it: the parser returns it)."""
    from plcrt.debug.commands import _count
    assert _count([str(MAX_COMMAND_SCANS)], "scan", 1) == MAX_COMMAND_SCANS


def test_max_wall_stops_a_long_command_and_the_session_goes_on() -> None:
    s, out = session(SEAL_IN)
    s.max_wall = 0.2
    start = time.monotonic()
    status = s.run([f"scan {MAX_COMMAND_SCANS}", "print Q0.0"])
    took = time.monotonic() - start
    text = out.getvalue()
    assert took < 10
    assert "stopped by --max-wall after 0.2 s of wall-clock time, at t=" in text
    assert 0 < s.plc.scans < MAX_COMMAND_SCANS
    assert "(plcrt) print Q0.0\nQ0.0 = 0" in text          # the next command ran
    assert status == 3


def test_max_wall_ends_run_until() -> None:
    s, out = session(SEAL_IN)
    s.max_wall = 0.2
    status = s.run(["run until Q0.0 timeout 20000s"])   # Q0.0 never comes on
    text = out.getvalue()
    assert "stopped by --max-wall" in text and "is true" not in text
    assert s.plc.time < 20000
    assert status == 3


def test_time_paused_at_a_breakpoint_does_not_count() -> None:
    s, out = session(SEAL_IN)
    s.max_wall = 0.5
    lines = iter(["break 1", "scan 3", "continue", "continue"])

    def slow(prompt: str) -> str | None:
        line = next(lines, None)
        if line == "continue":
            time.sleep(0.4)     # a user thinking while paused: 0.8 s in all
        return line

    status = s.run(readline=slow)
    assert "stopped by --max-wall" not in out.getvalue()
    assert status == 0


def test_drawing_the_network_at_a_stop_is_paused_time() -> None:
    """The stop display (the network drawn with its values, the first
    drawing imports the ladder view) is part of the pause: it used to count
    as run time, so a slow first drawing ended the command by --max-wall."""
    s, out = session(SEAL_IN)
    s.max_wall = 0.5
    show = s._show

    def slow_show(net) -> None:
        time.sleep(0.6)         # longer than the whole limit
        show(net)

    s._show = slow_show
    status = s.run(["break 1", "scan 2", "continue", "continue"])
    assert "stopped by --max-wall" not in out.getvalue()
    assert status == 0


def test_cli_max_wall_option(tmp_path) -> None:
    script = tmp_path / "s.txt"
    script.write_text(f"scan {MAX_COMMAND_SCANS}\nprint Q0.0\n", encoding="utf-8")
    r = subprocess.run([sys.executable, "-m", "plcrt", "debug", SEAL_IN, "--script",
                        str(script), "--max-wall", "0.3"], cwd=ROOT, capture_output=True,
                       text=True, timeout=60)
    assert "stopped by --max-wall after 0.3 s" in r.stdout
    assert "Q0.0 = 0" in r.stdout
    assert r.returncode == 3


@pytest.mark.parametrize("bad", ["0", "-1", "nan", "inf"])
def test_cli_bad_max_wall_is_refused(bad: str) -> None:
    r = subprocess.run([sys.executable, "-m", "plcrt", "debug", SEAL_IN, f"--max-wall={bad}"],
                       cwd=ROOT, capture_output=True, text=True, timeout=60, input="")
    assert r.returncode == 1
    assert "--max-wall must be a positive number" in r.stderr
