"""Table tests for the timer family (TON, TONR, TOF) and plcrt.engine.timers.

The expected scan numbers follow the update rules of the S7-200 System
Manual, "Understanding how resolution affects the timer action" (digest
section 3.4):

* 1 ms and 10 ms timers advance at the start of every scan by the whole
  ticks elapsed since the previous scan start (plcrt applies the 1 ms
  ticks at the scan start too, see ``plcrt.engine.timers``);
* 100 ms timers advance only when their box runs, by the 100 ms ticks
  between the previous scan start and this one.

In every table IN switches on (or off, for TOF) in scan ``start`` and the
row names the first scan whose program sees the timer bit change, with the
current value at that moment.
"""

from __future__ import annotations

import itertools

import pytest

import plcrt
from stl_helpers import load_ob1 as _load
from plcrt.errors import PlcCompileError


def _tbit(p: plcrt.Plc, n: int) -> int:
    """The timer bit of Tn (``plc["Tn"]`` reads the current value)."""
    return p.mem.areas["TB"][n >> 3] >> (n & 7) & 1


def _first_change(p: plcrt.Plc, n: int, start: int, value: int,
                  limit: int = 2000) -> tuple[int, int]:
    """Set I0.0 := value before scan ``start``; return (scan, CV) where Q0.0
    (a copy of the timer bit made in a later network) first differs from
    its state before ``start``."""
    before = None
    for i in range(limit):
        if i == start:
            before = p["Q0.0"]
            p["I0.0"] = value
        p.scan()
        if before is not None and p["Q0.0"] != before:
            return i, p[f"T{n}"]
    raise AssertionError("the timer bit never changed")


def _timer_program(box: str, n: int, pt: int, scan_ms: float) -> plcrt.Plc:
    """``LD I0.0 / <box> Tn, +PT`` and, in the next network, ``LD Tn / = Q0.0``."""
    return _load(f"LD I0.0\n{box} T{n}, +{pt}", f"LD T{n}\n= Q0.0", scan_ms=scan_ms)


# (timer, PT, scan ms, scan whose program first sees the bit on, CV then).
# All rows are a nominal 300 ms; IN turns on in scan 3.  A 100 ms timer can
# be up to one tick short when it starts between two ticks (manual).
TON_TABLE = [
    (32, 300, 7, 46, 301),
    (32, 300, 10, 33, 300),
    (32, 300, 30, 13, 300),
    (32, 300, 150, 5, 300),
    (33, 30, 7, 46, 30),
    (33, 30, 10, 33, 30),
    (33, 30, 30, 13, 30),
    (33, 30, 150, 5, 30),
    (37, 3, 7, 43, 3),
    (37, 3, 10, 30, 3),
    (37, 3, 30, 10, 3),
    (37, 3, 150, 5, 3),
]


@pytest.mark.parametrize("n,pt,scan_ms,on_scan,cv", TON_TABLE)
def test_ton_bit_turns_on_per_resolution_rules(n: int, pt: int, scan_ms: float,
                                               on_scan: int, cv: int) -> None:
    """TON at 1/10/100 ms sets its bit in the scan the resolution rules predict."""
    p = _timer_program("TON", n, pt, scan_ms)
    assert _first_change(p, n, 3, 1) == (on_scan, cv)


# TOF: IN on from scan 0, off in scan 3; (timer, PT, scan ms, scan the bit
# is first seen off, CV then).
TOF_TABLE = [
    (32, 300, 7, 46, 301),
    (32, 300, 10, 33, 300),
    (32, 300, 30, 13, 300),
    (32, 300, 150, 5, 300),
    (33, 30, 7, 46, 30),
    (33, 30, 10, 33, 30),
    (33, 30, 30, 13, 30),
    (33, 30, 150, 5, 30),
    (37, 3, 7, 43, 3),
    (37, 3, 10, 30, 3),
    (37, 3, 30, 10, 3),
    (37, 3, 150, 5, 3),
]


@pytest.mark.parametrize("n,pt,scan_ms,off_scan,cv", TOF_TABLE)
def test_tof_bit_turns_off_per_resolution_rules(n: int, pt: int, scan_ms: float,
                                                off_scan: int, cv: int) -> None:
    """TOF at 1/10/100 ms clears its bit PT after the falling edge of IN."""
    p = _timer_program("TOF", n, pt, scan_ms)
    p["I0.0"] = 1
    assert _first_change(p, n, 3, 0) == (off_scan, cv)
    assert p["Q0.0"] == 0           # the change was on -> off


