"""canopen's own BaseNode402 drives the simulated drive over python-can's
``virtual`` bus (plcrt.cia402.attach): enable, PP, PV, homing, fault reset,
SDO aborts, NMT and heartbeat."""

from __future__ import annotations

import itertools
import logging
import time

import pytest

canopen = pytest.importorskip("canopen")
from canopen.profiles.p402 import BaseNode402  # noqa: E402

from plcrt import cia402  # noqa: E402
from plcrt.devices.cia402.esm import EsmState  # noqa: E402
from plcrt.devices.cia402.plant import DrivePlant  # noqa: E402
from plcrt.devices.cia402.statemachine import State  # noqa: E402
from plcrt.errors import PlcConfigError  # noqa: E402

logging.getLogger("canopen.profiles.p402").setLevel(logging.ERROR)
_channels = itertools.count()


@pytest.fixture
def bus(request):
    """(device network, master network) on a channel of this test's own."""
    name = f"plcrt-{request.node.name}-{next(_channels)}"
    dev, mst = canopen.Network(), canopen.Network()
    dev.NOTIFIER_CYCLE = mst.NOTIFIER_CYCLE = 0.02    # a quick disconnect
    dev.connect(interface="virtual", channel=name)
    mst.connect(interface="virtual", channel=name)
    yield dev, mst
    mst.disconnect()
    dev.disconnect()


def master(mst, node_id=5, model="hcfa-am0520b"):
    n = BaseNode402(node_id, cia402.object_dictionary(model))
    mst.add_node(n)
    n.nmt.state = "PRE-OPERATIONAL"
    n.setup_402_state_machine()
    return n


@pytest.fixture
def pair(bus):
    dev, mst = bus
    sim = cia402.attach(dev, 5, clock="step")
    yield sim, master(mst)
    sim.close()


def enable(n, mode):
    n.op_mode = mode
    n.state = "OPERATION ENABLED"
    assert n.state == "OPERATION ENABLED"


def test_enable_to_operation_enabled(pair):
    sim, n = pair
    n.state = "OPERATION ENABLED"
    assert n.state == "OPERATION ENABLED"
    assert sim.drive.sm.state is State.OPERATION_ENABLED
    n.state = "SWITCH ON DISABLED"
    assert sim.drive.sm.state is State.SWITCH_ON_DISABLED


def test_pp_move_to_an_exact_target(pair):
    sim, n = pair
    enable(n, "PROFILED POSITION")
    for index, value in ((0x6081, 100_000), (0x6083, 1_000_000), (0x6084, 1_000_000),
                         (0x607A, 12_345)):
        n.sdo[index].raw = value
    n.controlword = 0x0F
    t0 = sim.drive.now
    n.controlword = 0x1F                              # new set-point edge (bit 4)
    for _ in range(2000):                            # one bus cycle per 6041h read
        if n.statusword & 0x0400:
            break
    assert n.statusword & 0x0400
    assert n.sdo[0x6064].raw == 12_345
    # ramps of 0.1 s each (5 000 counts) and 2 345 counts at 100 000 P/s: 0.223 s
    assert 0.222 <= (sim.drive.now - t0) / 1e6 <= 0.226


def test_pv_velocity_reached(pair):
    sim, n = pair
    enable(n, "PROFILED VELOCITY")
    n.sdo[0x6083].raw = 1_000_000
    n.sdo[0x6084].raw = 1_000_000
    n.sdo[0x60FF].raw = 50_000
    sim.advance(0.1)
    assert n.statusword & 0x0400                      # velocity reached
    assert n.sdo[0x606C].raw == 50_000


@pytest.mark.parametrize("seconds, words", [
    (-0.1, "cannot go back in time"), (float("nan"), "non-negative, finite"),
    (1.8e302, "too long to count in microseconds"), ("soon", "not a duration"),
    (10**400, "about 1e400 s is too long to count in microseconds"),
    (-(10**400), "cannot go back in time"),
    (1e300, r"1e\+300 s at 1 ms a bus cycle is more than 1_000_000_000 bus cycles"),
    ("3000h", "more than 1_000_000_000 bus cycles")])
def test_advance_takes_a_duration_it_can_count(pair, seconds, words):
    """advance() refuses what is not a countable duration with a PlcError,
    and the drive's time stays where it was."""
    sim, _ = pair
    t0 = sim.drive.now
    with pytest.raises(PlcConfigError, match=words):
        sim.advance(seconds)
    assert sim.drive.now == t0
    sim.advance("10ms")
    assert sim.drive.now == t0 + 10_000


def test_homing_method_35_returns_true(pair):
    sim, n = pair
    n.state = "OPERATION ENABLED"
    n.op_mode = "HOMING"
    n.sdo[0x6098].raw = 35
    assert n.homing(timeout=2) is True
    assert n.is_homed()
    assert sim.drive.position == 0


