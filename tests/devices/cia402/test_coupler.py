"""The fieldbus master module (plcrt/devices/cia402/coupler.py) seen from
V memory: the image layout and its byte order, when the bus cycles carry
what a scan wrote, the SDO mailbox's timing and abort codes, the online
bit, the diagnostics, and the plant-file errors of a FIELDBUS module.

The program does nothing: each test writes the image between scans, as a
ladder program would during one, and reads what the module wrote back.
"""

from __future__ import annotations

import re
import struct

import pytest

import plcrt
from plcrt.devices.cia402 import coupler
from plcrt.devices.cia402.coupler import IMAGE_BYTES, IN_LAYOUT, OUT_LAYOUT
from plcrt.devices.cia402.esm import EsmState
from plcrt.errors import PlcAddressError, PlcConfigError

IDLE = "ORGANIZATION_BLOCK MAIN:OB1\nTITLE=t\nBEGIN\nNetwork 1\nLD     SM0.0\nEND_ORGANIZATION_BLOCK\n"
IMG = 1000                 # the image of node 1 in every test plant


def plant(model: str = "hcfa-am0520b", cycle_ms: float = 1, **drive) -> str:
    lines = [f'[module.0]\nkind = "FIELDBUS"\ncycle_ms = {cycle_ms}\n',
             f'[module.0.drive.1]\nmodel = "{model}"\nimage = {IMG}\n']
    for k, v in drive.items():
        lines.append(f"{k} = {v}\n" if not isinstance(v, dict) else
                     f"{k} = {{ {', '.join(f'{n!r}'.replace(chr(39), chr(34)) + f' = {x}' for n, x in v.items())} }}\n")
    return "".join(lines)


def load(model: str = "hcfa-am0520b", scan_ms: float = 10, cycle_ms: float = 1, **drive):
    return plcrt.load(IDLE, plant=plant(model, cycle_ms, **drive), scan_ms=scan_ms)


def vbytes(plc, offset: int, n: int) -> bytes:
    return bytes(plc.read(f"VB{IMG + offset + i}") for i in range(n))


def status(plc) -> int:
    return plc.read(f"VB{IMG + 35}")


def drive(plc):
    return plc.module(0).drive(1)


def enable(plc, mode: int = 1) -> None:
    """Shutdown, switch on, enable operation, each until the drive shows
    its state (a scan may be shorter than the bus cycle)."""
    plc.write(f"VB{IMG + 2}", mode)
    for cw, state in ((0x06, "READY TO SWITCH ON"), (0x07, "SWITCHED ON"),
                      (0x0F, "OPERATION ENABLED")):
        plc.write(f"VW{IMG}", cw)
        for _ in range(100):
            plc.scan()
            if plc.drive(1).state == state:
                break
    assert plc.drive(1).state == "OPERATION ENABLED"


# ---------------------------------------------------------------- layout
def test_the_layout_tables_match_the_module_docstring():
    """The offsets and objects of OUT_LAYOUT/IN_LAYOUT are the table the
    docstring (and docs/cia402.md) give, with no gap and no overlap."""
    doc = coupler.__doc__
    rows = re.findall(r"^(\d+)\s+(WORD|BYTE|DINT|DWORD)\s+(\w+h)?", doc, flags=re.M)
    documented = [(int(off), obj or None) for off, _, obj in rows]
    coded = [(off, f"{obj:04X}h" if obj else None) for off, obj, _ in OUT_LAYOUT + IN_LAYOUT]
    assert documented == coded
    size = {"H": 2, "b": 1, "B": 1, "i": 4, "I": 4}
    for layout, start in ((OUT_LAYOUT, 0), (IN_LAYOUT, 32)):
        at = start
        for off, _, code in layout:
            assert off == at
            at += size[code]
        assert at == start + 32
    assert IMAGE_BYTES == 80


