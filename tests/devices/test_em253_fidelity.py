"""Regression tests for behaviours of the simulated EM253 that a user of the
real module would report as bugs (EM253 user manual, chapters 2.2 and 3.2).

Each test names the manual section it follows; the decisions behind the
expected values are logged in docs/em253.md.
"""

from __future__ import annotations

import pytest

import plcrt

GOTO_SPD = """ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     SM0.0
CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0
Network 2 // POS_GOTO_R on axis 0: Run M1.1, E_Stop M1.0
LD     SM0.0
CALL   POS_GOTO_R, 0, 0, VW100, VW102, VD104, VD108, VD112, VD116, VB120, M1.0, M1.1, VW122, VD124, VD128
Network 3 // SPD_CTRL on axis 0: Run M2.1, E_Stop M2.0, Dir M2.2
LD     SM0.0
CALL   SPD_CTRL, 0, 0, VW200, VW202, VD204, VD208, VD216, VB220, M2.2, M2.0, M2.1, VW222, VD228
END_ORGANIZATION_BLOCK
"""
GOTO_DATA = ("VW100 100\nVW102 100\nVD104 1000\nVD108 10000\nVD112 20000\n"
             "VW200 100\nVW202 100\nVD204 1000\nVD208 10000\n")

POS_RUN = """ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     SM0.0
CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0
Network 2 // POS_RUN on axis 0: Run M3.0, E_Stop M3.1
LD     SM0.0
CALL   POS_RUN, 0, 0, 0, +5000, &VB1000, 3, VD100, VB104, M3.1, M3.0, VW106, VD108, VD112, VB116
END_ORGANIZATION_BLOCK
"""
#: three steps of 100 000 pulses at 20 kHz; the last one with a long DecTime
RUN_TABLE = ("VW1000 1000\nVW1002 1000\nVD1004 20000\nVD1008 100000\n"
             "VW1012 1000\nVW1014 1000\nVD1016 20000\nVD1020 100000\n"
             "VW1024 1000\nVW1026 20000\nVD1028 20000\nVD1032 100000\n")


def _plant(**axis0: object) -> dict:
    return {"module": {"0": {"axis": {"0": dict(axis0)}}}}


def _run_until_stopped(plc: plcrt.Plc, limit_s: float = 120.0) -> None:
    plc.scan()  # a Run edge set before this call starts the move in this scan
    while plc.axis(0, 0)["status"] == "moving" and plc.time < limit_s:
        plc.scan()
    plc.scan()  # the block outputs of the stop, written at the next scan start


# ---------------------------------------------------------------------------
# 1. terminals show the state at the end of every scan, moving or not
# ---------------------------------------------------------------------------
def test_limit_input_reads_1_while_the_axis_stands_on_the_limit() -> None:
    """2.2 L+: an axis stopped on its positive limit switch reads L+ = 1
    (IB3.2 on a CPU 226, slot 0) in every scan after the stop, and the
    pulse output P (QB2.2) is off."""
    plc = plcrt.load(GOTO_SPD, plant=_plant(limit_pos=15000), data=GOTO_DATA, scan_ms=10)
    plc["M1.1"] = 1
    _run_until_stopped(plc)
    assert plc.axis(0, 0)["position"] == 15000
    for _ in range(3):
        plc.scan()
        assert plc["I3.2"] == 1, "L+ must read 1 while the axis stands on it"
        assert plc["Q2.2"] == 0, "the pulse output must be off after the stop"


def test_z_input_reads_1_when_a_move_ends_on_a_z_position() -> None:
    """2.2 Z: a move that ends exactly on a Z position reads Z = 1."""
    plc = plcrt.load(GOTO_SPD, plant=_plant(z_period=4000), data=GOTO_DATA, scan_ms=10)
    plc["M1.1"] = 1
    _run_until_stopped(plc)
    assert plc.axis(0, 0)["position"] == 20000
    assert plc["I3.4"] == 1
    assert plc["Q2.2"] == 0


@pytest.mark.parametrize("stop", ["end", "run0", "estop", "stf"])
def test_pulse_output_goes_off_after_every_kind_of_stop(stop: str) -> None:
    """2.2 P: the pulsing output is 1 only while pulses are sent, whatever
    stopped them (the end of the move, Run = 0, E_Stop, the STF input)."""
    plant = _plant(events=[{"at": 0.5, "input": "STF", "value": True}]) if stop == "stf" \
        else _plant()
    plc = plcrt.load(GOTO_SPD, plant=plant, data=GOTO_DATA, scan_ms=10)
    plc["M1.1"] = 1
    plc.run(seconds=0.3)
    assert plc["Q2.2"] == 1
    if stop == "run0":
        plc["M1.1"] = 0
    elif stop == "estop":
        plc["M1.0"] = 1
    _run_until_stopped(plc)
    assert plc["Q2.2"] == 0
    if stop == "stf":
        assert plc["I3.0"] == 1


