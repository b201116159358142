"""HOMING (EM253 user manual 3.2.7, appendix 1): where each mode ends, and
how the block behaves around it.

Expected home positions are computed here from the appendix's geometry
(which switch edge, which side of it the Z lies on), independently of
plcrt/devices/em253/homing.py.  Geometry of the default plant (mechanical
pulses): the reference switch RPS is active over [LO, HI]; a Z pulse every
PERIOD pulses at ZOFF + k * PERIOD; L- active at and below LNEG, L+ at and
above LPOS.  Positions are chosen so that each run simulates only a second
or two; the engine is event-driven, so the result is exact at any scan time.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.devices.em253.axis import Axis

LO, HI = 4000, 6999          #: RPS active in [LO, HI]
PERIOD, ZOFF = 1000, 250     #: Z at ..., 3250, 4250, ..., 7250, ...
LNEG, LPOS = -8000, 16000    #: hard limits
V_LOW, V_HIGH = 10_000, 40_000
AXIS1_START = 777

PROGRAM = """ORGANIZATION_BLOCK MAIN:OB1
TITLE=HOMING test rig: axis 0 of the EM253 in slot 0
BEGIN
Network 1 // Enable the module's motion instructions (every scan, first)
LD     SM0.0
CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0
Network 2 // HomingMode VW220, SpdLow VD224, SpdHigh VD228, PosOffset VD232
LD     SM0.0
CALL   HOMING, 0, 0, VW220, VD224, VD228, VD232, VD200, M5.1, M5.0, VW210, VD212
END_ORGANIZATION_BLOCK
"""

# Where appendix 1 puts the home Z of modes 1, 2 and 7-14: the RPS edge it is
# referred to and the side of that edge ("采...左边沿以左的 Z 相信号" = left of
# the left edge).  Modes 1/2 leave the switch to the right/left and take the
# next Z.  Mode 9 follows the appendix text (right edge, left of it), not
# its heading.
Z_SIDE = {
    1: ("right", "right"), 2: ("left", "left"),
    7: ("left", "left"), 8: ("left", "right"), 9: ("right", "left"), 10: ("right", "right"),
    11: ("right", "right"), 12: ("right", "left"), 13: ("left", "right"), 14: ("left", "left"),
}

#: First move direction when starting outside the switch: toward the limit
#: switch the mode uses (modes 7-10: L+, 11-14: L-), modes 1/3/5 negative.
SEARCH_DIR = {1: -1, 2: +1, 3: -1, 4: +1, 5: -1, 6: +1, 7: +1, 8: +1, 9: +1, 10: +1,
              11: -1, 12: -1, 13: -1, 14: -1}
#: First move direction when starting inside the switch (appendix 1,
#: track 2: "直接往负方向/正方向运动"; modes 1-4: "反转退出原点开关").
INSIDE_DIR = {1: +1, 2: -1, 3: +1, 4: -1, 7: -1, 8: -1, 9: +1, 10: +1,
              11: +1, 12: +1, 13: -1, 14: -1}


def z_list(period: int, zoff: int, a: int, b: int) -> list[int]:
    """Every Z position in [a, b]."""
    first = a + (zoff - a) % period
    return list(range(first, b + 1, period))


def expected_home(mode: int, start: int, lo: int = LO, hi: int = HI,
                  period: int = PERIOD, zoff: int = ZOFF) -> int:
    """Home position from the geometry of appendix 1 (PosOffset 0)."""
    if mode == 0:
        return start                 # no motion
    if mode == 3:
        return hi + 1                # leaving the switch to the right: RPS falls
    if mode == 4:
        return lo - 1                # leaving it to the left
    if mode in (5, 6):
        # the next Z in the direction of travel, strictly beyond the start
        if mode == 5:
            return max(z_list(period, zoff, start - period, start - 1))
        return min(z_list(period, zoff, start + 1, start + period))
    edge, side = Z_SIDE[mode]
    e = lo if edge == "left" else hi
    # the active range is closed: "left of the left edge" begins at lo - 1,
    # "right of the right edge" at hi + 1; the inside sides include the edge
    if side == "right":
        frm = e + 1 if edge == "right" else e
        return min(z_list(period, zoff, frm, frm + period))
    frm = e - 1 if edge == "left" else e
    return max(z_list(period, zoff, frm - period, frm))


@dataclass
class Move:
    """One call of Axis.start (a homing phase begins)."""

    t: int
    at: int           #: mechanical position when the move begins
    direction: int
    vmax: float       #: highest speed of its segments (Hz)
    keep: bool        #: re-plan of a running move (deceleration after the switch)
    axis: int         #: id() of the Axis object


@pytest.fixture
def moves(monkeypatch: pytest.MonkeyPatch) -> list[Move]:
    """Record every move an axis starts, with the speeds it plans."""
    log: list[Move] = []
    orig = Axis.start

    def start(self: Axis, t: int, direction: int, segs: list, on_done: Any = None,
              keep_travel: bool = False) -> None:
        vmax = max((max(s.v0, s.v1) for s in segs), default=0)
        log.append(Move(t, self.mechanical(t), direction, float(vmax), keep_travel, id(self)))
        orig(self, t, direction, segs, on_done, keep_travel)

    monkeypatch.setattr(Axis, "start", start)
    return log


def make(mode: int, start: int, *, v_low: int = V_LOW, v_high: int = V_HIGH,
         offset: int = 0, scan_ms: float = 1, rps: tuple[int, int] | None = (LO, HI),
         z: tuple[int, int] | None = (PERIOD, ZOFF),
         limits: tuple[int, int] = (LNEG, LPOS), events: list | None = None) -> Any:
    """A PLC whose HOMING waits for Run (M5.0); one scan has run."""
    ax0: dict[str, Any] = {"start": start, "limit_neg": limits[0], "limit_pos": limits[1]}
    if rps is not None:
        ax0["rps"] = list(rps)
    if z is not None:
        ax0["z_period"], ax0["z_offset"] = z
    if events:
        ax0["events"] = events
    ax1 = {"start": AXIS1_START, "rps": [100, 200], "limit_neg": -1000, "limit_pos": 1000,
           "z_period": 50}
    plc = plcrt.load(PROGRAM, plant={"module": {"0": {"axis": {"0": ax0, "1": ax1}}}},
                     scan_ms=scan_ms)
    plc.write("VW220", mode)
    plc.write("VD224", v_low)
    plc.write("VD228", v_high)
    plc.write("VD232", offset)
    plc.scan(1)
    return plc


def home(plc: Any, seconds: float = 5.0) -> int:
    """Raise Run and scan until C_Status is 8; returns the scans taken."""
    plc.write("M5.0", 1)
    limit = int(seconds * 1e6) // plc.scan_us
    for n in range(1, limit + 1):
        plc.scan(1)
        if plc.read("VW210") == 8:
            return n
    raise AssertionError(f"homing not done after {seconds} s: {plc.axis(0, 0)}, "
                         f"{[d.message for d in plc.diagnostics]}")


def messages(plc: Any) -> list[str]:
    return [d.message for d in plc.diagnostics]


def assert_homed(plc: Any, mech: int) -> None:
    a = plc.axis(0, 0)
    assert a["status"] == "stopped"
    assert a["mechanical"] == mech
    assert a["position"] == 0
    assert plc.read("VW210") == 8


def assert_not_homed(plc: Any, start: int) -> None:
    """The counter still counts the pulses since power-up (it started at 0)."""
    a = plc.axis(0, 0)
    assert a["status"] == "stopped"
    assert a["position"] == a["mechanical"] - start


# -- the geometry itself ----------------------------------------------------------
def test_expected_home_table() -> None:
    """The test's own geometry for the default plant, written out."""
    table = {0: 1234, 1: 7250, 2: 3250, 3: 7000, 4: 3999, 5: 250, 6: 1250,
             7: 3250, 8: 4250, 9: 6250, 10: 7250, 11: 7250, 12: 6250, 13: 4250, 14: 3250}
    assert {m: expected_home(m, 1234) for m in range(15)} == table


