"""plcrt's in-process CAN bus (``plcrt.cia402.bus``) with canopen's own
master: the same positions as over python-can's ``virtual`` bus for eight
drives in CSP at a 1 ms SYNC (a differential test of the two buses), EMCY,
the drive's own SDO aborts and NMT gating over it, and the bus's own rules:
delivery in the sender's thread before its send returns, to every other
party of the channel only, the frame shared and not copied, a receiver that
sends from its callback, a failing receiver that does not reach the sender."""

from __future__ import annotations

import itertools
import logging
import struct
import threading

import pytest

canopen = pytest.importorskip("canopen")
can = pytest.importorskip("can")

from plcrt import cia402  # noqa: E402
from plcrt.devices.cia402.esm import EsmState  # noqa: E402
from plcrt.devices.cia402.plant import DrivePlant  # noqa: E402
from plcrt.devices.cia402.statemachine import State  # noqa: E402
from plcrt.errors import PlcConfigError  # noqa: E402

from can_master_helpers import Frames, master, remap_sync, trajectory, wait_for  # noqa: E402

_channels = itertools.count()


def channel(request) -> str:
    return f"plcrt-bus-{request.node.name}-{next(_channels)}"[:60]


@pytest.fixture
def local(request):
    """A drive network and a master network on one in-process channel."""
    name = channel(request)
    dev, mst = cia402.bus(name), cia402.bus(name)
    yield dev, mst
    mst.disconnect()
    dev.disconnect()


def virtual_pair(name: str):
    dev, mst = canopen.Network(), canopen.Network()
    dev.NOTIFIER_CYCLE = mst.NOTIFIER_CYCLE = 0.02
    dev.connect(interface="virtual", channel=name)
    mst.connect(interface="virtual", channel=name)
    return dev, mst


def run_eight_drives(dev, mst):
    """Eight HCFA drives remapped and saved by their masters, SYNC at 1 ms
    (1006h = 1000 µs), CSP along :func:`trajectory`; drive 27 is blocked by
    a mechanical end at 20 000.  Returns (every TPDO per node, the EMCY
    codes each master saw, the drives' times, TPDOs missing right after a
    SYNC's send returned)."""
    ids = range(20, 28)
    sims = {i: cia402.attach(dev, i, clock="sync",
                             plant=DrivePlant(pos_stop=20_000) if i == 27 else None)
            for i in ids}
    try:
        nodes = {i: master(mst, i) for i in ids}
        pdos = {}
        for i, n in nodes.items():
            n.sdo[0x1006].raw = 1000
            n.sdo[0x6065].raw = 1000
            n.sdo[0x6066].raw = 5
            pdos[i] = remap_sync(n, sims[i])
        tpdos = Frames(mst, *(t.cob_id for t, _ in pdos.values()))
        for i in ids:
            nodes[i].nmt.state = "OPERATIONAL"
            assert wait_for(lambda: sims[i].drive.esm.state is EsmState.OP)
        late = 0
        steps = [(cw, 0) for cw in (0x06, 0x07, 0x0F, 0x0F)]
        steps += [(0x0F, trajectory(j)) for j in range(120)]
        for k, (cw, target) in enumerate(steps, 1):
            for i in ids:
                rpdo = pdos[i][1]
                rpdo[0x6040].raw, rpdo[0x607A].raw = cw, target
                rpdo.transmit()
            mst.sync.transmit()
            late += sum(len(v) < k for v in tpdos.got.values())
            tpdos.wait_all(k)
        assert wait_for(lambda: nodes[27].emcy.active)
        got = {pdos[i][0].cob_id: [struct.unpack("<iH", d) for d in tpdos.got[pdos[i][0].cob_id]]
               for i in ids}
        emcy = {i: [e.code for e in nodes[i].emcy.log] for i in ids}
        return got, emcy, [sims[i].drive.now for i in ids], late
    finally:
        for s in sims.values():
            s.close()


