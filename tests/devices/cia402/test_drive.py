"""The simulated drive as a whole: controlwords through the object dictionary and
process data, quick stop and faults with motion, limit switches, the homing hook,
exact time independent of the bus cycle, and cost independent of the speed."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.esm import EsmState
from plcrt.devices.cia402.homing_plan import HomingMotion, HomingRequest, HomingStep, Watch
from plcrt.devices.cia402.plant import DrivePlant
from plcrt.devices.cia402.statemachine import State, state_of_statusword
from plcrt.errors import PlcError

from cia402_drive_helpers import enable


# ---------------------------------------------------------------- enable and process data

def test_enable_sequence_through_controlwords_gives_the_hcfa_statuswords():
    d = Drive()
    assert d.store.get(0x6041) == 0x0250 and d.store.get(0x6061) == 8
    d.write(0x6060, 0, 1)
    seen = []
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
        seen.append(d.read(0x6041))
    assert seen == [0x0631, 0x0633, 0x8637]          # HCFA §7.3 PP column
    assert d.read(0x6061) == 1


def test_enable_operation_from_ready_takes_a_second_cycle_on_hcfa():
    d = Drive()
    d.write(0x6040, 0, 0x06)
    d.write(0x6040, 0, 0x0F)                          # HCFA §7.4.1 footnote 3**
    assert d.sm.state is State.SWITCHED_ON
    d.cycle(1000)
    assert d.sm.state is State.OPERATION_ENABLED


def test_skipping_states_is_refused_and_logged_with_the_section():
    d = Drive()
    d.write(0x6040, 0, 0x0F)
    assert d.sm.state is State.SWITCH_ON_DISABLED
    assert any("no transition from SWITCH ON DISABLED" in e.text and "§7.2" in e.text
               for e in d.log)


def to_op(d: Drive) -> None:
    for s in (EsmState.PREOP, EsmState.SAFEOP, EsmState.OP):
        assert d.request_esm(s).accepted
    assert d.esm.state is EsmState.OP


def rx(d: Drive, cw: int, target: int, extra: int = 0) -> bytes:
    """The default RxPDO 1600h: 6040h, 607Ah, 60B8h (HCFA §8.2, digest §3.4)."""
    return (cw.to_bytes(2, "little") + target.to_bytes(4, "little", signed=True)
            + extra.to_bytes(2, "little"))


def test_csp_through_process_data_images():
    d = Drive()                                       # 6060h = 8 by default
    to_op(d)
    tx = b""
    t = 0
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        t += 1000
        tx = d.cycle(t, rx(d, cw, 0))
    assert d.sm.state is State.OPERATION_ENABLED
    # 1A00h: 6041h, 603Fh, 6064h, 606Ch, 6061h, 60B9h, 60BAh
    assert int.from_bytes(tx[0:2], "little") == 0x1637 and tx[12] == 8
    for k in range(1, 11):
        t += 1000
        tx = d.cycle(t, rx(d, 0x0F, 100 * k))
    t += 1000
    tx = d.cycle(t, rx(d, 0x0F, 1000))
    assert int.from_bytes(tx[4:8], "little", signed=True) == 1000
    assert int.from_bytes(tx[8:12], "little", signed=True) == 0


def test_rxpdo_before_op_is_ignored_and_logged():
    d = Drive()
    d.cycle(1000, rx(d, 0x06, 0))
    assert d.sm.state is State.SWITCH_ON_DISABLED
    assert any("RxPDO ignored" in e.text for e in d.log)


def test_mapping_goes_through_the_dynamic_procedure():
    d = Drive()
    d.request_esm(EsmState.PREOP)
    d.write(0x1C12, 0, 0)
    with pytest.raises(PlcError) as e:
        d.write(0x1600, 1, 0x60410010)                # count not 0 first (step B)
    assert e.value.code == 0x06010003
    d.write(0x1600, 0, 0)
    with pytest.raises(PlcError) as e:
        d.write(0x1600, 1, 0x60410010)                # 6041h is not an RxPDO object
    assert e.value.code == 0x06040041
    d.write(0x1600, 1, 0x60400010)
    d.write(0x1600, 0, 1)
    d.write(0x1C12, 0, 1)
    assert d.read(0x1600, 0) == 1
    assert d.request_esm(EsmState.SAFEOP).accepted
    assert d.pdo.active_rx[0].index == 0x6040 and len(d.pdo.active_rx) == 1


# ---------------------------------------------------------------- quick stop and faults

@pytest.mark.parametrize("option,decel_index,end_state", [
    (1, 0x6084, State.SWITCH_ON_DISABLED), (2, 0x6085, State.SWITCH_ON_DISABLED),
    (5, 0x6084, State.QUICK_STOP_ACTIVE), (6, 0x6085, State.QUICK_STOP_ACTIVE)])
def test_quick_stop_ramps_on_the_605ah_deceleration(option, decel_index, end_state):
    d = enable(Drive(), 3, x6083=100_000, x6084=100_000, x6085=200_000, x605A=option)
    d.write(0x60FF, 0, 20_000)
    d.advance(1_000_000)                              # at 20 000 P/s
    d.write(0x6040, 0, 0x02)
    assert d.sm.state is State.QUICK_STOP_ACTIVE and d.statusword == 0x0217
    stop_us = 20_000 * 1_000_000 // (100_000 if decel_index == 0x6084 else 200_000)
    d.advance(1_000_000 + stop_us - 1)
    assert d.sm.state is State.QUICK_STOP_ACTIVE and d.moving
    d.advance(1_000_000 + stop_us)
    assert not d.moving and d.sm.state is end_state
    if end_state is State.QUICK_STOP_ACTIVE:
        assert d.statusword == 0x0617                 # at rest, bit 10
        d.write(0x6040, 0, 0x0F)                      # transition 16
        assert d.sm.state is State.OPERATION_ENABLED
    else:
        assert d.statusword & 0x4F == 0x40


def test_quick_stop_option_0_disables_at_once():
    d = enable(Drive(), 3, x6083=100_000, x6084=100_000, x605A=0)
    d.write(0x60FF, 0, 20_000)
    d.advance(500_000)
    held = d.position
    d.write(0x6040, 0, 0x02)
    assert d.sm.state is State.SWITCH_ON_DISABLED and not d.moving
    d.advance(600_000)
    assert d.position == held


def test_fault_reset_after_a_following_error_and_enable_again():
    d = enable(Drive(), 8, x6065=10, x6066=0, x6080=1000)
    d.cycle(0)
    d.write(0x607A, 0, 500)
    d.cycle(1000)
    d.cycle(2000)
    assert d.sm.state is State.FAULT_REACTION_ACTIVE and d.read(0x603F) == 0x8611
    d.cycle(3000)
    d.write(0x6040, 0, 0x8F)                          # bit 7 rises: transition 15
    assert d.sm.state is State.SWITCH_ON_DISABLED and d.read(0x603F) == 0
    d.write(0x607A, 0, d.position)
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
    d.cycle(4000)
    assert d.sm.state is State.OPERATION_ENABLED and d.statusword == 0x1637


# ---------------------------------------------------------------- limit switches

def test_limit_switch_stops_pv_at_the_exact_count_and_allows_motion_away():
    plant = DrivePlant(neg_limit=-5000, pos_limit=5000)
    d = enable(Drive(plant=plant), 3, x6083=100_000, x6084=100_000, x6085=0)
    d.write(0x60FF, 0, 10_000)                        # 0.1 s ramp (500 P), then 10 P/ms
    d.advance(2_000_000)
    assert d.position == 5000 and not d.moving        # 6085h = 0: at once, on the switch
    assert d.statusword & 0x0900 == 0x0900            # bits 11 (limit) and 8 (abnormal stop)
    assert d.read(0x60FD) == 0x2
    assert any("positive limit switch" in e.text for e in d.log)
    d.write(0x60FF, 0, 20_000)                        # still toward PLS: nothing
    d.advance(2_100_000)
    assert d.position == 5000
    d.write(0x60FF, 0, -10_000)
    d.advance(2_500_000)
    assert d.position < 5000 and not d.statusword & 0x0800 and d.read(0x60FD) == 0


def test_limit_switch_time_is_exact_with_a_ramp_beyond_it():
    plant = DrivePlant(pos_limit=5000)
    d = enable(Drive(plant=plant), 3, x6083=100_000, x6084=100_000, x6085=1_000_000)
    d.write(0x60FF, 0, 10_000)
    d.advance(3_000_000)
    # reached at 0.1 s + 4500 / 10 000 s = 550 ms; stops 10 000² / 2e6 = 50 P beyond
    assert d.position == 5050
    ev = [e for e in d.log if "limit switch" in e.text][0]
    assert ev.t_us == 550_000


def test_pp_set_point_beyond_an_active_limit_is_refused():
    d = Drive(plant=DrivePlant(pos_limit=-100))       # the axis starts on PLS
    enable(d, 1, x6081=1000, x6083=1000, x6084=1000)
    d.write(0x607A, 0, 500)
    d.write(0x6040, 0, 0x1F)
    assert any("refused" in e.text and "PLS" in e.text for e in d.log)
    d.write(0x6040, 0, 0x0F)
    d.write(0x607A, 0, -500)
    d.write(0x6040, 0, 0x1F)
    d.advance(10_000_000)
    assert d.position == -500


# ---------------------------------------------------------------- homing hook

def test_homing_method_35_makes_the_current_position_607ch():
    d = enable(Drive(), 6, x607C=1234, x6098=35)
    assert d.statusword == 0x8737                     # HCFA §7.3 HM idle
    d.write(0x6040, 0, 0x1F)
    assert d.statusword == 0x1637 and d.position == 1234   # attained: bits 12 and 10


def test_homing_an_unsimulated_method_raises_alarm_62():
    d = enable(Drive(homing={}), 6, x6098=1)
    d.write(0x6040, 0, 0x1F)
    assert d.sm.state is State.FAULT_REACTION_ACTIVE and d.read(0x603F) == 62


class SwitchPlan:
    """Run + at the fast speed to the home switch's low edge, stop, home there."""

    def start(self, r: HomingRequest) -> HomingStep:
        self.r = r
        lo = r.plant.home_switch[0]
        return HomingStep(HomingMotion("velocity", r.fast, accel=r.accel),
                          (Watch("hs", lo, 1),))

    def event(self, name: str, t_us: int, position: int) -> HomingStep:
        if name == "hs":
            self.hit = (t_us, position)
            return HomingStep(HomingMotion("stop", accel=self.r.accel))
        return HomingStep(outcome="attained", home_position=self.r.offset)


