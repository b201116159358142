"""The EM253 example programs in ``programs/em253/`` against the manual.

Each example reproduces an example of the EM253 user manual (chapter 3.2)
and runs with a plant file.  The expected figures are computed here from
the instruction parameters with the manual's rules (note 3: a ramp changes
the speed linearly from SpdSs to SpdSet in AccTime, from SpdSet to SpdSs in
DecTime; a trapezoidal move covers ramp + cruise + ramp), and the literal
figures are asserted as well, so a wrong formula cannot hide a wrong result.

Two ways of reading the state are used, and they mean different instants:

* ``plc.axis(slot, axis)`` is the module's state at ``plc.time``, i.e. at
  the end of the last scan (the device is advanced exactly, event by event,
  to the next scan start);
* the blocks' outputs (C_Pos, C_Spd, C_Status, C_Step) are written when the
  block runs, at the *start* of a scan: after ``run_to(plc, t + scan)``
  they show the state at ``t``.

Every behaviour is checked at 1 ms and at 10 ms scan time.  The programs
react at scan starts that are common to both (all commands are given at
multiples of 10 ms), so the axes must be in exactly the same state at the
same simulated times.
"""

from __future__ import annotations

import math
import re
import tomllib
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

import plcrt

EM253 = Path(__file__).resolve().parents[2] / "programs" / "em253"
PLANT = EM253 / "plant.toml"
HOMING_PLANT = EM253 / "homing_plant.toml"
EXAMPLES = ["abs_pos.awl", "homing.awl", "pos_goto_r.awl", "pos_run.awl", "spd_ctrl.awl"]
SCAN_MS = [1, 10]

SINGLE_ENDED_HZ = 200_000    # manual 2.1: single-ended output up to 200 kHz
DIFFERENTIAL_HZ = 500_000    # manual 2.1: differential output up to 500 kHz


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------

def load(name: str, scan_ms: float, plant: Path = PLANT, **kw: Any) -> plcrt.Plc:
    return plcrt.load(EM253 / name, plant=plant, scan_ms=scan_ms, **kw)