def test_the_output_half_reaches_the_drive_most_significant_byte_first():
    """Bytes written to V arrive as the objects of the table: VW1000 is
    6040h with VB1000 its high byte; signed bytes and DINTs keep their
    sign (6060h, 6098h, 607Ah, 60FFh)."""
    plc = load("kinco-servo")
    image = struct.pack(">HbbiiIII", 0x0006, 1, -17, -123456, -30000, 123456, 250000, 260000)
    for i, b in enumerate(image):
        plc.write(f"VB{IMG + i}", b)
    assert vbytes(plc, 0, 2) == b"\x00\x06" and vbytes(plc, 4, 4) == b"\xff\xfe\x1d\xc0"
    plc.scan()
    get = drive(plc).store.get
    assert [int(get(i, 0)) for i in (0x6040, 0x6060, 0x6098, 0x607A, 0x60FF, 0x6081,
                                      0x6083, 0x6084)] == \
        [0x0006, 1, -17, -123456, -30000, 123456, 250000, 260000]
    assert plc.drive(1).state == "READY TO SWITCH ON"


def test_the_input_half_mirrors_the_drive_after_the_scan():
    """After every scan the input half holds 6041h, 6061h, the module
    status, 6064h, 606Ch, 603Fh, the bus cycle counter (10 per 10 ms scan),
    60F4h, 60FDh, the SDO data and abort,
    big-endian; 60FDh has bit 0 (NLS) and bit 2 (home switch) from the
    plant at position 0."""
    plc = load(neg_limit=0, pos_limit=100000, home_switch="[-10, 10]")
    plc.scan()
    fields = struct.unpack(">HbBiiHHiIiI", vbytes(plc, 32, 32))
    assert fields == (0x0250, 8, 0x01, 0, 0, 0, 10, 0, 0b101, 0, 0)
    assert vbytes(plc, 32, 2) == b"\x02\x50"
    enable(plc)
    for name, value in (("6081", 50000), ("6083", 100000), ("6084", 100000)):
        plc.write(f"VD{IMG + {'6081': 12, '6083': 16, '6084': 20}[name]}", value)
    plc.write(f"VD{IMG + 4}", 0x12345)
    plc.write(f"VW{IMG}", 0x1F)
    for _ in range(40):
        plc.scan()
        d = drive(plc)
        get = d.store.get
        fields = struct.unpack(">HbBiiHHiIiI", vbytes(plc, 32, 32))
        assert fields == (get(0x6041), get(0x6061), 0x01, get(0x6064), get(0x606C),
                          get(0x603F), plc.scans * 10, get(0x60F4), get(0x60FD), 0, 0)
    plc.scan(300)
    assert plc.drive(1).position == 0x12345
    assert vbytes(plc, 36, 4) == b"\x00\x01\x23\x45"


def test_the_program_bytes_64_to_79_are_left_alone():
    plc = load()
    for i in range(64, 80):
        plc.write(f"VB{IMG + i}", i)
    plc.scan(5)
    assert vbytes(plc, 64, 16) == bytes(range(64, 80))


# ---------------------------------------------------------------- timing
@pytest.mark.parametrize("scan_ms,cycle_ms,extra,scan_us,taken_us", [
    (10, 1, 0, 30_000, 31_000),    # the first bus cycle after the scan's start
    (10, 4, 0, 30_000, 32_000),    # cycles at 32, 36 and 40 ms
    (10, 4, 1, 40_000, 44_000),    # the scan's own start is no cycle after it
    (1, 4, 0, 12_000, 16_000),     # no cycle in the scans at 13, 14 and 15 ms
    (1, 4, 2, 14_000, 16_000),
    (1, 0.25, 0, 3_000, 3_250),
])
def test_a_scan_s_outputs_act_at_the_next_bus_cycle(scan_ms, cycle_ms, extra, scan_us,
                                                    taken_us):
    """The module samples the output half after a scan and the drive takes
    it at the first multiple of the bus cycle after that scan's start."""
    plc = load(scan_ms=scan_ms, cycle_ms=cycle_ms)
    enable(plc)
    plc.scan(extra)
    assert round(plc.time * 1e6) == scan_us
    for offset, value in ((4, 1000), (12, 50000), (16, 100000), (20, 100000)):
        plc.write(f"VD{IMG + offset}", value)
    plc.write(f"VW{IMG}", 0x1F)
    plc.scan(10)
    taken = [e for e in drive(plc).log if "set-point" in e.text and "taken" in e.text]
    assert [e.t_us for e in taken] == [taken_us]