def test_homing_plan_watches_and_motion_end_are_reported_exactly():
    plan = SwitchPlan()
    d = Drive(plant=DrivePlant(home_switch=(10_000, 12_000)), homing={1: lambda: plan})
    enable(d, 6, x6098=1, x6099_1=20_000, x609A=200_000, x607C=-7)
    d.write(0x6040, 0, 0x1F)
    assert d.statusword & 0xB400 == 0                 # running: 0x0237
    d.advance(5_000_000)
    # 0.1 s ramp (1000 P), then 9000 P at 20 kP/s: the switch at 0.55 s
    assert plan.hit == (550_000, 10_000)
    assert d.position == -7 and d.statusword == 0x1637
    # the count moved, the switches did not: the axis stands on the home switch
    assert d.axis.mechanical(d.now) == 10_000 + 1000 and d.read(0x60FD) == 0x4
    d.write(0x6060, 0, 1)                             # PP targets are counts
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
    d.cycle(d.now)
    for index, value in ((0x6081, 10_000), (0x6083, 100_000), (0x6084, 100_000)):
        d.write(index, 0, value)
    d.write(0x607A, 0, -7 + 1001)                     # mechanical 12 001: off the switch
    d.write(0x6040, 0, 0x1F)
    d.advance(d.now + 2_000_000)
    assert d.position == 994 and d.read(0x60FD) == 0