# -- every mode from every kind of start ------------------------------------------------
STARTS = {
    "far_left": -6000,      # left of the switch, far from it
    "left": 2500,
    "lo_minus_1": LO - 1,   # just outside, left
    "on_lo": LO,            # exactly on the left edge (active)
    "inside": 5500,
    "on_hi": HI,            # exactly on the right edge (active)
    "hi_plus_1": HI + 1,    # just outside, right
    "right": 12000,
}


@pytest.mark.parametrize("scan_ms", [1, 10])
@pytest.mark.parametrize("where", list(STARTS))
@pytest.mark.parametrize("mode", range(15))
def test_mode_ends_at_home(mode: int, where: str, scan_ms: int, moves: list[Move]) -> None:
    start = STARTS[where]
    plc = make(mode, start, scan_ms=scan_ms)
    home(plc)
    assert_homed(plc, expected_home(mode, start))
    assert messages(plc) == []
    assert all(m.vmax <= V_HIGH for m in moves), "the homing ran above SpdHigh"
    if mode == 0:
        assert moves == []


@pytest.mark.parametrize("mode", range(1, 15))
def test_result_does_not_depend_on_scan_time(mode: int) -> None:
    """Same home and same final state with 1 ms, 7 ms and 10 ms scans."""
    ends = set()
    for scan_ms in (1, 7, 10):
        plc = make(mode, 12000, scan_ms=scan_ms)
        home(plc)
        a = plc.axis(0, 0)
        ends.add((a["mechanical"], a["position"]))
    assert ends == {(expected_home(mode, 12000), 0)}