def test_ramps_written_with_their_target_in_one_scan_act_on_that_target():
    """6083h and 60FFh written in the same scan: the bus cycle applies the
    profile before the target, so PV ramps on the new 6083h (100000
    counts/s²: 900 counts/s after the 9 ms from the cycle at 31 ms to the
    one at 40 ms), not at once on the old 0."""
    plc = load()
    enable(plc, mode=3)
    plc.write(f"VD{IMG + 16}", 100000)
    plc.write(f"VD{IMG + 8}", 10000)
    plc.scan()
    assert plc.drive(1).velocity == 900 and plc.read(f"VD{IMG + 40}") == 900


def test_without_a_bus_cycle_between_two_scans_the_input_half_stands_still():
    """With a 4 ms bus cycle and 1 ms scans the statusword changes only
    in the scan after a cycle: a program reads the drive's answer to a
    command one bus cycle later, not one scan later."""
    plc = load(scan_ms=1, cycle_ms=4)
    seen = []
    plc.write(f"VW{IMG}", 0x06)
    for _ in range(6):
        plc.scan()
        seen.append((plc.scans, plc.read(f"VW{IMG + 32}")))
    # the scan at 0 ms; cycle at 4 ms, seen after the scan at 3 ms (t_to = 4 ms)
    assert seen == [(1, 0x0250), (2, 0x0250), (3, 0x0250), (4, 0x0631), (5, 0x0631),
                    (6, 0x0631)]


def test_the_bus_cycle_counter_counts_cycles_and_wraps():
    """Offset 46 counts the bus cycles up to the next scan's start: with a
    4 ms cycle and 1 ms scans it moves after the scans at 3 and 7 ms; it
    wraps from 65535 to 0."""
    plc = load(scan_ms=1, cycle_ms=4)
    seen = []
    for _ in range(8):
        plc.scan()
        seen.append(plc.read(f"VW{IMG + 46}"))
    assert seen == [0, 0, 0, 1, 1, 1, 1, 2]
    plc.module(0).cycles = 65535
    plc.scan(4)
    assert plc.read(f"VW{IMG + 46}") == 0


# ---------------------------------------------------------------- SDO mailbox
def sdo(plc, index: int, sub: int, write: bool = False, value: int = 0) -> None:
    plc.write(f"VW{IMG + 24}", index)
    plc.write(f"VB{IMG + 26}", sub)
    plc.write(f"VD{IMG + 28}", value)
    plc.write(f"VB{IMG + 27}", 0x03 if write else 0x01)


def test_sdo_busy_then_done_at_the_second_bus_cycle_and_held_until_req_drops():
    """REQ seen after the scan at 0 ms, 5 ms bus cycle: served at 10 ms;
    the scans at 1..9 ms read busy, those from 10 ms on done with the
    value, as long as REQ stays; REQ low: the flags clear after one scan."""
    plc = load(scan_ms=1, cycle_ms=5, params={"6099:01": 20000})
    sdo(plc, 0x6099, 1)
    flags = []
    for _ in range(14):
        plc.scan()
        flags.append(status(plc))
    assert flags == [0x03] * 9 + [0x05] * 5
    assert plc.read(f"VD{IMG + 56}") == 20000 and plc.read(f"VD{IMG + 60}") == 0
    plc.write(f"VB{IMG + 27}", 0)
    plc.scan()
    assert status(plc) == 0x01
    assert plc.read(f"VD{IMG + 56}") == 20000        # the response stays until the next


def test_sdo_write_then_read_back_a_negative_value():
    plc = load()
    sdo(plc, 0x607C, 0, write=True, value=-250)
    plc.scan()
    assert status(plc) == 0x05 and drive(plc).read(0x607C) == -250
    plc.write(f"VB{IMG + 27}", 0)
    plc.scan()
    sdo(plc, 0x607C, 0)
    plc.scan()
    assert status(plc) == 0x05 and plc.read(f"VD{IMG + 56}") == -250