def test_fault_reset_after_an_injected_fault(pair):
    sim, n = pair
    n.state = "OPERATION ENABLED"
    with sim.drive.store.lock:
        sim.drive.fault(sim.drive.now, 0x8611, None, "injected by the test")
        sim.drive.publish()
    assert n.state == "FAULT"
    n.reset_from_fault()                              # canopen re-enables after the edge
    assert n.state != "FAULT" and sim.drive.sm.state is not State.FAULT
    assert n.sdo[0x603F].raw == 0


@pytest.mark.parametrize("index,sub,write,code", [
    (0x1234, 0, None, 0x06020000),                   # unknown object
    (0x6041, 0, b"\x01\x00", 0x06010002),             # read-only statusword
])
def test_sdo_abort_codes_reach_the_master(pair, index, sub, write, code):
    _, n = pair
    with pytest.raises(canopen.SdoAbortedError) as e:
        if write is None:
            n.sdo.upload(index, sub)
        else:
            n.sdo.download(index, sub, write)
    assert e.value.code == code


def test_value_out_of_range_is_refused_with_the_drives_code(pair, caplog):
    sim, n = pair
    with caplog.at_level(logging.INFO, logger="plcrt.cia402.canopen"):
        with pytest.raises(canopen.SdoAbortedError) as e:
            n.sdo.download(0x6098, 0, b"\xff")        # 6098h = -1, minimum 0 (HCFA §8.3)
    assert e.value.code == 0x06090032
    assert sim.drive.read(0x6098) == 1                # unchanged
    assert any("6098" in r.getMessage() for r in caplog.records)


def wait_for(cond, timeout=1.0):
    """NMT commands are unconfirmed: the node acts in its Notifier thread."""
    end = time.monotonic() + timeout
    while not cond() and time.monotonic() < end:
        time.sleep(0.001)
    return cond()


def test_nmt_and_heartbeat(bus):
    dev, mst = bus
    sim = cia402.attach(dev, 7, clock="manual")
    try:
        n = BaseNode402(7, cia402.object_dictionary())
        mst.add_node(n)
        n.sdo.download(0x1017, 0, (10).to_bytes(2, "little"))   # 10 ms heartbeat (CAN view)
        n.nmt.wait_for_heartbeat(timeout=1)
        assert n.nmt.state == "PRE-OPERATIONAL"
        n.nmt.state = "OPERATIONAL"
        assert wait_for(lambda: sim.drive.esm.state is EsmState.OP)
        n.nmt.wait_for_heartbeat(timeout=1)
        assert n.nmt.state == "OPERATIONAL"
        n.nmt.state = "PRE-OPERATIONAL"
        assert wait_for(lambda: sim.drive.esm.state is EsmState.PREOP)
    finally:
        sim.close()


def test_wall_clock_drive_moves_on_its_own(bus):
    dev, mst = bus
    sim = cia402.attach(dev, 9)
    try:
        n = master(mst, 9)
        enable(n, "PROFILED VELOCITY")
        t0 = sim.drive.now
        time.sleep(0.05)
        assert n.statusword and sim.drive.now - t0 >= 20_000
    finally:
        sim.close()


@pytest.mark.parametrize("kwargs,words", [
    (dict(node_id=5, model="no-such-drive"), "unknown drive model"),
    (dict(node_id=0), "node id"),
    (dict(node_id=128), "node id"),
    (dict(node_id=5, clock="sundial"), "clock"),
])
def test_bad_arguments_are_config_errors(bus, kwargs, words):
    dev, _ = bus
    with pytest.raises(PlcConfigError, match=words):
        cia402.attach(dev, **kwargs)


def test_a_network_that_is_not_connected_is_refused():
    with pytest.raises(PlcConfigError, match="not connected"):
        cia402.attach(canopen.Network(), 5)