def test_eight_drives_give_the_same_positions_over_both_buses(request):
    """The differential test: the same masters, remaps and set-points over
    python-can's virtual bus and over the in-process bus give the same TPDO
    of every drive at every SYNC; the position of SYNC k + 1 is the target
    of SYNC k; the blocked drive's following error (8611h) reaches its
    master as EMCY on both.  Over the in-process bus every TPDO of a SYNC
    has reached the master when ``sync.transmit()`` returns."""
    name = channel(request)
    dev, mst = virtual_pair(name)
    try:
        by_virtual = run_eight_drives(dev, mst)
    finally:
        mst.disconnect()
        dev.disconnect()
    dev, mst = cia402.bus(name), cia402.bus(name)
    try:
        by_local = run_eight_drives(dev, mst)
    finally:
        mst.disconnect()
        dev.disconnect()
    got, emcy, times, late = by_local
    assert got == by_virtual[0]
    assert emcy == by_virtual[1] == {i: [0x8611] if i == 27 else [] for i in range(20, 28)}
    assert times == by_virtual[2] == [124_000] * 8
    assert late == 0
    for cob_id, seen in got.items():
        for j in range(1, 120):
            pos, sw = seen[4 + j]
            if cob_id != 0x180 + 27 or trajectory(j - 1) <= 20_000:
                assert pos == trajectory(j - 1), (hex(cob_id), j)
        assert all(sw & 0x6F == 0x27 for _, sw in seen[4:5])          # OPERATION ENABLED


def test_emcy_and_the_drives_sdo_aborts_over_the_in_process_bus(local):
    """A fault's EMCY is in ``node.emcy.active`` as soon as the write that
    caused it returns, the reset's 0000h clears it; a missing subindex is
    the drive's own abort 0x06090011 (6041h:01), a missing object 0x06020000."""
    dev, mst = local
    sim = cia402.attach(dev, 5, clock="manual", plant=DrivePlant(pos_stop=1_000))
    try:
        n = master(mst, 5)
        for index, sub, code in ((0x6041, 1, 0x06090011), (0x6007, 0, 0x06020000)):
            with pytest.raises(canopen.SdoAbortedError) as e:
                n.sdo.upload(index, sub)
            assert e.value.code == code
        n.sdo[0x6065].raw = 100
        n.sdo[0x6066].raw = 5
        n.sdo[0x6060].raw = 8
        for cw in (0x06, 0x07, 0x0F):
            n.sdo[0x6040].raw = cw
        n.sdo[0x607A].raw = 5_000                      # past the mechanical end
        sim.advance("20ms")
        assert [e.code for e in n.emcy.active] == [0x8611]
        assert n.sdo[0x1001].raw == 0x01
        n.sdo[0x607A].raw = sim.drive.read(0x6064)
        n.sdo[0x6040].raw = 0x00
        n.sdo[0x6040].raw = 0x80                       # the reset edge (transition 15)
        assert not n.emcy.active
        assert [e.code for e in n.emcy.log] == [0x8611, 0x0000]
    finally:
        sim.close()


def test_pdos_act_in_operational_only_over_the_in_process_bus(local):
    """CiA 301 §7.3.2.2 Table 36 as over the virtual bus: no PDO before
    OPERATIONAL (the RPDO ignored and logged), none in STOPPED, no SDO
    answer in STOPPED."""
    dev, mst = local
    sim = cia402.attach(dev, 10, clock="sync")
    try:
        n = master(mst, 10)
        tpdo, rpdo = remap_sync(n, sim, tx=(0x6041,))
        tpdos = Frames(mst, tpdo.cob_id)
        mst.sync.transmit()
        rpdo[0x6040].raw = 0x06
        rpdo.transmit()
        mst.sync.transmit()
        assert any("RPDO ignored" in e.text for e in sim.drive.log)
        assert tpdos.got[tpdo.cob_id] == []
        assert sim.drive.sm.state is State.SWITCH_ON_DISABLED
        n.nmt.state = "OPERATIONAL"
        assert sim.drive.esm.state is EsmState.OP              # at once: no thread between
        mst.sync.transmit()
        assert len(tpdos.got[tpdo.cob_id]) == 1
        rpdo.transmit()
        mst.sync.transmit()
        assert sim.drive.sm.state is State.READY_TO_SWITCH_ON
        n.nmt.state = "STOPPED"
        assert sim.drive.esm.state is EsmState.SAFEOP
        mst.sync.transmit()
        assert len(tpdos.got[tpdo.cob_id]) == 2
        n.sdo.RESPONSE_TIMEOUT = 0.05
        with pytest.raises(canopen.SdoCommunicationError):
            n.sdo[0x6041].raw
        assert any("not answered in NMT STOPPED" in e.text for e in sim.drive.log)
    finally:
        sim.close()


