"""Pin the behaviour of the sample programs in ``programs/``, scan by scan.

Each test drives a sample the way a commissioning engineer would: switch
inputs, run scans in simulated time (10 ms per scan unless said otherwise)
and look at outputs, timers, counters and V words.  The expected values
follow the S7-200 rules listed in docs/decisions.md; where a value depends
on a plcrt choice the comment says which one.

These tests are about the samples as documentation: if one breaks, either a
sample or the core changed behaviour, and the README/CLI examples need a
look too.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt
from plcrt.cli import render_dump

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"
SAMPLES = sorted(p.name for p in PROGRAMS.glob("*.awl"))


def load(name: str, **kw: object) -> plcrt.Plc:
    return plcrt.load(PROGRAMS / name, **kw)  # type: ignore[arg-type]


def test_all_five_samples_exist() -> None:
    assert SAMPLES == ["counters.awl", "scr_sequence.awl", "seal_in.awl",
                       "subroutine.awl", "timers.awl"]


def test_programs_readme_lists_every_sample() -> None:
    readme = (PROGRAMS / "README.md").read_text(encoding="utf-8")
    for name in SAMPLES:
        assert f"`{name}`" in readme


@pytest.mark.parametrize("name", SAMPLES)
def test_sample_compiles_without_diagnostics(name: str) -> None:
    plc = load(name)
    assert plc.diagnostics == []
    assert plc.mode == "RUN"


@pytest.mark.parametrize("name", SAMPLES)
def test_sample_dump_names_every_instruction(name: str) -> None:
    plc = load(name)
    dump = render_dump(plc)
    markers = [ln for ln in dump.splitlines() if ln.lstrip().startswith("# [")]
    assert len(markers) == plc.program.instruction_count()
    compile(dump, name, "exec")  # the dump is still valid Python text


@pytest.mark.parametrize("name", SAMPLES)
def test_sample_is_in_microwin_export_format(name: str) -> None:
    text = (PROGRAMS / name).read_text(encoding="utf-8")
    assert text.startswith("ORGANIZATION_BLOCK MAIN:OB1\nTITLE=")
    assert text.rstrip().endswith(("END_ORGANIZATION_BLOCK", "END_SUBROUTINE_BLOCK"))
    in_body = False
    for line in text.splitlines():
        if line == "BEGIN":
            in_body = True
        elif line.startswith("END_"):
            in_body = False
        elif in_body and " " in line and not line.startswith(("Network ", "//")):
            # an instruction with operands: the mnemonic padded to seven columns
            assert line[6] == " " and line[7] != " ", line


# ---------------------------------------------------------------------------
# seal_in.awl
# ---------------------------------------------------------------------------

def test_seal_in_latches_and_stops() -> None:
    plc = load("seal_in.awl")
    plc.scan()
    assert (plc["Q0.0"], plc["Q0.1"]) == (0, 0)

    plc["I0.0"] = 1  # press start
    plc.scan()
    assert (plc["Q0.0"], plc["Q0.1"]) == (1, 1)  # the lamp follows in the same scan

    plc["I0.0"] = 0  # release start: the seal keeps the motor on
    plc.scan(50)
    assert (plc["Q0.0"], plc["Q0.1"]) == (1, 1)

    plc["I0.1"] = 1  # press stop
    plc.scan()
    assert (plc["Q0.0"], plc["Q0.1"]) == (0, 0)

    plc["I0.1"] = 0
    plc.scan(5)
    assert plc["Q0.0"] == 0  # stays off until start is pressed again


def test_seal_in_stop_wins_over_start() -> None:
    plc = load("seal_in.awl")
    plc["I0.0"] = 1
    plc["I0.1"] = 1
    plc.scan(3)
    assert plc["Q0.0"] == 0
    plc["I0.1"] = 0
    plc.scan()
    assert plc["Q0.0"] == 1


def test_seal_in_physical_outputs_follow_at_scan_end() -> None:
    plc = load("seal_in.awl")
    plc["I0.0"] = 1
    plc.scan()
    # The terminals (PQ) are written from the image at the end of the scan.
    assert (plc.mem.areas["PQ"][0] & 0b11) == 0b11


# ---------------------------------------------------------------------------
# timers.awl (T37, T38, T5 are 100 ms timers)
# ---------------------------------------------------------------------------

def test_ton_turns_on_after_two_seconds() -> None:
    plc = load("timers.awl")
    plc["I0.0"] = 1
    # The scan that sees IN go to 1 starts T37 at 0; ticks count from the
    # next scan start, so after 2.00 s of scans the value is 19 ...
    plc.run(seconds=2.0)
    assert plc.time == pytest.approx(2.0)
    assert (plc["T37"], plc["Q0.0"]) == (19, 0)
    # ... and the scan starting at t = 2.00 s reaches the preset 20.
    plc.scan()
    assert (plc["T37"], plc["Q0.0"]) == (20, 1)
    plc.run(seconds=1.0)
    assert (plc["T37"], plc["Q0.0"]) == (30, 1)  # TON keeps counting past PT

    plc["I0.0"] = 0  # IN off clears value and bit at once
    plc.scan()
    assert (plc["T37"], plc["Q0.0"]) == (0, 0)


def test_ton_short_pulse_does_not_switch() -> None:
    plc = load("timers.awl")
    plc["I0.0"] = 1
    plc.run(seconds=1.5)
    plc["I0.0"] = 0
    plc.scan()
    plc["I0.0"] = 1
    plc.run(seconds=1.5)
    assert plc["Q0.0"] == 0  # two 1.5 s pulses do not add up (TON is not retentive)


def test_tof_holds_output_three_seconds_after_input_drops() -> None:
    plc = load("timers.awl")
    plc.scan(10)  # t = 0.10 s: start on a 100 ms boundary
    plc["I0.1"] = 1
    plc.scan()
    assert (plc["Q0.1"], plc["T38"]) == (1, 0)  # on at once, value 0
    plc.scan(9)
    plc["I0.1"] = 0  # falling edge at t = 0.20 s starts the off-delay
    on_scans = 0
    while plc["Q0.1"] == 1 or on_scans == 0:
        plc.scan()
        if plc["Q0.1"]:
            on_scans += 1
        assert on_scans < 1000
    assert on_scans == 300  # 3.0 s of 10 ms scans
    assert plc["T38"] == 30  # the value stops at PT


def test_tof_restarts_when_input_returns_before_preset() -> None:
    plc = load("timers.awl")
    plc["I0.1"] = 1
    plc.scan()
    plc["I0.1"] = 0
    plc.run(seconds=2.0)
    assert plc["Q0.1"] == 1 and plc["T38"] > 0
    plc["I0.1"] = 1
    plc.scan()
    assert (plc["Q0.1"], plc["T38"]) == (1, 0)
    plc["I0.1"] = 0
    plc.run(seconds=2.0)
    assert plc["Q0.1"] == 1  # a fresh 3 s, not the remaining 1 s


def test_tonr_accumulates_on_time_and_resets_only_with_r() -> None:
    plc = load("timers.awl")
    plc["I0.2"] = 1
    plc.run(seconds=3.0)
    assert plc["T5"] == 29  # started in the first scan, 29 ticks since
    plc["I0.2"] = 0
    plc.run(seconds=1.0)
    assert (plc["T5"], plc["Q0.2"]) == (29, 0)  # value kept while IN is off
    plc["I0.2"] = 1
    plc.run(seconds=2.0)
    # Each start loses up to one tick (the manual's start granularity):
    # 5.0 s of on-time so far, 48 ticks counted.
    assert (plc["T5"], plc["Q0.2"]) == (48, 0)
    plc.run(seconds=0.1)
    assert (plc["T5"], plc["Q0.2"]) == (49, 0)
    plc.run(seconds=0.1)
    assert (plc["T5"], plc["Q0.2"]) == (50, 1)
    plc["I0.2"] = 0
    plc.run(seconds=5.0)
    assert plc["Q0.2"] == 1  # still on: only a reset clears a TONR
    plc["I0.3"] = 1
    plc.scan()
    assert (plc["T5"], plc["Q0.2"]) == (0, 0)


def test_timers_run_with_a_slow_scan() -> None:
    # 250 ms scans: the 100 ms timer adds two or three ticks per scan.
    plc = load("timers.awl", scan_ms=250)
    plc["I0.0"] = 1
    plc.scan(8)  # starts at t = 0, last scan starts at t = 1.75 s
    assert (plc["T37"], plc["Q0.0"]) == (17, 0)
    plc.scan()   # scan starting at 2.00 s
    assert (plc["T37"], plc["Q0.0"]) == (20, 1)


# ---------------------------------------------------------------------------
# counters.awl
# ---------------------------------------------------------------------------

def pulse(plc: plcrt.Plc, addr: str, times: int = 1) -> None:
    for _ in range(times):
        plc[addr] = 1
        plc.scan()
        plc[addr] = 0
        plc.scan()


def test_ctu_counts_rising_edges_only() -> None:
    plc = load("counters.awl")
    plc["I0.2"] = 1
    plc.scan(20)  # held on for 20 scans: one edge
    assert plc["C0"] == 1
    plc["I0.2"] = 0
    plc.scan()
    pulse(plc, "I0.2", 3)
    assert (plc["C0"], plc["Q0.0"], plc["VW0"]) == (4, 0, 4)
    pulse(plc, "I0.2")
    assert (plc["C0"], plc["Q0.0"], plc["VW0"]) == (5, 1, 5)  # bit at CV >= PV
    pulse(plc, "I0.2", 2)
    assert (plc["C0"], plc["Q0.0"]) == (7, 1)  # CTU keeps counting past PV


def test_ctu_reset_clears_and_blocks_counting() -> None:
    plc = load("counters.awl")
    pulse(plc, "I0.2", 6)
    plc["I0.3"] = 1
    plc.scan()
    assert (plc["C0"], plc["Q0.0"], plc["VW0"]) == (0, 0, 0)
    pulse(plc, "I0.2", 2)  # reset still held: edges are ignored
    assert plc["C0"] == 0
    plc["I0.3"] = 0
    pulse(plc, "I0.2")
    assert plc["C0"] == 1


def test_ctu_counts_an_input_already_on_at_power_up() -> None:
    # docs/decisions.md: counter edge memory starts at 0.
    plc = load("counters.awl")
    plc["I0.2"] = 1
    plc.scan()
    assert plc["C0"] == 1


def test_ctud_counts_up_and_down() -> None:
    plc = load("counters.awl")
    pulse(plc, "I0.4", 3)
    assert (plc["C1"], plc["Q0.1"], plc["VW2"]) == (3, 1, 3)
    pulse(plc, "I0.5")
    assert (plc["C1"], plc["Q0.1"]) == (2, 0)
    pulse(plc, "I0.5", 4)
    assert (plc["C1"], plc["Q0.1"], plc["VW2"]) == (-2, 0, -2)  # CTUD goes negative
    plc["I0.6"] = 1
    plc.scan()
    assert plc["C1"] == 0


def test_ctud_wraps_at_the_int_limits() -> None:
    plc = load("counters.awl")
    plc.scan()
    plc["C1"] = 32767
    pulse(plc, "I0.4")
    assert (plc["C1"], plc["Q0.1"]) == (-32768, 0)
    pulse(plc, "I0.5")
    assert (plc["C1"], plc["Q0.1"]) == (32767, 1)


# ---------------------------------------------------------------------------
# subroutine.awl
# ---------------------------------------------------------------------------

@pytest.mark.parametrize(("raw", "value", "high"), [
    (0, 0, 0),
    (16000, 500, 0),
    (25568, 799, 0),
    (25600, 800, 1),   # Value >= Limit
    (32000, 1000, 1),
    (31, 0, 0),        # /I truncates
    (-100, 0, 0),      # negative raw reads as 0
])
def test_scale_subroutine_first_channel(raw: int, value: int, high: int) -> None:
    plc = load("subroutine.awl")
    plc["AIW0"] = raw
    plc.scan()
    assert (plc["VW10"], plc["Q0.0"]) == (value, high)


def test_scale_subroutine_second_channel_runs_only_when_enabled() -> None:
    plc = load("subroutine.awl")
    plc["VW20"] = 16000
    plc["VW22"] = 400
    plc.scan()
    assert (plc["VW24"], plc["Q0.1"]) == (0, 0)  # I0.0 off: CALL skipped
    plc["I0.0"] = 1
    plc.scan()
    assert (plc["VW24"], plc["Q0.1"]) == (500, 1)
    plc["I0.0"] = 0
    plc["VW20"] = 0
    plc.scan()
    assert (plc["VW24"], plc["Q0.1"]) == (500, 1)  # outputs keep the last call's result


def test_scale_subroutine_calls_do_not_disturb_each_other() -> None:
    plc = load("subroutine.awl")
    plc["AIW0"] = 32000
    plc["VW20"] = 3200
    plc["VW22"] = 900
    plc["I0.0"] = 1
    plc.scan()
    assert (plc["VW10"], plc["Q0.0"], plc["VW24"], plc["Q0.1"]) == (1000, 1, 100, 0)


# ---------------------------------------------------------------------------
# scr_sequence.awl
# ---------------------------------------------------------------------------

def state(plc: plcrt.Plc) -> tuple[int, ...]:
    """(S0.0, S0.1, S0.2, Q0.0, Q0.1, Q0.2)."""
    return tuple(int(plc[a]) for a in ("S0.0", "S0.1", "S0.2", "Q0.0", "Q0.1", "Q0.2"))


def run_batch(plc: plcrt.Plc) -> None:
    """One batch from idle to idle, checking every step on the way."""
    plc["I0.0"] = 1  # start
    plc.scan()
    assert state(plc) == (1, 0, 0, 1, 0, 0)  # filling
    plc["I0.0"] = 0
    plc.scan(20)
    assert state(plc) == (1, 0, 0, 1, 0, 0)

    plc["I0.1"] = 1  # tank full
    plc.scan()
    # SCRT sets S0.1 at once and the S0.1 segment comes later in OB1, so
    # mixing starts in the same scan.
    assert state(plc) == (0, 1, 0, 0, 1, 0)
    plc["I0.1"] = 0
    t_mix = plc.time
    while plc["S0.1"]:
        plc.scan()
        assert plc.time - t_mix < 10
    # 5 s preset on a 100 ms timer, minus up to one tick of start granularity
    assert 4.9 <= plc.time - t_mix <= 5.01
    assert state(plc) == (0, 0, 1, 0, 0, 1)  # draining, mixer off
    assert plc["T37"] == 0  # reset in the transition

    plc.scan(30)
    assert state(plc) == (0, 0, 1, 0, 0, 1)
    plc["I0.2"] = 1  # tank empty
    plc.scan()
    assert state(plc) == (0, 0, 0, 0, 0, 0)
    plc["I0.2"] = 0
    plc.scan()


def test_scr_sequence_idles_until_start() -> None:
    plc = load("scr_sequence.awl")
    plc.run(seconds=1.0)
    assert state(plc) == (0, 0, 0, 0, 0, 0)
    assert plc["VW0"] == 0


def test_scr_sequence_runs_a_batch_step_by_step() -> None:
    plc = load("scr_sequence.awl")
    plc.scan()
    run_batch(plc)
    assert plc["VW0"] == 1


def test_scr_sequence_runs_a_second_batch_with_full_mix_time() -> None:
    plc = load("scr_sequence.awl")
    plc.scan()
    run_batch(plc)
    run_batch(plc)  # the mix time is checked again: T37 was reset
    assert plc["VW0"] == 2


def test_scr_start_is_ignored_while_a_batch_runs() -> None:
    plc = load("scr_sequence.awl")
    plc["I0.0"] = 1
    plc.scan()
    plc["I0.1"] = 1
    plc.scan()
    plc["I0.1"] = 0
    plc.scan(10)
    assert state(plc) == (0, 1, 0, 0, 1, 0)  # start still pressed: no second step 1


def test_scr_inactive_step_keeps_timer_still() -> None:
    plc = load("scr_sequence.awl")
    plc.run(seconds=10.0)
    assert plc["T37"] == 0  # the TON in step 2 never ran