@pytest.mark.parametrize("index,sub,write,value,abort,words", [
    (0x6007, 0, False, 0, 0x06020000, "does not exist"),
    (0x6099, 7, False, 0, 0x06090011, "6099h"),
    (0x6041, 0, True, 1, 0x06010002, "read-only"),
    (0x6060, 0, True, 300, 0x06070010, "does not fit"),
    (0x6060, 0, True, 9, 0x06090030, "is not one of"),
    (0x1008, 0, False, 0, 0x06070010, "does not fit the mailbox's DINT"),
])
def test_sdo_errors_carry_the_abort_code_and_explain_it(index, sub, write, value, abort, words):
    """Error (status bit 3) with the CiA 301 abort code at image + 60; the
    diagnostics say which object and why; the drive is unchanged."""
    plc = load()
    plc.scan()
    sdo(plc, index, sub, write, value)
    plc.scan()
    assert status(plc) == 0x09
    assert plc.read(f"VD{IMG + 60}") & 0xFFFFFFFF == abort
    assert plc.drive(1).mode == 8 and plc.drive(1).statusword == 0x0250
    [msg] = [d.message for d in plc.diagnostics if "SDO" in d.message]
    assert msg.startswith("fieldbus slot 0 node 1: SDO ")
    assert f"0x{abort:08X}" in msg and words in msg


def test_a_req_edge_while_busy_is_ignored_and_said():
    plc = load(scan_ms=1, cycle_ms=5)
    sdo(plc, 0x6099, 1)
    plc.scan()
    plc.write(f"VB{IMG + 27}", 0)
    plc.scan()
    sdo(plc, 0x6099, 2)
    plc.scan()
    assert any("SDO REQ rose while the request before is busy" in d.message
               for d in plc.diagnostics)
    plc.scan(10)
    assert drive(plc).read(0x6099, 1) == plc.read(f"VD{IMG + 56}")


# ---------------------------------------------------------------- state
def test_the_online_bit_follows_the_drive_s_ethercat_state():
    """Bit 0 of the module status and DriveState.online are 1 in OP; a
    drive that falls back to PRE-OP is offline and leaves OPERATION
    ENABLED (HCFA §6.5)."""
    plc = load()
    enable(plc)
    assert status(plc) & 1 and plc.drive(1).online
    drive(plc).request_esm(EsmState.PREOP)
    plc.scan()
    assert status(plc) & 1 == 0 and not plc.drive(1).online
    assert plc.drive(1).state != "OPERATION ENABLED"


def test_a_refused_controlword_is_in_the_diagnostics():
    """16#000F in SWITCH ON DISABLED skips transitions 2 and 3: the drive
    refuses it and the diagnostics name the way (HCFA §7.2, §7.4.1)."""
    plc = load()
    plc.write(f"VW{IMG}", 0x0F)
    plc.scan()
    assert plc.drive(1).state == "SWITCH ON DISABLED"
    [msg] = [d.message for d in plc.diagnostics if "0x000F" in d.message]
    assert msg.startswith("fieldbus slot 0 node 1: ")
    assert "first 0x0006 Shutdown (2), then 0x0007 Switch on (3)" in msg


def test_drive_states_by_node_and_bad_nodes():
    plc = plcrt.load(IDLE, plant=plant() + '[module.0.drive.7]\nmodel = "kinco-servo"\n')
    assert [(d.slot, d.node, d.model) for d in plc.drives()] == \
        [(0, 1, "hcfa-am0520b"), (0, 7, "kinco-servo")]
    assert plc.drive(7).model == "kinco-servo"
    assert plc.module(0).ports[7].image == IMG + IMAGE_BYTES     # the next free image
    with pytest.raises(PlcAddressError, match="no drive at node 3"):
        plc.drive(3)


def test_a_fork_runs_its_own_drive():
    """Forked after enabling in PV: the original runs at +10000 counts/s,
    the fork at -10000 (6083h = 6084h = 0: at once), from the bus cycle
    after the scan that wrote 60FFh to the cycle before the last scan."""
    plc = load()
    enable(plc, mode=3)
    fork = plc.fork()
    plc.write(f"VD{IMG + 8}", 10000)
    fork.write(f"VD{IMG + 8}", -10000)
    plc.scan(10)
    fork.scan(10)
    assert (plc.drive(1).position, fork.drive(1).position) == (990, -990)
    assert plc.read(f"VD{IMG + 36}") == 990 and fork.read(f"VD{IMG + 36}") == -990