# -- search direction, track 2 and reversal at the limit -----------------------------
@pytest.mark.parametrize("mode", range(1, 15))
def test_first_direction_outside_the_switch(mode: int, moves: list[Move]) -> None:
    plc = make(mode, 12000 if SEARCH_DIR[mode] < 0 else 2500, scan_ms=10)
    home(plc)
    assert moves[0].direction == SEARCH_DIR[mode]


@pytest.mark.parametrize("mode", sorted(INSIDE_DIR))
def test_first_direction_inside_the_switch(mode: int, moves: list[Move]) -> None:
    """Appendix 1, track 2: from inside the switch no search is needed."""
    plc = make(mode, 5500, scan_ms=10)
    home(plc)
    assert moves[0].direction == INSIDE_DIR[mode]
    assert all(m.at not in (LNEG, LPOS) for m in moves)


@pytest.mark.parametrize("mode", [1, 2, 3, 4, 7, 8, 9, 10, 11, 12, 13, 14])
def test_search_reverses_at_the_limit(mode: int, moves: list[Move]) -> None:
    """Starting on the far side of the switch (mode 1 left of it, mode 7
    right of it, ...) the search meets the limit first, stops there at once
    and searches back (appendix 1, tracks 1/3)."""
    d = SEARCH_DIR[mode]
    start = 2500 if d < 0 else 12000
    plc = make(mode, start, scan_ms=10)
    home(plc)
    assert_homed(plc, expected_home(mode, start))
    lim = LNEG if d < 0 else LPOS
    rev = [m for m in moves if m.at == lim]
    assert len(rev) == 1 and rev[0].direction == -d and not rev[0].keep


@pytest.mark.parametrize("mode", [1, 2, 3, 4, 7, 8, 9, 10, 11, 12, 13, 14])
def test_no_reversal_from_the_near_side(mode: int, moves: list[Move]) -> None:
    d = SEARCH_DIR[mode]
    start = 12000 if d < 0 else 2500
    plc = make(mode, start, scan_ms=10)
    home(plc)
    assert_homed(plc, expected_home(mode, start))
    assert all(m.at not in (LNEG, LPOS) for m in moves)


@pytest.mark.parametrize("mode", [1, 7, 10, 14])
@pytest.mark.parametrize("start", [LPOS, LPOS + 50, LNEG, LNEG - 50])
def test_start_on_or_beyond_a_limit(mode: int, start: int) -> None:
    """A limit already active in the search direction reverses at once
    (beyond it the position threshold would never be crossed)."""
    plc = make(mode, start, scan_ms=10)
    home(plc)
    assert_homed(plc, expected_home(mode, start))


# -- Z pulses on the switch edges, narrow switches, equal speeds -----------------------
Z_ON_EDGE = {"z_at_lo_minus_1": LO - 1, "z_at_lo": LO, "z_at_hi": HI, "z_at_hi_plus_1": HI + 1}


