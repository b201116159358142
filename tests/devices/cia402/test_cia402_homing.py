"""CiA 402 homing (HM): every method of the HCFA and Kinco models by geometry.

Expected home points are computed here from the geometry table of
shared/reference/homing-and-motion.md §1.2 (edge, side of the index pulse),
with a step-by-step index search of its own, never from the implementation.
"""

from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import assume, given, settings, strategies as st

from plcrt.devices.cia402.homing import (
    Done, Failed, HomingParams, HomingSequence, Phase, homing_status, power_on_homing, run)
from plcrt.devices.cia402.homing_methods import METHODS, HomingPlant, method_table
from plcrt.errors import PlcError

NL, PL, LO, HI = -10000, 10000, 1000, 3000
PERIOD, PHASE = 500, 130
PLANT = HomingPlant(NL, PL, (LO, HI), PERIOD, PHASE, -12000, 12000)
V_HIGH, V_LOW, ACC = 20000, 2000, 200000

HCFA, KINCO = "hcfa-am0520b", "kinco-servo"
SWITCH_METHODS = [*range(1, 15), *range(17, 31)]


def ref_point(n: int, nl: int, pl: int, lo: int, hi: int) -> tuple[int, int]:
    """(reference position, final direction) from the §1.2 table: the first
    position past the defining edge in the final approach direction."""
    table = {1: (nl + 1, +1), 2: (pl - 1, -1),
             3: (lo - 1, -1), 4: (lo, +1), 5: (hi + 1, +1), 6: (hi, -1),
             7: (lo - 1, -1), 8: (lo, +1), 9: (hi, -1), 10: (hi + 1, +1),
             11: (hi + 1, +1), 12: (hi, -1), 13: (lo, +1), 14: (lo - 1, -1)}
    return table[n if n < 15 else n - 16]


def first_index(pos: int, d: int, period: int, phase: int) -> int:
    """Walk position by position to the first index pulse at or beyond pos."""
    while (pos - phase) % period:
        pos += d
    return pos


def expected_home(n: int, plant: HomingPlant = PLANT, blind: int = 0) -> int:
    assert plant.home_switch is not None and plant.index_period is not None
    r, d = ref_point(n, plant.neg_limit, plant.pos_limit, *plant.home_switch)
    if n > 16:
        return r
    return first_index(r + d * blind, d, plant.index_period, plant.index_phase)


def params(n: int, **kw) -> HomingParams:
    base = dict(v_search=V_HIGH, v_zero=V_LOW, accel=ACC)
    base.update(kw)
    return HomingParams(n, **base)


def home(model: str, n: int, start: int, plant: HomingPlant = PLANT, **kw):
    return run(HomingSequence(model, params(n, **kw), plant), 0, start)


def allowed_at_start(n: int, x: int) -> bool:
    """§7.5.4 (HCFA) and its extension: a limit active at the start is a
    homing error unless the method uses it (1/17 NLS, 2/18 PLS) or it
    reverses the method's search (7-10/23-26 PLS, 11-14/27-30 NLS)."""
    b = n if n < 15 else n - 16
    if x <= NL:
        return b in (1, 11, 12, 13, 14)
    if x >= PL:
        return b in (2, 7, 8, 9, 10)
    return True


# -- every method from every start ------------------------------------------------------------
STARTS = {"on NLS": NL, "left of the home switch": -5000, "inside the home switch": 2000,
          "right of the home switch": 6000, "on PLS": PL}


@pytest.mark.parametrize("model", [HCFA, KINCO])
@pytest.mark.parametrize("n", SWITCH_METHODS)
@pytest.mark.parametrize("where", list(STARTS))
def test_switch_method_homes_on_the_geometry_table_point(model, n, where):
    """Each switch method ends on its §1.2 home point from every start, and
    an active limit the method does not use at the start is a homing error."""
    x = STARTS[where]
    result, phases = home(model, n, x)
    if not allowed_at_start(n, x):
        assert isinstance(result, Failed)
        assert "limit" in result.explanation and f"method {n}" in result.explanation
        assert not phases
        return
    assert isinstance(result, Done), result
    assert result.home_point == expected_home(n)
    assert result.position == result.home_point     # stops at the home event
    assert result.position + result.position_shift == 0


@pytest.mark.parametrize("model", [HCFA, KINCO])
@pytest.mark.parametrize("n,start", [(n, 6000) for n in (7, 8, 9, 10, 23, 24, 25, 26)]
                         + [(n, -5000) for n in (11, 12, 13, 14, 27, 28, 29, 30)])