def run_to(plc: plcrt.Plc, t: float) -> None:
    """Run scans until the simulated time is exactly ``t`` seconds."""
    target_us = round(t * 1e6)
    left = target_us - plc.now_us
    assert left >= 0 and left % plc.scan_us == 0, (t, plc.time)
    plc.scan(left // plc.scan_us)
    assert plc.now_us == target_us


def after_scan_at(plc: plcrt.Plc, t: float) -> None:
    """Run until the scan that starts at ``t`` has run (its block outputs
    then show the state at ``t``)."""
    run_to(plc, t)
    plc.scan()


def line_of(name: str, needle: str) -> int:
    """1-based line number of the first line of an example containing ``needle``."""
    lines = (EM253 / name).read_text(encoding="utf-8").splitlines()
    return next(i for i, line in enumerate(lines, 1) if needle in line)


def ramp_hz(v0: float, v1: float, ms: int, t: float) -> float:
    """Speed ``t`` seconds into a linear ramp from v0 to v1 lasting ``ms``."""
    return v0 + (v1 - v0) * t / (ms / 1000)


def ramp_pulses(v0: float, v1: float, ms: int) -> float:
    """Pulses sent during a whole ramp from v0 to v1 lasting ``ms``."""
    return (v0 + v1) / 2 * ms / 1000


# ---------------------------------------------------------------------------
# all examples
# ---------------------------------------------------------------------------

def test_all_examples_exist_and_are_listed_in_the_readme() -> None:
    assert sorted(p.name for p in EM253.glob("*.awl")) == EXAMPLES
    readme = (EM253 / "README.md").read_text(encoding="utf-8")
    for name in EXAMPLES + ["plant.toml", "homing_plant.toml", "pos_run.db"]:
        assert f"`{name}`" in readme, name


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_calls_motion_en3_with_sm0_0_first(name: str) -> None:
    text = (EM253 / name).read_text(encoding="utf-8")
    assert text.startswith("ORGANIZATION_BLOCK MAIN:OB1\nTITLE=")
    body = [ln for ln in text.split("BEGIN\n", 1)[1].splitlines()
            if ln and not ln.startswith(("//", "Network "))]
    assert body[0] == "LD     SM0.0"
    assert body[1].startswith("CALL   MOTION_EN3, 0, ")
    calls = [ln.split()[1].rstrip(",") for ln in body if ln.startswith("CALL")]
    assert calls.count("MOTION_EN3") == 1 and len(calls) > 1


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_loads_without_diagnostics(name: str) -> None:
    plant = HOMING_PLANT if name == "homing.awl" else PLANT
    data = EM253 / "pos_run.db" if name == "pos_run.awl" else None
    plc = load(name, 10, plant=plant, data=data)
    plc.scan(10)  # nothing started: no run-time warnings either
    assert plc.diagnostics == []
    assert plc["VW0"] == 1  # MOTION_EN3 Status: 1 = running normally


# ---------------------------------------------------------------------------
# POS_GOTO_R (manual 3.2.5): 4800 ms ramps, 5 kHz -> 80 kHz, 1 000 000 pulses
# ---------------------------------------------------------------------------

GOTO_ACC_MS, GOTO_SS, GOTO_SET, GOTO_POS = 4800, 5000, 80_000, 1_000_000


def goto_pulses(t: float) -> float:
    """Pulses of the manual's POS_GOTO_R move ``t`` seconds after its start."""
    ramp = ramp_pulses(GOTO_SS, GOTO_SET, GOTO_ACC_MS)
    acc_s = GOTO_ACC_MS / 1000
    cruise_s = (GOTO_POS - 2 * ramp) / GOTO_SET
    if t <= acc_s:
        return GOTO_SS * t + (GOTO_SET - GOTO_SS) / acc_s * t * t / 2
    if t <= acc_s + cruise_s:
        return ramp + GOTO_SET * (t - acc_s)
    return GOTO_POS - goto_pulses(2 * acc_s + cruise_s - t)


def goto_end_s() -> float:
    ramp = ramp_pulses(GOTO_SS, GOTO_SET, GOTO_ACC_MS)
    return 2 * GOTO_ACC_MS / 1000 + (GOTO_POS - 2 * ramp) / GOTO_SET


def test_pos_goto_r_figures_from_the_manual() -> None:
    # the formulas give the literal figures of the brief
    assert ramp_pulses(GOTO_SS, GOTO_SET, GOTO_ACC_MS) == 204_000
    assert goto_pulses(10.0) == 620_000
    assert goto_end_s() == pytest.approx(17.0)


@pytest.mark.parametrize("scan_ms", SCAN_MS)
def test_pos_goto_r_trapezoid(scan_ms: int) -> None:
    plc = load("pos_goto_r.awl", scan_ms)
    plc["M2.0"] = 1  # the block sees the rising edge in the scan at t = 0
    checks = [(1.2, "moving"), (4.8, "moving"), (10.0, "moving"), (12.2, "moving"),
              (16.0, "moving"), (16.99, "moving"), (17.0, "stopped")]
    for t, status in checks:
        run_to(plc, t)
        ax = plc.axis(0, 0)
        assert ax["position"] == math.floor(goto_pulses(t)), t
        assert ax["mechanical"] == ax["position"]  # plant.toml: start 0, no SevOn
        assert ax["status"] == status, t
    assert plc.axis(0, 0)["position"] == 1_000_000
    assert plc.axis(0, 0)["speed"] == 0

    # block outputs: the scan starting at 17.0 s reports the finished move
    after_scan_at(plc, 17.0)
    assert plc["VW106"] == 8          # C_Status: stopped
    assert plc["VD108"] == 1_000_000  # C_Pos: pulses sent by this move
    assert plc["VD112"] == 0          # C_Spd
    assert plc["VD120"] == 1_000_000  # GET_AbsPos
    assert plc.diagnostics == []


@pytest.mark.parametrize("scan_ms", SCAN_MS)
def test_pos_goto_r_block_outputs_are_taken_at_the_scan_start(scan_ms: int) -> None:
    plc = load("pos_goto_r.awl", scan_ms)
    plc["M2.0"] = 1
    run_to(plc, 10.0)
    # the last scan started one scan time before 10 s
    last_start = 10.0 - scan_ms / 1000
    assert plc["VD108"] == math.floor(goto_pulses(last_start))
    assert plc["VD108"] == {1: 619_920, 10: 619_200}[scan_ms]
    assert plc["VW106"] == 1  # C_Status: running
    after_scan_at(plc, 10.0)
    assert plc["VD108"] == 620_000
    assert plc["VD112"] == GOTO_SET  # C_Spd: cruising at 80 kHz


@pytest.mark.parametrize("scan_ms", SCAN_MS)
def test_pos_goto_r_speed_is_linear_in_the_ramp(scan_ms: int) -> None:
    plc = load("pos_goto_r.awl", scan_ms)
    plc["M2.0"] = 1
    after_scan_at(plc, 2.4)   # half-way through the 4.8 s acceleration
    assert plc["VD112"] == ramp_hz(GOTO_SS, GOTO_SET, GOTO_ACC_MS, 2.4) == 42_500
    after_scan_at(plc, 14.6)  # 2.4 s into the deceleration (it starts at 12.2 s)
    assert plc["VD112"] == ramp_hz(GOTO_SET, GOTO_SS, GOTO_ACC_MS, 2.4) == 42_500


def test_pos_goto_r_same_positions_at_1_and_10_ms() -> None:
    states = []
    for scan_ms in SCAN_MS:
        plc = load("pos_goto_r.awl", scan_ms)
        plc["M2.0"] = 1
        seen = []
        for k in range(1, 181):  # every 0.1 s up to 18 s
            run_to(plc, k / 10)
            seen.append(plc.axis(0, 0))
        states.append(seen)
    assert states[0] == states[1]


# ---------------------------------------------------------------------------
# SPD_CTRL (manual 3.2.4): axis 0 3000 ms, 5 kHz -> 50 kHz; axis 1 6000 ms,
# 5 kHz -> 100 kHz
# ---------------------------------------------------------------------------

AX0 = (3000, 5000, 50_000)     # AccTime = DecTime (ms), SpdSs, SpdSet
AX1 = (6000, 5000, 100_000)


def start_spd(scan_ms: int, forward: bool = True) -> plcrt.Plc:
    plc = load("spd_ctrl.awl", scan_ms)
    plc["M1.1"] = int(forward)   # axis 0 direction
    plc["M1.4"] = 1              # axis 1 forward
    plc["M1.0"] = 1              # run axis 0
    plc["M1.3"] = 1              # run axis 1
    return plc


def test_spd_ctrl_figures_from_the_manual() -> None:
    assert ramp_hz(AX0[1], AX0[2], AX0[0], 1.5) == 27_500
    assert ramp_hz(AX1[1], AX1[2], AX1[0], 3.0) == 52_500
    assert ramp_pulses(AX0[1], AX0[2], AX0[0]) == 82_500


@pytest.mark.parametrize("scan_ms", SCAN_MS)
def test_spd_ctrl_ramps_linearly(scan_ms: int) -> None:
    plc = start_spd(scan_ms)
    for t in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0):
        run_to(plc, t)
        assert plc.axis(0, 0)["speed"] == ramp_hz(AX0[1], AX0[2], AX0[0], t), t
        assert plc.axis(0, 1)["speed"] == math.floor(ramp_hz(AX1[1], AX1[2], AX1[0], t)), t
    run_to(plc, 1.5 + 1.5)
    assert plc.axis(0, 0)["speed"] == 50_000       # axis 0 at SpdSet after its 3 s ramp
    assert plc.axis(0, 1)["speed"] == 52_500       # axis 1 half-way through its 6 s ramp
    assert plc.axis(0, 0)["position"] == 82_500    # (5 kHz + 50 kHz) / 2 x 3 s
    run_to(plc, 4.5)
    assert plc.axis(0, 0)["speed"] == 50_000       # it stays there
    run_to(plc, 6.0)
    assert plc.axis(0, 1)["speed"] == 100_000
    run_to(plc, 7.0)
    assert plc.axis(0, 1)["speed"] == 100_000
    # C_Spd of the blocks (at the scan start) and C_Status running
    after_scan_at(plc, 7.0)
    assert (plc["VD108"], plc["VD208"]) == (50_000, 100_000)
    assert (plc["VW106"], plc["VW206"]) == (1, 1)
    assert plc.diagnostics == []


