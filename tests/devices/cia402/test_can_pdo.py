"""The process-data path over CAN, driven by canopen's own master
(``BaseNode402`` / ``RemoteNode``) on python-can's ``virtual`` bus: PDO
remapping honoured or refused with CiA 301's abort codes, transmission
types and SYNC, CSP of eight drives at a 1 ms SYNC in simulated time, EMCY
per fault family, the SDO answers of the drive itself, the library's gaps
filtered, and a quiet start."""

from __future__ import annotations

import itertools
import logging
import struct
import time

import pytest

canopen = pytest.importorskip("canopen")
can = pytest.importorskip("can")

from plcrt import cia402  # noqa: E402
from plcrt.devices.cia402.emcy import EMCY_TABLE, emcy_code  # noqa: E402
from plcrt.devices.cia402.esm import EsmState  # noqa: E402
from plcrt.devices.cia402.plant import DrivePlant  # noqa: E402
from plcrt.devices.cia402.reactions import FAULT_CODES  # noqa: E402
from plcrt.devices.cia402.statemachine import State  # noqa: E402

from can_master_helpers import Frames, master, remap_sync, trajectory, wait_for  # noqa: E402

_channels = itertools.count()
MODELS = ("hcfa-am0520b", "kinco-servo")


@pytest.fixture
def bus(request):
    name = f"plcrt-pdo-{request.node.name}-{next(_channels)}"
    dev, mst = canopen.Network(), canopen.Network()
    dev.NOTIFIER_CYCLE = mst.NOTIFIER_CYCLE = 0.02
    dev.connect(interface="virtual", channel=name)
    mst.connect(interface="virtual", channel=name)
    yield dev, mst
    mst.disconnect()
    dev.disconnect()


def operational(n, sim):
    n.nmt.state = "OPERATIONAL"
    assert wait_for(lambda: sim.drive.esm.state is EsmState.OP)


# --------------------------------------------------------------------------- remapping

@pytest.mark.parametrize("model", MODELS)
def test_a_remapped_tpdo_and_rpdo_are_what_the_drive_sends_and_reads(bus, model):
    """TPDO remapped to 6064h + 6041h (on the Kinco drive: 1A04h) and
    RPDO to 607Ah + 6040h, saved: the frames on the bus have the new layout."""
    dev, mst = bus
    sim = cia402.attach(dev, 7, model, clock="sync")
    try:
        n = master(mst, 7, model)
        tpdo, rpdo = remap_sync(n, sim)
        assert [e.index for e in sim.pdos.entries(sim.pdos.by_map[0x1A00 + sim.tpdo_no - 1])] \
            == [0x6064, 0x6041]
        frames = Frames(mst, tpdo.cob_id)
        operational(n, sim)
        mst.sync.transmit()
        data, = frames.wait(tpdo.cob_id, 1)
        assert len(data) == 6                                   # I32 + U16, nothing else
        pos, sw = struct.unpack("<iH", data)
        assert (pos, sw) == (sim.drive.read(0x6064), sim.drive.statusword)
        # the RPDO's new order: 607Ah first, 6040h second, applied at the next SYNC
        rpdo[0x607A].raw, rpdo[0x6040].raw = 0, 0x06
        rpdo.transmit()
        assert not wait_for(lambda: sim.drive.controlword == 0x06, timeout=0.05)
        mst.sync.transmit()
        assert wait_for(lambda: sim.drive.controlword == 0x06)
        assert sim.drive.sm.state is State.READY_TO_SWITCH_ON
        assert n.sdo[0x1A00 + sim.tpdo_no - 1][0].raw == 2      # read back from the drive
    finally:
        sim.close()