@pytest.mark.parametrize("n", [32, 33, 37])
def test_tof_needs_a_falling_edge_and_short_pulses_keep_it_on(n: int) -> None:
    """TOF stays off until IN has been on; an off-time shorter than PT keeps the bit on."""
    p = _timer_program("TOF", n, {32: 300, 33: 30, 37: 3}[n], 10)
    p.scan(50)
    assert (p["Q0.0"], p[f"T{n}"]) == (0, 0)
    p["I0.0"] = 1
    p.scan()
    assert p["Q0.0"] == 1
    p["I0.0"] = 0
    p.scan(15)                      # 150 ms off: shorter than 300 ms
    assert p["Q0.0"] == 1 and p[f"T{n}"] > 0
    p["I0.0"] = 1
    p.scan()
    assert (p["Q0.0"], p[f"T{n}"]) == (1, 0)   # IN on again: CV cleared


# TONR: IN pattern per scan (10 ms scans for T0/T1, 100 ms for T5) and the
# (CV, bit) seen after each scan.  1/10 ms timers also count the interval
# up to the scan in which the box sees IN = 0 (they advance at the scan
# start); a 100 ms TONR only adds ticks when its box runs with IN = 1.
TONR_TABLE = [
    ("T0 1 ms", 0, 25, 10, [1, 1, 1, 0, 0, 1, 1, 0],
     [(0, 0), (10, 0), (20, 0), (30, 1), (30, 1), (30, 1), (40, 1), (50, 1)]),
    ("T1 10 ms", 1, 3, 10, [1, 1, 1, 0, 0, 1, 1, 0],
     [(0, 0), (1, 0), (2, 0), (3, 1), (3, 1), (3, 1), (4, 1), (5, 1)]),
    ("T5 100 ms", 5, 3, 100, [1, 1, 1, 0, 0, 1, 1, 0],
     [(0, 0), (1, 0), (2, 0), (2, 0), (2, 0), (2, 0), (3, 1), (3, 1)]),
]


@pytest.mark.parametrize("label,n,pt,scan_ms,pattern,expected", TONR_TABLE,
                         ids=[r[0] for r in TONR_TABLE])
def test_tonr_keeps_its_value_while_in_is_off(label: str, n: int, pt: int, scan_ms: float,
                                               pattern: list[int],
                                               expected: list[tuple[int, int]]) -> None:
    """TONR accumulates over separate on-periods and keeps CV and bit when IN is off."""
    p = _timer_program("TONR", n, pt, scan_ms)
    got = []
    for v in pattern:
        p["I0.0"] = v
        p.scan()
        got.append((p[f"T{n}"], _tbit(p, n)))
    assert got == expected


@pytest.mark.parametrize("n,pt", [(0, 5), (1, 5), (5, 5)])
def test_tonr_is_cleared_only_by_r(n: int, pt: int) -> None:
    """R Tn clears a TONR's current value and bit; IN = 0 alone does not."""
    p = _load(f"LD I0.0\nTONR T{n}, +{pt}", f"LD I0.1\nR T{n}, 1", scan_ms=100)
    p["I0.0"] = 1
    p.scan(80)
    p["I0.0"] = 0
    p.scan(3)
    assert p[f"T{n}"] > 0 and _tbit(p, n) == 1
    p["I0.1"] = 1
    p.scan()
    assert (p[f"T{n}"], _tbit(p, n)) == (0, 0)


@pytest.mark.parametrize("n,res", [(32, 1), (33, 10), (37, 100)])
def test_ton_in_off_clears_value_and_bit(n: int, res: int) -> None:
    """TON: IN = 0 clears the current value and the bit at once."""
    p = _timer_program("TON", n, 1, 10)
    p["I0.0"] = 1
    p.scan(30)
    assert p[f"T{n}"] > 0 and _tbit(p, n) == 1
    p["I0.0"] = 0
    p.scan()
    assert (p[f"T{n}"], _tbit(p, n)) == (0, 0)


@pytest.mark.parametrize("n,scan_ms,scans", [(32, 60_000, 2), (33, 60_000, 7), (37, 1000, 3300)])
def test_current_value_saturates_at_32767(n: int, scan_ms: float, scans: int) -> None:
    """A running TON stops counting at 32767 and keeps its bit on."""
    p = _timer_program("TON", n, 100, scan_ms)
    p["I0.0"] = 1
    p.scan(scans)
    assert p[f"T{n}"] == 32767
    p.scan(3)
    assert p[f"T{n}"] == 32767 and _tbit(p, n) == 1


