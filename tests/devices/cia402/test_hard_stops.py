"""Mechanical ends (hard stops) in a drive's plant: the axis stands at an end
while the demand goes on (60F4h grows), the following error window 6065h /
time out 6066h fault the drive in PP and PV at their exact µs, a move that
never arrives leaves target reached (bit 10) at 0, and Kinco -17 / -18 home
on the ends (Kinco §2.5).

Expected times are computed here from the profile in closed form (ramp with
609Ah / 6083h to the speed, then cruise), never from the implementation.
"""

from __future__ import annotations

import math
from fractions import Fraction

import pytest
from hypothesis import given, settings, strategies as st

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.homing import Done, Failed, HomingParams, HomingSequence, run
from plcrt.devices.cia402.homing_methods import HomingPlant
from plcrt.devices.cia402.plant import DrivePlant
from plcrt.devices.cia402.statemachine import State
from plcrt.devices.cia402.states import Cia402Error
from plcrt.errors import PlcError

HCFA, KINCO = "hcfa-am0520b", "kinco-servo"
B10, B12, B13, B15 = 0x0400, 0x1000, 0x2000, 0x8000
NS, NL, PL, PS = -12000, -10000, 10000, 12000        # ends and limits around 0
V, ACC = 20000, 200000                               # 6099h:01, 609Ah
US = 1_000_000