def test_zone_method_reverses_once_at_its_limit(model, n, start):
    """With the home switch behind the start, the search runs into the limit
    in its direction, stops there and searches back at 6099h:01 (path B)."""
    result, phases = home(model, n, start)
    m = method_table(model)[n]
    assert isinstance(result, Done)
    assert phases[0].name == phases[1].name == "search"
    assert phases[0].direction == m.search and phases[1].direction == -m.search
    limit = PL if m.search > 0 else NL
    assert phases[1].x0 == limit
    assert phases[1].speed_at(phases[1].t0) == 0


@pytest.mark.parametrize("model", [HCFA, KINCO])
@pytest.mark.parametrize("n,d", [(33, -1), (34, +1)])
@pytest.mark.parametrize("start", [-5000, 6000, -370, -369])
def test_index_only_methods_find_the_next_index(model, n, d, start):
    """33/34: the next index strictly beyond the start (a start on an index
    moves one period)."""
    result, phases = home(model, n, start)
    assert isinstance(result, Done)
    assert result.home_point == first_index(start + d, d, PERIOD, PHASE)
    assert [p.name for p in phases] == ["final"]
    assert phases[0].speed_at(0) == V_LOW


def test_hcfa_index_method_running_into_the_home_switch_is_an_error():
    """§7.5.4: the home switch active in 33/34 is a homing error (HCFA)."""
    result, _ = home(HCFA, 34, 900)
    assert isinstance(result, Failed)
    assert "home switch" in result.explanation and "§7.5.4" in result.explanation
    ok, _ = home(KINCO, 34, 900)
    assert isinstance(ok, Done) and ok.home_point == 1130


def test_hcfa_index_method_started_on_the_home_switch_fails():
    result, _ = home(HCFA, 33, 2000)
    assert isinstance(result, Failed) and "active at the start" in result.explanation


# -- paths of HCFA §10.1 ------------------------------------------------------------
@pytest.mark.parametrize("n,start,names", [
    (1, -5000, ["search", "decelerate", "final"]),   # 1A
    (1, NL, ["final"]),                                # 1B: slow from the limit
    (4, -5000, ["final"]),                             # 4B: slow, straight on
    (4, 2000, ["leave", "decelerate", "final"]),       # 4A: leaves at high speed
    (8, -5000, ["search", "decelerate", "back", "final"]),   # 8A
    (8, 2000, ["back", "final"]),                      # 8C
    (9, -5000, ["search", "pass", "final"]),           # 9A
    (10, -5000, ["search", "final"]),                  # 10A
    (12, 6000, ["search", "decelerate", "back", "final"]),   # 12A
    (13, 6000, ["search", "pass", "final"]),           # 13A
    (7, 6000, ["search", "search", "final"]),          # 7B: PLS, back fast, slow on the edge
    (9, 6000, ["search", "search", "decelerate", "back", "final"]),   # 9B
    (11, -5000, ["search", "search", "final"]),        # 11B
    (14, 2000, ["final"]),                             # 14C: slow out through lo
])
def test_hcfa_paths_follow_section_10_1(n, start, names):
    result, phases = home(HCFA, n, start)
    assert isinstance(result, Done)
    assert [p.name for p in phases] == names
    for p in phases:
        if p.name in ("back", "final", "pass") and p.speed_at(p.t0) <= V_LOW:
            assert p.segs[-1].v1 == V_LOW        # the approach runs at 6099h:02
        if p.name in ("search", "leave"):
            assert p.segs[-1].v1 == V_HIGH       # the search at 6099h:01


def test_kinco_method_12_latches_the_edge_in_the_search():
    """Kinco §2.5 method 12 from the positive side: the edge is met moving
    -, then the index follows at once; HCFA re-approaches at 6099h:02."""
    k, kp = home(KINCO, 12, 6000)
    h, hp = home(HCFA, 12, 6000)
    assert k.home_point == h.home_point == expected_home(12)
    assert [p.name for p in kp] == ["search", "final"]
    assert kp[1].speed_at(kp[1].t0) == V_HIGH    # latched at search speed
    assert len(hp) == 4


def test_kinco_method_25_stops_at_the_edge_after_the_limit():
    """Kinco §2.5 method 25 from the positive side: PLS, reverse, stop on
    entering the switch (its right edge)."""
    result, phases = home(KINCO, 25, 6000)
    assert result.home_point == HI
    assert [p.name for p in phases] == ["search", "search"]


