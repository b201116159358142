"""Homing through the drive: controlwords (enable, 6060h = 6, 6098h, bit 4 rising)
run every homing method of both models on a plant with limits, a home switch and
index pulses, and the drive ends where the pure :class:`HomingSequence` says.

The reference is the sequence itself (its geometry is pinned by
test_cia402_homing.py): these tests pin the join - the drive's motion, watches,
count shift, statusword bits, faults and explanations - not the geometry.
"""

from __future__ import annotations

import math
import os

import pytest
from hypothesis import example, given, settings, strategies as st

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.drive_service import cite
from plcrt.devices.cia402.homing import Done, Failed, HomingParams, HomingSequence, run
from plcrt.devices.cia402.homing_adapter import SequencePlan
from plcrt.devices.cia402.homing_methods import HomingPlant, method_table
from plcrt.devices.cia402.homing_plan import homing_plans
from plcrt.devices.cia402.od import SdoAbort
from plcrt.devices.cia402.plant import DrivePlant
from plcrt.devices.cia402.statemachine import State

HCFA, KINCO = "hcfa-am0520b", "kinco-servo"
NL, PL, LO, HI = -10000, 10000, 1000, 3000
PERIOD, PHASE = 500, 130
V_HIGH, V_LOW, ACC = 20000, 2000, 200000
STARTS = {"left of the home switch": -5000, "inside the home switch": 2000,
          "right of the home switch": 6000, "on NLS": NL, "on PLS": PL}
B10, B12, B13, B15 = 0x0400, 0x1000, 0x2000, 0x8000


def shifted(start: int, nl=NL, pl=PL, lo=LO, hi=HI, period=PERIOD, phase=PHASE,
            index=True) -> tuple[DrivePlant, HomingPlant]:
    """The plant seen from an axis that powers up at mechanical 0 = ``start``."""
    drive = DrivePlant(nl - start, pl - start, (lo - start, hi - start),
                       period if index else None, (phase - start) % period)
    pure = HomingPlant(drive.neg_limit, drive.pos_limit, drive.home_switch,
                       drive.index_period, drive.index_phase)
    return drive, pure


def reference(model: str, n: int, pure: HomingPlant, offset: int = 0, offset_mode: int = 0,
              timeout_ms: int = 0, blind_zone: int = 0, v_high: int = V_HIGH, v_low: int = V_LOW,
              acc: int = ACC) -> Done | Failed:
    params = HomingParams(n, v_high, v_low, acc, offset,
                          offset_mode=offset_mode, blind_zone=blind_zone,
                          timeout_ms=timeout_ms)
    result, phases = run(HomingSequence(model, params, pure), 0, 0)
    PHASES[id(result)] = len(phases)
    return result


#: phases of each reference run, by id of its result (for the time tolerance)
PHASES: dict[int, int] = {}


def home_on_drive(model: str, n: int, plant: DrivePlant, offset: int = 0,
                  offset_mode: int = 0, timeout_ms: int = 0, blind_zone: int = 0, v_high: int = V_HIGH,
                  v_low: int = V_LOW, acc: int = ACC, horizon_us: int = 120_000_000) -> Drive:
    d = Drive(model, plant=plant)
    d.write(0x6060, 0, 6)
    for (index, sub), value in {(0x6098, 0): n, (0x6099, 1): v_high, (0x6099, 2): v_low,
                                (0x609A, 0): acc, (0x607C, 0): offset}.items():
        d.write(index, sub, value)
    if model == KINCO:
        d.write(0x6099, 5, offset_mode)
        d.write(0x6099, 6, blind_zone)
    else:
        d.write(0x2003, 7, timeout_ms)
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
    if d.sm.state is State.SWITCHED_ON:
        d.cycle(d.now)
    assert d.sm.state is State.OPERATION_ENABLED
    d.write(0x6040, 0, 0x1F)                          # bit 4 rising: homing starts
    d.advance(horizon_us)
    return d