def test_pdos_carry_the_statusword_and_the_controlword(bus):
    """The CAN view (object_dictionary(model, node_id)): BaseNode402 finds
    the cyclic TPDO (6041h, 6064h, 6061h) and the RPDO (6040h, 607Ah) and
    drives the drive through them in NMT OPERATIONAL."""
    dev, mst = bus
    sim = cia402.attach(dev, 11)
    try:
        n = BaseNode402(11, cia402.object_dictionary("hcfa-am0520b", node_id=11))
        mst.add_node(n)
        n.nmt.state = "PRE-OPERATIONAL"
        n.setup_402_state_machine(read_pdos=True)
        assert 0x6041 in n.tpdo_pointers and 0x6040 in n.rpdo_pointers
        n.nmt.state = "OPERATIONAL"
        assert wait_for(lambda: sim.drive.esm.state is EsmState.OP)
        n.tpdo[sim.tpdo_no].wait_for_reception(timeout=1)
        n.op_mode = "PROFILED POSITION"
        n.state = "OPERATION ENABLED"
        assert sim.drive.sm.state is State.OPERATION_ENABLED
        for index, value in ((0x6081, 200_000), (0x6083, 2_000_000), (0x6084, 2_000_000)):
            n.sdo[index].raw = value
        rpdo = n.rpdo[sim.rpdo_no]
        rpdo[0x607A].raw = 4_000                       # the RPDO carries the target
        rpdo[0x6040].raw = 0x0F
        rpdo.transmit()
        rpdo[0x6040].raw = 0x1F
        rpdo.transmit()
        assert wait_for(lambda: n.tpdo[sim.tpdo_no][0x6064].raw == 4_000, timeout=2)
        assert n.statusword & 0x0400
    finally:
        sim.close()


def test_rpdo_outside_operational_is_ignored_and_logged(bus):
    dev, mst = bus
    sim = cia402.attach(dev, 12, clock="manual")
    try:
        n = BaseNode402(12, cia402.object_dictionary("hcfa-am0520b", node_id=12))
        mst.add_node(n)
        n.rpdo.read()
        n.rpdo[sim.rpdo_no][0x6040].raw = 0x06
        n.rpdo[sim.rpdo_no].transmit()
        assert wait_for(lambda: any("RPDO ignored" in e.text for e in sim.drive.log))
        assert sim.drive.sm.state is State.SWITCH_ON_DISABLED
    finally:
        sim.close()


def test_a_fresh_master_learns_pre_operational_from_the_heartbeat(bus):
    """Caveat 1: setup_402_state_machine() on a fresh node needs the master's
    NMT to know the state; the node's default heartbeat (50 ms) tells it."""
    dev, mst = bus
    sim = cia402.attach(dev, 13, clock="manual")
    try:
        n = BaseNode402(13, cia402.object_dictionary())
        mst.add_node(n)
        n.nmt.wait_for_heartbeat(timeout=1)
        assert n.nmt.state == "PRE-OPERATIONAL"
        n.setup_402_state_machine()                     # no AssertionError
    finally:
        sim.close()


def test_the_kinco_model_is_enabled_by_its_master(bus):
    dev, mst = bus
    sim = cia402.attach(dev, 14, model="kinco-servo", clock="step")
    try:
        n = master(mst, 14, "kinco-servo")
        n.state = "OPERATION ENABLED"
        assert sim.drive.sm.state is State.OPERATION_ENABLED
    finally:
        sim.close()


def test_a_fault_and_its_reset_reach_the_master_as_emcy_messages(pair):
    """CiA 301 §7.2.7: 603Fh and 1001h in an EMCY on 080h + node id when the
    fault comes, and the code 0000h (error reset) when it is reset."""
    sim, n = pair
    n.state = "OPERATION ENABLED"
    with sim.drive.store.lock:
        sim.drive.fault(sim.drive.now, 0x8611, None, "injected by the test")
        sim.drive.publish()
    assert n.state == "FAULT"                         # the read runs the port's cycle
    assert wait_for(lambda: n.emcy.active, timeout=2)
    err, = n.emcy.active
    assert err.code == 0x8611 and err.register & 0x01
    n.reset_from_fault()
    assert wait_for(lambda: not n.emcy.active, timeout=2)        # 0000h cleared the master's list
    assert [e.code for e in n.emcy.log] == [0x8611, 0x0000]
    assert any("EMCY 0x8611 sent" in str(ev) for ev in sim.drive.log)


def test_a_homing_timeout_is_an_emcy_with_the_hcfa_code(bus):
    """HCFA §4.7 alarm 63 (homing timeout, P03.07) reaches the master as EMCY
    FF3Fh (manufacturer-specific: 003Fh would read as an error reset) with
    603Fh = 63 in the manufacturer-specific bytes."""
    dev, mst = bus
    # NLS far away: the search for it outlasts the homing time limit
    sim = cia402.attach(dev, 5, clock="manual", plant=DrivePlant(neg_limit=-10**9))
    try:
        n = master(mst)
        n.state = "OPERATION ENABLED"
        n.op_mode = "HOMING"
        n.sdo[0x6098].raw = 17                        # method 17: search NLS
        n.sdo[0x2003][7].raw = 1000                   # P03.07: 1000 ms
        n.controlword = 0x1F
        sim.advance(2.0)
        assert wait_for(lambda: n.emcy.log, timeout=2)
        assert [e.code for e in n.emcy.log] == [0xFF3F]
        assert n.emcy.active and n.emcy.log[0].data[:2] == (63).to_bytes(2, "little")
    finally:
        sim.close()
