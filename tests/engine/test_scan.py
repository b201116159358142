"""The scan cycle of plcrt.engine.runtime: special memory, simulated time and I/O images.

S7-200 System Manual, "The scan cycle" and the SMB0 table (digest section
3.6): inputs are copied from the terminals at the scan start, outputs to the
terminals at the scan end; SM0.0 is always on, SM0.1 on in the first scan,
SM0.5 a 1 s clock, SM0.6 a scan clock.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt
from plcrt.errors import PlcConfigError

# Copies the special bits to Q0.x so the program's own view is tested.
SM_PROGRAM = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\n"
              "LD SM0.0\n= Q0.0\nLD SM0.1\n= Q0.1\nLD SM0.3\n= Q0.3\nLD SM0.4\n= Q0.4\n"
              "LD SM0.5\n= Q0.5\nLD SM0.6\n= Q0.6\nLD SM0.7\n= Q0.7\n"
              "END_ORGANIZATION_BLOCK\n")


def _bits(p: plcrt.Plc, *names: str) -> tuple[int, ...]:
    return tuple(p[n] for n in names)


def test_sm00_always_on_and_sm01_sm03_first_scan_only() -> None:
    """SM0.0 is 1 in every scan; SM0.1 and SM0.3 only in the first; SM0.7 (RUN switch) is 1."""
    p = plcrt.load(SM_PROGRAM, scan_ms=10)
    seen = []
    for _ in range(5):
        p.scan()
        seen.append(_bits(p, "Q0.0", "Q0.1", "Q0.3", "Q0.7"))
    assert seen == [(1, 1, 1, 1)] + [(1, 0, 0, 1)] * 4


def test_sm06_toggles_every_scan() -> None:
    """SM0.6 is on in the first scan and alternates afterwards."""
    p = plcrt.load(SM_PROGRAM, scan_ms=7)
    seen = []
    for _ in range(6):
        p.scan()
        seen.append(p["Q0.6"])
    assert seen == [1, 0, 1, 0, 1, 0]


@pytest.mark.parametrize("scan_ms", [10, 50, 100, 250])
def test_sm05_is_a_one_second_clock(scan_ms: int) -> None:
    """SM0.5 is off for the first 0.5 s of each second and on for the second half."""
    p = plcrt.load(SM_PROGRAM, scan_ms=scan_ms)
    for _ in range(int(3000 / scan_ms)):
        start_ms = p.scans * scan_ms
        p.scan()
        assert p["Q0.5"] == int(start_ms % 1000 >= 500), start_ms


def test_sm04_is_a_one_minute_clock() -> None:
    """SM0.4 is off for 30 s and on for 30 s."""
    p = plcrt.load(SM_PROGRAM, scan_ms=1000)
    seen = []
    for _ in range(120):
        p.scan()
        seen.append(p["Q0.4"])
    assert seen == ([0] * 30 + [1] * 30) * 2


@pytest.mark.parametrize("scan_ms,seconds,scans,time", [
    (10, 1.0, 100, 1.0),
    (10, 0.1, 10, 0.1),
    (30, 0.09, 3, 0.09),
    (150, 1.2, 8, 1.2),
    (0.5, 0.01, 20, 0.01),
    (7, 1.0, 143, 1.001),           # whole scans only: rounded up
    (100, 0.0, 0, 0.0),
])
def test_time_is_exact_after_run(scan_ms: float, seconds: float, scans: int, time: float) -> None:
    """run(seconds=...) runs whole scans; plc.time is exactly scans x scan time (no float drift)."""
    p = plcrt.load(SM_PROGRAM, scan_ms=scan_ms)
    p.run(seconds=seconds)
    assert p.scans == scans
    assert p.time == time
    p.run(seconds=seconds)
    assert p.time == round(2 * time, 6)


def test_time_does_not_drift_over_many_scans() -> None:
    """After 100000 scans of 10 ms the time is exactly 1000 s."""
    p = plcrt.load(SM_PROGRAM, scan_ms=10)
    p.run(scans=100_000)
    assert p.time == 1000.0


@pytest.mark.parametrize("kwargs", [{}, {"seconds": 1, "scans": 2}, {"seconds": -1},
                                    {"seconds": 1.8e302}, {"seconds": float("nan")}])
def test_run_needs_exactly_one_non_negative_duration(kwargs: dict) -> None:
    """run() takes exactly one of seconds= or scans=, a duration that can
    be counted in microseconds (1.8e302 s is finite, its microseconds are
    not)."""
    p = plcrt.load(SM_PROGRAM)
    with pytest.raises(PlcConfigError):
        p.run(**kwargs)


IO_PROGRAM = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\n"
              "LD I0.0\n= Q0.0\nLD SM0.0\nMOVB IB1, QB1\n"
              "END_ORGANIZATION_BLOCK\n")


def test_inputs_written_through_the_api_persist_across_scans() -> None:
    """plc["I0.0"] = 1 acts like a switch left on: it stays on over the following scans."""
    p = plcrt.load(IO_PROGRAM)
    p["I0.0"] = 1
    for _ in range(5):
        p.scan()
        assert p["Q0.0"] == 1
    p["I0.0"] = 0
    p.scan(3)
    assert p["Q0.0"] == 0


def test_input_image_is_copied_from_the_terminals_at_the_scan_start() -> None:
    """Writing only the image I is overwritten by the terminals PI at the next scan start."""
    p = plcrt.load(IO_PROGRAM)
    p.mem.areas["I"][1] = 0x55          # image only
    p.scan()
    assert p["QB1"] == 0 and p["IB1"] == 0
    p.mem.areas["PI"][1] = 0x3C         # terminal
    p.scan()
    assert p["QB1"] == 0x3C and p["IB1"] == 0x3C


def test_outputs_reach_the_terminals_at_the_scan_end() -> None:
    """Q is copied to PQ after the program; a device sees the old PQ during the scan."""
    class Probe:
        def __init__(self) -> None:
            self.pq: list[int] = []

        def step(self, plc: plcrt.Plc, t_from: int, t_to: int) -> None:
            self.pq.append(plc.mem.areas["PQ"][0])

    p = plcrt.load(IO_PROGRAM, scan_ms=10)
    probe = Probe()
    p.devices.append(probe)
    p["I0.0"] = 1
    p.scan()
    assert probe.pq == [0] and p.mem.areas["PQ"][0] == 1
    p.scan()
    assert probe.pq == [0, 1]


def test_scan_time_words_report_the_scan_time() -> None:
    """SMW22/24/26 (last/min/max scan time in ms) hold the simulated scan time."""
    p = plcrt.load(SM_PROGRAM, scan_ms=25)
    p.scan()
    assert (p["SMW22"], p["SMW24"], p["SMW26"]) == (25, 25, 25)


@pytest.mark.parametrize("scan_ms", [0, -5, 60001, "10"])
def test_scan_time_is_validated(scan_ms) -> None:
    """The scan time must be a number of milliseconds in a sane range."""
    with pytest.raises(PlcConfigError):
        plcrt.load(SM_PROGRAM, scan_ms=scan_ms)


def test_memory_persists_between_scans_and_outputs_hold() -> None:
    """Nothing is cleared between scans: a latched bit and a counter word keep their values."""
    p = plcrt.load("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD I0.0\nS M0.0, 1\n"
                   "LD SM0.0\nINCW VW0\nLD M0.0\n= Q0.2\nEND_ORGANIZATION_BLOCK\n")
    p["I0.0"] = 1
    p.scan()
    p["I0.0"] = 0
    p.scan(9)
    assert (p["M0.0"], p["Q0.2"], p["VW0"], p.scans) == (1, 1, 10, 10)


@pytest.mark.parametrize("scan_ms, us", [(0.001, 1), (1.1, 1100), (7, 7000), (0.25, 250),
                                         (60000, 60_000_000)])
def test_a_scan_time_of_whole_microseconds_is_taken_exactly(scan_ms, us) -> None:
    """Whole microseconds are taken as they are (1.1 ms is 1100 µs, whatever
    the float's last bit says)."""
    p = plcrt.load(SM_PROGRAM, scan_ms=scan_ms)
    p.scan(3)
    assert p.scan_us == us and p.now_us == 3 * us


@pytest.mark.parametrize("scan_ms, shown, give", [(0.0015, "1.5 µs", "give 0.001 or 0.002"),
                                                  (10.0001, "10000.1 µs",
                                                   "give 10 or 10.001")])
def test_a_scan_time_of_a_fraction_of_a_microsecond_is_refused(scan_ms, shown, give) -> None:
    """The simulated clock counts whole µs: a scan time between two is
    refused, naming both neighbours, never rounded."""
    with pytest.raises(PlcConfigError) as info:
        plcrt.load(SM_PROGRAM, scan_ms=scan_ms)
    assert f"is {shown}; {give}" in info.value.message
    assert "whole number of microseconds" in info.value.message


def test_the_marker_and_the_harness_check_the_scan_time_the_same_way() -> None:
    from plcrt.testing import Harness
    from plcrt.testing.plugin import PlcUsageError, _make_spec
    with pytest.raises(PlcConfigError, match="whole number of microseconds"):
        Harness.load(SM_PROGRAM, scan_ms=0.0015)
    with pytest.raises(PlcUsageError, match="scan_ms= must be a whole number of microseconds"):
        root = Path(__file__).resolve().parents[2]
        _make_spec((root / "programs" / "timers.awl",), {"scan_ms": 0.0015}, [root], root)
