"""docs/cia402.md's homing methods table says, for each method and drive
model, what the method tables of the code hold (plcrt.devices.cia402.
homing_methods.METHODS): a method the table marks "yes" is run, one marked
"no" is refused."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from plcrt.devices.cia402.homing_methods import METHODS

DOC = Path(__file__).resolve().parents[2] / "docs" / "cia402.md"
HEADER = "| # | HCFA (§10.1) | Kinco (§2.2, §2.5) |"


def method_rows() -> list[tuple[list[int], str, str]]:
    """(method numbers, HCFA cell, Kinco cell) of every row of the table."""
    lines = DOC.read_text(encoding="utf-8").splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(HEADER))
    rows = []
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip("|").split("|")]
        numbers = [int(n.replace("−", "-")) for n in re.findall(r"−?\d+", cells[0])]
        rows.append((numbers, cells[1], cells[2]))
    return rows


def test_the_table_lists_every_method_of_both_models() -> None:
    listed = {n for numbers, _, _ in method_rows() for n in numbers}
    assert listed == set(METHODS["hcfa-am0520b"]) | set(METHODS["kinco-servo"])


@pytest.mark.parametrize("numbers, hcfa, kinco", method_rows(),
                         ids=lambda v: str(v) if isinstance(v, list) else "")
def test_each_row_says_which_model_runs_the_method(numbers: list[int], hcfa: str,
                                                   kinco: str) -> None:
    for n in numbers:
        assert hcfa.startswith("yes") == (n in METHODS["hcfa-am0520b"]), (n, hcfa)
        assert kinco.startswith("yes") == (n in METHODS["kinco-servo"]), (n, kinco)