@pytest.mark.parametrize("start", [2500, 12000])
@pytest.mark.parametrize("zname", list(Z_ON_EDGE))
@pytest.mark.parametrize("mode", [1, 2, 7, 8, 9, 10, 11, 12, 13, 14])
def test_z_pulse_on_a_switch_edge(mode: int, zname: str, start: int) -> None:
    """A Z at the crossing itself is taken; a Z just on the other side of
    the edge is not (the next one is)."""
    zoff = Z_ON_EDGE[zname] % PERIOD
    plc = make(mode, start, z=(PERIOD, zoff), scan_ms=10)
    home(plc)
    assert_homed(plc, expected_home(mode, start, zoff=zoff))


def test_z_on_edge_examples() -> None:
    """Spelled out: Z at LO (inside): mode 8 homes on it, mode 7 one period left."""
    assert expected_home(8, 0, zoff=LO % PERIOD) == LO
    assert expected_home(7, 0, zoff=LO % PERIOD) == LO - PERIOD
    assert expected_home(10, 0, zoff=(HI + 1) % PERIOD) == HI + 1
    assert expected_home(9, 0, zoff=(HI + 1) % PERIOD) == HI + 1 - PERIOD


NARROW = (LO, LO + 9)   # 10 pulses: the deceleration (2500 pulses) overshoots it


@pytest.mark.parametrize("scan_ms", [1, 10])
@pytest.mark.parametrize("start", [-6000, 2500, LO + 5, 12000])
@pytest.mark.parametrize("mode", range(1, 15))
def test_narrow_switch(mode: int, start: int, scan_ms: int, moves: list[Move]) -> None:
    plc = make(mode, start, rps=NARROW, scan_ms=scan_ms)
    home(plc)
    assert_homed(plc, expected_home(mode, start, lo=NARROW[0], hi=NARROW[1]))
    assert messages(plc) == []
    assert all(m.vmax <= V_HIGH for m in moves)


def test_narrow_switch_is_overshot(moves: list[Move]) -> None:
    """Mode 8 from the left: the deceleration after the switch ends right
    of it, so the axis comes back through it at SpdLow."""
    plc = make(8, 2500, rps=NARROW, scan_ms=10)
    home(plc)
    after = [m for m in moves if not m.keep and m.at > NARROW[1]]
    assert after and after[0].direction == -1 and after[0].vmax == V_LOW
    assert_homed(plc, expected_home(8, 2500, lo=NARROW[0], hi=NARROW[1]))


@pytest.mark.parametrize("start", [2500, 5500, 12000])
@pytest.mark.parametrize("mode", range(15))
def test_equal_speeds(mode: int, start: int, moves: list[Move]) -> None:
    """SpdLow == SpdHigh: no ramp, the whole homing at that one speed."""
    plc = make(mode, start, v_low=15_000, v_high=15_000, scan_ms=10)
    home(plc)
    assert_homed(plc, expected_home(mode, start))
    assert all(m.vmax in (0, 15_000) for m in moves)
    assert messages(plc) == []


# -- PosOffset ---------------------------------------------------------------------
@pytest.mark.parametrize("offset", [300, -1700, 8000])
@pytest.mark.parametrize("mode", [0, 1, 4, 6, 7, 9, 12])
def test_pos_offset(mode: int, offset: int, moves: list[Move]) -> None:
    """The axis moves PosOffset pulses (in its sign) past the home point and
    the counter reads 0 there."""
    plc = make(mode, 2500, offset=offset, scan_ms=10)
    home(plc)
    assert_homed(plc, expected_home(mode, 2500) + offset)
    assert all(m.vmax <= V_HIGH for m in moves)
    assert moves[-1].direction == (1 if offset > 0 else -1)
    assert messages(plc) == []


def test_pos_offset_into_a_limit_fails() -> None:
    plc = make(10, 12000, offset=LPOS, scan_ms=10)
    home(plc)
    a = plc.axis(0, 0)
    assert a["mechanical"] == LPOS and a["position"] != 0
    assert any("L+" in m and "failed" in m for m in messages(plc))