def test_homing_time_limit_p03_07_raises_alarm_63():
    class Forever(SwitchPlan):
        def start(self, r):
            self.r = r
            return HomingStep(HomingMotion("velocity", r.fast, accel=r.accel))
    d = Drive(homing={1: Forever})
    enable(d, 6, x6098=1, x2003_7=250)
    d.write(0x6040, 0, 0x1F)
    d.advance(249_999)
    assert d.sm.state is State.OPERATION_ENABLED
    d.advance(300_000)
    assert d.read(0x603F) == 63 and d.log[-1].t_us == 250_000 or d.read(0x603F) == 63


def test_homing_bit_4_falling_stops_at_once():
    d = Drive(plant=DrivePlant(home_switch=(10_000, 12_000)), homing={1: SwitchPlan})
    enable(d, 6, x6098=1, x6099_1=20_000, x609A=200_000)
    d.write(0x6040, 0, 0x1F)
    d.advance(200_000)
    d.write(0x6040, 0, 0x0F)
    held = d.position
    d.advance(400_000)
    assert d.position == held and d.statusword & 0x3400 == 0x0400   # interrupted


# ---------------------------------------------------------------- exact time, cost

def pp_run(period: int) -> list[int]:
    d = enable(Drive(), 1, x6081=37_000, x6083=123_457, x6084=98_765)
    out = []
    t = 0
    while t < 3_000_000:
        t += period
        d.cycle(t)
        if t == 10_000:
            d.write(0x607A, 0, 54_321)
            d.write(0x6040, 0, 0x1F)
            d.write(0x6040, 0, 0x0F)
            d.write(0x607A, 0, -1_111)
            d.write(0x6040, 0, 0x1F)                  # buffered set-point
            d.write(0x6040, 0, 0x0F)
        if t % 1000 == 0:
            out.append(d.position)
    return out