def test_preset_from_a_word_operand_is_read_at_each_execution() -> None:
    """PT may come from VW memory; a changed preset applies at the next execution."""
    p = _load("LD I0.0\nTON T37, VW10", "LD T37\n= Q0.0", scan_ms=100)
    p["VW10"] = 50
    p["I0.0"] = 1
    p.scan(6)
    assert (p["T37"], p["Q0.0"]) == (5, 0)
    p["VW10"] = 5
    p.scan()
    assert (p["T37"], p["Q0.0"]) == (6, 1)


def test_100ms_timer_executed_twice_per_scan_gains_time() -> None:
    """A 100 ms box that runs twice in a scan adds the scan's ticks twice (manual warning)."""
    p = _load("LD I0.0\nTON T37, +1000", "LD I0.0\nTON T37, +1000", scan_ms=100)
    assert any(d.code == "timer-twice" and d.severity == "warning" for d in p.diagnostics)
    p["I0.0"] = 1
    p.scan(11)                      # 1 s of running time
    assert p["T37"] == 20


# A 100 ms timer whose box is jumped over loses the skipped time; a 10 ms
# timer keeps counting because it advances at every scan start.
@pytest.mark.parametrize("n,pt,expected", [(37, 1000, 5), (33, 10000, 10)])
def test_skipped_box_loses_time_only_at_100ms(n: int, pt: int, expected: int) -> None:
    """JMP around a running timer: 100 ms loses the skipped ticks, 10 ms does not."""
    scan = 100 if n == 37 else 10
    p = _load("LD I0.1\nJMP 1", f"LD I0.0\nTON T{n}, +{pt}", "LBL 1", scan_ms=scan)
    p["I0.0"] = 1
    p.scan(5)                       # CV 4 after five scans
    p["I0.1"] = 1
    p.scan(5)                       # box skipped for five scans
    p["I0.1"] = 0
    p.scan()
    assert p[f"T{n}"] == expected


# Figure 9-4 of the manual: the self-resetting one-shot
# "LDN T3x / TON T3x, PT / LD T3x / = Q0.0".
ONE_SHOT = [
    # (timer, PT, scan ms, scans run, scans with Q0.0 on)
    (37, 3, 10, 150, [30, 60, 90, 120]),
    (37, 3, 30, 50, [10, 20, 30, 40]),
    (37, 3, 7, 180, [43, 86, 129, 172]),
    (37, 3, 150, 10, [2, 6]),
    (38, 5, 10, 150, [50, 100]),
    (33, 30, 10, 150, []),
    (33, 3, 7, 200, []),
    (33, 3, 30, 100, []),
    # 1 ms: plcrt advances 1 ms timers at the scan start (engine.timers
    # docstring), so the timer is never updated between TON and LD T32 and
    # the one-shot never fires; on hardware it fires only in the rare scans
    # where a 1 ms tick lands between the two instructions.
    (32, 300, 10, 150, []),
    (32, 30, 7, 200, []),
]


@pytest.mark.parametrize("n,pt,scan_ms,scans,on_scans", ONE_SHOT)
def test_self_resetting_one_shot(n: int, pt: int, scan_ms: float, scans: int,
                                 on_scans: list[int]) -> None:
    """The manual's one-shot pulses one scan per period at 100 ms; never at 10 ms (or 1 ms)."""
    p = _load(f"LDN T{n}\nTON T{n}, +{pt}", f"LD T{n}\n= Q0.0", scan_ms=scan_ms)
    got = []
    for i in range(scans):
        p.scan()
        if p["Q0.0"]:
            got.append(i)
    assert got == on_scans


@pytest.mark.parametrize("n", [32, 33, 37])
def test_correct_one_shot_with_ldn_q_enable_fires_every_period(n: int) -> None:
    """The manual's corrected form (enable from LDN Q0.0) pulses at every resolution."""
    pt = {32: 300, 33: 30, 37: 3}[n]
    p = _load(f"LDN Q0.0\nTON T{n}, +{pt}", f"LD T{n}\n= Q0.0", scan_ms=10)
    got = []
    for i in range(100):
        p.scan()
        if p["Q0.0"]:
            got.append(i)
    assert got and all(30 <= b - a <= 32 for a, b in itertools.pairwise(got))


@pytest.mark.parametrize("n", [37, 38])
def test_r_clears_a_running_ton(n: int) -> None:
    """R Tn clears CV and bit; an enabled TON restarts from 0 at its next execution."""
    p = _load(f"LD I0.0\nTON T{n}, +3", f"LD I0.1\nR T{n}, 1", scan_ms=100)
    p["I0.0"] = 1
    p.scan(5)
    assert (p[f"T{n}"], _tbit(p, n)) == (4, 1)
    p["I0.1"] = 1
    p.scan()
    assert (p[f"T{n}"], _tbit(p, n)) == (0, 0)
    p["I0.1"] = 0
    p.scan(2)
    assert p[f"T{n}"] == 1