@pytest.mark.parametrize("scan_ms", SCAN_MS)
def test_spd_ctrl_run_0_decelerates_over_dectime(scan_ms: int) -> None:
    plc = start_spd(scan_ms)
    run_to(plc, 3.0)
    plc["M1.0"] = 0   # the block sees Run = 0 in the scan starting at 3.0 s
    dec_ms, v_ss, v_set = AX0
    for dt in (0.5, 1.5, 2.5):
        run_to(plc, 3.0 + dt)
        assert plc.axis(0, 0)["speed"] == ramp_hz(v_set, v_ss, dec_ms, dt), dt
        assert plc.axis(0, 0)["status"] == "moving"
        if dt == 1.5:
            assert plc.axis(0, 0)["speed"] == 27_500   # half-way down
    run_to(plc, 5.99)
    assert plc.axis(0, 0)["status"] == "moving"
    run_to(plc, 6.0)  # down to SpdSs after exactly DecTime, then the pulses stop
    ax = plc.axis(0, 0)
    assert (ax["status"], ax["speed"]) == ("stopped", 0)
    expected = ramp_pulses(v_ss, v_set, dec_ms) * 2   # ramp up + ramp down
    assert ax["position"] == expected == 165_000
    after_scan_at(plc, 6.0)
    assert plc["VW106"] == 8 and plc["VD108"] == 0   # C_Status stopped, C_Spd 0
    assert plc["VD120"] == 165_000                   # GET_AbsPos
    assert plc.axis(0, 1)["status"] == "moving"      # axis 1 is not affected