def test_positions_do_not_depend_on_the_bus_cycle():
    assert pp_run(1000) == pp_run(250)


def pv_run(period: int) -> list[int]:
    d = enable(Drive(plant=DrivePlant(pos_limit=30_000)), 3, x6083=77_777, x6084=55_555,
               x6085=333_333)
    out, t = [], 0
    while t < 2_000_000:
        t += period
        d.cycle(t)
        if t == 5000:
            d.write(0x60FF, 0, 23_456)
        if t == 400_000:
            d.write(0x60FF, 0, -9_999)
        if t == 700_000:
            d.write(0x60FF, 0, 40_000)                # runs into PLS
        if t % 1000 == 0:
            out.append((d.position, d.statusword))
    return out


def test_pv_and_the_limit_stop_do_not_depend_on_the_bus_cycle():
    slow, fast = pv_run(1000), pv_run(250)
    assert slow == fast and slow[-1][1] & 0x0800


def evaluations(speed: int) -> int:
    # the limit switch is crossed mid-move: its time is found by bisection
    d = enable(Drive(plant=DrivePlant(pos_limit=5 * 10**6)), 1,
               x6080=10**8, x6081=speed, x6083=speed * 10, x6084=speed * 10, x6085=0)
    d.write(0x607A, 0, 10**7)
    d.write(0x6040, 0, 0x1F)
    start = d.axis.evaluations
    d.advance(2 * 10**13 // speed)                  # twice the cruise time
    assert d.position == 5 * 10**6 and d.statusword & 0x0800
    return d.axis.evaluations - start


def test_cost_of_a_move_does_not_grow_with_speed():
    slow, fast = evaluations(10_000), evaluations(5_000_000)
    assert fast <= slow + 10 and slow < 200


# ---------------------------------------------------------------- invariant

@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([0x00, 0x02, 0x06, 0x07, 0x0F, 0x1F, 0x80, 0x8F,
                                           0x10F]),
                          st.integers(0, 50_000), st.booleans()), max_size=25),
       st.sampled_from([1, 3, 6, 8]))
def test_statusword_always_shows_drive402_state(steps, mode):
    d = Drive()
    d.write(0x6060, 0, mode)
    d.write(0x6081, 0, 10_000)
    d.write(0x6083, 0, 100_000)
    d.write(0x6084, 0, 100_000)
    d.write(0x60FF, 0, 5000)
    t = 0
    for cw, dt, fault in steps:
        if fault and d.sm.state is State.OPERATION_ENABLED:
            d.fault(d.now, 62, 62, "injected")
        d.write(0x6040, 0, cw)
        t += dt
        d.cycle(t)
        sw = d.read(0x6041)
        assert sw == d.sm.statusword
        assert state_of_statusword(sw) is d.sm.state
        if d.sm.state not in (State.OPERATION_ENABLED, State.QUICK_STOP_ACTIVE):
            assert not d.moving


@settings(max_examples=50, deadline=None)
@given(st.lists(st.integers(-2**31, 2**31 - 1), min_size=7, max_size=7))
def test_fast_images_are_the_bytes_of_pdo_pack(vals):
    from plcrt.devices.cia402.pdo import pack, unpack
    d = Drive()
    tx = d.pdo.active_tx
    keys = [(e.index, e.sub) for e in tx]
    values = {}
    for (index, sub), v, e in zip(keys, vals, tx):
        lo = -(1 << (e.bits - 1)) if (index, sub) in d._signed else 0
        values[(index, sub)] = lo + v % (1 << e.bits)
    codec = d._codec(tx)
    data = codec[0].pack(*[values[k] for k in codec[1]])
    assert data == pack(tx, values)
    assert dict(zip(codec[1], codec[0].unpack(data))) == unpack(tx, data, d._signed)


# ---------------------------------------------------------------- more reactions