def test_a_29_bit_frame_is_not_an_sdo_request_over_the_in_process_bus(local):
    """The port's filter stands in front of the network's dispatch here too."""
    dev, mst = local
    sim = cia402.attach(dev, 5, clock="manual")
    try:
        answers = []
        mst.subscribe(0x585, lambda *a: answers.append(a))
        mst.send_message(0x605, b"\x40\x41\x60\x00\0\0\0\0")  # 11-bit: answered
        assert len(answers) == 1
        mst.bus.send(can.Message(arbitration_id=0x605, is_extended_id=True,
                                 data=b"\x40\x41\x60\x00\0\0\0\0"))
        assert len(answers) == 1
        assert sum("29-bit frame 0x605 dropped" in e.text for e in sim.drive.log) == 1
    finally:
        sim.close()


# --------------------------------------------------------------------------- the bus itself

def test_a_frame_reaches_every_other_party_of_its_channel_before_send_returns(request):
    """Delivery in the sender's thread, to every other network of the
    channel and to none of another channel, never back to the sender; all
    receivers get the one frame (no copy: the aliasing rule of can_bus.py)."""
    name = channel(request)
    a, b, c, other = cia402.bus(name), cia402.bus(name), cia402.bus(name), cia402.bus(name + "x")
    try:
        seen: dict[str, list] = {k: [] for k in "abco"}
        for key, net in zip("abco", (a, b, c, other)):
            net.subscribe(0x123, lambda i, d, t, key=key: seen[key].append(
                (d, threading.get_ident())))
        a.send_message(0x123, b"\x01\x02")
        assert seen["a"] == [] and seen["o"] == []
        (db, tb), = seen["b"]
        (dc, tc), = seen["c"]
        assert bytes(db) == b"\x01\x02" and db is dc
        assert tb == tc == threading.get_ident()
        b.disconnect()
        a.send_message(0x123, b"\x03")
        assert len(seen["b"]) == 1 and len(seen["c"]) == 2
        with pytest.raises(RuntimeError):
            b.send_message(0x123, b"")
    finally:
        for net in (a, c, other):
            net.disconnect()


def test_the_in_process_network_dispatches_a_frame_as_canopens_network_does(request):
    """A subscriber gets the frame's data as a bytearray (python-can's
    type); the node scanner lists the nodes canopen's own Network.notify
    lists for the same frames; a network with a listener of its own gets
    each frame through its listeners, as a can.Message."""
    name = channel(request)
    a, b, c = cia402.bus(name), cia402.bus(name), cia402.bus(name)
    reference = canopen.Network()                  # canopen's dispatch, not connected
    ids = (0x185, 0x605, 0x000, 0x70A, 0x58B, 0x185, 0x08C, 0x7E5)
    try:
        got: list = []
        b.subscribe(0x185, lambda i, d, t: got.append(d))
        heard: list = []

        class Own(can.Listener):
            def on_message_received(self, msg: can.Message) -> None:
                heard.append(msg)

        c.notifier.add_listener(Own())
        for can_id in ids:
            a.send_message(can_id, b"\x05")
            reference.notify(can_id, bytearray(b"\x05"), 0.0)
        assert [(d.__class__, bytes(d)) for d in got] == [(bytearray, b"\x05")] * 2
        assert b.scanner.nodes == reference.scanner.nodes == [5, 10, 11, 12]
        assert c.scanner.nodes == reference.scanner.nodes
        assert [(m.arbitration_id, bytes(m.data)) for m in heard] == [(i, b"\x05") for i in ids]
    finally:
        for net in (a, b, c):
            net.disconnect()