def test_tof_in_an_inactive_scr_segment_is_reset() -> None:
    """A TOF timing inside an SCR segment is reset (CV 0, bit 0) once the segment is inactive."""
    p = _load("LD SM0.1\nS S0.0, 1", "LSCR S0.0", "LD I0.0\nTOF T37, +50",
              "LD I0.1\nSCRT S0.1", "SCRE", scan_ms=100)
    p["I0.0"] = 1
    p.scan()
    p["I0.0"] = 0
    p.scan(3)
    assert (p["T37"], _tbit(p, 37)) == (2, 1)
    p["I0.1"] = 1
    p.scan()                        # SCRT: this scan still ran the segment
    p["I0.1"] = 0
    p.scan()
    assert (p["T37"], _tbit(p, 37), p["S0.0"], p["S0.1"]) == (0, 0, 0, 1)
    p.scan(5)
    assert (p["T37"], _tbit(p, 37)) == (0, 0)


def test_symbolic_tof_in_an_inactive_scr_segment_is_reset() -> None:
    """The SCR reset also finds a TOF whose timer is named by a symbol."""
    src = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD SM0.1\nS S0.0, 1\n"
           "Network 2\nLSCR S0.0\nNetwork 3\nLD I0.0\nTOF Fan_Delay, +50\n"
           "Network 4\nLD I0.1\nSCRT S0.1\nNetwork 5\nSCRE\nEND_ORGANIZATION_BLOCK\n")
    symbols = '"Symbol","Address","Comment"\n"Fan_Delay","T37","fan run-on"\n'
    p = plcrt.load(src, symbols=symbols, scan_ms=100)
    p["I0.0"] = 1
    p.scan()
    p["I0.0"] = 0
    p.scan(3)
    p["I0.1"] = 1
    p.scan()
    p.scan()
    assert (p["T37"], _tbit(p, 37)) == (0, 0)


COMPILE_ERRORS = [
    ("TON and TOF share T37", "LD I0.0\nTON T37, +10\nLD I0.1\nTOF T37, +10",
     "TON and TOF cannot share"),
    ("TOF then TON on T40", "LD I0.0\nTOF T40, +10\nLD I0.1\nTON T40, +10",
     "TON and TOF cannot share"),
    ("TONR number by TON", "LD I0.0\nTON T5, +10", "T5 is a TONR"),
    ("TONR number by TOF", "LD I0.0\nTOF T64, +10", "T64 is a TONR"),
    ("TON number by TONR", "LD I0.0\nTONR T37, +10", "T37 is a TON/TOF"),
    ("not a timer", "LD I0.0\nTON C5, +10", "timer"),
]


@pytest.mark.parametrize("label,body,message", COMPILE_ERRORS,
                         ids=[c[0] for c in COMPILE_ERRORS])
def test_timer_number_misuse_is_a_compile_error(label: str, body: str, message: str) -> None:
    """Timer numbers follow the manual's table: wrong box type or TON/TOF sharing is rejected."""
    with pytest.raises(PlcCompileError) as exc:
        _load(body)
    assert message in str(exc.value)


@pytest.mark.parametrize("n,res", [(0, 1), (64, 1), (1, 10), (68, 10), (5, 100), (95, 100),
                                   (32, 1), (96, 1), (33, 10), (100, 10), (37, 100),
                                   (101, 100), (255, 100)])
def test_resolution_follows_the_timer_number(n: int, res: int) -> None:
    """The resolution table of the manual (T0/T64 1 ms, T1-T4 10 ms, ...)."""
    from plcrt.engine.timers import resolution_ms
    assert resolution_ms(n) == res


@pytest.mark.parametrize("n,scan_ms", [(37, 10), (33, 10), (32, 0.5)])
def test_ton_bit_follows_a_current_value_written_by_the_program(n: int, scan_ms: float) -> None:
    """A running TON compares CV with PT at every execution, also after MOVW wrote its CV."""
    p = _load(f"LD I0.0\nTON T{n}, +50", f"LD I0.1\nMOVW +60, T{n}", f"LD T{n}\n= Q0.0",
              scan_ms=scan_ms)
    p["I0.0"] = 1
    p.scan(2)
    assert p["Q0.0"] == 0
    p["I0.1"] = 1
    p.scan()                        # CV written after the box ran
    p["I0.1"] = 0
    p.scan()                        # next execution: no new 100 ms tick, CV 60 >= 50
    assert p["Q0.0"] == 1 and p[f"T{n}"] >= 60
