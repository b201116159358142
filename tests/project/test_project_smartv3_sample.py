"""examples/project/seal_in.smartV3, the SMART V3 sample of
docs/project-files.md, is what the tests' V3 writer makes of
programs/seal_in.awl with the symbols and data block of the .mwp sample
(so the sample cannot drift from the writer the tests check the reader
with)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from smartv3_writer import project_bytes  # noqa: E402
from test_project_sample import DATA, SYMBOLS  # noqa: E402

from plcrt.lang.stl import parse_program

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "examples" / "project" / "seal_in.smartV3"


def sample_bytes() -> bytes:
    program = parse_program((ROOT / "programs" / "seal_in.awl").read_text(encoding="utf-8"),
                            "seal_in.awl")
    return project_bytes(program, symbols=SYMBOLS, data=DATA, cpu="CPU ST40")


def test_sample_is_the_writers() -> None:
    assert SAMPLE.read_bytes() == sample_bytes()


if __name__ == "__main__":          # python tests/project/test_project_smartv3_sample.py writes it
    SAMPLE.write_bytes(sample_bytes())