def test_deceleration_is_exact():
    """Method 1A: the search decelerates with 609Ah from 6099h:01; the stop
    lies v^2 / 2a past the NLS and the approach restarts there."""
    _, phases = home(HCFA, 1, -5000)
    dec = phases[1]
    assert dec.x0 == NL
    overshoot = Fraction(V_HIGH ** 2, 2 * ACC)
    assert phases[2].x0 == NL - int(overshoot)
    assert dec.end_time() - dec.t0 == pytest.approx(V_HIGH / ACC * 1e6, abs=1)


def test_phase_events_are_exact_to_the_microsecond():
    """At the reported event time the axis is at the watched position; one
    µs earlier it is not yet."""
    seq = HomingSequence(HCFA, params(34), PLANT)
    ph = seq.start(0, 0)
    t, x, event = ph.first_event()
    assert (x, event) == (130, "home")
    assert ph.position_at(t) == 130 and ph.position_at(t - 1) == 129
    assert t == 130 * 1_000_000 // V_LOW


# -- offsets (digest §4.4) ------------------------------------------------------------
@pytest.mark.parametrize("offset", [1234, -1234])
def test_hcfa_offset_is_the_position_at_the_home_point(offset):
    """HCFA: 6064h reads +607Ch at the home point; no offset move."""
    result, _ = home(HCFA, 10, -5000, offset=offset)
    assert result.position == result.home_point == expected_home(10)
    assert result.home_point + result.position_shift == offset


@pytest.mark.parametrize("offset", [1234, -1234])
def test_kinco_offset_mode_1_sets_minus_offset(offset):
    """Kinco 6099h:05 = 1: stay at the home event, 6064h = -607Ch there."""
    result, phases = home(KINCO, 10, -5000, offset=offset, offset_mode=1)
    assert result.position == result.home_point
    assert result.home_point + result.position_shift == -offset
    assert phases[-1].name == "final"


@pytest.mark.parametrize("offset", [1234, -1234])
def test_kinco_offset_mode_0_moves_the_offset_then_zeroes(offset):
    """Kinco 6099h:05 = 0: move 607Ch on from the home event, then 6064h = 0;
    the home event therefore reads -607Ch."""
    result, phases = home(KINCO, 10, -5000, offset=offset, offset_mode=0)
    assert result.home_point == expected_home(10)
    assert result.position == result.home_point + offset
    assert result.position + result.position_shift == 0
    assert result.home_point + result.position_shift == -offset
    assert phases[-1].name == "offset" and phases[-1].direction == (1 if offset > 0 else -1)