@pytest.mark.parametrize("scan_ms", SCAN_MS)
def test_spd_ctrl_direction_and_emergency_stop(scan_ms: int) -> None:
    plc = start_spd(scan_ms, forward=False)  # M1.1 = 0: reverse
    run_to(plc, 2.0)
    x2 = AX0[1] * 2.0 + (AX0[2] - AX0[1]) / 3.0 * 2.0 ** 2 / 2   # 40 000 pulses
    assert plc.axis(0, 0)["speed"] == -35_000
    assert plc.axis(0, 0)["position"] == -x2 == -40_000
    plc["M1.2"] = 1   # E_Stop: the pulses stop at once, no ramp
    after_scan_at(plc, 2.0)
    ax = plc.axis(0, 0)
    assert (ax["status"], ax["speed"], ax["position"]) == ("stopped", 0, -40_000)
    assert plc["VW106"] == 8


def test_spd_ctrl_same_positions_at_1_and_10_ms() -> None:
    states = []
    for scan_ms in SCAN_MS:
        plc = start_spd(scan_ms)
        seen = []
        for k in range(1, 81):
            if k == 31:
                plc["M1.0"] = 0   # at 3.0 s, a scan start in both runs
            run_to(plc, k / 10)
            seen.append(plc.axes())
        states.append(seen)
    assert states[0] == states[1]


# ---------------------------------------------------------------------------
# POS_RUN (manual 3.2.6): axis 1, SpdSs 5 kHz, &VB1000, 7 steps (pos_run.db)
# ---------------------------------------------------------------------------

def profile_table() -> list[tuple[int, int, int, int]]:
    """The 7 steps of pos_run.db, read as text with the 12-byte stride."""
    values: dict[int, int] = {}
    for line in (EM253 / "pos_run.db").read_text(encoding="utf-8").splitlines():
        m = re.match(r"V[WD](\d+)\s+(\d+)", line)
        if m:
            values[int(m.group(1))] = int(m.group(2))
    return [(values[1000 + 12 * i], values[1002 + 12 * i], values[1004 + 12 * i],
             values[1008 + 12 * i]) for i in range(7)]


def test_pos_run_table_is_the_manuals() -> None:
    assert profile_table() == [
        (1000, 1000, 20_000, 500_000), (10_000, 10_000, 10_000, 300_000),
        (5000, 5000, 30_000, 100_000), (20_000, 20_000, 50_000, 50_000),
        (800, 800, 50_000, 500_000), (8000, 8000, 500_000, 30_000),
        (1000, 1000, 5000, 50_000)]
    assert sum(step[3] for step in profile_table()) == 1_530_000