def first_us(travel: Fraction | int, v: int = V, acc: int = ACC) -> int:
    """First integer µs at which a ramp from rest at *acc* to *v*, then a
    cruise, has covered *travel* counts."""
    travel = Fraction(travel)
    d_ramp = Fraction(v * v, 2 * acc)
    if travel <= d_ramp:
        t2 = 2 * travel / acc * US * US       # t in µs, squared
        t = math.isqrt(t2.numerator // t2.denominator)
        while Fraction(acc, 2) * Fraction(t, US) ** 2 < travel:
            t += 1
        return t
    t = Fraction(v, acc) * US + (travel - d_ramp) / v * US
    return -(-t.numerator // t.denominator)


def enabled(model: str, plant: DrivePlant, mode: int) -> Drive:
    d = Drive(model, plant=plant)
    d.write(0x6060, 0, mode)
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
    if d.sm.state is State.SWITCHED_ON:
        d.cycle(d.now)                       # the HCFA two-step enable
    assert d.sm.state is State.OPERATION_ENABLED
    return d


# -- the plant ----------------------------------------------------------------------------------
@pytest.mark.parametrize("kw,message", [
    (dict(neg_stop=100, pos_stop=100), "neg_stop = 100 must lie below pos_stop = 100"),
    (dict(neg_limit=-100, neg_stop=-50), "neg_stop = -50 must lie at or below neg_limit = -100"),
    (dict(pos_limit=100, pos_stop=99), "pos_stop = 99 must lie at or above pos_limit = 100"),
    (dict(pos_limit=100, neg_stop=100), "neg_stop = 100 must lie below pos_limit = 100"),
    (dict(neg_limit=-100, pos_stop=-100), "pos_stop = -100 must lie above neg_limit = -100"),
    (dict(pos_stop=1.5), "pos_stop = 1.5 must be a whole count"),
])
def test_plant_refuses_ends_inside_the_limits_or_crossed(kw, message):
    with pytest.raises(Cia402Error, match="plant: " + message.replace("(", r"\(")) as info:
        DrivePlant(**kw)
    assert isinstance(info.value, PlcError)


def test_plant_takes_ends_at_or_beyond_the_limits_as_keywords():
    p = DrivePlant(neg_limit=-100, pos_limit=100, neg_stop=-100, pos_stop=250)
    assert (p.neg_stop, p.pos_stop) == (-100, 250)
    assert p.beyond_stop(-101) == "neg_stop" and p.beyond_stop(251) == "pos_stop"
    assert p.beyond_stop(-100) is None and p.beyond_stop(250) is None


def test_a_drive_cannot_power_up_beyond_an_end():
    with pytest.raises(Cia402Error, match="powers up at mechanical position 0, beyond "
                                          "neg_stop = 5"):
        Drive(KINCO, plant=DrivePlant(neg_stop=5))


# -- Kinco -17 / -18 through the drive -------------------------------------------------------------
STARTS = {"between the limits": 0, "on NLS": -11000, "on PLS": 11000,
          "at neg_stop": NS, "at pos_stop": PS}
CRITERIA = {"following error 6065h": ((0x6065, 0), 100),
            "current 6099h:04": ((0x6099, 4), 1),
            "velocity window 60F9h:0A": ((0x60F9, 10), 10)}


def plant_from(start: int) -> DrivePlant:
    """The plant seen from an axis that powers up at mechanical 0 = *start*."""
    return DrivePlant(neg_limit=NL - start, pos_limit=PL - start, neg_stop=NS - start,
                      pos_stop=PS - start)


def kinco_home(method: int, start: int, criterion: str, offset: int = 0,
               offset_mode: int = 1, horizon: int = 3 * US) -> Drive:
    d = enabled(KINCO, plant_from(start), 6)
    for (index, sub), value in {(0x6098, 0): method, (0x6099, 1): V, (0x6099, 2): 2000,
                                (0x609A, 0): ACC, (0x607C, 0): offset, (0x6099, 5): offset_mode,
                                (0x6065, 0): 0}.items():
        d.write(index, sub, value)
    key, value = CRITERIA[criterion]
    d.write(*key, value)
    d.write(0x6040, 0, 0x1F)
    d.advance(horizon)
    return d


def expected_stall(method: int, start: int, criterion: str) -> tuple[int, int]:
    """(mechanical end in the drive's frame, µs the stall criterion holds)."""
    end = (NS if method == -17 else PS)
    dist = abs(end - start)
    t_reach = first_us(dist) if dist else 0
    if criterion.startswith("following"):
        return end - start, first_us(dist + 100)      # 60F4h reaches 6065h = 100
    if criterion.startswith("current"):
        return end - start, t_reach                     # blocked: at once
    return end - start, max(t_reach, V * US // ACC)     # 606Ch = 0 < 10, after the ramp


@pytest.mark.parametrize("method", [-17, -18])
@pytest.mark.parametrize("where", STARTS)
@pytest.mark.parametrize("criterion", CRITERIA)
def test_kinco_hard_stop_homing_ends_on_the_mechanical_end(method, where, criterion):
    """-17 / -18 from a start between the limits, on a limit, at either end:
    the axis stands on the end from the µs it reaches it, the first armed
    criterion (Kinco §2.5) zeroes 6064h there (offset mode 1, 607Ch = 0),
    statusword bits 10 and 12 set, 13 clear, 15 reference found (§2.6)."""
    start = STARTS[where]
    d = kinco_home(method, start, criterion)
    end, t_home = expected_stall(method, start, criterion)
    done = [e.t_us for e in d.log if "home at" in e.text]
    assert done == [t_home], [str(e) for e in d.log]
    assert d.axis.mechanical(d.now) == end and d.axis.exact(d.now)[0] == end
    assert d.position == 0 and d.read(0x6064) == 0 and d.read(0x60F4) == 0
    sw = d.statusword
    assert sw & (B10 | B12 | B13 | B15) == B10 | B12 | B15, hex(sw)
    assert not d.axis.moving(d.now)


@pytest.mark.parametrize("method", [-17, -18])
@pytest.mark.parametrize("where", ["between the limits", "at neg_stop", "at pos_stop"])
def test_the_pure_sequence_and_the_drive_agree_on_the_stall(method, where):
    start = STARTS[where]
    params = HomingParams(method, V, 2000, ACC, offset_mode=1, following_error_window=100)
    ref, _ = run(HomingSequence(KINCO, params, HomingPlant(NL - start, PL - start,
                                                           neg_stop=NS - start,
                                                           pos_stop=PS - start)), 0, 0)
    assert isinstance(ref, Done)
    d = kinco_home(method, start, "following error 6065h")
    assert [e.t_us for e in d.log if ref.explanation in e.text] == [ref.t]
    assert d.axis.mechanical(d.now) == ref.position


def test_during_the_stall_the_following_error_grows_against_the_standing_axis():
    """-17 from 0 with 6065h = 100: the axis stands at -12000 from 650000 µs;
    2.5 ms later the demand is 50 counts further (20000 P/s), 606Ch = 0."""
    d = kinco_home(-17, 0, "following error 6065h", horizon=652_500)
    assert d.read(0x6064) == NS and d.read(0x606C) == 0
    assert d.read(0x6062) == NS - 50 and d.read(0x60F4) == -50
    assert d.statusword & (B10 | B12 | B13 | B15) == 0          # homing running
    assert any("mechanical end neg_stop = -12000 reached" in e.text and e.t_us == 650_000
               for e in d.log)


@pytest.mark.parametrize("offset,mode,mechanical,count", [
    (300, 0, NS + 300, 0),         # move 607Ch off the end, 6064h = 0 there
    (300, 1, NS, -300),            # stay, 6064h = -607Ch
    (-300, 1, NS, 300),
])
def test_kinco_hard_stop_offset_modes(offset, mode, mechanical, count):
    """Kinco §2.3-3: 6099h:05 = 0 moves 607Ch on and reads 0 there; 1 stays on
    the end and reads -607Ch."""
    d = kinco_home(-17, 0, "current 6099h:04", offset=offset, offset_mode=mode)
    assert d.axis.mechanical(d.now) == mechanical and d.position == count
    assert d.statusword & (B10 | B12 | B13 | B15) == B10 | B12 | B15


def test_kinco_offset_into_the_end_is_a_homing_error():
    d = kinco_home(-17, 0, "current 6099h:04", offset=-300, offset_mode=0)
    assert d.statusword & (B12 | B13 | B15) == B13
    assert d.axis.mechanical(d.now) == NS and d.sm.state is State.OPERATION_ENABLED
    assert any("points into the mechanical end" in e.text for e in d.log)


def test_kinco_hard_stop_without_any_criterion_is_a_homing_error():
    d = enabled(KINCO, plant_from(0), 6)
    for (index, sub), value in {(0x6098, 0): -18, (0x6099, 1): V, (0x609A, 0): ACC,
                                (0x6065, 0): 0}.items():
        d.write(index, sub, value)
    d.write(0x6040, 0, 0x1F)
    d.advance(2 * US)
    assert d.statusword & (B12 | B13) == B13
    assert d.axis.mechanical(d.now) == PS and d.read(0x60F4) == 0
    assert any("no stall criterion is armed" in e.text for e in d.log)


# -- PP, PV, CSP into an end ---------------------------------------------------------------------
def pp(d: Drive, target: int, v: int = 50_000, acc: int = 100_000, cw: int = 0x1F) -> None:
    for index, value in ((0x6081, v), (0x6083, acc), (0x6084, acc), (0x607A, target)):
        d.write(index, 0, value)
    d.write(0x6040, 0, cw)
    d.write(0x6040, 0, 0x0F)


def test_pp_into_an_end_faults_at_the_exact_microsecond_of_6065h_and_6066h():
    """Kinco, pos_stop = 50000, target 100000 at 50000 P/s, 100000 P/s²: the
    demand ramps 0.5 s (12500 counts) then cruises; it is at the end at
    1.25 s, 60F4h exceeds 6065h = 1000 when the demand reaches 51001
    (0.5 s + 38501 / 50000 s = 1270020 µs), the fault 0x8611 follows 6066h =
    20 ms later."""
    d = enabled(KINCO, DrivePlant(pos_stop=50_000), 1)
    d.write(0x6065, 0, 1000)
    d.write(0x6066, 0, 20)
    pp(d, 100_000)
    d.advance(1_249_999)
    assert d.read(0x6064) == 49_999
    d.advance(1_250_000)
    assert d.read(0x6064) == 50_000
    d.advance(1_250_001)
    assert d.read(0x6064) == 50_000 and d.read(0x606C) == 0 and d.read(0x60F4) == 0
    d.advance(1_290_019)
    assert d.sm.state is State.OPERATION_ENABLED and d.read(0x6064) == 50_000
    assert d.read(0x60F4) == d.read(0x6062) - 50_000 > 1000
    d.advance(1_290_020)
    assert d.sm.state in (State.FAULT_REACTION_ACTIVE, State.FAULT)
    assert d.read(0x603F) == 0x8611 and d.read(0x6064) == 50_000
    texts = [(e.t_us, e.text) for e in d.log]
    assert any(t == 1_250_000 and "mechanical end pos_stop = 50000 reached" in x
               for t, x in texts)
    assert any(t == 1_270_020 and "60F4h = 1001 beyond 6065h = 1000" in x for t, x in texts)
    fault = [x for t, x in texts if t == 1_290_020 and "pos_stop = 50000" in x]
    assert fault and "6066h = 20 ms" in fault[0], texts


def test_pp_into_an_end_without_supervision_stands_blocked_with_target_not_reached():
    """HCFA (6065h = all ones: off): the move's demand ends at 100000, the axis
    stands at 50000; bit 10 stays 0, 60F4h = 50000.  A set-point back
    (bit 5) unwinds the demand: the axis leaves the end when the demand is
    back on it and ends exactly on its target with bit 10."""
    d = enabled(HCFA, DrivePlant(pos_stop=50_000), 1)
    pp(d, 100_000)
    d.advance(10 * US)
    assert d.read(0x6064) == 50_000 and d.read(0x6062) == 100_000
    assert d.read(0x60F4) == 50_000 and d.sm.state is State.OPERATION_ENABLED
    assert not d.statusword & B10
    assert any("stands at the mechanical end pos_stop = 50000" in e.text
               and "bit 10" in e.text for e in d.log)
    pp(d, 0, cw=0x3F)                                 # change set immediately
    t0 = d.now
    d.advance(t0 + first_us(50_000, 50_000, 100_000) - 1)
    assert d.read(0x6064) == 50_000                   # the demand is still past the end
    d.advance(t0 + 20 * US)
    assert d.read(0x6064) == 0 and d.read(0x60F4) == 0 and d.statusword & B10


def test_pv_into_an_end_stands_at_zero_speed_with_the_following_error_growing():
    """HCFA PV at 10000 P/s (6083h = 100000): at the end 20000 after 2.05 s;
    at 3 s the demand is at 29500: 60F4h = 9500, 606Ch = 0, bit 10 (speed
    reached) 0, bit 12 (speed 0) 1."""
    d = enabled(HCFA, DrivePlant(pos_stop=20_000), 3)
    for index, value in ((0x6083, 100_000), (0x6084, 100_000), (0x60FF, 10_000)):
        d.write(index, 0, value)
    d.advance(2_049_999)
    assert d.read(0x6064) == 19_999
    d.advance(2_050_000)
    assert d.read(0x6064) == 20_000
    d.advance(3 * US)
    assert d.read(0x6064) == 20_000 and d.read(0x606C) == 0
    assert d.read(0x6062) == 29_500 and d.read(0x60F4) == 9_500
    assert d.statusword & (B10 | B12) == B12


def test_pv_into_an_end_faults_when_6065h_is_exceeded():
    """Kinco PV, 6065h = 500, 6066h = 0: the fault comes the µs the demand
    reaches 20501 (0.1 s ramp of 500 counts, then 20001 counts at 10000 P/s)."""
    d = enabled(KINCO, DrivePlant(neg_stop=-20_000, pos_stop=20_000), 3)
    d.write(0x6065, 0, 500)
    for index, value in ((0x6083, 100_000), (0x6084, 100_000), (0x60FF, 10_000)):
        d.write(index, 0, value)
    d.advance(2_100_099)
    assert d.sm.state is State.OPERATION_ENABLED
    d.advance(2_100_100)
    assert d.read(0x603F) == 0x8611 and d.read(0x6064) == 20_000


def test_csp_into_an_end_keeps_its_own_following_error_supervision():
    """CSP: 607Ah steps past the end every 1 ms; the axis stands on it and
    CSP's per-cycle supervision (60F4h = previous 607Ah - 6064h) faults."""
    d = enabled(KINCO, DrivePlant(neg_stop=-1000, pos_stop=1000), 8)
    d.write(0x6065, 0, 200)
    d.write(0x6066, 0, 0)
    t = 0
    for k in range(1, 200):
        t = k * 1000
        d.write(0x607A, 0, 10 * k)
        d.cycle(t)
        assert d.axis.mechanical(t) <= 1000
        if d.sm.state is not State.OPERATION_ENABLED:
            break
    assert d.read(0x603F) == 0x8611 and d.read(0x6064) == 1000
    assert any("mechanical end pos_stop = 1000 reached" in e.text for e in d.log)


# -- property: never beyond an end ----------------------------------------------------------------
COMMANDS = st.lists(st.tuples(st.sampled_from(["pp", "pp now", "pv", "halt", "go"]),
                              st.integers(-60_000, 60_000), st.integers(1_000, 80_000),
                              st.integers(1, 400_000)), min_size=1, max_size=6)


@settings(max_examples=60, deadline=None)
@given(model=st.sampled_from([HCFA, KINCO]), neg=st.integers(-40_000, 0),
       width=st.integers(1, 60_000), window=st.integers(0, 30_000),
       timeout=st.integers(0, 50), commands=COMMANDS)
def test_no_position_is_ever_beyond_an_end(model, neg, width, window, timeout, commands):
    """Any PP / PV commands on any plant with ends: 6064h and the exact
    position stay within [neg_stop, pos_stop], 60F4h = 6062h - 6064h, and a
    fault leaves the axis at rest within the ends."""
    neg = min(neg, 0)
    plant = DrivePlant(neg_stop=neg, pos_stop=max(neg + width, 1))
    d = enabled(model, plant, 1)
    d.write(0x6065, 0, window)
    d.write(0x6066, 0, timeout)
    for index, value in ((0x6081, 30_000), (0x6083, 200_000), (0x6084, 200_000)):
        d.write(index, 0, value)
    for kind, value, speed, dt in commands:
        if d.sm.state is State.OPERATION_ENABLED:
            if kind.startswith("pp"):
                if d.mode_number != 1:
                    d.write(0x6060, 0, 1)
                d.write(0x6081, 0, speed)
                d.write(0x607A, 0, value)
                d.write(0x6040, 0, 0x3F if kind == "pp now" else 0x1F)
                d.write(0x6040, 0, 0x0F)
            elif kind == "pv":
                if d.mode_number != 3:
                    d.write(0x6060, 0, 3)
                d.write(0x60FF, 0, value)
            else:
                d.write(0x6040, 0, 0x10F if kind == "halt" else 0x0F)
        for step in range(4):
            d.advance(d.now + dt // 4 + 1)
            x, v = d.axis.exact(d.now)
            assert plant.neg_stop <= x <= plant.pos_stop
            assert plant.neg_stop <= d.read(0x6064) <= plant.pos_stop
            demand = d.axis.demand(d.now)[0]
            if not plant.neg_stop <= demand <= plant.pos_stop:    # held at the end
                assert v == 0 and x == (plant.neg_stop if demand < x else plant.pos_stop)
            assert d.read(0x60F4) == d.read(0x6062) - d.read(0x6064)
    if d.sm.state is not State.OPERATION_ENABLED:
        assert not d.axis.moving(d.now) and d.read(0x606C) == 0


def test_homing_that_runs_into_an_end_faults_on_the_following_error():
    """A method that is not -17 / -18 meets a mechanical end (Kinco 19, its home
    switch placed beyond pos_stop): the switch is never reached, the demand
    pushes on, and 6065h = 10000 (Kinco default), 6066h = 0 fault the drive
    the µs the demand reaches 50000 + 10001."""
    d = enabled(KINCO, DrivePlant(home_switch=(60_000, 70_000), pos_stop=50_000), 6)
    for (index, sub), value in {(0x6098, 0): 19, (0x6099, 1): V, (0x6099, 2): 2000,
                                (0x609A, 0): ACC}.items():
        d.write(index, sub, value)
    d.write(0x6040, 0, 0x1F)
    t_fault = first_us(60_001)
    d.advance(t_fault - 1)
    assert d.sm.state is State.OPERATION_ENABLED and d.read(0x6064) == 50_000
    d.advance(t_fault)
    assert d.read(0x603F) == 0x8611 and d.read(0x6064) == 50_000
    assert any(e.t_us == first_us(50_000) and "60F4h is supervised against 6065h = 10000"
               in e.text for e in d.log)


@settings(max_examples=40, deadline=None)
@given(method=st.sampled_from([-17, -18]), start=st.integers(NS, PS),
       window=st.integers(0, 3000), current=st.integers(0, 1), vwin=st.integers(0, 50),
       offset=st.integers(-2000, 2000), offset_mode=st.integers(0, 1))
def test_kinco_hard_stop_homing_agrees_with_the_sequence(method, start, window, current, vwin,
                                                          offset, offset_mode):
    """Any start between the ends, any armed criteria, offset and offset mode:
    the drive ends as the pure sequence does (outcome, time, position, 6064h),
    and its axis is never beyond an end."""
    params = HomingParams(method, V, 2000, ACC, offset, offset_mode=offset_mode,
                          following_error_window=window, max_current=current,
                          velocity_window=vwin)
    pure = HomingPlant(NL - start, PL - start, neg_stop=NS - start, pos_stop=PS - start)
    ref, _ = run(HomingSequence(KINCO, params, pure), 0, 0)
    d = enabled(KINCO, plant_from(start), 6)
    for (index, sub), value in {(0x6098, 0): method, (0x6099, 1): V, (0x6099, 2): 2000,
                                (0x609A, 0): ACC, (0x607C, 0): offset,
                                (0x6099, 5): offset_mode, (0x6065, 0): window,
                                (0x6099, 4): current, (0x60F9, 10): vwin}.items():
        d.write(index, sub, value)
    d.write(0x6040, 0, 0x1F)
    t = 0
    while t < 3 * US:
        t += 50_000
        d.advance(t)
        assert NS - start <= d.axis.exact(t)[0] <= PS - start
    assert [e.t_us for e in d.log if ref.explanation in e.text] == [ref.t]
    assert d.axis.mechanical(d.now) == ref.position
    if isinstance(ref, Done):
        assert d.position == ref.position + ref.position_shift
        assert d.statusword & (B10 | B12 | B13 | B15) == B10 | B12 | B15
    else:
        assert isinstance(ref, Failed) and d.statusword & (B12 | B13) == B13


def test_a_window_lowered_while_the_axis_stands_at_an_end_starts_the_time_out():
    """HCFA PP blocked at pos_stop = 50000 with the demand at rest at 100000:
    writing 6065h = 1000 (6066h = 5 ms) starts the time out at once, the
    fault follows 5 ms later; raising 6065h back before then cancels it."""
    d = enabled(HCFA, DrivePlant(pos_stop=50_000), 1)
    pp(d, 100_000)
    d.advance(10 * US)
    d.write(0x6066, 0, 5)
    d.write(0x6065, 0, 1000)
    d.advance(10 * US + 4_000)
    d.write(0x6065, 0, 60_000)                        # back within: no fault
    d.advance(11 * US)
    assert d.sm.state is State.OPERATION_ENABLED
    assert any("back within 6065h = 60000" in e.text for e in d.log)
    d.write(0x6065, 0, 1000)
    t0 = d.now
    d.advance(t0 + 4_999)
    assert d.sm.state is State.OPERATION_ENABLED
    d.advance(t0 + 5_000)
    assert d.read(0x603F) == 0x8611 and d.read(0x6064) == 50_000


def test_a_move_that_ends_on_the_end_itself_reaches_its_target():
    """PP to exactly pos_stop: the axis arrives, bit 10 is set, 60F4h stays 0
    (with 6065h = 0) and nothing is blocked."""
    d = enabled(KINCO, DrivePlant(pos_stop=50_000), 1)
    d.write(0x6065, 0, 0)
    pp(d, 50_000)
    d.advance(5 * US)
    assert d.read(0x6064) == 50_000 and d.read(0x60F4) == 0 and d.statusword & B10
    assert d.sm.state is State.OPERATION_ENABLED
    assert not any("stands" in e.text for e in d.log)


def test_a_halted_stall_is_supervised_again():
    """Halt (bit 8) during the -17 stall abandons the homing with the demand
    past the end; the following error is then supervised as in any mode:
    6065h = 1000, 6066h = 0 fault the drive while 609Ah ramps the demand down."""
    d = enabled(KINCO, plant_from(0), 6)
    for (index, sub), value in {(0x6098, 0): -17, (0x6099, 1): V, (0x6099, 2): 2000,
                                (0x609A, 0): ACC, (0x6065, 0): 10_000}.items():
        d.write(index, sub, value)             # the stall criterion is 0.5 s away
    d.write(0x6040, 0, 0x1F)
    d.advance(660_000)
    assert d.read(0x60F4) == -200 and d.sm.state is State.OPERATION_ENABLED
    d.write(0x6065, 0, 1000)                   # the running stall ignores it
    d.advance(670_000)
    assert d.read(0x60F4) == -400 and d.sm.state is State.OPERATION_ENABLED
    d.write(0x6040, 0, 0x11F)                  # halt: homing abandoned, 609Ah ramp of 1000
    d.advance(800_000)
    assert d.read(0x603F) == 0x8611 and d.read(0x6064) == NS
    assert not any("home at" in e.text for e in d.log)