def test_a_receiver_may_send_from_its_callback_and_a_failing_one_is_logged(request, caplog):
    """No lock is held while receivers run: a callback that answers on its
    own network does not deadlock; an exception in a callback is logged as
    canopen's listener logs it and does not reach the sender."""
    name = channel(request)
    a, b = cia402.bus(name), cia402.bus(name)
    try:
        answers = []
        b.subscribe(0x181, lambda i, d, t: b.send_message(0x201, bytes(d)))
        a.subscribe(0x201, lambda i, d, t: answers.append(bytes(d)))
        a.send_message(0x181, b"\x07")
        assert answers == [b"\x07"]

        def broken(can_id, data, timestamp):
            raise ValueError("receiver broke")
        b.subscribe(0x182, broken)
        with caplog.at_level(logging.ERROR, logger="canopen.network"):
            a.send_message(0x182, b"")
        assert "receiver broke" in caplog.text
    finally:
        a.disconnect()
        b.disconnect()


def test_a_periodic_sync_drives_the_drives_from_its_own_thread(local):
    """``network.sync.start(period)`` (python-can's periodic task) reaches
    SYNC-clocked drives over the in-process bus: each SYNC is one bus cycle."""
    dev, mst = local
    sim = cia402.attach(dev, 3, clock="sync")
    try:
        n = master(mst, 3)
        n.nmt.state = "OPERATIONAL"
        start = sim.drive.now
        mst.sync.start(0.002)
        try:
            assert wait_for(lambda: sim.drive.now >= start + 5_000)
        finally:
            mst.sync.stop()
        assert (sim.drive.now - start) % 1_000 == 0
    finally:
        sim.close()


@pytest.mark.parametrize("bad", ["", "x" * 65, "a\nb", 7, None])
def test_a_bad_channel_is_a_config_error(bad):
    with pytest.raises(PlcConfigError, match="cia402.bus: channel"):
        cia402.bus(bad)


def test_connecting_twice_or_with_python_can_arguments_is_a_config_error(request):
    net = cia402.bus(channel(request))
    try:
        with pytest.raises(PlcConfigError, match="connected to .* already"):
            net.connect("other")
    finally:
        net.disconnect()
    with pytest.raises(PlcConfigError, match="channel only, not bitrate, interface"):
        type(net)().connect("x", interface="virtual", bitrate=500_000)


def test_sdo_reads_between_syncs_see_the_drives_current_objects(local):
    """A SYNC samples the TPDOs from values the drive holds for its bus cycle
    and writes its store once; an SDO read that comes between two SYNCs
    still answers the drive's current objects (6064h and 6041h as the axis
    and the state machine give them at the drive's time)."""
    dev, mst = local
    sim = cia402.attach(dev, 9, clock="sync")
    try:
        n = master(mst, 9)
        n.sdo[0x1006].raw = 1000
        tpdo, rpdo = remap_sync(n, sim)
        n.nmt.state = "OPERATIONAL"
        assert wait_for(lambda: sim.drive.esm.state is EsmState.OP)
        d = sim.drive
        steps = [(cw, 0) for cw in (0x06, 0x07, 0x0F, 0x0F)]
        steps += [(0x0F, trajectory(j)) for j in range(40)]
        for k, (cw, target) in enumerate(steps):
            if k % 4 != 3:          # every fourth cycle: a SYNC without a new RPDO
                rpdo[0x6040].raw, rpdo[0x607A].raw = cw, target
                rpdo.transmit()
            mst.sync.transmit()
            if k % 2 == 1:
                assert struct.unpack("<i", n.sdo.upload(0x6064, 0))[0] == d.position, k
                assert struct.unpack("<H", n.sdo.upload(0x6041, 0))[0] == d.statusword, k
        assert d.position == trajectory(39 if 39 % 4 != 3 else 38)
    finally:
        sim.close()