# -- index blind zone (Kinco §2.4) ------------------------------------------------------------
@pytest.mark.parametrize("blind,expected", [(0, 3201), (1, 3201), (2, 3701)])
def test_kinco_blind_zone_ignores_index_pulses_near_the_edge(blind, expected):
    """Method 11 (right edge, approach +, reference 3001); the index lies 200
    counts past it: inside a 1/2-rev (250) blind zone, outside a 1/4-rev
    (125) one."""
    plant = HomingPlant(NL, PL, (LO, HI), PERIOD, 3201)
    result, _ = home(KINCO, 11, 6000, plant, blind_zone=blind)
    assert result.home_point == expected
    assert expected == expected_home(11, plant, blind=PERIOD * blind // 4)


@pytest.mark.parametrize("kw,what", [({"blind_zone": 3}, "6099h:06 = 3"),
                                     ({"offset_mode": 2}, "6099h:05 = 2")])
def test_kinco_refuses_bad_homing_settings(kw, what):
    result, _ = home(KINCO, 11, 6000, **kw)
    assert isinstance(result, Failed) and what in result.explanation


def test_protocol_misuse_is_a_plc_error():
    seq = HomingSequence(HCFA, params(7), PLANT)
    seq.start(0, -5000)
    with pytest.raises(PlcError, match="not expected"):
        seq.on_event(10, -4000, "stall")


def test_hcfa_has_no_blind_zone():
    plant = HomingPlant(NL, PL, (LO, HI), PERIOD, 3201)
    result, _ = home(HCFA, 11, 6000, plant, blind_zone=2)
    assert result.home_point == 3201


@pytest.mark.parametrize("model", [HCFA, KINCO])
def test_index_on_the_edge_counts(model):
    """An index at the reference crossing itself is the home point; one on
    the other side of the edge is not (method 8: crossing at lo)."""
    on, _ = home(model, 8, -5000, HomingPlant(NL, PL, (LO, HI), PERIOD, LO))
    assert on.home_point == LO
    off, _ = home(model, 7, -5000, HomingPlant(NL, PL, (LO, HI), PERIOD, LO))
    assert off.home_point == LO - PERIOD


# -- hard stop (Kinco §2.5) ------------------------------------------------------------
def stall_times(start: int, stop: int) -> tuple[int, int]:
    """(time the axis reaches the stop, ramp end) from the profile."""
    t_ramp = Fraction(V_HIGH, ACC) * 10**6
    d_ramp = Fraction(V_HIGH ** 2, 2 * ACC)
    return int(t_ramp + (abs(stop - start) - d_ramp) / V_HIGH * 10**6), int(t_ramp)


@pytest.mark.parametrize("n,stop", [(-17, -12000), (-18, 12000)])
@pytest.mark.parametrize("crit,delay", [("following_error_window", 5000),
                                        ("max_current", 0), ("velocity_window", 0)])
def test_kinco_hard_stop_homes_on_the_mechanical_end(n, stop, crit, delay):
    """-17/-18: the first armed criterion zeroes the position at the stop;
    following error 100 counts at 20000 counts/s takes 5 ms more."""
    result, phases = home(KINCO, n, 0, **{crit: 100})
    t_stop, _ = stall_times(0, stop)
    assert isinstance(result, Done)
    assert result.home_point == result.position == stop
    assert result.position + result.position_shift == 0
    assert phases[-1].name == "stall" and phases[-1].t0 == t_stop
    assert result.t == t_stop + delay


def test_kinco_velocity_window_is_armed_after_the_ramp():
    """A stop reached during the acceleration ramp is detected by the
    velocity window only when the ramp would end (digest §4.4)."""
    plant = HomingPlant(neg_stop=-400)
    result, _ = home(KINCO, -17, 0, plant, velocity_window=10)
    assert result.home_point == -400
    assert result.t == V_HIGH * 10**6 // ACC


def test_kinco_hard_stop_without_criterion_fails():
    result, _ = home(KINCO, -17, 0)
    assert isinstance(result, Failed) and "6065h" in result.explanation


def test_kinco_offset_into_the_mechanical_end_fails():
    result, _ = home(KINCO, -17, 0, max_current=1, offset=-10)
    assert isinstance(result, Failed) and "mechanical end" in result.explanation


def test_kinco_hard_stop_moves_off_by_a_positive_offset():
    result, _ = home(KINCO, -17, 0, max_current=1, offset=300)
    assert result.position == -12000 + 300 and result.position + result.position_shift == 0


@pytest.mark.parametrize("n,start,offset,end", [
    (18, 0, 1, PL), (17, 0, -1, NL),                         # home next to the limit
    (19, -5000, PL - (LO - 1), PL), (19, -5000, NL - (LO - 1), NL),
    (19, -5000, PL - LO, None), (19, -5000, NL - LO + 2, None),   # one count short
])
def test_kinco_offset_move_that_ends_on_a_limit_is_a_homing_error(n, start, offset, end):
    """Kinco 6099h:05 = 0: an offset move that ends where a limit goes active meets
    it, as every phase that does not use the limit: bit 13 at the limit, naming it
    and the offset phase; a move that stops one count short homes there."""
    result, phases = home(KINCO, n, start, offset=offset, offset_mode=0)
    assert phases[-1].name == "offset"
    if end is None:
        assert isinstance(result, Done) and result.position == result.home_point + offset
        return
    which = "positive limit (PLS)" if end == PL else "negative limit (NLS)"
    assert isinstance(result, Failed) and result.position == end
    assert f"{which} active at {end} in the offset phase" in result.explanation


@pytest.mark.parametrize("start,offset,fails", [
    (PL, 250, True), (PL + 5, 1, True), (NL, -250, True),    # further into the active limit
    (PL, -250, False), (NL - 5, 250, False),                 # off it
])
def test_kinco_offset_move_from_an_active_limit(start, offset, fails):
    """Kinco 35 started on a limit, 6099h:05 = 0: an offset move further into the
    active limit is a homing error at once (the limit is active all the way); one
    that leaves the limit homes."""
    result, phases = home(KINCO, 35, start, offset=offset, offset_mode=0)
    if fails:
        assert isinstance(result, Failed) and phases == [] and result.position == start
        assert "in the offset phase" in result.explanation
    else:
        assert isinstance(result, Done) and result.position == start + offset


def test_on_a_limit_without_an_offset_move_35_homes():
    """35 moves nothing with HCFA's rule or Kinco offset mode 1: a start on a limit
    homes there."""
    for model, mode in ((HCFA, 0), (KINCO, 1)):
        result, phases = home(model, 35, PL, offset=250, offset_mode=mode)
        assert isinstance(result, Done) and phases == [] and result.position == PL


# -- methods 35 / 37 and the method tables ------------------------------------------------------------
def test_kinco_35_zeroes_here_without_motion():
    result, phases = home(KINCO, 35, 777)
    assert phases == [] and result.position == 777 and result.position_shift == -777


def test_supported_methods_per_model():
    assert sorted(METHODS[HCFA]) == [*range(1, 15), *range(17, 31), 33, 34, 35, 37]
    assert sorted(METHODS[KINCO]) == [-18, -17, *range(1, 15), *range(17, 31), 33, 34, 35]
    with pytest.raises(PlcError, match="unknown drive model"):
        method_table("nope")


@pytest.mark.parametrize("model,n,alarm", [(HCFA, 15, 62), (HCFA, 36, 62), (HCFA, -17, 62),
                                           (KINCO, 37, None), (KINCO, 15, None)])
def test_unsupported_method_fails_with_the_alarm(model, n, alarm):
    result, _ = home(model, n, 0)
    assert isinstance(result, Failed) and result.alarm == alarm
    assert f"6098h = {n}" in result.explanation


# -- failures with their explanations ------------------------------------------------------------
def test_index_method_without_index_pulses_fails():
    result, _ = home(HCFA, 7, 0, HomingPlant(NL, PL, (LO, HI)))
    assert isinstance(result, Failed) and result.alarm == 62
    assert "index_period" in result.explanation and "method 7" in result.explanation
    assert "§2.2" in result.explanation


def test_switch_method_without_home_switch_fails():
    result, _ = home(KINCO, 23, 0, HomingPlant(NL, PL))
    assert isinstance(result, Failed) and "home_switch" in result.explanation


def test_zero_speed_is_refused():
    result, _ = home(HCFA, 1, 0, v_zero=0)
    assert isinstance(result, Failed) and "bit 14" in result.explanation


def test_limit_during_deceleration_is_a_homing_error():
    """Method 7 with PLS 800 counts past the switch edge: slowing down from
    6099h:01 needs 1000 counts, so the axis reaches PLS after the edge."""
    plant = HomingPlant(NL, 7800, (7000, 7500), PERIOD, PHASE)
    result, _ = home(HCFA, 7, 0, plant)
    assert isinstance(result, Failed)
    assert "positive limit (PLS) active at 7800 in the decelerate phase" in result.explanation


def test_both_limits_is_a_homing_error():
    """The home switch lies outside the travel: PLS reverses, NLS ends it."""
    plant = HomingPlant(NL, PL, (20000, 21000), PERIOD, PHASE)
    result, phases = home(HCFA, 7, 0, plant)
    assert isinstance(result, Failed) and "both limits" in result.explanation
    assert [p.name for p in phases] == ["search", "search"]


def test_index_beyond_the_limit_fails_in_the_final_phase():
    plant = HomingPlant(NL, PL, (LO, HI), 30000, 15000)
    result, _ = home(HCFA, 10, 0, plant)
    assert isinstance(result, Failed)
    assert "PLS" in result.explanation and "final phase" in result.explanation


def test_hcfa_timeout_is_alarm_63():
    """P03.07 = 100 ms: method 1 from far away takes longer."""
    result, _ = home(HCFA, 1, 5000, timeout_ms=100)
    assert isinstance(result, Failed) and result.alarm == 63 and result.t == 100_000
    assert "P03.07" in result.explanation


def test_kinco_has_no_timeout():
    result, _ = home(KINCO, 1, 5000, timeout_ms=100)
    assert isinstance(result, Done)


def test_search_without_switch_or_limit_ahead_fails():
    plant = HomingPlant(None, None, (LO, HI), PERIOD, PHASE)
    result, _ = home(HCFA, 7, 6000, plant)
    assert isinstance(result, Failed) and "not ahead" in result.explanation


def test_bad_plant_is_refused():
    with pytest.raises(PlcError, match="lo > hi"):
        HomingPlant(home_switch=(5, 1))
    with pytest.raises(PlcError, match="index_period"):
        HomingPlant(index_period=0)


# -- statusword, power-on homing -----------------------------------------------------------------------
def test_statusword_bits_per_model():
    """HCFA §7.3 HM words: idle 0x8737 (bit 15 can trigger), running 0x0237,
    done 0x1637, error 0x2637; Kinco bit 15 = reference found (§2.6)."""
    assert homing_status(HCFA, "idle", False) == 0x8400
    assert homing_status(HCFA, "running", True) == 0x0000
    assert homing_status(HCFA, "done", True) == 0x1400
    assert homing_status(HCFA, "failed", False) == 0x2400
    assert homing_status(KINCO, "done", True) == 0x9400
    assert homing_status(KINCO, "idle", True) == 0x8400
    assert homing_status(KINCO, "idle", False) == 0x0400


def test_power_on_homing_setting():
    assert [power_on_homing(v) for v in (0, 1, 2)] == ["off", "home", "restore"]
    with pytest.raises(PlcError, match="6099h:03"):
        power_on_homing(3)


# -- properties ------------------------------------------------------------
@st.composite
def geometry(draw):
    nl = draw(st.integers(-40000, -5000))
    lo = draw(st.integers(nl + 3000, 20000))
    hi = draw(st.integers(lo, lo + 8000))
    pl = draw(st.integers(hi + 3000, hi + 40000))
    period = draw(st.integers(20, 2000))
    phase = draw(st.integers(0, period - 1))
    start = draw(st.integers(nl + 1, pl - 1))
    return HomingPlant(nl, pl, (lo, hi), period, phase), start


SPEEDS = st.tuples(st.integers(5000, 30000), st.integers(100, 4000))


@settings(max_examples=300, deadline=None)
@given(geometry(), st.sampled_from([HCFA, KINCO]), st.sampled_from(SWITCH_METHODS),
       SPEEDS, SPEEDS, st.integers(-5000, 5000))
def test_home_is_the_defined_point_and_no_limit_is_passed(geo, model, n, sp1, sp2, offset):
    """Whatever the geometry, start and speeds: the home point is the table's,
    6064h there is the model's offset, no phase goes beyond a limit except
    into the one the method homes on, and speeds do not change the result."""
    plant, start = geo
    lo, hi = plant.home_switch
    ref, d = ref_point(n, plant.neg_limit, plant.pos_limit, lo, hi)
    exp = expected_home(n, plant)
    assume(plant.neg_limit + 1 < exp < plant.pos_limit - 1)
    results = []
    for vh, vl in (sp1, sp2):
        acc = vh * vh // 1000   # slowing down from 6099h:01 takes 500 counts
        seq = HomingSequence(model, HomingParams(n, vh, vl, acc, offset, offset_mode=1), plant)
        result, phases = run(seq, 0, start)
        assert isinstance(result, Done), result
        assert result.home_point == exp
        shown = result.home_point + result.position_shift
        assert shown == (offset if model == HCFA else -offset)
        b = n if n < 15 else n - 16
        for ph in phases:
            t_end, x_end, _ = ph.first_event() if ph.segs else (0, ph.x0, "")
            for x in (ph.x0, x_end):
                if b != 1:
                    assert x > plant.neg_limit or (x == plant.neg_limit and b in (11, 12, 13, 14))
                if b != 2:
                    assert x < plant.pos_limit or (x == plant.pos_limit and b in (7, 8, 9, 10))
        results.append(result.home_point)
    assert results[0] == results[1]


@settings(max_examples=100, deadline=None)
@given(st.integers(-20000, 20000), st.integers(20, 3000), st.integers(0, 2999),
       st.sampled_from([33, 34]), st.sampled_from([HCFA, KINCO]))
def test_index_only_property(start, period, phase, n, model):
    phase %= period
    plant = HomingPlant(index_period=period, index_phase=phase)
    d = -1 if n == 33 else 1
    result, _ = run(HomingSequence(model, params(n), plant), 0, start)
    assert result.home_point == first_index(start + d, d, period, phase)
    assert 0 < (result.home_point - start) * d <= period


def test_phase_protocol_shapes():
    """A Phase exposes what the drive needs: start, direction, segments,
    watches and the speed/position at any time."""
    seq = HomingSequence(HCFA, params(7), PLANT)
    ph = seq.start(0, -5000)
    assert isinstance(ph, Phase) and ph.direction == 1 and ph.x0 == -5000
    assert {w.event for w in ph.watches} == {"entry", "limit"}
    assert ph.speed_at(0) == 0 and ph.speed_at(10**6) == V_HIGH
    seq.abort(5)
    assert seq.state == "aborted"
