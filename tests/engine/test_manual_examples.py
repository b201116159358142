"""The S7-200 System Manual examples of the shared corpus behave as the manual says.

The corpus file reconstructs the logic-stack example (networks 1 and 2) and
the on-delay timer example (networks 3 and 4).  It is read from
``../shared/corpus`` beside the repository and never copied into the
project; every test skips when the corpus is absent.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

import plcrt

CORPUS = Path(__file__).resolve().parents[2].parent / "shared" / "corpus"
EXAMPLES = CORPUS / "siemens_manual__S7-200_System_Manual__reconstructed_examples.awl"


@pytest.fixture()
def plc() -> plcrt.Plc:
    if not EXAMPLES.is_file():
        pytest.skip(f"corpus file not found at {EXAMPLES}")
    return plcrt.load(EXAMPLES, scan_ms=10)


def test_examples_compile_without_diagnostics(plc: plcrt.Plc) -> None:
    """The reconstructed manual examples compile cleanly (no errors or warnings)."""
    assert plc.diagnostics == []


NET1_INPUTS = ["I0.0", "I0.1", "I2.0", "I2.1"]


@pytest.mark.parametrize("bits", list(itertools.product((0, 1), repeat=4)),
                         ids=lambda b: "".join(map(str, b)))
def test_network1_truth_table(plc: plcrt.Plc, bits: tuple[int, ...]) -> None:
    """Network 1: Q5.0 = I0.0 AND (I0.1 OR (I2.0 AND I2.1))."""
    for addr, v in zip(NET1_INPUTS, bits):
        plc[addr] = v
    plc.scan()
    a, b, c, d = bits
    assert plc["Q5.0"] == int(bool(a and (b or (c and d))))


NET2_INPUTS = ["I0.0", "I0.5", "I0.6", "I2.1", "I1.3", "I1.0"]


@pytest.mark.parametrize("bits", list(itertools.product((0, 1), repeat=6)),
                         ids=lambda b: "".join(map(str, b)))
def test_network2_truth_table(plc: plcrt.Plc, bits: tuple[int, ...]) -> None:
    """Network 2 (LPS/LRD/LPP): Q7.0 = I0.0(I0.5+I0.6), Q6.0 = I0.0(I2.1+I1.3), Q3.0 = I0.0 I1.0."""
    for addr, v in zip(NET2_INPUTS, bits):
        plc[addr] = v
    plc.scan()
    i00, i05, i06, i21, i13, i10 = bits
    expected = (int(bool(i00 and (i05 or i06))), int(bool(i00 and (i21 or i13))),
                int(bool(i00 and i10)))
    assert (plc["Q7.0"], plc["Q6.0"], plc["Q3.0"]) == expected
    # the physical outputs follow at the end of the scan
    pq = plc.mem.areas["PQ"]
    assert (pq[7] & 1, pq[6] & 1, pq[3] & 1) == expected


@pytest.mark.parametrize("scan_ms,first_on_ms", [(10, 1000), (7, 1001), (30, 1020), (100, 1000)])
def test_t37_turns_q00_on_after_one_second(plc: plcrt.Plc, scan_ms: int,
                                           first_on_ms: int) -> None:
    """Networks 3-4: with I0.0 on from power-up, Q0.0 is on from the first scan starting at 1 s."""
    plc = plcrt.load(EXAMPLES, scan_ms=scan_ms)
    plc["I0.0"] = 1
    first_on = None
    while first_on is None:
        start_us = plc.scans * scan_ms * 1000
        plc.scan()
        if plc["Q0.0"]:
            first_on = start_us // 1000
    assert first_on == first_on_ms
    assert plc["T37"] == 10


def test_t37_resets_when_i00_goes_off(plc: plcrt.Plc) -> None:
    """Network 3: I0.0 off disables T37 and resets it; Q0.0 drops in the same scan."""
    plc["I0.0"] = 1
    plc.run(seconds=1.5)
    assert plc["Q0.0"] == 1 and plc["T37"] == 14   # last scan started at 1.49 s
    plc["I0.0"] = 0
    plc.scan()
    assert (plc["Q0.0"], plc["T37"]) == (0, 0)
    plc["I0.0"] = 1
    plc.run(seconds=0.5)
    assert plc["Q0.0"] == 0                  # timing restarts from 0


def test_t37_off_time_shorter_than_preset_never_sets_q00(plc: plcrt.Plc) -> None:
    """Pulses of I0.0 shorter than 1 s never let T37 reach its preset."""
    for _ in range(5):
        plc["I0.0"] = 1
        plc.run(seconds=0.8)
        assert plc["Q0.0"] == 0
        plc["I0.0"] = 0
        plc.scan()
