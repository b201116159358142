"""Which backend ``plcrt run`` runs on a machine that starts with an empty
disk cache (a fresh install), run after run (docs/native.md, "Tiers").

The rule pinned here, in fresh processes as a user runs them:

* a run too short for machine code to pay runs on the Python build and
  leaves nothing on disk: the next short run is Python again;
* a run whose length says it will outlast the native compile (its first
  scans give the rate) starts the compile at once and finishes native,
  and leaves the machine code on disk;
* every later run of that program, short or long, is native from its
  first scan ("python_scans": 0), and says so.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("llvmlite")

ROOT = Path(__file__).resolve().parents[2]
TIMERS = "programs/timers.awl"


def plcrt_run(cache: Path, *args: str) -> tuple[dict, str]:
    """``plcrt run TIMERS ARGS --json --verbose`` in a fresh process whose
    disk cache is ``cache``: the JSON object and the --verbose line."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("PLCRT_")}
    env["PLCRT_CACHE_DIR"] = str(cache)
    done = subprocess.run([sys.executable, "-m", "plcrt", "run", TIMERS, "--set", "I0.0=1",
                           "--watch", "Q0.0", "--json", "--verbose", *args],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    line = next(x for x in done.stderr.splitlines() if x.startswith("backend: "))
    return json.loads(done.stdout), line


def test_the_first_long_run_leaves_machine_code_and_every_later_run_is_native(
        tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    short = ("--scans", "3")
    for _ in range(2):          # short runs compile nothing and leave nothing
        obj, line = plcrt_run(cache, *short)
        assert (obj["backend"], obj["python_scans"]) == ("python", 3)
        assert line == "backend: python (native not ready yet)"
    values = {short: obj["values"]}
    assert not list(cache.glob("native/*.native"))

    long = ("--seconds", "36000")      # 3.6 million scans of 10 ms
    obj, line = plcrt_run(cache, *long)
    assert obj["backend"] == "native" and obj["scans"] == 3_600_000
    assert 0 < obj["python_scans"] < obj["scans"]
    assert line.endswith(f", after {obj['python_scans']} scans in Python)")
    values[long] = obj["values"]

    for args in (long, short):          # machine code on disk: native at once
        obj, line = plcrt_run(cache, *args)
        assert (obj["backend"], obj["python_scans"]) == ("native", 0)
        assert obj["values"] == values[args]     # the same results on either build
        assert line.endswith(", from the first scan)"), line