# -- status, speed output, Run and E_Stop ----------------------------------------------
def test_status_and_speed_outputs() -> None:
    """C_Status 0 before, 1 while homing, 8 when done; C_Spd shows the
    speed while moving (never above SpdHigh) and 0 once stopped."""
    plc = make(10, -6000, scan_ms=10)
    assert plc.read("VW210") == 0 and plc.read("VD212") == 0
    plc.write("M5.0", 1)
    seen: list[tuple[int, int]] = []
    for _ in range(500):
        plc.scan(1)
        seen.append((plc.read("VW210"), plc.read("VD212")))
        if seen[-1][0] == 8:
            break
    states = [s for s, _ in seen]
    assert states[-1] == 8 and set(states[:-1]) == {1}
    spds = [v for s, v in seen if s == 1]
    assert all(v != 0 and abs(v) <= V_HIGH for v in spds)
    assert max(abs(v) for v in spds) == V_HIGH          # the search reaches SpdHigh
    assert seen[-1][1] == 0
    assert_homed(plc, expected_home(10, -6000))
    plc.scan(3)
    assert plc.read("VW210") == 8 and plc.read("VD212") == 0


def test_mode_0_status_and_restart() -> None:
    """Mode 0 sets the counter to 0 where the axis stands; a new Run edge
    homes again (after the axis was moved by the counter)."""
    plc = make(0, 4321)
    home(plc)
    assert_homed(plc, 4321)
    plc.write("M5.0", 0)
    plc.scan(1)
    home(plc)
    assert_homed(plc, 4321)


def _scan_until(plc: Any, cond: Any, limit: int = 2000) -> None:
    for _ in range(limit):
        plc.scan(1)
        if cond(plc.axis(0, 0)):
            return
    raise AssertionError("condition not reached")


def test_run_0_decelerates_and_stops_without_home() -> None:
    start = -6000
    plc = make(7, start, scan_ms=1)
    plc.write("M5.0", 1)
    _scan_until(plc, lambda a: a["speed"] >= V_HIGH)   # cruising at SpdHigh
    at_stop = plc.axis(0, 0)["mechanical"]
    plc.write("M5.0", 0)
    speeds = []
    while True:
        plc.scan(1)
        a = plc.axis(0, 0)
        if a["status"] == "stopped":
            break
        speeds.append(a["speed"])
        assert plc.read("VW210") == 1          # still running while it decelerates
    assert speeds == sorted(speeds, reverse=True) and len(speeds) > 10
    plc.scan(1)
    assert plc.read("VW210") == 8 and plc.read("VD212") == 0
    assert_not_homed(plc, start)
    # decelerated (from 40 kHz to 10 kHz in 75 ms: 1875 pulses), did not stop dead
    assert plc.axis(0, 0)["mechanical"] - at_stop > 1500
    assert messages(plc) == []
    # a new rising edge of Run homes from where it stopped
    home(plc)
    assert_homed(plc, expected_home(7, start))


def test_run_0_during_final_approach_stops() -> None:
    plc = make(1, 12000, scan_ms=1)
    plc.write("M5.0", 1)
    # the final approach moves right at SpdLow after the deceleration
    _scan_until(plc, lambda a: a["speed"] == V_LOW)
    plc.write("M5.0", 0)
    plc.scan(2)
    assert plc.read("VW210") == 8
    assert_not_homed(plc, 12000)


def test_e_stop_stops_at_once() -> None:
    start = -6000
    plc = make(7, start, scan_ms=1)
    plc.write("M5.0", 1)
    _scan_until(plc, lambda a: a["speed"] >= V_HIGH)
    before = plc.axis(0, 0)["mechanical"]
    plc.write("M5.1", 1)
    plc.scan(1)
    a = plc.axis(0, 0)
    # the block runs at the scan start: the pulses stopped right there
    assert a["status"] == "stopped" and a["mechanical"] == before
    assert plc.read("VW210") == 8
    assert_not_homed(plc, start)
    # releasing E_Stop does not restart: Run needs a new rising edge
    plc.write("M5.1", 0)
    plc.scan(50)
    assert plc.axis(0, 0)["mechanical"] == before
    plc.write("M5.0", 0)
    plc.scan(1)
    home(plc)
    assert_homed(plc, expected_home(7, start))