def envelope_bounds(v_ss: int, limit: int) -> list[tuple[float, float]]:
    """(end time in s, speed at the end in Hz) of steps 1..6 of the table.

    An inner step changes the speed toward its SpdSet at the step's rate
    (note 3: (SpdSet - SpdSs) / AccTime, DecTime when slowing down) for as
    long as its distance allows, then holds it.  SpdSet is limited to the
    output's maximum.
    """
    t, v = 0.0, float(v_ss)
    out = []
    for acc, dec, spd, pos in profile_table()[:6]:
        top = min(spd, limit)
        rate = (top - v_ss) / ((acc if top >= v else dec) / 1000)   # Hz/s
        ramp = abs(top * top - v * v) / (2 * rate)                  # pulses to reach top
        if ramp >= pos:
            v_end = math.sqrt(v * v + math.copysign(2 * rate * pos, top - v))
            t += abs(v_end - v) / rate
        else:
            v_end = top
            t += abs(top - v) / rate + (pos - ramp) / top
        v = v_end
        out.append((t, v))
    return out


def start_pos_run(scan_ms: int, differential: bool = False) -> plcrt.Plc:
    plc = load("pos_run.awl", scan_ms, data=EM253 / "pos_run.db")
    plc["M0.0"] = int(differential)   # P_DorCCW: 1 = differential output
    plc["M3.0"] = 1
    return plc


@pytest.mark.parametrize("scan_ms", SCAN_MS)
def test_pos_run_ends_at_the_sum_of_its_steps(scan_ms: int) -> None:
    plc = start_pos_run(scan_ms)
    bounds = envelope_bounds(5000, SINGLE_ENDED_HZ)
    # literal end times of the first steps (step 2 slows from 20 to 10 kHz
    # in exactly its 300 000 pulses)
    assert [round(b[0], 3) for b in bounds[:3]] == [25.375, 45.375, 50.042]
    starts = [0.0] + [b[0] for b in bounds]
    for step, (t0, t1) in enumerate(zip(starts, starts[1:]), 1):
        # the scans well inside a step report that step in C_Step (VB316)
        for t in (t0 + 0.02, t1 - 0.02):
            tt = round(t, 2)
            after_scan_at(plc, tt)
            assert plc["VB316"] == step, (step, tt)
            assert plc["VW306"] == 1
    end = None
    while plc.time < 70:
        plc.scan()
        if plc.axis(0, 1)["status"] == "stopped":
            end = plc.time
            break
    # step 7 runs at SpdSs; how it gets there from step 6's speed is not
    # pinned here (see the README of the examples), only that it follows
    assert end is not None and bounds[-1][0] < end < 70
    ax = plc.axis(0, 1)
    assert ax["position"] == ax["mechanical"] == 1_530_000
    plc.scan()
    assert plc["VB316"] == 7        # C_Step
    assert plc["VW306"] == 8        # C_Status: stopped
    assert plc["VD308"] == 50_000   # C_Pos: pulses of the current (last) step
    assert plc["VD320"] == 1_530_000


