"""``bench/em253.py --against DIR``: the side-by-side comparison runs both
checkouts in fresh processes and reports every example on both sides.

These check what the comparison reports, never how fast anything is."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "bench" / "em253.py"
EXAMPLES = sorted(p.name for p in (ROOT / "programs" / "em253").glob("*.awl"))


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(BENCH), *args], capture_output=True,
                          text=True, timeout=300)


def test_against_itself_reports_every_example_and_the_slowest(tmp_path: Path) -> None:
    done = _run("--against", str(ROOT), "--rounds", "2", "--seconds", "0.02",
                "--repeats", "1")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert [ln.split(":")[0] for ln in lines[:2]] == ["round 1", "round 2"]
    rows = {m.group(1): m for m in (re.match(
        r"\s+(\S+(?: example)?)\s+(\d+)\s+(\d+)\s+([\d.]+)\s+((?:\d+ ?)+)$", ln)
        for ln in lines) if m}
    assert set(rows) == set(EXAMPLES) | {"slowest example"}
    for m in rows.values():
        here, there, ratio = int(m.group(2)), int(m.group(3)), float(m.group(4))
        assert here > 0 and there > 0 and ratio > 0
        assert len(m.group(5).split()) == 2          # one figure per round


def test_against_a_directory_without_the_bench_is_a_clear_error(tmp_path: Path) -> None:
    done = _run("--against", str(tmp_path), "--rounds", "1")
    assert done.returncode == 2
    assert done.stderr.strip() == f"error: {tmp_path} has no bench/em253.py"
    assert "Traceback" not in done.stderr


def test_a_failing_bench_on_the_other_side_is_reported_without_a_traceback(
        tmp_path: Path) -> None:
    (tmp_path / "bench").mkdir()
    (tmp_path / "bench" / "em253.py").write_text('import sys\nsys.exit("no such example")\n')
    done = _run("--against", str(tmp_path), "--rounds", "1", "--seconds", "0.02",
                "--repeats", "1")
    assert done.returncode == 1
    assert done.stderr.strip() == (f"error: the bench in {tmp_path} failed (exit 1):\n"
                                   f"no such example")
    assert "Traceback" not in done.stderr
