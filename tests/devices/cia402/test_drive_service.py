"""The test surface of a simulated CiA 402 drive: the plant as a dict or a
TOML file, faults injected by name or number, the power cycle, the digital
inputs through their functions and polarity, the touch probe, and log lines
that cite their own model's manual."""

from __future__ import annotations

import logging

import canopen
import pytest
from hypothesis import given, settings, strategies as st
from canopen.profiles.p402 import BaseNode402

from plcrt import cia402
from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.esm import EsmState
from plcrt.devices.cia402.plant import DrivePlant, plant_of
from plcrt.devices.cia402.statemachine import State
from plcrt.errors import PlcConfigError

from cia402_drive_helpers import enable


def reset(d: Drive) -> None:
    d.write(0x6040, 0, 0x00)
    d.write(0x6040, 0, 0x80)


# ---------------------------------------------------------------- the plant

def test_a_plant_dict_and_a_toml_file_give_the_same_drive_plant(tmp_path):
    plant = {"neg_limit": -50_000, "pos_limit": 50_000, "home_switch": [-1000, 1000],
             "index_period": 10_000, "index_phase": 250, "neg_stop": -60_000,
             "pos_stop": 60_000, "probe": [3000, 3100]}
    f = tmp_path / "axis.toml"
    f.write_text("neg_limit = -50000\npos_limit = 50000\nhome_switch = [-1000, 1000]\n"
                 "index_period = 10000\nindex_phase = 250\nneg_stop = -60000\n"
                 "pos_stop = 60000\nprobe = [3000, 3100]\n")
    expected = DrivePlant(-50_000, 50_000, (-1000, 1000), 10_000, 250, -60_000, 60_000,
                          (3000, 3100))
    assert plant_of(plant) == plant_of(f) == plant_of(str(f)) == expected
    assert Drive(plant=plant).plant == expected


@pytest.mark.parametrize("plant, message", [
    ({"neg_limt": 5}, "plant: unknown key 'neg_limt'; keys: neg_limit"),
    ({"pos_limit": "50000"}, "plant.pos_limit must be a whole count"),
    ({"pos_limit": 1.5}, "plant.pos_limit must be a whole count"),
    ({"pos_limit": True}, "plant.pos_limit must be a whole count"),
    ({"pos_limit": 2**40}, "plant.pos_limit must be a whole count"),
    ({"home_switch": 5}, "plant.home_switch must be [low, high]"),
    ({"home_switch": [1, "x"]}, "plant.home_switch[1] must be a whole count"),
    ({"probe": [10, 0]}, "plant: probe = (10, 0) is no range lo <= hi"),
    ({"neg_limit": 10, "pos_limit": 0}, "plant: neg_limit = 10 must lie below pos_limit = 0"),
    ({"pos_limit": 100, "pos_stop": 50}, "plant: pos_stop = 50 must lie at or above pos_limit"),
    ({"inertia": 0.01}, "plant.inertia: load inertia is not simulated"),
    ([1, 2], "plant: a plant is a dict of neg_limit"),
])
def test_a_bad_plant_is_a_config_error_naming_the_key(plant, message):
    with pytest.raises(PlcConfigError) as e:
        plant_of(plant)
    assert message in str(e.value)