@pytest.mark.parametrize("cpu, slot, ib, qb", [("CPU222", 1, 3, 3), ("CPU224", 6, 14, 14),
                                              ("CPU226", 5, 13, 12)])
def test_terminals_after_a_stop_on_other_slots_and_cpus(cpu: str, slot: int, ib: int,
                                                        qb: int) -> None:
    """Chapter 1 note / note 1: the module in slot n occupies its own bytes;
    the terminals there are current after a stop on every CPU."""
    prog = GOTO_SPD.replace("MOTION_EN3, 0,", f"MOTION_EN3, {slot},") \
        .replace("POS_GOTO_R, 0,", f"POS_GOTO_R, {slot},") \
        .replace("SPD_CTRL, 0,", f"SPD_CTRL, {slot},")
    plant = {"module": {str(slot): {"axis": {"0": {"limit_pos": 15000}}}}}
    plc = plcrt.load(prog, plant=plant, data=GOTO_DATA, scan_ms=10, cpu=cpu)
    plc["M1.1"] = 1
    while plc.axis(slot, 0)["status"] == "moving" or plc.time < 0.1:
        plc.scan()
    plc.scan()
    assert plc[f"I{ib}.2"] == 1 and plc[f"Q{qb}.2"] == 0


# ---------------------------------------------------------------------------
# 2. POS_RUN after an early stop reports the step that ran
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("stop", ["estop", "inner", "stf", "limit"])
def test_pos_run_early_stop_reports_the_running_step(stop: str) -> None:
    """3.2.6 C_Step / C_Pos ("当前步数发送的脉冲数"): after a stop in step 2
    C_Step is 2 and C_Pos the pulses sent in step 2 (never negative)."""
    plant = _plant()
    if stop == "stf":
        plant = _plant(events=[{"at": 7.0, "input": "STF", "value": True}])
    elif stop == "limit":
        plant = _plant(limit_pos=140000)
    plc = plcrt.load(POS_RUN, plant=plant, data=RUN_TABLE, scan_ms=10)
    plc["M3.0"] = 1
    plc.run(seconds=7)
    if stop == "estop":
        plc["M3.1"] = 1
    elif stop == "inner":
        plc["VD100"] = 5
    _run_until_stopped(plc)
    pos = plc.axis(0, 0)["position"]
    assert 100000 < pos < 200000
    assert plc["VW106"] == 8
    assert plc["VB116"] == 2
    assert plc["VD108"] == pos - 100000


# ---------------------------------------------------------------------------
# 3. POS_RUN Run = 0 never runs past the envelope's end
# ---------------------------------------------------------------------------
def test_pos_run_run_off_uses_the_running_steps_dectime() -> None:
    """3.2.6: each step has its own DecTime; Run = 0 in step 2 slows down
    with step 2's rate ((20 000 - 5 000) Hz / 1000 ms), not the last
    step's, and stops 12 500 pulses later."""
    plc = plcrt.load(POS_RUN, plant=_plant(), data=RUN_TABLE, scan_ms=10)
    plc["M3.0"] = 1
    plc.run(seconds=7)
    at = plc.axis(0, 0)["position"]
    assert plc.axis(0, 0)["speed"] == 20000
    plc["M3.0"] = 0
    _run_until_stopped(plc)
    assert plc.axis(0, 0)["position"] - at in (12500, 12501)
    assert plc["VW106"] == 8 and plc["VB116"] == 2


def test_pos_run_run_off_near_the_end_stops_exactly_at_the_end() -> None:
    """A Run = 0 whose ramp would need more pulses than the envelope has
    left stops exactly at the envelope's end, with a diagnostic that gives
    the steeper rate used."""
    # step 2 with a long DecTime (its stop ramp needs 250 000 pulses), a
    # short step 3 with a steep one (no look-ahead slowdown in step 2)
    table = RUN_TABLE.replace("VD1032 100000", "VD1032 10000").replace(
        "VW1014 1000", "VW1014 20000").replace("VW1026 20000", "VW1026 100")
    plc = plcrt.load(POS_RUN, plant=_plant(), data=table, scan_ms=10)
    plc["M3.0"] = 1
    plc.run(seconds=9.5)   # in step 2, about 26 000 pulses before the end
    assert plc["VB116"] == 2
    plc["M3.0"] = 0
    _run_until_stopped(plc)
    assert plc.axis(0, 0)["position"] == 210000
    assert any("programmed end" in d.message for d in plc.diagnostics)