@pytest.mark.parametrize("model", MODELS)
def test_mapping_that_the_drive_cannot_honour_is_refused(bus, model):
    """CiA 301 §7.5.2.35–38: each wrong step aborts with its code and
    changes nothing; the drive keeps sending what its mapping says."""
    dev, mst = bus
    sim = cia402.attach(dev, 8, model, clock="manual")
    try:
        n = master(mst, 8, model)
        t, r = sim.tpdo_no, sim.rpdo_no
        tcom, tmap, rmap = 0x1800 + t - 1, 0x1A00 + t - 1, 0x1600 + r - 1
        before = [n.sdo[tmap][k].raw for k in range(0, 4)]

        def refused(index, sub, value, code):
            with pytest.raises(canopen.SdoAbortedError) as e:
                if sub in n.object_dictionary[index]:
                    n.sdo[index][sub].raw = value
                else:
                    n.sdo.download(index, sub, value.to_bytes(4, "little"))
            assert e.value.code == code, hex(e.value.code)

        refused(tmap, 0, 0, 0x06010000)                 # the PDO is valid (step 1 skipped)
        cob = n.sdo[tcom][1].raw
        refused(tcom, 1, (cob & 0x7FF) + 1, 0x06090030)  # CAN-ID of a valid PDO
        refused(tcom, 1, 0x20000000 | cob, 0x06090030)   # 29-bit CAN-ID
        refused(tcom, 2, 252, 0x06090030)                # RTR-only synchronous
        refused(tcom, 2, 245, 0x06090030)                # reserved
        refused(tcom, 3, 10, 0x06090030)                 # inhibit time of a valid TPDO
        refused(tcom, 0, 6, 0x06010002)                  # highest subindex is read-only
        refused(tcom, 4, 0, 0x06090011)                  # sub 4 is reserved: no such subindex
        n.sdo[tcom][1].raw = cob | 0x80000000            # step 1: PDO not valid
        refused(tmap, 1, 0x60640020, 0x06010000)         # step 2 skipped: sub 0 is 3
        n.sdo[tmap][0].raw = 0                           # step 2
        refused(tmap, 1, 0x60400010, 0x06040041)         # controlword is not TxPDO-mappable
        refused(tmap, 1, 0x60070010, 0x06020000)         # no such object
        refused(tmap, 1, 0x60640010, 0x06040043)         # 6064h is 32 bits
        for k, entry in enumerate((0x60640020, 0x606C0020, 0x60410010), 1):
            n.sdo[tmap][k].raw = entry
        refused(tmap, 0, 3, 0x06040042)                  # 10 bytes > 8
        refused(tmap, 0, 9, 0x06040042)                  # more than 8 entries
        refused(tmap, 0, 4, 0x06040043)                  # entry 4 never written
        n.sdo[tmap][0].raw = 2
        n.sdo[tcom][1].raw = cob                         # step 5: valid again
        assert [n.sdo[tmap][k].raw for k in range(3)] == [2, 0x60640020, 0x606C0020]
        assert before[0] == 3
        n.nmt.state = "OPERATIONAL"
        assert wait_for(lambda: sim.drive.esm.state is EsmState.OP)
        n.sdo[0x1400 + r - 1][1].raw = n.sdo[0x1400 + r - 1][1].raw | 0x80000000
        refused(rmap, 0, 0, 0x08000022)                  # mapping in PRE-OPERATIONAL only
    finally:
        sim.close()


# --------------------------------------------------------------------------- transmission types