@pytest.mark.parametrize("scan_ms", SCAN_MS)
@pytest.mark.parametrize("differential", [False, True], ids=["single-ended", "differential"])
def test_pos_run_step_6_speed_limit(scan_ms: int, differential: bool) -> None:
    """Step 6 asks for 500 kHz.  Single-ended, plcrt limits SpdSet to
    200 kHz (and the step's ramp rate follows the limited SpdSet) and says
    so; differential, 500 kHz is allowed.  Step 6 is only 30 000 pulses
    long, so the speed never gets near either limit: the limit shows in the
    slope of the ramp."""
    limit = DIFFERENTIAL_HZ if differential else SINGLE_ENDED_HZ
    plc = start_pos_run(scan_ms, differential)
    bounds = envelope_bounds(5000, limit)
    t5, v5 = bounds[4]
    t6, v6 = bounds[5]
    assert v5 == 50_000
    rate6 = (limit - 5000) / 8.0                       # Hz/s: (SpdSet - SpdSs) / AccTime
    assert rate6 == {False: 24_375, True: 61_875}[differential]
    t = math.ceil((t5 + 0.1) * 100) / 100              # a time inside step 6
    assert t < t6
    run_to(plc, 60.0)
    run_to(plc, t)
    speed = plc.axis(0, 1)["speed"]
    assert speed == pytest.approx(v5 + rate6 * (t - t5), abs=2)
    assert v6 == pytest.approx({False: 62_948.4, True: 78_819.4}[differential], abs=0.1)
    run_to(plc, 70.0)
    assert plc.axis(0, 1)["position"] == 1_530_000
    limited = [d for d in plc.diagnostics if "output limit" in d.message]
    if differential:
        assert limited == []
    else:
        assert len(limited) == 1
        text = str(limited[0])
        line = line_of("pos_run.awl", "CALL   POS_RUN")
        assert text.startswith(f"{EM253 / 'pos_run.awl'}:{line}:")
        assert "POS_RUN" in text and "[OB1 network 2]" in text
        assert "SpdSet 500000 Hz" in text and "single-ended" in text
        assert "200000 Hz" in text


@pytest.mark.parametrize("differential", [False, True], ids=["single-ended", "differential"])
def test_pos_run_long_step_6_cruises_at_the_output_limit(differential: bool) -> None:
    """With step 6 made long enough (6 000 000 pulses) to reach its speed
    and, with look-ahead, to slow down for step 7 before its end, the axis
    cruises at 200 kHz single-ended and at 500 kHz differential."""
    table = (EM253 / "pos_run.db").read_text(encoding="utf-8")
    assert table.count("VD1068  30000\n") == 1
    table = table.replace("VD1068  30000\n", "VD1068  6000000\n")
    # plant.toml's L1+ at 3 000 000 would stop this longer envelope: no limits
    free = {"module": {"0": {"axis": {"1": {}}}}}
    plc = plcrt.load(EM253 / "pos_run.awl", plant=free, data=table, scan_ms=10)
    plc["M0.0"] = int(differential)
    plc["M3.0"] = 1
    limit = DIFFERENTIAL_HZ if differential else SINGLE_ENDED_HZ
    t5 = envelope_bounds(5000, limit)[4][0]
    ramp_s = (limit - 50_000) / ((limit - 5000) / 8.0)   # from step 5's 50 kHz
    run_to(plc, math.ceil((t5 + ramp_s + 0.5) * 100) / 100)
    assert plc.axis(0, 1)["speed"] == limit
    plc.scan()
    assert (plc["VB316"], plc["VD312"]) == (6, limit)    # C_Step, C_Spd
    run_to(plc, 120.0)
    assert plc.axis(0, 1)["position"] == 1_530_000 - 30_000 + 6_000_000
    # look-ahead: step 6 slows down before its end so that step 7 (50 000
    # pulses at SpdSs) reaches SpdSs; the pulses never stop at high speed
    assert not any("too short" in d.message for d in plc.diagnostics)


def test_pos_run_same_positions_at_1_and_10_ms() -> None:
    states = []
    for scan_ms in SCAN_MS:
        plc = start_pos_run(scan_ms)
        seen = []
        for k in range(1, 131):   # every 0.5 s up to 65 s
            run_to(plc, k / 2)
            seen.append(plc.axis(0, 1))
        states.append(seen)
    assert states[0] == states[1]


# ---------------------------------------------------------------------------
# HOMING (manual 3.2.7, appendix 1) with homing_plant.toml
# ---------------------------------------------------------------------------

def homing_plant() -> dict[int, dict[str, Any]]:
    data = tomllib.loads(HOMING_PLANT.read_text(encoding="utf-8"))
    return {int(k): v for k, v in data["module"]["0"]["axis"].items()}


def first_z_at_or_above(pos: int, period: int, offset: int) -> int:
    return offset + math.ceil(Fraction(pos - offset, period)) * period