# ---------------------------------------------------------------------------
# 4. POS_GOTO_R: an Update keeps the pulse count exact
# ---------------------------------------------------------------------------
def test_pos_goto_r_longer_dectime_during_the_final_ramp_still_ends_on_posset() -> None:
    """3.2.5 PosSet is the number of pulses of the move: lengthening
    DecTime with Update during the final ramp cannot stretch the move; it
    ends exactly on PosSet (the deceleration stays as steep as needed, and
    a diagnostic says so), never with "PosSet cannot be reached"."""
    data = GOTO_DATA.replace("VD112 20000", "VD112 200000").replace(
        "VW100 100", "VW100 1000").replace("VW102 100", "VW102 1000")
    plc = plcrt.load(GOTO_SPD, plant=_plant(), data=data, scan_ms=10)
    plc["M1.1"] = 1
    plc.run(seconds=20.6)   # the final ramp started at about 20.05 s
    assert 0 < plc.axis(0, 0)["speed"] < 10000
    plc["VW102"] = 5000
    plc["VB120"] = 1
    _run_until_stopped(plc)
    assert plc.axis(0, 0)["position"] == 200000
    assert plc["VD124"] == 200000 and plc["VW122"] == 8
    assert not any("cannot be reached" in d.message for d in plc.diagnostics)
    assert any("programmed end" in d.message for d in plc.diagnostics)


def test_pos_goto_r_posset_already_passed_says_how_many_pulses_are_out() -> None:
    """Physically impossible: an Update to a PosSet that the move has
    already passed stops beyond it, and the diagnostic says why."""
    plc = plcrt.load(GOTO_SPD, plant=_plant(), data=GOTO_DATA, scan_ms=10)
    plc["M1.1"] = 1
    plc.run(seconds=1)
    plc["VD112"] = 100
    plc["VB120"] = 1
    _run_until_stopped(plc)
    assert plc.axis(0, 0)["position"] > 100
    msg = next(d.message for d in plc.diagnostics if "already passed" in d.message)
    assert "pulses of this move are sent" in msg


# ---------------------------------------------------------------------------
# 5. POS_GOTO_R keeps C_Pos when another instruction moves the axis
# ---------------------------------------------------------------------------
def test_pos_goto_r_c_pos_is_kept_while_another_instruction_moves_the_axis() -> None:
    """3.2.5 C_Pos (pulses sent by the move) is kept until the block's next
    start, also while SPD_CTRL moves the same axis."""
    plc = plcrt.load(GOTO_SPD, plant=_plant(), data=GOTO_DATA, scan_ms=10)
    plc["M1.1"] = 1
    _run_until_stopped(plc)
    assert plc["VD124"] == 20000
    plc["M2.2"] = 1
    plc["M2.1"] = 1
    plc.run(seconds=1)
    assert plc.axis(0, 0)["status"] == "moving"
    assert plc["VD124"] == 20000
    assert plc["VD128"] == 0   # C_Spd: this block does not move the axis


# ---------------------------------------------------------------------------
# 6. a refused POS_RUN Update says that the envelope goes on
# ---------------------------------------------------------------------------
def test_pos_run_direction_changing_update_says_the_envelope_goes_on() -> None:
    """3.2.6: a direction change inside a running envelope is refused; the
    diagnostic says the envelope goes on (it does), not that it "does not
    start"."""
    plc = plcrt.load(POS_RUN, plant=_plant(), data=RUN_TABLE, scan_ms=10)
    plc["M3.0"] = 1
    plc.run(seconds=2)
    plc["VD1020"] = -100000
    plc["VB104"] = 1
    _run_until_stopped(plc)
    assert plc.axis(0, 0)["position"] == 300000
    msgs = [d.message for d in plc.diagnostics if "direction" in d.message]
    assert msgs and all("does not start" not in m for m in msgs)
    assert any("goes on as planned" in m for m in msgs)


# ---------------------------------------------------------------------------
# documented choices reconsidered
# ---------------------------------------------------------------------------
def test_spd_ctrl_direction_update_reverses_through_spdss() -> None:
    """Note 5 lists the direction among what Update applies (and advises
    against changing it while running): the axis slows down to SpdSs with
    DecTime, stops, and runs the other way up to SpdSet, C_Status 1 all
    along; the diagnostic names note 5."""
    plc = plcrt.load(GOTO_SPD, plant=_plant(), data=GOTO_DATA, scan_ms=10)
    plc["M2.2"] = 1
    plc["M2.1"] = 1
    plc.run(seconds=1)
    assert plc.axis(0, 0)["speed"] == 10000
    turn_from = plc.axis(0, 0)["position"]
    plc["M2.2"] = 0
    plc["VB220"] = 1
    peak = turn_from
    for _ in range(100):
        plc.scan()
        peak = max(peak, plc.axis(0, 0)["position"])
        assert plc["VW222"] == 1
    assert plc.axis(0, 0)["speed"] == -10000 and plc["VD228"] == -10000
    # 10 kHz -> 1 kHz at (10 000 - 1 000) Hz / 100 ms: 550 pulses to the turn
    assert peak - turn_from in (550, 551)
    assert any("note 5" in d.message for d in plc.diagnostics)