# ---------------------------------------------------------------- plant errors
F = '[module.0]\nkind = "FIELDBUS"\n'
D1 = '[module.0.drive.1]\nmodel = "hcfa-am0520b"\n'


@pytest.mark.parametrize("text,message", [
    (F + '[module.0.drive.1]\nmodel = "acme"\n',
     "module.0.drive.1.model: unknown CiA 402 drive model 'acme'; known models: "
     "hcfa-am0520b, kinco-servo"),
    (F + '[module.0.drive.1]\nmodel = 3\n', "module.0.drive.1.model must name a drive model"),
    (F + D1 + 'image = 1000\n[module.0.drive.2]\nmodel = "kinco-servo"\nimage = 1040\n',
     "module.0.drive.2.image: VB1040..VB1119 overlaps the image of <plant>: module.0.drive.1 "
     "at VB1000"),
    (F + D1 + 'image = 10200\n',
     "module.0.drive.1.image: VB10200..VB10279 is beyond the CPU226's V memory (VB0..VB10239)"),
    (F + D1 + 'params = { "6007:00" = 1 }\n',
     "module.0.drive.1.params.6007:00: the drive refuses 6007h:00 = 1: SDO abort 0x06020000"),
    (F + D1 + 'params = { "2000:02" = 9 }\n',
     "module.0.drive.1.params.2000:02: the drive refuses 2000h:02 = 9: SDO abort 0x06090032"),
    (F + D1 + 'params = { "6060" = 1 }\n',
     "module.0.drive.1.params.6060: 6060h is in the module's process image (VB1002, offset 2)"),
    (F + D1 + 'params = { "6041" = 1 }\n',
     "module.0.drive.1.params.6041: the drive refuses 6041h:00 = 1: SDO abort 0x06010002"),
    (F + D1 + 'params = { "speed" = 9 }\n',
     "module.0.drive.1.params: 'speed' is no object address"),
    (F + D1 + 'params = { "6099:01" = "fast" }\n',
     "module.0.drive.1.params.6099:01 must be an integer, got 'fast'"),
    (F + D1 + 'speed = 3\n', "module.0.drive.1: unknown key(s) speed (known: home_switch, "),
    (F + 'baud = 3\n' + D1, "module.0: unknown key(s) baud (a FIELDBUS module has cycle_ms, "
                            "drive, kind, v)"),
    (F + '[module.0.drive.0]\nmodel = "hcfa-am0520b"\n',
     "module.0.drive.0: the node address must be 1..127"),
    (F, "module.0: a FIELDBUS module needs drives"),
    (F + 'cycle_ms = 0.1\n' + D1, "module.0.cycle_ms must be a whole number of µs from 0.125 "
                                  "to 100 ms, got 0.1"),
    (F + 'v = -1\n' + D1, "module.0.v must be a V byte address (0 or more), got -1"),
    (F + D1 + 'neg_limit = 100\npos_limit = -100\n', "module.0.drive.1: plant: neg_limit = 100 "
                                                     "must lie below pos_limit = -100"),
    (F + D1 + 'home_switch = [5]\n', "module.0.drive.1.home_switch must be [low, high]"),
    (F + D1 + 'index_period = -5\n', "module.0.drive.1: plant: index_period = -5 must be "
                                     "positive"),
])
def test_plant_file_errors_are_located_config_errors(text, message):
    with pytest.raises(PlcConfigError) as e:
        plcrt.load(IDLE, plant=text)
    assert f"<plant>: {message}" in e.value.message


def test_a_module_slot_the_cpu_does_not_have():
    with pytest.raises(PlcConfigError, match=r"module.0: the CPU221 takes 0 expansion module"):
        plcrt.load(IDLE, plant=F + D1, cpu="CPU221")


def test_errors_in_a_plant_file_name_the_file(tmp_path):
    path = tmp_path / "line.toml"
    path.write_text(F + '[module.0.drive.1]\nmodel = "acme"\n', encoding="utf-8")
    with pytest.raises(PlcConfigError) as e:
        plcrt.load(IDLE, plant=str(path))
    assert e.value.message.startswith(f"{path}: module.0.drive.1.model: unknown CiA 402")


