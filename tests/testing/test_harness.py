"""The test harness (plcrt.testing.Harness) used directly, without the plugin:
time control in simulated time, conditions, stimuli, forcing, fork and
snapshots, and an EM253 move."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import plcrt
from plcrt import PlcConfigError
from plcrt.testing import Harness, PlcTimeout, seconds
from stl_helpers import ob1_text

ROOT = Path(__file__).resolve().parents[2]
SEAL_IN = ROOT / "programs" / "seal_in.awl"
EM253 = ROOT / "programs" / "em253"

# T37 is a 100 ms timer: PT +10 is 1 s.  Q0.0 follows its bit.
TON_1S = ob1_text("LD I0.0\nTON T37, +10", "LD T37\n= Q0.0")
# VW100 counts scans; Q0.0 is on from the third scan on.
COUNTER = ob1_text("LD SM0.0\nINCW VW100", "LDW>= VW100, +3\n= Q0.0")


def seal_in(**kw) -> Harness:
    return Harness.load(SEAL_IN, watch=["I0.0", "I0.1", "Q0.0"], **kw)


# -- time ----------------------------------------------------------------------
@pytest.mark.parametrize("text, value", [
    (2, 2.0), (0.25, 0.25), ("1.5s", 1.5), ("200ms", 0.2), ("2min", 120.0),
    ("250 us", 0.00025), (".5", 0.5),
])
def test_durations(text, value) -> None:
    assert seconds(text) == pytest.approx(value)


@pytest.mark.parametrize("bad", ["fast", "1.5 parsecs", "-1s", True, float("nan")])
def test_bad_durations_are_config_errors(bad) -> None:
    with pytest.raises(PlcConfigError):
        seconds(bad)


def test_scan_and_run_with_durations() -> None:
    h = seal_in()
    h.scan()
    h.scan(2)
    assert (h.scans, h.time) == (3, pytest.approx(0.03))
    h.run("1.5s")
    assert h.scans == 153
    h.run("200ms")
    assert h.scans == 173 and h.time == pytest.approx(1.73)
    h.run(scans=7)
    assert h.scans == 180
    with pytest.raises(PlcConfigError):
        h.run("1s", scans=3)
    with pytest.raises(PlcConfigError):
        h.run()


def test_scan_ms_sets_the_time_step() -> None:
    h = Harness.load(SEAL_IN, scan_ms=2.5)
    h.run("10ms")
    assert (h.scans, h.time) == (4, pytest.approx(0.01))


def test_run_until_returns_the_exact_simulated_time() -> None:
    h = Harness.load(TON_1S, watch=["T37", "Q0.0"], history=5)
    h["I0.0"] = 1
    took = h.run_until("Q0.0")
    # The TON box sees 1.00 s elapsed at the start of scan 101 (it started
    # timing at t = 0, the start of scan 1); the condition is checked after
    # each scan, so it holds after scan 101, at t = 1.01 s.
    assert took == pytest.approx(1.01)
    assert h.scans == 101 and h["T37"] == 10
    rows = h.history_rows()
    assert [r[0] for r in rows] == [97, 98, 99, 100, 101]
    assert [r[2] for r in rows[-2:]] == [(9, 0), (10, 1)]


def test_run_until_counts_from_now() -> None:
    h = Harness.load(TON_1S)
    h.run("3s")                     # I0.0 off: nothing happens
    h["I0.0"] = 1
    assert h.run_until("Q0.0") == pytest.approx(1.01)
    assert h.time == pytest.approx(4.01)


def test_run_until_timeout_names_the_condition_and_the_time() -> None:
    h = Harness.load(TON_1S)
    h["I0.0"] = 1
    with pytest.raises(PlcTimeout) as exc:
        h.run_until("Q0.0", timeout="500ms", message="motor did not start")
    assert isinstance(exc.value, AssertionError)
    text = str(exc.value)
    assert "motor did not start" in text
    assert "'Q0.0' did not become true within 0.5 s of simulated time (50 scans)" in text
    assert "t = 0.500 s, scan 50" in text
    assert h.scans == 50


def test_string_conditions() -> None:
    h = Harness.load(COUNTER)
    assert h.run_until("VW100 >= 5") == pytest.approx(0.05)
    assert h["VW100"] == 5
    h2 = Harness.load(COUNTER)
    assert h2.run_while("not Q0.0") == pytest.approx(0.03)
    assert h2["Q0.0"] == 1
    h3 = Harness.load(COUNTER)
    assert h3.run_until("VW100 == 2") == pytest.approx(0.02)
    assert h3.run_until(lambda h: h["VW100"] > 6) == pytest.approx(0.05)
    assert h3.run_until(lambda: h3["VW100"] == 10) == pytest.approx(0.03)
    with pytest.raises(PlcConfigError):
        h3.run_until("VW100 >= lots")


def test_stays() -> None:
    h = Harness.load(COUNTER)
    h.stays("not Q0.0", "20ms")
    with pytest.raises(AssertionError) as info:
        h.stays("not Q0.0", "1s")
    assert str(info.value) == ("expected 'not Q0.0' to stay true for 1 s from t = 0.020 s; "
                               "it became false 0.010 s later; at t = 0.030 s, scan 3")


def test_stays_names_a_lambda_by_its_text_and_shows_the_watched_values() -> None:
    h = Harness.load(COUNTER, watch=["VW100", "Q0.0"])
    with pytest.raises(AssertionError) as info:
        h.stays(lambda: h["VW100"] < 2, "1s", message="counter too fast")
    assert str(info.value) == (
        "counter too fast; expected 'lambda: h[\"VW100\"] < 2' to stay true for 1 s from "
        "t = 0.000 s; it became false 0.020 s later; at t = 0.020 s, scan 2; "
        "VW100 = 2, Q0.0 = 0")


def test_a_comparison_that_never_holds_shows_its_value() -> None:
    h = Harness.load(COUNTER)
    with pytest.raises(PlcTimeout) as info:
        h.run_until("VW100 >= 500", timeout="50ms")
    assert str(info.value) == ("'VW100 >= 500' did not become true within 0.05 s of simulated "
                               "time (5 scans); at t = 0.050 s, scan 5; VW100 = 5")


def test_a_function_without_source_is_the_condition() -> None:
    h = Harness.load(COUNTER)
    cond = eval("lambda: False")        # no source file to quote
    with pytest.raises(PlcTimeout, match=r"^the condition did not become true within 0.02 s"):
        h.run_until(cond, timeout="20ms")


# -- stimuli -------------------------------------------------------------------
def test_pulse_holds_for_the_scans_then_reverts() -> None:
    h = seal_in()
    h.pulse("I0.0")
    assert h["I0.0"] == 0 and h["Q0.0"] == 1
    h.scan(2)
    assert h["Q0.0"] == 1           # sealed in
    h.pulse("I0.1", scans=2)
    assert h["I0.1"] == 0 and h["Q0.0"] == 0
    # the history shows the stop button on for exactly two scans
    assert [r[2][1] for r in h.history_rows()] == [0, 0, 0, 1, 1]


def test_patch_puts_the_old_values_back() -> None:
    h = Harness.load(ob1_text("LD I0.0\n= Q0.0", "LD SM0.0\nMOVW VW10, VW12"),
                     watch=["VW12", "Q0.0"])
    h["VW10"] = 42
    h.patch({"VW10": 5, "I0.0": 1}, scans=3)
    assert h["VW10"] == 42 and h["I0.0"] == 0
    h.scan()
    assert [r[2] for r in h.history_rows()] == [(5, 1)] * 3 + [(42, 0)]


# A program that writes both addresses the tests force, every scan; network 2
# copies VW10 after the program's write.
WRITER = ob1_text("LD SM0.0\nMOVW +7, VW10\n= Q0.3", "LD SM0.0\nMOVW VW10, VW20")


def test_force_survives_the_program_writing_the_address() -> None:
    h = Harness.load(WRITER)
    h.force("VW10", 3)
    h.force("Q0.3", 0)
    h.scan(3)
    assert h["VW10"] == 3 and h["Q0.3"] == 0
    assert h.plc.mem.areas["PQ"][0] & 8 == 0     # the terminal sees the forced value
    # as on the CPU, the program's own write is visible to the rest of its scan
    assert h["VW20"] == 7
    h.unforce("VW10")
    h.scan()
    assert h["VW10"] == 7 and h["Q0.3"] == 0
    h.unforce()
    h.scan()
    assert h["Q0.3"] == 1


def test_force_as_context_manager_unforces() -> None:
    h = Harness.load(WRITER)
    with h.force("VW10", 3) as same:
        assert same is h
        h.scan(2)
        assert h["VW10"] == 3 and "VW10" in h.plc.forces
    assert "VW10" not in h.plc.forces
    h.scan()
    assert h["VW10"] == 7
    with h.forced({"VW10": 1, "Q0.3": 0}):
        h.scan()
        assert (h["VW10"], h["Q0.3"]) == (1, 0)
    assert h.plc.forces == {}


def test_stimulus_rows_apply_before_the_first_scan_at_their_time() -> None:
    h = seal_in(history=100)
    h.stimulus([("50ms", "I0.0", 0), (0, "I0.0", 1), (0.2, "I0.1", 1), ("245ms", "I0.1", 0)],
               until="300ms")
    assert h.time == pytest.approx(0.3) and h.scans == 30
    rows = {scan: vals for scan, _, vals in h.history_rows()}
    # scan n starts at (n - 1) * 10 ms
    assert rows[1] == (1, 0, 1)      # start pressed from t = 0
    assert rows[5] == (1, 0, 1)      # scan 5 starts at 40 ms
    assert rows[6] == (0, 0, 1)      # released at 50 ms, sealed in
    assert rows[20] == (0, 0, 1)
    assert rows[21] == (0, 1, 0)     # stop at 200 ms: scan 21
    assert rows[25] == (0, 1, 0)     # 245 ms falls inside scan 25 ...
    assert rows[26] == (0, 0, 0)     # ... so scan 26 (250 ms) sees it released
    with pytest.raises(PlcConfigError, match="stimulus row 1"):
        h.stimulus([("1s", "I0.0")])


# -- state -----------------------------------------------------------------------
def test_fork_is_independent_and_equal() -> None:
    h = seal_in()
    h.pulse("I0.0")
    h.run("1s")
    f = h.fork()
    assert (f.time, f.scans, f.history_rows()) == (h.time, h.scans, h.history_rows())
    for x in (h, f):
        x.run("0.5s")
    assert f.values("Q0.0", "Q0.1") == h.values("Q0.0", "Q0.1") == {"Q0.0": 1, "Q0.1": 1}
    assert f.history_rows() == h.history_rows()
    f.pulse("I0.1")
    assert f["Q0.0"] == 0 and h["Q0.0"] == 1
    h.scan()
    assert h["Q0.0"] == 1 and f.scans == h.scans
    assert h.forks == [f]


def test_snapshot_and_restore() -> None:
    h = Harness.load(TON_1S)
    h["I0.0"] = 1
    h.run("0.5s")
    snap = h.snapshot()
    h.run("2s")
    assert h["Q0.0"] == 1
    h.restore(snap)
    assert (h.time, h["T37"], h["Q0.0"]) == (pytest.approx(0.5), 4, 0)
    assert h.run_until("Q0.0") == pytest.approx(0.51)
    other = Harness.load(TON_1S)
    with pytest.raises(PlcConfigError, match="different program"):
        other.restore(snap)


def test_load_accepts_a_parsed_program() -> None:
    from plcrt.engine.runtime import parse_sources
    prog = parse_sources(SEAL_IN)
    a, b = Harness.load(prog), Harness.load(prog)
    a.pulse("I0.0")
    assert (a["Q0.0"], b["Q0.0"]) == (1, 0)     # one parse, separate PLCs


# -- motion ----------------------------------------------------------------------
def test_em253_point_to_point_move_ends_at_17_s() -> None:
    h = Harness.load(EM253 / "pos_goto_r.awl", plant=EM253 / "plant.toml", scan_ms=1,
                     watch=["VW106", "VD108"])
    h["M2.0"] = 1                   # start the 1 000 000 pulse move
    h.run("10s")
    at_10s = h.fork()
    took = h.axis_done_within("17.2s") + 10.0
    assert took == pytest.approx(17.0, abs=1e-9)
    ax = h.axis(0, 0)
    assert (ax.position, ax.mechanical, ax.speed, ax.moving) == (1_000_000, 1_000_000, 0, False)
    # one scan more has run: the block has reported the end (C_Status 8, C_Pos)
    assert h.time == pytest.approx(17.001)
    assert (h["VW106"], h["VD108"]) == (8, 1_000_000)
    # the same move cannot be done 0.1 s sooner
    with pytest.raises(PlcTimeout) as info:
        at_10s.axis_done_within("6.9s")
    assert str(info.value) == (
        "expected the move of axis 0.0 to be done within 6.9 s; it was still moving 6.9 s "
        "later; at t = 16.900 s, scan 16900; axis0.0.position = 999421, axis0.0.speed = 6562, "
        "VW106 = 1, VD108 = 999415")


def test_axis_done_within_a_move_that_never_starts_says_so() -> None:
    h = Harness.load(EM253 / "pos_goto_r.awl", plant=EM253 / "plant.toml", scan_ms=1)
    with pytest.raises(PlcTimeout) as info:
        h.axis_done_within("5s")
    assert str(info.value) == (
        "expected the move of axis 0.0 to be done within 5 s; the axis did not start moving "
        "within 1 s; at t = 1.000 s, scan 1000; axis0.0.position = 0, axis0.0.speed = 0")


# -- property: forking mid-way changes nothing -----------------------------------
_rows = st.lists(st.tuples(st.integers(0, 600), st.sampled_from(["I0.0", "I0.1"]),
                           st.integers(0, 1)), max_size=12)


@settings(max_examples=40, deadline=None)
@given(table=_rows, mid_scans=st.integers(0, 60))
def test_fork_mid_way_gives_the_same_history(table, mid_scans) -> None:
    end, mid = 0.65, mid_scans / 100
    straight = seal_in(history=100)
    straight.stimulus([(t / 1000, a, v) for t, a, v in table], until=end)
    h = seal_in(history=100)
    h.stimulus([(t / 1000, a, v) for t, a, v in table if t / 1000 < mid], until=mid)
    f = h.fork()
    rest = [(t / 1000 - mid, a, v) for t, a, v in table if t / 1000 >= mid]
    for x in (h, f):
        x.stimulus(rest, until=end - mid)
    assert f.history_rows() == h.history_rows() == straight.history_rows()
    assert f.scans == h.scans == straight.scans == 65


# -- edge cases --------------------------------------------------------------------
STOPS = ob1_text("LD SM0.0\nINCW VW100", "LD I0.2\nSTOP")


def test_run_until_with_a_condition_that_raises_says_when() -> None:
    h = Harness.load(COUNTER)

    def broken() -> bool:
        raise ZeroDivisionError("oops")

    with pytest.raises(ZeroDivisionError) as info:
        h.run_until(broken)
    # the test's own exception, with a note on the scan it was checked after
    assert info.value.__notes__ == [
        "while checking the condition 'broken' after scan 1 (t = 0.010 s)"]
    assert h.scans == 1


@pytest.mark.parametrize("cond", [None, 5, ["Q0.0"]])
def test_a_condition_of_the_wrong_type_is_named(cond) -> None:
    with pytest.raises(PlcConfigError, match="a condition is a string such as"):
        Harness.load(COUNTER).run_until(cond)


@pytest.mark.parametrize("cond", ["VW100 >=", "VW100 >= =3", "VW100 == == 3"])
def test_an_incomplete_comparison_is_not_read_as_a_value(cond: str) -> None:
    # "VW100 >=" used to be read as "VW100 > '='" ("'=' is not a number")
    with pytest.raises(PlcConfigError, match="cannot read the condition"):
        Harness.load(COUNTER).run_until(cond)


def test_stays_fails_when_the_cpu_is_in_stop() -> None:
    # In STOP no scan runs and time stands still: "stays off for 1 s" would
    # pass without a single scan.
    h = Harness.load(STOPS)
    h["I0.2"] = 1
    with pytest.raises(AssertionError, match="the CPU went to STOP before 1 s had passed"):
        h.stays("not Q0.0", "1s")
    with pytest.raises(AssertionError, match="went to STOP"):
        h.stays("not Q0.0", "1s")   # already in STOP
    assert h.scans == 1


def test_stimulus_checks_every_row_before_the_first_scan() -> None:
    h = Harness.load(COUNTER)
    for table, error in (
            ([(0, "VW10", 1), ("1s", "XX9.9", 1)], "stimulus row 2 .*'XX9.9' is not an address"),
            ([(0, "VW10", 1), (-1, "VW10", 2)], "stimulus row 2 .*must be a non-negative"),
            ([(0, "I0.0", 3)], "stimulus row 1 .*a bit takes 0 or 1"),
            ([(0.1, "VB0", 300)], "stimulus row 1 .*does not fit")):
        with pytest.raises(plcrt.PlcError, match=error):
            h.stimulus(table)
        assert h.scans == 0 and h["VW10"] == 0      # nothing ran, nothing written


def test_stimulus_keeps_the_order_of_rows_with_equal_times() -> None:
    h = Harness.load(COUNTER)
    h.stimulus([("20ms", "VW10", 5), (0, "VW10", 1), ("20ms", "VW10", 3), ("10ms", "VW10", 7),
                ("20ms", "VW10", 2)])
    assert h["VW10"] == 2 and h.scans == 2


def test_force_and_unforce_by_symbol_or_address(tmp_path: Path) -> None:
    symbols = tmp_path / "s.sym"
    symbols.write_text("Start\tI0.0\tstart\nStop\tI0.1\tstop\n", encoding="utf-8")
    h = Harness.load(SEAL_IN, symbols=symbols)
    h.force("I0.0", 1)
    h.unforce("Start")
    assert h.plc.forces == {}
    with h.force("Start", 1):
        h.force("I0.0", 0)          # the same location, forced again by address
    assert h.plc.forces == {}        # released at the end of the block all the same
    with h.forced({"Stop": 1}):
        h.unforce("I0.1")            # released inside the block: no error at its end
    assert h.plc.forces == {}


def test_fork_and_snapshot_of_a_faulted_plc() -> None:
    fault = ob1_text("LD SM0.0\nINCW VW0", "LD I0.1\nBMB VB0, VB10200, VB500")
    h = Harness.load(fault, watch=["VW0"])
    h.run(scans=2)
    h["VB500"] = 100
    h["I0.1"] = 1
    with pytest.raises(plcrt.PlcRuntimeError, match="block move runs past the end"):
        h.scan()
    twin = h.fork()
    assert (twin.plc.mode, twin.scans, twin["VW0"]) == ("STOP", 2, 3)
    assert str(twin.plc.fault) == str(h.plc.fault)
    twin.scan(5)                        # STOP: nothing runs, nothing raises
    assert twin.scans == 2
    with pytest.raises(PlcTimeout, match="the CPU went to STOP"):
        twin.run_until("VW0 > 10")
    h.restore(twin.snapshot())
    assert h.plc.mode == "STOP"


def test_trace_records_numpy_arrays_from_now_on() -> None:
    """Harness.trace records once per scan from the moment it is started:
    a TON T37 (PT 20 x 100 ms) with 10 ms scans counts 0, 0, ..., 1 ... and
    its output comes on in the scan at 2.01 s."""
    h = Harness.load(ROOT / "programs" / "timers.awl")
    h["I0.0"] = 1
    tr = h.trace("T37", "Q0.0")
    h.run("2.5s")
    assert len(tr) == 250
    assert tr.time[0] == pytest.approx(0.01)
    q = tr["Q0.0"]
    first_on = int(np.argmax(q == 1))
    assert tr.time[first_on] == pytest.approx(2.01)
    assert tr["T37"][first_on] == 20
    assert list(np.unique(np.diff(tr["T37"]))) == [0, 1]
    tr.detach()
    h.scan(3)
    assert len(tr) == 250


@pytest.mark.parametrize("limit", [1.8e302, "inf", -1, "soon"])
def test_a_time_limit_that_cannot_be_counted_is_a_config_error(limit: object) -> None:
    """max_time, like run(seconds=), must be a duration whose microseconds
    exist: 1.8e302 s is a finite float, its microseconds are not."""
    h = Harness.load(ROOT / "programs" / "seal_in.awl")
    with pytest.raises(PlcConfigError):
        h.limit_time(limit)
    assert h.max_time is None and h.run("0.1s").plc.scans == 10


def test_max_time_stops_any_run_and_carries_over_to_forks() -> None:
    """max_time counts simulated time from power-up: plain runs, run_until
    and forks all stop at the first scan past it."""
    h = Harness.load(ROOT / "programs" / "seal_in.awl", max_time="0.5s")
    h.run("0.4s")
    f = h.fork()
    with pytest.raises(PlcTimeout, match=r"limit of 0.5 s .* at t = 0.510 s, scan 51"):
        h.run("1s")
    with pytest.raises(PlcTimeout, match="limit of 0.5 s"):
        f.run_until("Q0.0", timeout="10s")
    g = Harness.load(ROOT / "programs" / "seal_in.awl")
    g.run("2s").limit_time(3)
    g.run("1s")
    with pytest.raises(PlcTimeout, match="limit of 3 s"):
        g.scan(1)