def assert_agrees(d: Drive, ref: Done | Failed, v_low: int = V_LOW, acc: int = ACC) -> None:
    """The drive ended as the pure sequence did, and at the same time up to one
    count per phase (at 6099h:02, or from rest at 609Ah): the drive's count is the
    floor of the exact position, so moving - it reaches a watched count early."""
    texts = " | ".join(e.text for e in d.log)
    # the drive's log cites its own model's manual (drive_service.cite)
    explanation = cite(d.model, ref.explanation, "")[0]
    t_end = [e.t_us for e in d.log if explanation in e.text]
    assert t_end, texts
    one_count = max(-(-1_000_000 // v_low), math.isqrt(2 * 10**12 // acc) + 1) + 1
    slack = PHASES.get(id(ref), 0) * one_count
    assert abs(t_end[0] - ref.t) <= slack, (t_end[0], ref.t, slack)
    if isinstance(ref, Done):
        sw = d.statusword
        assert sw & (B10 | B12 | B13) == B10 | B12, (hex(sw), texts)
        assert d.axis.mechanical(d.now) == ref.position, texts
        assert d.position == ref.position + ref.position_shift, texts
        assert not d.axis.moving(d.now)
        assert explanation in texts
        return
    assert explanation in texts
    if ref.alarm is not None:
        assert d.sm.state in (State.FAULT_REACTION_ACTIVE, State.FAULT)
        assert d.read(0x603F) == ref.alarm
    else:
        assert d.sm.state is State.OPERATION_ENABLED
        assert d.statusword & (B12 | B13) == B13
        assert d.axis.mechanical(d.now) == ref.position
        assert not d.axis.moving(d.now)


CASES = [(model, n, where) for model in (HCFA, KINCO) for n in sorted(method_table(model))
         for where in STARTS]


@pytest.mark.parametrize("model,n,where", CASES)
def test_every_method_through_the_drive_ends_where_the_sequence_does(model, n, where):
    """Every method of each model, from each side of and inside the home switch and
    on an active limit: the drive's outcome, final position, 6064h and explanation
    are the pure sequence's; 6064h follows the model's offset rule (607Ch = 250)."""
    drive_plant, pure = shifted(STARTS[where])
    ref = reference(model, n, pure, offset=250)
    d = home_on_drive(model, n, drive_plant, offset=250)
    assert_agrees(d, ref)


def test_switch_methods_succeed_from_all_three_sides():
    """The geometry plants of this file home every method but the hard-stop ones from
    left of, inside and right of the home switch (the comparison above is not
    vacuous); HCFA 33/34 started on the switch are §7.5.4 homing errors."""
    for model in (HCFA, KINCO):
        for n in sorted(method_table(model)):
            if n < 0:
                continue
            for where in ("left of the home switch", "inside the home switch",
                          "right of the home switch"):
                ref = reference(model, n, shifted(STARTS[where])[1])
                error = model == HCFA and n in (33, 34) and where.startswith("inside")
                assert isinstance(ref, Failed if error else Done), (model, n, where)


@pytest.mark.parametrize("model,offset_mode,count", [
    (HCFA, 0, 250),          # HCFA: 6064h = +607Ch at the home point
    (KINCO, 1, -250),        # Kinco offset mode 1: 6064h = -607Ch at the home point
    (KINCO, 0, 0),           # Kinco offset mode 0: move 607Ch, then 6064h = 0 (§2.3-3)
])
def test_offset_rule_per_model(model, offset_mode, count):
    drive_plant, pure = shifted(-5000)
    ref = reference(model, 19, pure, offset=250, offset_mode=offset_mode)
    d = home_on_drive(model, 19, drive_plant, offset=250, offset_mode=offset_mode)
    assert isinstance(ref, Done) and d.position == count
    home_point = LO - 1 - (-5000)                    # method 19: lo edge, approached from -
    assert ref.home_point == home_point
    moved = 250 if offset_mode == 0 and model == KINCO else 0
    assert d.axis.mechanical(d.now) == home_point + moved


def test_statusword_bits_while_running_and_after_homing():
    """Bit 12 is 0 while running and 1 after; bit 15: HCFA "can be triggered" (0 once
    done), Kinco "reference found" (1 once done, cleared by a new start)."""
    for model, b15_done in ((HCFA, 0), (KINCO, B15)):
        drive_plant, _ = shifted(-5000)
        d = home_on_drive(model, 7, drive_plant, horizon_us=1000)
        assert d.statusword & (B10 | B12 | B13 | B15) == 0
        d.advance(120_000_000)
        assert d.statusword & (B10 | B12 | B13 | B15) == B10 | B12 | b15_done
        d.write(0x6040, 0, 0x0F)
        d.write(0x6040, 0, 0x1F)                      # a new homing
        assert d.statusword & (B12 | B15) == 0


def test_missing_index_pulses_fault_with_alarm_62_on_hcfa():
    drive_plant, pure = shifted(-5000, index=False)
    ref = reference(HCFA, 7, pure)
    assert isinstance(ref, Failed) and ref.alarm == 62
    d = home_on_drive(HCFA, 7, drive_plant)
    assert_agrees(d, ref)
    assert "index_period" in ref.explanation and "§2.2" in ref.explanation


def test_kinco_missing_index_is_a_homing_error_without_fault():
    drive_plant, pure = shifted(-5000, index=False)
    ref = reference(KINCO, 7, pure)
    assert isinstance(ref, Failed) and ref.alarm is None
    d = home_on_drive(KINCO, 7, drive_plant)
    assert_agrees(d, ref)


def test_hcfa_time_limit_p03_07_gives_alarm_63():
    drive_plant, _ = shifted(-5000)
    d = home_on_drive(HCFA, 7, drive_plant, timeout_ms=100)
    assert d.read(0x603F) == 63 and d.sm.state in (State.FAULT_REACTION_ACTIVE, State.FAULT)
    assert any("P03.07" in e.text for e in d.log)


def test_kinco_hard_stop_methods_fail_on_a_plant_without_mechanical_ends():
    drive_plant, pure = shifted(0)
    for n in (-17, -18):
        ref = reference(KINCO, n, pure)
        assert isinstance(ref, Failed) and "and the plant has none" in ref.explanation
        assert_agrees(home_on_drive(KINCO, n, drive_plant), ref)


def test_a_method_outside_the_model_is_refused():
    """HCFA 36 is no method of §10.1 / §7.5.4: alarm 62 naming 6098h; Kinco's 6098h
    takes only its §2.2 methods, so 37 is refused by the SDO write itself."""
    d = home_on_drive(HCFA, 36, shifted(0)[0])
    assert d.read(0x603F) == 62
    assert any("6098h = 36" in e.text for e in d.log)
    with pytest.raises(SdoAbort, match="6098h:00.*37"):
        home_on_drive(KINCO, 37, shifted(0)[0])


def test_registry_holds_every_method_of_both_models():
    for model in (HCFA, KINCO):
        plans = homing_plans(model)
        assert sorted(plans) == sorted(method_table(model))
        assert all(f is SequencePlan for f in plans.values())


#: a model and one of its methods, each model as likely as the other
MODEL_METHOD = st.sampled_from([HCFA, KINCO]).flatmap(
    lambda model: st.tuples(st.just(model), st.sampled_from(sorted(method_table(model)))))


@settings(max_examples=int(os.environ.get("PLCRT_PROPERTY_EXAMPLES", "60")), deadline=None)
@given(model_method=MODEL_METHOD,
       start=st.integers(NL - 200, PL + 200), lo=st.integers(-8000, 7000),
       width=st.integers(1, 2500), period=st.integers(50, 4000),
       phase=st.integers(0, 3999), offset=st.integers(-5000, 5000),
       offset_mode=st.integers(0, 1), blind_zone=st.integers(0, 2))
# the Kinco offset move of method 18 ends on PLS (home at PL - 1, 607Ch = 1)
@example(model_method=(KINCO, 18), start=0, lo=0, width=1, period=50, phase=0, offset=1,
         offset_mode=0, blind_zone=0)
def test_drive_and_sequence_agree(model_method, start, lo, width, period, phase, offset,
                                  offset_mode, blind_zone):
    """For any method, start, switch, index pattern, offset and (Kinco) offset mode
    and index blind zone the drive ends as the pure sequence does (outcome,
    position, 6064h, alarm, time)."""
    model, n = model_method
    drive_plant, pure = shifted(start, lo=lo, hi=lo + width, period=period,
                                phase=phase % period)
    ref = reference(model, n, pure, offset=offset, offset_mode=offset_mode,
                    blind_zone=blind_zone if model == KINCO else 0)
    d = home_on_drive(model, n, drive_plant, offset=offset, offset_mode=offset_mode,
                      blind_zone=blind_zone)
    assert_agrees(d, ref)


@pytest.mark.parametrize("n,start,offset", [
    (18, 0, 1), (17, 0, -1),                                  # ends on the limit
    (19, -5000, PL - (LO - 1)), (19, -5000, NL - (LO - 1)),
    (35, PL, 250), (35, NL, -250),                            # starts on it, goes further
])
def test_kinco_offset_move_onto_or_along_a_limit_fails_on_the_drive(n, start, offset):
    """Kinco 6099h:05 = 0: the drive's offset move that ends on a limit, or starts
    on an active one and points further into it, is the sequence's homing error:
    bit 13 without a fault, the axis standing where the limit stopped it, no home
    set - even when the move's end and the limit fall on the same µs."""
    drive_plant, pure = shifted(start)
    ref = reference(KINCO, n, pure, offset=offset)
    assert isinstance(ref, Failed) and "in the offset phase" in ref.explanation
    d = home_on_drive(KINCO, n, drive_plant, offset=offset)
    assert_agrees(d, ref)
    assert not d.sm.homed and d.position == d.axis.mechanical(d.now)


def test_halt_and_bit_4_falling_end_homing_with_the_hcfa_words():
    """HCFA §7.3 / §7.5.4: halt during homing gives 0x0737, bit 4 falling 0x8637;
    neither sets a home (6064h keeps counting from the start)."""
    drive_plant, _ = shifted(-5000)
    d = home_on_drive(HCFA, 7, drive_plant, horizon_us=50_000)
    d.write(0x6040, 0, 0x11F)                         # halt
    d.advance(d.now + 1_000_000)
    assert d.statusword == 0x0737 and d.position == d.axis.mechanical(d.now)
    d = home_on_drive(HCFA, 7, drive_plant, horizon_us=50_000)
    d.write(0x6040, 0, 0x0F)                          # bit 4 falls
    assert d.statusword == 0x8637 and not d.axis.moving(d.now)


def test_kinco_blind_zone_reaches_the_sequence():
    """6099h:06 = 2 (½ rev, Kinco §2.4) moves the home of method 7 to a later index,
    through the drive as in the sequence."""
    drive_plant, pure = shifted(-5000, phase=LO - 1 - 10)   # an index 10 counts past the edge
    near = reference(KINCO, 7, pure)
    far = reference(KINCO, 7, pure, blind_zone=2)
    assert isinstance(near, Done) and isinstance(far, Done) and far.home_point != near.home_point
    assert_agrees(home_on_drive(KINCO, 7, drive_plant, blind_zone=2), far)