# ---------------------------------------------------------------- layout = "mapping"
def _mapped_enable(plc) -> None:
    for cw, state in ((0x06, "READY TO SWITCH ON"), (0x07, "SWITCHED ON"),
                      (0x0F, "OPERATION ENABLED")):
        plc.write(f"VW{IMG}", cw)
        for _ in range(100):
            plc.scan()
            if plc.drive(1).state == state:
                break
    assert plc.drive(1).state == "OPERATION ENABLED"


def test_a_mapping_layout_image_is_the_drives_default_pdo_images():
    """HCFA 1600h (6040h, 607Ah, 60B8h) at offsets 0..7 and 1A00h (6041h,
    603Fh, 6064h, 606Ch, 6061h, 60B9h, 60BAh) from 32, S7 byte order; CSP
    from the image."""
    plc = load(layout='"mapping"')
    _mapped_enable(plc)
    plc.write(f"VD{IMG + 2}", 5000)
    for _ in range(3):
        plc.scan()
    d = drive(plc)
    sw, err, pos, vel, mode = struct.unpack(">HHiib", vbytes(plc, 32, 13))
    assert (sw, err, pos, vel, mode) == (d.statusword, 0, d.position, d.read(0x606C), 8)
    assert pos == 5000
    assert plc.read(f"VB{IMG + 64}") & 0x01                    # online
    assert plc.read(f"VW{IMG + 66}") == plc.module(0).cycles


def test_a_mapping_layout_image_follows_a_remap_of_the_plant_params():
    """The plant's start-up list moves the TxPDO to 1A01h = 6064h, 6041h
    (CoE steps B, D, E, F, G): the input half is now 6064h then 6041h."""
    params = {"1C13": 0, "1A01:01": 0x60640020, "1A01:02": 0x60410010, "1A01:00": 2,
              "1C13:01": 0x1A01, "1C13:00": 1}
    plc = load(layout='"mapping"', params=params)
    _mapped_enable(plc)
    plc.write(f"VD{IMG + 2}", -1234)
    for _ in range(3):
        plc.scan()
    pos, sw = struct.unpack(">iH", vbytes(plc, 32, 6))
    assert (pos, sw) == (-1234, drive(plc).statusword)
    assert vbytes(plc, 38, 4) == bytes(4)                     # nothing beyond the 6 bytes


def test_a_kinco_mapping_layout_with_one_rxpdo():
    """A CANopen model: every map with entries is in force; the start-up list
    leaves RxPDO 1 = 6040h + 607Ah and TxPDO 1 = 6041h + 6064h only."""
    params = {"1601:00": 0, "1602:00": 0, "1603:00": 0, "1600:00": 0, "1600:01": 0x60400010,
              "1600:02": 0x607A0020, "1600:0": 2, "1A01:00": 0, "1A02:00": 0, "1A03:00": 0,
              "1A00:00": 0, "1A00:01": 0x60410010, "1A00:02": 0x60640020, "1A00:0": 2,
              "6060": 8}
    plc = load("kinco-servo", layout='"mapping"', params=params)
    _mapped_enable(plc)
    plc.write(f"VD{IMG + 2}", 777)
    for _ in range(3):
        plc.scan()
    sw, pos = struct.unpack(">Hi", vbytes(plc, 32, 6))
    assert (sw, pos) == (drive(plc).statusword, 777)


@pytest.mark.parametrize("layout, params, words", [
    ('"other"', {}, "layout must be one of"),
    ('"mapping"', {"1C13": 0, "1A01:01": 0x60640020, "1A01:02": 0x60640020, "1A01:03": 0x606C0020,
                   "1A01:04": 0x60F40020, "1A01:00": 4, "1C13:01": 0x1A00, "1C13:02": 0x1A01,
                   "1C13:00": 2}, "image is 35 bytes"),
])
def test_a_mapping_layout_the_image_cannot_hold_is_refused(layout, params, words):
    with pytest.raises(PlcConfigError, match=words):
        load(layout=layout, params=params)