def test_kinco_model_runs_pp_and_shows_reference_found_after_homing():
    d = enable(Drive("kinco-servo"), 1, x6081=10_000, x6083=100_000, x6084=100_000)
    d.write(0x607A, 0, 5000)
    d.write(0x6040, 0, 0x1F)
    d.write(0x6040, 0, 0x0F)
    d.advance(2_000_000)
    assert d.position == 5000 and d.statusword & 0x0400 and not d.statusword & 0x8000
    d.write(0x6060, 0, 6)
    d.write(0x607C, 0, 0)
    d.write(0x6098, 0, 35)
    d.write(0x6040, 0, 0x1F)
    assert d.position == 0 and d.statusword & 0x9400 == 0x9400   # Kinco §2.6 bit 15


def test_disable_operation_stops_the_axis_at_once_and_the_mode_forgets_its_move():
    d = enable(Drive(), 1, x6081=10_000, x6083=100_000, x6084=100_000)
    d.write(0x607A, 0, 50_000)
    d.write(0x6040, 0, 0x1F)
    d.advance(1_000_000)
    d.write(0x6040, 0, 0x07)                          # transition 5
    held = d.position
    d.advance(2_000_000)
    assert d.sm.state is State.SWITCHED_ON and d.position == held
    d.write(0x6040, 0, 0x0F)
    d.advance(3_000_000)
    assert d.position == held and d.statusword == 0x8637


def test_mode_change_while_moving_stops_and_is_logged():
    d = enable(Drive(), 3, x6083=100_000, x6084=100_000)
    d.write(0x60FF, 0, 10_000)
    d.advance(500_000)
    d.write(0x6060, 0, 1)
    assert not d.moving and d.read(0x6061) == 1
    assert any("while moving" in e.text for e in d.log)


def test_the_bus_leaving_op_disables_the_drive():
    d = Drive()
    to_op(d)
    t = 0
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        t += 1000
        d.cycle(t, rx(d, cw, 0))
    assert d.sm.state is State.OPERATION_ENABLED
    d.request_esm(EsmState.SAFEOP)
    assert d.sm.state is State.SWITCH_ON_DISABLED


def test_quick_stop_during_a_pp_move_drops_its_set_points():
    d = enable(Drive(), 1, x6081=10_000, x6083=100_000, x6084=100_000, x6085=1_000_000,
               x605A=6)
    d.write(0x607A, 0, 50_000)
    d.write(0x6040, 0, 0x1F)
    d.write(0x6040, 0, 0x0F)
    d.advance(1_000_000)
    d.write(0x6040, 0, 0x0B)                          # bit 2 = 0: quick stop
    d.advance(1_010_000)                              # 10 000 / 1e6 = 10 ms
    assert not d.moving and d.statusword == 0x0617
    stopped = d.position
    d.write(0x6040, 0, 0x0F)                          # 16: back to OE, no motion
    d.advance(3_000_000)
    assert d.position == stopped and d.statusword & 0x0400


def test_time_cannot_go_back():
    d = Drive()
    d.advance(1000)
    with pytest.raises(PlcError, match="cannot go back"):
        d.advance(999)


def test_a_homing_plan_asking_for_a_move_at_speed_0_ends_in_homing_error():
    class Bad(SwitchPlan):
        def start(self, r):
            self.r = r
            return HomingStep(HomingMotion("position", 1000, speed=0, accel=r.accel))
    d = Drive(homing={1: Bad})
    enable(d, 6, x6098=1)
    d.write(0x6040, 0, 0x1F)
    assert d.statusword == 0x2637 and "positive speed" in d.log[-1].text


def test_homing_parameter_zero_refuses_the_start_with_bit_14():
    d = Drive(homing={1: SwitchPlan})
    enable(d, 6, x6098=1, x609A=0)
    d.write(0x6040, 0, 0x1F)
    assert d.statusword & 0x4000 and "609Ah" in d.log[-1].text


@pytest.mark.parametrize("model, first_tx", [("hcfa-am0520b", [0x6041, 0x603F, 0x6064, 0x606C,
                                                                0x6061, 0x60B9, 0x60BA]),
                                              ("kinco-servo", [0x6041, 0x6041, 0x6061, 0x6041,
                                                               0x6064, 0x6041, 0x606C])])
def test_a_bus_cycle_uses_the_models_own_power_up_maps(model: str, first_tx: list[int]) -> None:
    """Each model's process data at power-up are the maps of its own object
    dictionary (HCFA: 1C13h -> 1A00h; Kinco, CANopen without assignment
    objects: every TxPDO map with entries, in number order), so a cycle of
    the Kinco drive never asks for an HCFA object."""
    d = Drive(model)
    tx = d.cycle(1000)
    assert [e.index for e in d.pdo.active_tx] == first_tx
    assert int.from_bytes(tx[:2], "little") == d.statusword