def test_e_stop_during_deceleration_after_the_switch() -> None:
    """Regression: the deceleration's end must not continue the homing
    when E_Stop cut it short."""
    start = -6000
    plc = make(7, start, scan_ms=1)
    plc.write("M5.0", 1)
    _scan_until(plc, lambda a: a["mechanical"] > LO + 200)    # decelerating in the switch
    assert V_LOW < plc.axis(0, 0)["speed"] < V_HIGH
    plc.write("M5.1", 1)
    plc.scan(1)
    stopped_at = plc.axis(0, 0)["mechanical"]
    plc.write("M5.1", 0)
    plc.scan(300)
    a = plc.axis(0, 0)
    assert a["status"] == "stopped" and a["mechanical"] == stopped_at
    assert plc.read("VW210") == 8
    assert_not_homed(plc, start)


def test_inner_state_written_during_homing() -> None:
    """The program overwrites InnerState while the axis decelerates after
    the switch: the block stops the axis and the homing does not go on."""
    start = -6000
    plc = make(7, start, scan_ms=1)
    plc.write("M5.0", 1)
    _scan_until(plc, lambda a: a["mechanical"] > LO + 200)
    plc.write("VD200", 0)
    plc.scan(1)
    stopped_at = plc.axis(0, 0)["mechanical"]
    plc.scan(300)
    a = plc.axis(0, 0)
    assert a["status"] == "stopped" and a["mechanical"] == stopped_at
    assert plc.read("VW210") == 8
    assert_not_homed(plc, start)
    assert any("InnerState" in m for m in messages(plc))


def _entry_time(mode: int, start: int) -> int:
    """Time (µs) at which the search reaches the switch, from a dry run."""
    log: list[tuple[int, bool]] = []
    orig = Axis.start

    def spy(self: Axis, t: int, d: int, segs: list, on_done: Any = None,
            keep_travel: bool = False) -> None:
        log.append((t, keep_travel))
        orig(self, t, d, segs, on_done, keep_travel)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Axis, "start", spy)
        home(make(mode, start, scan_ms=10))
    return next(t for t, keep in log if keep)


@pytest.mark.parametrize("phase", ["search", "deceleration"])
def test_stf_input_interrupts_homing(phase: str) -> None:
    """The STF terminal stops the pulses (manual 2.1 item 6); the homing
    ends with status 8 and a diagnostic, and no home is set."""
    start = -6000
    t_entry = _entry_time(7, start)
    at = t_entry - 50_000 if phase == "search" else t_entry + 20_000
    plc = make(7, start, scan_ms=1,
               events=[{"at": at / 1e6, "input": "STF", "value": True}])
    home(plc)
    plc.scan(200)
    assert_not_homed(plc, start)
    assert any("interrupted" in m for m in messages(plc))
    assert plc.read("VW210") == 8


def test_no_start_while_stf_is_active() -> None:
    plc = make(1, 12000, events=[{"at": 0, "input": "STF", "value": True}])
    plc.scan(1)
    home(plc)
    assert plc.axis(0, 0)["mechanical"] == 12000
    assert any("STF" in m and "failed" in m for m in messages(plc))


# -- missing signals and unreachable switches --------------------------------------------
@pytest.mark.parametrize("mode,missing,word", [
    (1, "rps", "reference switch"), (3, "rps", "reference switch"),
    (8, "rps", "reference switch"), (13, "rps", "reference switch"),
    (1, "z", "Z pulses"), (5, "z", "Z pulses"), (6, "z", "Z pulses"), (10, "z", "Z pulses"),
])
def test_missing_signal(mode: int, missing: str, word: str) -> None:
    plc = make(mode, 2500, rps=None if missing == "rps" else (LO, HI),
               z=None if missing == "z" else (PERIOD, ZOFF))
    assert home(plc) == 1                       # status 8 at once
    a = plc.axis(0, 0)
    assert a["mechanical"] == 2500 and a["position"] == 0 and a["status"] == "stopped"
    assert any(word in m and f"mode {mode}" in m for m in messages(plc))


@pytest.mark.parametrize("mode,kw", [(3, {"z": None}), (4, {"z": None}), (5, {"rps": None}),
                                     (6, {"rps": None})])
def test_modes_that_need_less(mode: int, kw: dict) -> None:
    """Modes 3/4 need no Z, modes 5/6 no reference switch."""
    plc = make(mode, 2500, scan_ms=10, **kw)
    home(plc)
    assert_homed(plc, expected_home(mode, 2500))
    assert messages(plc) == []