@pytest.mark.parametrize("block", ["goto", "spd"])
def test_run_back_to_1_during_the_stop_ramp_is_reported(block: str) -> None:
    """Run = 0 starts a stop; Run back to 1 before the pulses end does not
    take the stop back (the manual gives no such rule): the axis stops,
    C_Status reads 8, and a diagnostic says that a new Run edge is needed."""
    plc = plcrt.load(GOTO_SPD, plant=_plant(), data=GOTO_DATA.replace(
        "VW102 100", "VW102 1000").replace("VW202 100", "VW202 1000"), scan_ms=10)
    run = "M1.1" if block == "goto" else "M2.1"
    plc[run] = 1
    plc.run(seconds=1.5)
    plc[run] = 0
    plc.scan()
    plc[run] = 1
    _run_until_stopped(plc)
    assert plc["VW122" if block == "goto" else "VW222"] == 8
    assert any("Run went back to 1" in d.message for d in plc.diagnostics)


HOMING_PROG = """ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     SM0.0
CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0
Network 2
LD     SM0.0
CALL   HOMING, 0, 0, VW100, VD102, VD106, {offset}, VD114, M1.0, M1.1, VW118, VD120
END_ORGANIZATION_BLOCK
"""


def test_homing_pos_offset_may_be_a_byte_as_in_the_manuals_table() -> None:
    """3.2.7 types PosOffset as a byte: a program written from that table
    compiles (with a warning that a byte cannot be negative or above 255)
    and the offset move is that many pulses."""
    plant = _plant(start=50000, rps=[10000, 20000], limit_neg=-100000, limit_pos=400000)
    plc = plcrt.load(HOMING_PROG.format(offset="VB110"), plant=plant,
                     data="VW100 3\nVD102 2000\nVD106 20000\nVB110 200\n", scan_ms=1)
    assert any("PosOffset" in d.message and "BYTE" in d.message for d in plc.diagnostics)
    plc["M1.1"] = 1
    plc.run(seconds=20)
    ax = plc.axis(0, 0)
    assert (ax["position"], ax["mechanical"]) == (0, 20001 + 200)


def test_homing_braking_into_a_limit_explains_the_ramp() -> None:
    """HOMING has no DecTime: the slow-down on the switch takes 100 ms.
    With the switch nearer to a limit than that ramp needs, the limit stops
    the axis; the diagnostic gives the pulses needed and available and the
    highest SpdHigh that fits."""
    plant = _plant(start=30000, rps=[10000, 10400], limit_neg=9000, limit_pos=10600)
    plc = plcrt.load(HOMING_PROG.format(offset="VD110"), plant=plant,
                     data="VW100 3\nVD102 1000\nVD106 50000\n", scan_ms=1)
    plc["M1.1"] = 1
    plc.run(seconds=5)
    assert plc["VW118"] == 8 and plc.axis(0, 0)["position"] != 0
    msg = next(d.message for d in plc.diagnostics if "failed" in d.message)
    assert "100 ms homing ramp needs 1000 pulses" in msg
    assert "600 pulses past the edge" in msg and "at most 11000 Hz" in msg


@pytest.mark.parametrize("block", ["goto", "spd"])
def test_single_ended_while_above_200_khz_brings_the_speed_down(block: str) -> None:
    """2.1: single-ended output reaches 200 kHz.  Switching P_DorCCW to 0
    while an axis runs at 300 kHz ramps it down to 200 kHz (DecTime), and a
    POS_GOTO_R move still ends exactly on PosSet."""
    data = GOTO_DATA.replace("VD108 10000", "VD108 300000").replace(
        "VD208 10000", "VD208 300000").replace("VD112 20000", "VD112 900000")
    plc = plcrt.load(GOTO_SPD, plant=_plant(), data=data, scan_ms=10)
    plc["M0.0"] = 1                      # differential
    plc["M1.1" if block == "goto" else "M2.1"] = 1
    plc["M2.2"] = 1
    plc.run(seconds=0.9)
    assert plc.axis(0, 0)["speed"] == 300000
    plc["M0.0"] = 0                      # single-ended
    plc.run(seconds=0.5)
    assert plc.axis(0, 0)["speed"] == 200000
    assert any("P_DorCCW" in d.message for d in plc.diagnostics)
    if block == "goto":
        _run_until_stopped(plc)
        assert plc.axis(0, 0)["position"] == 900000
