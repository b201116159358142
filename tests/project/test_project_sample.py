"""examples/project/seal_in.mwp, the sample project of docs/project-files.md,
is what the tests' writer makes of programs/seal_in.awl with its symbols,
a data block and Micro/WIN's default system block (so the sample cannot
drift from the writer the tests check the reader with)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from project_writer import project_bytes  # noqa: E402
from sysblock_writer import v4_block  # noqa: E402

from plcrt.lang.stl import parse_program

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "examples" / "project" / "seal_in.mwp"
SYMBOLS = [("Start", "I0.0", "start button (normally open)"),
           ("Stop", "I0.1", "stop button (normally open)"),
           ("Motor", "Q0.0", "motor contactor"), ("Lamp", "Q0.1", "running lamp")]
DATA = [("VW100", [1500], "motor run-up time, ms")]


def sample_bytes() -> bytes:
    program = parse_program((ROOT / "programs" / "seal_in.awl").read_text(encoding="utf-8"),
                            "seal_in.awl")
    return project_bytes(program, symbols=SYMBOLS, data=DATA, system=v4_block())


def test_sample_is_the_writers() -> None:
    assert SAMPLE.read_bytes() == sample_bytes()


if __name__ == "__main__":          # python tests/project/test_project_sample.py writes it
    SAMPLE.write_bytes(sample_bytes())