def test_switch_outside_the_travel_fails() -> None:
    """Both limits met during the search: diagnostic, status 8, no home."""
    plc = make(7, 2500, rps=(LPOS + 100, LPOS + 200), scan_ms=10)
    home(plc, seconds=10)
    assert_not_homed(plc, 2500)
    assert plc.axis(0, 0)["mechanical"] == LNEG
    assert any("L-" in m and "failed" in m for m in messages(plc))


def test_no_z_before_the_limit_fails() -> None:
    """Mode 10: the next Z right of the switch lies beyond L+."""
    plc = make(10, 2500, limits=(LNEG, HI + 100), scan_ms=10)
    home(plc)
    assert_not_homed(plc, 2500)
    assert plc.axis(0, 0)["mechanical"] == HI + 100
    assert any("L+" in m and "final" in m for m in messages(plc))


def test_invalid_mode_does_nothing() -> None:
    plc = make(15, 2500)
    plc.write("M5.0", 1)
    plc.scan(5)
    assert plc.read("VW210") == 0 and plc.axis(0, 0)["mechanical"] == 2500
    assert any("HomingMode 15" in m for m in messages(plc))


def test_spd_high_above_output_limit_is_clamped(moves: list[Move]) -> None:
    """Single-ended output: at most 200 kHz (manual 2.1)."""
    plc = make(7, -6000, v_low=20_000, v_high=300_000, scan_ms=10)
    home(plc)
    assert_homed(plc, expected_home(7, -6000))
    assert max(m.vmax for m in moves) == 200_000
    assert any("SpdHigh 300000" in m for m in messages(plc))


# -- repeated homing and the other axis ------------------------------------------------------
@pytest.mark.parametrize("mode", [1, 3, 8, 9, 12])
def test_homing_again_finds_the_same_home(mode: int) -> None:
    """Appendix 1: "模块寻找的设备原点总是唯一的"; homing again from home ends there."""
    plc = make(mode, 12000, scan_ms=10)
    home(plc)
    plc.write("M5.0", 0)
    plc.scan(1)
    home(plc)
    assert_homed(plc, expected_home(mode, 12000))


def test_z_only_mode_from_a_z_moves_one_period() -> None:
    """Mode 6 from a Z: the *next* Z is one period further."""
    plc = make(6, ZOFF + 3 * PERIOD, scan_ms=10)
    home(plc)
    assert_homed(plc, ZOFF + 4 * PERIOD)


def test_axis_1_is_unaffected() -> None:
    plc = make(10, -6000, scan_ms=10)
    plc.write("M5.0", 1)
    for _ in range(1000):
        plc.scan(1)
        b = plc.axis(0, 1)
        assert (b["position"], b["mechanical"], b["speed"], b["status"]) == \
            (0, AXIS1_START, 0, "stopped")
        if plc.read("VW210") == 8:
            break
    assert_homed(plc, expected_home(10, -6000))


def test_literal_call_from_the_brief() -> None:
    """The documented call form with constants (mode 3, 2 kHz / 20 kHz)."""
    text = PROGRAM.replace("VW220, VD224, VD228, VD232", "+3, +2000, +20000, +0")
    plant = {"module": {"0": {"axis": {"0": {"start": 12000, "rps": [LO, HI],
                                             "limit_neg": LNEG, "limit_pos": LPOS}}}}}
    plc = plcrt.load(text, plant=plant, scan_ms=10)
    plc.scan(1)
    home(plc)
    assert_homed(plc, HI + 1)


# -- property: any geometry, any mode -----------------------------------------------------------
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mode=st.integers(1, 14), lo=st.integers(-2000, 10000), width=st.integers(1, 4000),
       period=st.integers(50, 3000), zoff=st.integers(0, 2999),
       start=st.integers(-4000, 12000))
def test_any_geometry(mode: int, lo: int, width: int, period: int, zoff: int,
                      start: int) -> None:
    # the ranges keep every home Z (period <= 3000) and every deceleration
    # overshoot (2500 pulses) inside the limits, so every case must succeed
    hi = min(lo + width - 1, 12000)
    plc = make(mode, start, rps=(lo, hi), z=(period, zoff % period), scan_ms=10)
    home(plc, seconds=10)
    assert_homed(plc, expected_home(mode, start, lo=lo, hi=hi, period=period,
                                    zoff=zoff % period))
    assert messages(plc) == []