def test_a_bad_plant_file_names_the_file(tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text("pos_limit = [\n")
    with pytest.raises(PlcConfigError, match="bad.toml: not a TOML file"):
        plant_of(f)
    f.write_text("index_period = 0\n")
    with pytest.raises(PlcConfigError, match="bad.toml: index_period = 0 must be positive"):
        plant_of(f)
    with pytest.raises(PlcConfigError, match="missing.toml"):
        plant_of(tmp_path / "missing.toml")


def test_attach_takes_the_plant_as_a_dict_and_a_master_sees_its_limit_switch():
    """cia402.attach(..., plant=dict): canopen's own master reads 60FDh bit 1
    (PLS, HCFA §8.3) of an axis that starts on the positive limit switch."""
    dev, mst = canopen.Network(), canopen.Network()
    dev.connect(interface="virtual", channel="svc-plant")
    mst.connect(interface="virtual", channel="svc-plant")
    try:
        port = cia402.attach(dev, 5, plant={"pos_limit": -10}, clock="manual")
        node = BaseNode402(5, cia402.object_dictionary())
        mst.add_node(node)
        assert node.sdo[0x60FD].raw == 0x2
        with pytest.raises(PlcConfigError, match=r"cia402.attach: plant: unknown key 'x'"):
            cia402.attach(dev, 6, plant={"x": 1}, clock="manual")
        port.close()
    finally:
        mst.disconnect()
        dev.disconnect()


# ---------------------------------------------------------------- faults

@pytest.mark.parametrize("model, name, code, resettable", [
    ("hcfa-am0520b", "following_error", 0x8611, True),
    ("hcfa-am0520b", "limit", 0x8612, True),
    ("hcfa-am0520b", "overcurrent", 20704, False),
    ("hcfa-am0520b", "encoder", 10256, True),
    ("hcfa-am0520b", "power_stage", 20640, False),
    ("kinco-servo", "following_error", 0x8611, True),
    ("kinco-servo", "overcurrent", 0x2310, False),
    ("kinco-servo", "encoder", 0x7305, True),
    ("kinco-servo", "power_stage", 0x5400, False),
])
def test_inject_a_fault_by_name(model, name, code, resettable):
    """HCFA §4.7: the fault's 603Fh code, 1001h bit 0, transitions 13 and 14;
    a reset (15) clears it unless the table says power cycle only ("否")."""
    d = enable(Drive(model), 3, x60FF=1000, x6083=1000, x6084=1000)
    d.advance(500_000)
    assert d.inject_fault(name) == code
    assert d.sm.state is State.FAULT_REACTION_ACTIVE and not d.moving
    assert d.read(0x603F) == code and d.read(0x1001) & 1
    d.cycle(501_000)
    assert d.sm.state is State.FAULT
    reset(d)
    assert (d.sm.state is State.SWITCH_ON_DISABLED) is resettable
    if not resettable:
        d.power_cycle()
        assert d.sm.state is State.SWITCH_ON_DISABLED and d.read(0x603F) == 0


def test_inject_a_fault_by_alarm_number_and_a_persisting_cause():
    d = Drive()
    d.inject_fault(63, persist=True)                 # homing timeout, HCFA §4.7
    d.cycle(1000)
    reset(d)
    assert d.sm.state is State.FAULT                 # the cause is still there
    assert any("cause" in e.text for e in d.log)
    d.clear_fault_cause()
    d.write(0x6040, 0, 0x00)
    d.write(0x6040, 0, 0x80)
    assert d.sm.state is State.SWITCH_ON_DISABLED and d.read(0x603F) == 0


@pytest.mark.parametrize("fault", ["melted", 12345, True, None])
def test_an_unknown_fault_is_a_config_error(fault):
    with pytest.raises(PlcConfigError, match="following_error"):
        Drive().inject_fault(fault)


# ---------------------------------------------------------------- power cycle, alarm 83

def test_a_power_up_parameter_raises_alarm_83_and_acts_after_a_power_cycle():
    """HCFA §4.7 alarm 83 "变更参数需要重新接通电源生效", §5.1 再次通电: P00.01
    (direction) written: alarm 83, the drive keeps 0 until the power cycle,
    which applies it, clears the alarm and starts at SOD, ESM INIT, count 0."""
    d = enable(Drive(), 1, x6081=10_000, x6083=100_000, x6084=100_000)
    d.write(0x607A, 0, 5000)
    d.write(0x6040, 0, 0x1F)
    d.advance(2_000_000)
    assert d.position == 5000
    d.write(0x2000, 1, 1)
    assert d.read(0x603F) == 83 and d.sm.state is State.FAULT_REACTION_ACTIVE
    assert d.read(0x2000, 1) == 1 and d.store.get(0x2000, 1) == 0
    assert any("acts after the next power cycle" in e.text for e in d.log)
    applied = d.power_cycle()
    assert len(applied) == 1 and "P00.01" in applied[0]
    assert d.store.get(0x2000, 1) == 1 and d.store.pending == {}
    assert d.sm.state is State.SWITCH_ON_DISABLED and d.read(0x603F) == 0
    assert d.esm.state.name == "INIT" and d.read(0x6040) == 0
    assert d.position == 0 and d.axis.mechanical(d.now) == 5000


def test_writing_the_active_value_of_a_power_up_parameter_raises_nothing():
    d = Drive()
    d.write(0x2000, 1, 0)
    assert d.read(0x603F) == 0 and d.sm.state is State.SWITCH_ON_DISABLED


# ---------------------------------------------------------------- P18 display

def test_p18_display_parameters_read_live_values():
    """HCFA §5.1, §8.2 P18.01 speed feedback (rpm), P18.03 speed command (rpm),
    P18.09 the mode set by the master, P18.36 the EtherCAT state: 50 000 P/s at
    P00.02 = 50 000 P/rev is 60 rpm."""
    d = enable(Drive(), 3, x60FF=50_000, x6083=100_000, x6084=100_000)
    assert d.read(0x2012, 9) == 3 and d.read(0x2012, 36) == 1
    d.advance(1_000_000)
    assert d.read(0x2012, 1) == 60 and d.read(0x2012, 3) == 60
    d.write(0x60FF, 0, -25_000)
    d.advance(3_000_000)
    assert d.read(0x2012, 1) == 30                  # UINT16: no sign (HCFA §8.2)


# ---------------------------------------------------------------- digital inputs

def test_di_monitor_reads_the_plant_through_p02_functions_and_polarity():
    """HCFA §5.1 P02.01–05 (defaults DI1 NLS, DI2 PLS, DI3 home) and P02.10
    (bit n = DI n+1 normally closed): P18.21 shows each DI as the drive
    reads it."""
    d = Drive(plant={"neg_limit": 100, "home_switch": [-5, 5]})  # the axis at 0: NLS, home
    assert d.read(0x2012, 21) == 0b00101
    d.write(0x2002, 10, 0b00001)                     # DI1 normally closed
    assert d.read(0x2012, 21) == 0b00100
    d.write(0x2002, 3, 2)                            # DI3 now PLS: not active here
    assert d.read(0x2012, 21) == 0b00000


def test_the_e_stop_input_faults_the_drive_until_released():
    """HCFA §5.1 P02.04 = 8 (E-stop, DI4 by default): the input active faults
    the drive (603Fh 0x5441, CiA 402); a reset is refused until it is
    released.  With P02.10 bit 3 (normally closed) the open contact is the
    active one."""
    d = enable(Drive(), 3, x60FF=1000, x6083=1000, x6084=1000)
    d.set_input("estop", True)
    assert d.read(0x603F) == 0x5441 and d.sm.state is State.FAULT_REACTION_ACTIVE
    d.cycle(1000)
    reset(d)
    assert d.sm.state is State.FAULT
    d.set_input(4, False)
    reset(d)
    assert d.sm.state is State.SWITCH_ON_DISABLED
    d.write(0x2002, 10, 0b01000)                     # NC: level low = E-stop
    d.set_input(4, True)
    assert d.sm.state is State.SWITCH_ON_DISABLED
    d.set_input(4, False)
    assert d.read(0x603F) == 0x5441
    with pytest.raises(PlcConfigError, match="DI 6 is not 1..5"):
        d.set_input(6, True)


# ---------------------------------------------------------------- touch probe

def test_touch_probe_latches_the_index_pulse_at_its_exact_position():
    """HCFA §8.3, CiA 402 60B8h: probe 1 on the index pulse (bits 0, 2, 4),
    first event: 60BAh holds the first index pulse's count after enabling,
    60B9h bits 0 and 1; in CSP at 1 ms with 700 counts a cycle the pulse at
    index_phase + k * period is latched exactly, not at a cycle's count."""
    d = Drive(plant={"index_period": 1000, "index_phase": 234})
    for s in (EsmState.PREOP, EsmState.SAFEOP, EsmState.OP):
        d.request_esm(s)
    t = 0
    image = lambda cw, x, fn: (cw.to_bytes(2, "little") + x.to_bytes(4, "little", signed=True)
                               + fn.to_bytes(2, "little"))
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        t += 1000
        d.cycle(t, image(cw, 0, 0))
    t += 1000
    d.cycle(t, image(0x0F, 0, 0x15))                # enable, index source, rising edge
    assert d.read(0x60B9) == 0x1
    x = 0
    for _ in range(5):
        t += 1000
        x += 700
        d.cycle(t, image(0x0F, x, 0x15))
    # first event only (bit 1 = 0): the pulses at 1234 and 2234 are not taken
    assert d.read(0x60B9) == 0x3 and d.read(0x60BA) == 234
    assert any("touch probe 1 latched the rise of the index pulse at count 234" in e.text
               for e in d.log)
    for fn in (0x00, 0x15):                         # re-armed at count 3500
        t += 1000
        d.cycle(t, image(0x0F, x, fn))
    assert d.position == 3500 and d.read(0x60B9) == 0x1
    for _ in range(2):
        t += 1000
        x -= 700
        d.cycle(t, image(0x0F, x, 0x15))
    assert d.read(0x60B9) == 0x3 and d.read(0x60BA) == 3234     # moving back


@settings(max_examples=60, deadline=None)
@given(period=st.integers(1, 5000), phase=st.integers(-10_000, 10_000),
       step=st.integers(-800, 800).filter(bool))
def test_touch_probe_index_latch_is_the_first_pulse_ahead(period, phase, step):
    """Whatever the pulse pattern and the CSP step, probe 1 on the index
    latches the first pulse strictly ahead of the count it was armed at, in
    the direction of motion (a pulse on that count is behind it)."""
    d = Drive(plant={"index_period": period, "index_phase": phase})
    start = 0
    for s_ in (EsmState.PREOP, EsmState.SAFEOP, EsmState.OP):
        d.request_esm(s_)
    t, x = 0, start
    img = lambda cw, x, fn: (cw.to_bytes(2, "little") + x.to_bytes(4, "little", signed=True)
                             + fn.to_bytes(2, "little"))
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        t += 1000
        d.cycle(t, img(cw, x, 0))
    t += 1000
    d.cycle(t, img(0x0F, x, 0x15))
    for _ in range(-(-2 * period // abs(step)) + 2):
        t += 1000
        x += step
        d.cycle(t, img(0x0F, x, 0x15))
    k = (start - phase) // period + 1 if step > 0 else -((phase - start) // period) - 1
    assert d.read(0x60B9) == 0x3
    assert d.read(0x60BA) == phase + k * period


def test_touch_probe_latches_both_edges_of_a_probe_input_continuously():
    """Probe 1 on its input (60B8h bit 2 = 0), both edges (bits 4, 5),
    continuous (bit 1): a PV pass over the plant's probe zone [3000, 3100]
    latches 3000 (rise) and 3101 (fall); the pass back latches 3100 and 2999."""
    d = enable(Drive(plant={"probe": [3000, 3100]}), 3, x6083=100_000, x6084=100_000)
    d.write(0x60B8, 0, 0x33)
    d.write(0x60FF, 0, 5000)
    d.advance(1_500_000)
    assert d.read(0x60BA) == 3000 and d.read(0x60BB) == 3101 and d.read(0x60B9) & 0x7 == 0x7
    d.write(0x60FF, 0, -5000)
    d.advance(3_000_000)
    assert d.read(0x60BA) == 3100 and d.read(0x60BB) == 2999


def test_canopens_master_reads_exact_touch_probe_latches():
    """canopen's BaseNode402 over the virtual bus: PV at 7000 P/s past index
    pulses every 1000 counts from 137; 60B8h = 0x15 (probe 1, index, rising,
    first event) set at rest latches 137 exactly, 60B9h = 0x3; re-armed
    (0 then 0x15) at a count between pulses it latches the next pulse."""
    logging.getLogger("canopen.profiles.p402").setLevel(logging.ERROR)
    dev, mst = canopen.Network(), canopen.Network()
    dev.connect(interface="virtual", channel="svc-probe")
    mst.connect(interface="virtual", channel="svc-probe")
    try:
        sim = cia402.attach(dev, 5, plant={"index_period": 1000, "index_phase": 137},
                            clock="manual")
        n = BaseNode402(5, cia402.object_dictionary())
        mst.add_node(n)
        n.nmt.state = "PRE-OPERATIONAL"
        n.setup_402_state_machine()
        n.op_mode = "PROFILED VELOCITY"
        n.state = "OPERATION ENABLED"
        n.sdo[0x6083].raw = n.sdo[0x6084].raw = 7_000_000
        n.sdo[0x60B8].raw = 0x15
        assert n.sdo[0x60B9].raw == 0x1
        n.sdo[0x60FF].raw = 7000
        sim.advance(0.5)
        assert n.sdo[0x60B9].raw == 0x3 and n.sdo[0x60BA].raw == 137
        pos = n.sdo[0x6064].raw
        n.sdo[0x60B8].raw = 0
        n.sdo[0x60B8].raw = 0x15
        sim.advance(0.5)
        assert n.sdo[0x60BA].raw == 137 + 1000 * ((pos - 137) // 1000 + 1)
        sim.close()
    finally:
        mst.disconnect()
        dev.disconnect()


# ---------------------------------------------------------------- the log

def test_log_lines_cite_their_own_models_manual_and_print_the_time_once():
    for model, own, other in (("kinco-servo", "CiA 402", "HCFA"), ("hcfa-am0520b", "HCFA", "Kinco")):
        d = Drive(model)
        d.write(0x6040, 0, 0x0F)                     # refused: no transition from SOD
        lines = [str(e) for e in d.log]
        assert all(other not in line for line in lines), lines
        assert any(own in line for line in lines)
        assert all(line.count("t=") == 1 for line in lines), lines


# ---------------------------------------------------------------- from a PLC

IDLE = "ORGANIZATION_BLOCK MAIN:OB1\nTITLE=t\nBEGIN\nNetwork 1\nLD     SM0.0\nEND_ORGANIZATION_BLOCK\n"


def test_a_fieldbus_drive_takes_power_up_start_up_values_and_injected_faults():
    """A plant file's start-up params of a power-up parameter (P00.01) act from
    the start, without alarm 83 (the module power-cycles the drive after
    them); plc.module(slot).drive(node) is the Drive, whose faults the
    program's side sees in plc.drive(node)."""
    import plcrt

    plant = ('[module.0]\nkind = "FIELDBUS"\n[module.0.drive.1]\nmodel = "hcfa-am0520b"\n'
             'probe = [100, 200]\nparams = { "2000:01" = 1 }\n')
    plc = plcrt.load(IDLE, plant=plant, scan_ms=10)
    d = plc.module(0).drive(1)
    assert d.store.get(0x2000, 1) == 1 and d.plant.probe == (100, 200)
    plc.scan()
    assert plc.drive(1).error_code == 0
    d.inject_fault("encoder")
    plc.scan()
    assert plc.drive(1).error_code == 10256 and plc.drive(1).fault