def test_transmission_types_every_nth_sync_acyclic_and_event_driven(bus):
    """Type 2: every second SYNC; type 0: at a SYNC after a change only;
    254: on change after the inhibit time, and when the event timer runs out."""
    dev, mst = bus
    sim = cia402.attach(dev, 9, clock="sync")
    try:
        n = master(mst, 9, "hcfa-am0520b")
        tpdo, rpdo = remap_sync(n, sim, tx=(0x6041,), trans=2)
        frames = Frames(mst, tpdo.cob_id)
        operational(n, sim)
        for k in range(1, 7):
            mst.sync.transmit()
            got = frames.wait(tpdo.cob_id, k // 2)
            assert len(got) == k // 2
        assert wait_for(lambda: sim.drive.now == 6000)          # 1006h = 0: 1 ms per SYNC

        n.nmt.state = "PRE-OPERATIONAL"
        assert wait_for(lambda: sim.drive.esm.state is EsmState.PREOP)
        tpdo.trans_type = 0
        tpdo.save()
        operational(n, sim)
        seen = len(frames.got[tpdo.cob_id])
        mst.sync.transmit()                                     # first SYNC: never sent yet
        frames.wait(tpdo.cob_id, seen + 1)
        for _ in range(3):                                      # nothing changes: silent
            mst.sync.transmit()
        assert not wait_for(lambda: len(frames.got[tpdo.cob_id]) > seen + 1, timeout=0.1)
        rpdo[0x6040].raw, rpdo[0x607A].raw = 0x06, 0
        rpdo.transmit()
        mst.sync.transmit()                                     # applied: 0x0250 -> 0x0231
        mst.sync.transmit()                                     # sampled changed: sent
        got = frames.wait(tpdo.cob_id, seen + 2)
        assert struct.unpack("<H", got[-1])[0] & 0x6F == 0x21

        n.nmt.state = "PRE-OPERATIONAL"
        assert wait_for(lambda: sim.drive.esm.state is EsmState.PREOP)
        tpdo.trans_type, tpdo.event_timer, tpdo.inhibit_time = 254, 5, 30   # 5 ms, 3 ms
        tpdo.save()
        operational(n, sim)
        seen = len(frames.got[tpdo.cob_id])
        t0 = sim.drive.now
        stamps = []
        frames_before = seen
        for _ in range(12):
            mst.sync.transmit()
            if wait_for(lambda: len(frames.got[tpdo.cob_id]) > frames_before, timeout=0.05):
                frames_before = len(frames.got[tpdo.cob_id])
                stamps.append(sim.drive.now - t0)
        # sent on entering OPERATIONAL (t0), then every 5 ms of drive time
        assert stamps == [5000, 10000]
    finally:
        sim.close()


def test_pdos_and_sync_act_in_operational_only(bus):
    dev, mst = bus
    sim = cia402.attach(dev, 10, clock="sync")
    try:
        n = master(mst, 10, "hcfa-am0520b")
        tpdo, rpdo = remap_sync(n, sim, tx=(0x6041,), trans=1)
        frames = Frames(mst, tpdo.cob_id)
        mst.sync.transmit()                       # PRE-OPERATIONAL: no TPDO
        rpdo[0x6040].raw = 0x06
        rpdo.transmit()
        mst.sync.transmit()
        assert wait_for(lambda: any("RPDO ignored" in e.text for e in sim.drive.log))
        assert not frames.got[tpdo.cob_id]
        assert sim.drive.sm.state is State.SWITCH_ON_DISABLED
        operational(n, sim)
        mst.sync.transmit()
        assert frames.wait(tpdo.cob_id, 1)
        n.nmt.state = "STOPPED"
        assert wait_for(lambda: sim.drive.esm.state is EsmState.SAFEOP)
        mst.sync.transmit()
        mst.sync.transmit()
        assert not wait_for(lambda: len(frames.got[tpdo.cob_id]) > 1, timeout=0.1)
        n.sdo.RESPONSE_TIMEOUT = 0.1
        with pytest.raises(canopen.SdoCommunicationError):      # no SDO in STOPPED
            n.sdo[0x6041].raw
        assert any("not answered in NMT STOPPED" in e.text for e in sim.drive.log)
    finally:
        sim.close()


# --------------------------------------------------------------------------- CSP at 1 ms SYNC

def test_eight_drives_follow_a_csp_trajectory_exactly_at_a_1ms_sync(bus):
    """Eight HCFA drives in CSP, each SYNC one 1 ms bus cycle (1006h =
    1000 µs): the target of SYNC k is the actual position the TPDO of SYNC
    k + 1 reports, for every drive and cycle; a drive blocked by a
    mechanical end faults with a following error (603Fh 8611h) that its
    master sees as EMCY."""
    dev, mst = bus
    ids = range(20, 28)
    blocked = 27
    sims = {i: cia402.attach(dev, i, clock="sync",
                             plant=DrivePlant(pos_stop=20_000) if i == blocked else None)
            for i in ids}
    try:
        nodes = {i: master(mst, i, "hcfa-am0520b") for i in ids}
        pdos = {}
        for i, n in nodes.items():
            n.sdo[0x1006].raw = 1000
            n.sdo[0x6065].raw = 1000                  # following error window, P
            n.sdo[0x6066].raw = 5                     # time-out, ms
            pdos[i] = remap_sync(n, sims[i])
        frames = Frames(mst, *(t.cob_id for t, _ in pdos.values()))
        for i in ids:
            operational(nodes[i], sims[i])

        def cycle(k, cw, target):
            for i in ids:
                _, rpdo = pdos[i]
                rpdo[0x6040].raw, rpdo[0x607A].raw = cw, target
                rpdo.transmit()
            mst.sync.transmit()
            return {i: struct.unpack("<iH", frames.wait(pdos[i][0].cob_id, k)[k - 1])
                    for i in ids}

        k = 0
        for cw in (0x06, 0x07, 0x0F, 0x0F):       # each TPDO shows the state before its SYNC's RPDO
            k += 1
            seen = cycle(k, cw, 0)
        assert all(sw & 0x6F == 0x27 for _, sw in seen.values())     # OPERATION ENABLED
        base = k
        for j in range(0, 120):
            seen = cycle(base + j + 1, 0x0F, trajectory(j))
            if j == 0:
                continue
            for i in ids:
                pos, sw = seen[i]
                if i != blocked or trajectory(j - 1) <= 20_000:
                    assert pos == trajectory(j - 1), (i, j)
        assert all(sims[i].drive.now == (base + 120) * 1000 for i in ids)
        n = nodes[blocked]
        assert wait_for(lambda: n.emcy.active)
        assert [e.code for e in n.emcy.active] == [0x8611]
        assert sims[blocked].drive.sm.error_code == 0x8611
        assert all(not nodes[i].emcy.log for i in ids if i != blocked)
    finally:
        for s in sims.values():
            s.close()


def test_the_sync_cycle_is_bounded_by_the_hcfa_manual(bus):
    """HCFA §7.4.3: 200 µs to 10 ms; Kinco gives no limit."""
    dev, mst = bus
    sim = cia402.attach(dev, 11, clock="sync")
    kinco = cia402.attach(dev, 12, "kinco-servo", clock="sync")
    try:
        n = master(mst, 11, "hcfa-am0520b")
        for bad in (199, 10_001):
            with pytest.raises(canopen.SdoAbortedError) as e:
                n.sdo[0x1006].raw = bad
            assert e.value.code == 0x06090030
        n.sdo[0x1006].raw = 250
        assert n.sdo[0x1006].raw == 250
        k = master(mst, 12, "kinco-servo")
        k.sdo[0x1006].raw = 50
        assert k.sdo[0x1006].raw == 50
    finally:
        sim.close()
        kinco.close()


# --------------------------------------------------------------------------- EMCY

FAMILIES = sorted({(row.family, row.code_603f) for row in EMCY_TABLE})


@pytest.mark.parametrize("code", [c for _, c in FAMILIES],
                         ids=[f"{f}-{c:#x}" for f, c in FAMILIES])
def test_every_fault_is_an_emcy_in_the_masters_active_list_until_reset(bus, code):
    """Each fault's EMCY code is a CiA 301 error (never 00xxh), 1001h rides
    along and equals the object, 603Fh is in the manufacturer bytes; a
    reset sends 0000h and empties ``node.emcy.active``."""
    dev, mst = bus
    sim = cia402.attach(dev, 13, clock="step")
    try:
        n = master(mst, 13, "hcfa-am0520b")
        fc = FAULT_CODES[code]
        with sim.drive.store.lock:
            sim.drive.fault(sim.drive.now, code, fc.alarm, "injected by the test")
            sim.drive.publish()
            sim._after()
        assert wait_for(lambda: n.emcy.active)
        err, = n.emcy.active
        assert err.code == emcy_code(code) and err.code & 0xFF00
        assert err.register == n.sdo[0x1001].raw == 0x01
        assert err.data[:2] == code.to_bytes(2, "little")
        if not fc.resettable:
            return
        n.sdo[0x6040].raw = 0x00
        n.sdo[0x6040].raw = 0x80                     # the reset edge (transition 15)
        assert wait_for(lambda: not n.emcy.active)
        assert [e.code for e in n.emcy.log] == [emcy_code(code), 0x0000]
        assert n.sdo[0x1001].raw == 0
    finally:
        sim.close()


# --------------------------------------------------------------------------- SDO

@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("index, sub, write, code", [
    (0x6041, 1, None, 0x06090011),         # a subindex of a plain object
    (0x1008, 1, None, 0x06090011),
    (0x6040, 1, b"\x06\x00", 0x06090011),
    (0x1017, 1, None, 0x06090011),         # a CAN-view object too
    (0x6007, 0, None, 0x06020000),
    (0x1010, 1, b"save", 0x06020000),
])
def test_the_drive_answers_every_sdo_itself(bus, model, index, sub, write, code):
    dev, mst = bus
    sim = cia402.attach(dev, 14, model, clock="manual")
    try:
        n = canopen.RemoteNode(14, cia402.object_dictionary(model, node_id=14))
        mst.add_node(n)
        with pytest.raises(canopen.SdoAbortedError) as e:
            if write is None:
                n.sdo.upload(index, sub)
            else:
                n.sdo.download(index, sub, write)
        assert e.value.code == code
        assert sim.drive.read(0x6040) == 0
    finally:
        sim.close()


def test_segmented_transfers_and_refused_block_upload(bus, caplog):
    dev, mst = bus
    sim = cia402.attach(dev, 15, "kinco-servo", clock="manual")
    try:
        n = canopen.RemoteNode(15, cia402.object_dictionary("kinco-servo", node_id=15))
        mst.add_node(n)
        assert n.sdo.upload(0x1008, 0) == b"Kinco servo"          # segmented upload
        with pytest.raises(canopen.SdoAbortedError) as e:
            with n.sdo[0x1008].open("rb", block_transfer=True) as f:
                f.read()
        assert e.value.code == 0x05040001
        with pytest.raises(canopen.SdoAbortedError) as e:          # segmented download
            n.sdo.download(0x1008, 0, b"a longer name", force_segment=True)
        assert e.value.code == 0x06010002
    finally:
        sim.close()


def test_29_bit_and_short_frames_are_not_sdo_requests(bus, caplog):
    """canopen dispatches by identifier alone: the port drops a 29-bit
    0x605 and ignores an SDO frame shorter than 8 bytes, without a traceback."""
    dev, mst = bus
    sim = cia402.attach(dev, 5, clock="manual")
    try:
        answers = Frames(mst, 0x585)
        request = bytes([0x40, 0x41, 0x60, 0, 0, 0, 0, 0])       # upload 6041h
        with caplog.at_level(logging.DEBUG):
            mst.bus.send(can.Message(arbitration_id=0x605, data=request, is_extended_id=True))
            mst.bus.send(can.Message(arbitration_id=0x605, data=request[:3],
                                     is_extended_id=False))
            assert not wait_for(lambda: answers.got[0x585], timeout=0.1)
            mst.send_message(0x605, request)                     # a real one is answered
            data, = answers.wait(0x585, 1)
        assert data[0] == 0x4B and struct.unpack_from("<H", data, 4)[0] == sim.drive.statusword
        assert not [r for r in caplog.records if r.levelno >= logging.WARNING or r.exc_info]
        assert any("29-bit" in e.text for e in sim.drive.log)
        assert any("not answered" in e.text for e in sim.drive.log)
    finally:
        sim.close()


# --------------------------------------------------------------------------- quiet

def test_attaching_a_drive_and_its_master_as_documented_prints_nothing(bus, capsys, caplog):
    """With the CAN view's dictionary and read_pdos=True, BaseNode402 finds
    6040h/6060h in an RPDO and 6041h/6061h in a TPDO: no "fallback to SDO"
    warning, nothing printed."""
    dev, mst = bus
    with caplog.at_level(logging.WARNING):
        sim = cia402.attach(dev, 16)
        try:
            n = master(mst, 16, "hcfa-am0520b")
            n.nmt.state = "OPERATIONAL"
            n.tpdo[sim.tpdo_no].wait_for_reception(timeout=1)
            n.op_mode = "PROFILED POSITION"
            n.state = "OPERATION ENABLED"
            assert n.state == "OPERATION ENABLED"
            assert n.op_mode == "PROFILED POSITION"
        finally:
            sim.close()
    assert not caplog.records
    out = capsys.readouterr()
    assert out.out == out.err == ""


def test_an_event_driven_tpdo_waits_out_its_inhibit_time(bus):
    """Type 254 with an inhibit time of 3 ms (30 x 100 µs) and no event
    timer: the position changes at every 1 ms SYNC, the TPDO leaves every
    third one."""
    dev, mst = bus
    sim = cia402.attach(dev, 17, clock="sync")
    try:
        n = master(mst, 17, "hcfa-am0520b")
        tpdo, rpdo = remap_sync(n, sim, tx=(0x6064,), trans=1)
        tpdo.trans_type, tpdo.inhibit_time, tpdo.event_timer = 254, 30, 0
        tpdo.save()
        sent = []
        tpdo.add_callback(lambda m: sent.append(m[0x6064].raw))
        operational(n, sim)
        for cw in (0x06, 0x07, 0x0F):
            rpdo[0x6040].raw, rpdo[0x607A].raw = cw, 0
            rpdo.transmit()
            mst.sync.transmit()
        for k in range(1, 13):                      # 100 counts per 1 ms bus cycle
            rpdo[0x6040].raw, rpdo[0x607A].raw = 0x0F, 100 * k
            rpdo.transmit()
            mst.sync.transmit()
        assert wait_for(lambda: sim.drive.now == 15_000)
        assert wait_for(lambda: len(sent) >= 5)
        time.sleep(0.05)
        moving = [pos for pos in sent if pos]
        # one TPDO per 3 ms: the positions it carries are 300 counts apart
        assert len(moving) == 4 and all(b - a == 300 for a, b in zip(moving, moving[1:]))
    finally:
        sim.close()


@pytest.mark.parametrize("model", MODELS)
def test_a_pp_move_from_synchronous_pdos(bus, model):
    """PP from the process image: the set-point and the new-set-point bit
    in a synchronous RPDO, the statusword's target-reached bit and the
    position in the synchronous TPDO, at a 2 ms SYNC (1006h)."""
    dev, mst = bus
    sim = cia402.attach(dev, 18, model, clock="sync")
    try:
        n = master(mst, 18, model)
        n.sdo[0x1006].raw = 2000
        for index, value in ((0x6060, 1), (0x6081, 100_000), (0x6083, 1_000_000),
                             (0x6084, 1_000_000)):
            n.sdo[index].raw = value
        tpdo, rpdo = remap_sync(n, sim, tx=(0x6041, 0x6064))
        got = []
        tpdo.add_callback(lambda m: got.append((m[0x6041].raw, m[0x6064].raw)))
        operational(n, sim)
        words = [0x06, 0x07, 0x0F, 0x0F, 0x1F] + [0x0F] * 150     # the move takes 224 ms
        for cw in words:
            rpdo[0x6040].raw, rpdo[0x607A].raw = cw, 12_345
            rpdo.transmit()
            mst.sync.transmit()
        assert wait_for(lambda: len(got) == len(words))
        sw, pos = got[-1]
        assert sw & 0x0400 and pos == 12_345
        assert sim.drive.now == 2000 * len(words)
        first = next(k for k, (s, p) in enumerate(got) if p)
        assert got[first - 1][1] == 0 and 0 < got[first][1] < 12_345    # it ramps, SYNC by SYNC
    finally:
        sim.close()


def test_the_sync_cob_id_is_the_one_in_1005h(bus):
    dev, mst = bus
    sim = cia402.attach(dev, 19, clock="sync")
    try:
        n = master(mst, 19, "hcfa-am0520b")
        with pytest.raises(canopen.SdoAbortedError) as e:
            n.sdo[0x1005].raw = 0x40000080           # bit 30: the drive would produce SYNC
        assert e.value.code == 0x06090030
        n.sdo[0x1005].raw = 0x10
        mst.sync.transmit()                           # 080h: no longer the drive's SYNC
        mst.send_message(0x10, b"")
        assert wait_for(lambda: sim.drive.now == 1000)
        assert not wait_for(lambda: sim.drive.now > 1000, timeout=0.05)
    finally:
        sim.close()


def test_a_masters_periodic_sync_drives_synchronous_tpdos_on_the_wall_clock(bus):
    """canopen's ``network.sync.start(period)`` with the default wall clock:
    a TPDO of type 1 follows every SYNC."""
    dev, mst = bus
    sim = cia402.attach(dev, 21)
    try:
        n = master(mst, 21, "hcfa-am0520b")
        tpdo, _ = remap_sync(n, sim, tx=(0x6041, 0x6064), trans=1)
        frames = Frames(mst, tpdo.cob_id)
        operational(n, sim)
        mst.sync.start(0.005)
        try:
            assert len(frames.wait(tpdo.cob_id, 10)) >= 10
        finally:
            mst.sync.stop()
        assert struct.unpack("<H", frames.got[tpdo.cob_id][-1][:2])[0] == sim.drive.statusword
    finally:
        sim.close()