def test_homing_plant_figures() -> None:
    p0, p1 = homing_plant()[0], homing_plant()[1]
    # axis 0, mode 1: home is the first Z pulse beyond the switch's positive
    # edge, approached in the positive direction
    assert first_z_at_or_above(p0["rps"][1] + 1, p0["z_period"], p0["z_offset"]) == 21_000
    # axis 1, mode 3: home is where the switch is left in the positive direction
    assert p1["rps"][1] + 1 == 20_001
    # axis 1 starts left of the switch, so the negative search meets L1- first
    assert p1["limit_neg"] < p1["start"] < p1["rps"][0]


@pytest.mark.parametrize("scan_ms", SCAN_MS)
def test_homing_ends_at_the_plants_home_position(scan_ms: int) -> None:
    plant = homing_plant()
    home0 = first_z_at_or_above(plant[0]["rps"][1] + 1, plant[0]["z_period"],
                                plant[0]["z_offset"])
    home1 = plant[1]["rps"][1] + 1
    plc = load("homing.awl", scan_ms, plant=HOMING_PLANT)
    plc["M4.0"] = 1
    plc["M4.2"] = 1
    lowest = plant[1]["start"]
    for k in range(1, 1201):   # 12 s, read every 10 ms (a scan start in both runs)
        run_to(plc, k / 100)
        lowest = min(lowest, plc.axis(0, 1)["mechanical"])
    ax0, ax1 = plc.axis(0, 0), plc.axis(0, 1)
    assert (ax0["mechanical"], ax0["position"], ax0["status"]) == (home0, 0, "stopped")
    assert (ax1["mechanical"], ax1["position"], ax1["status"]) == (home1, 0, "stopped")
    assert (home0, home1) == (21_000, 20_001)
    # the search reversed at L1- (-30 000): reading every 10 ms at SpdHigh
    # 20 kHz sees the lowest point to within 200 pulses, never beyond it
    assert plant[1]["limit_neg"] == -30_000
    assert -30_000 <= lowest < -30_000 + 20_000 * 0.01
    plc.scan()
    assert (plc["VW406"], plc["VW446"]) == (8, 8)        # C_Status: done
    assert (plc["VD420"], plc["VD460"]) == (0, 0)        # GET_AbsPos at home
    assert plc["I3.4"] == 1   # axis 0 rests on a Z pulse (Z0 input, module IB3)
    assert plc.diagnostics == []


def test_homing_same_positions_at_1_and_10_ms() -> None:
    states = []
    for scan_ms in SCAN_MS:
        plc = load("homing.awl", scan_ms, plant=HOMING_PLANT)
        plc["M4.0"] = 1
        plc["M4.2"] = 1
        seen = []
        for k in range(1, 101):
            run_to(plc, k / 10)
            seen.append(plc.axes())
        states.append(seen)
    assert states[0] == states[1]


# ---------------------------------------------------------------------------
# SET_AbsPos / GET_AbsPos (manual 3.2.2, 3.2.3)
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("scan_ms", SCAN_MS)
def test_abs_pos_sets_the_counter_not_the_machine(scan_ms: int) -> None:
    plc = load("abs_pos.awl", scan_ms)
    plc.scan()
    assert (plc["VD510"], plc["VW514"]) == (0, 1)    # GET_AbsPos: C_Status 1
    plc["M5.0"] = 1
    plc.scan()
    assert plc["M5.0"] == 0                          # Start cleared by the block
    assert plc["VW500"] == 1                         # SET_AbsPos C_Status
    assert plc["VD510"] == 100_000                   # read back in the same scan
    ax = plc.axis(0, 0)
    assert (ax["position"], ax["mechanical"]) == (100_000, 0)

    plc["M5.1"] = 1                                  # move +50 000 pulses
    t0 = plc.time
    ramp = ramp_pulses(5000, 20_000, 500)            # 6250 pulses per ramp
    duration = 2 * 0.5 + (50_000 - 2 * ramp) / 20_000
    assert duration == 2.875
    run_to(plc, round(t0 + 3.0, 3))
    ax = plc.axis(0, 0)
    assert (ax["position"], ax["mechanical"], ax["status"]) == (150_000, 50_000, "stopped")
    assert (plc["VD510"], plc["VW526"], plc["VD528"]) == (150_000, 8, 50_000)
    assert plc.diagnostics == []
