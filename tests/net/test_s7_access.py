"""The S7 server's data access, driven by python-snap7's client while a
ladder program reacts: V as DB1, I, Q, M, SM, AI/AQ, timers and counters
by the 200 family's and the S7-300's area codes, bits, words, reals,
multi-item reads and writes."""

from __future__ import annotations

import struct
from collections.abc import Iterator
from typing import Any

import pytest

import plcrt

from .s7_support import connect, cpu_mode, item, load, read_items, snap7, wait_for, write_items

Area = snap7.type.Area
WordLen = snap7.type.WordLen


@pytest.fixture
def served() -> Iterator[tuple[Any, Any]]:
    plc = load()
    with plcrt.serve(plc, s7=0, speed="realtime") as srv:
        wait_for(lambda: srv.call(lambda p: p.scans) > 0)   # SMB0 is set by a scan
        yield plc, srv


@pytest.fixture
def client(served: tuple[Any, Any]) -> Iterator[Any]:
    c = connect(served[1].port("s7"))
    yield c
    c.disconnect()


def test_v_memory_is_db1_and_the_program_copies_it_to_q(served, client) -> None:
    _, srv = served
    client.db_write(1, 0, bytearray(b"\x12\x34"))
    # the program moves VW0 to QW0 at its next scan
    wait_for(lambda: client.read_area(Area.PA, 0, 0, 2) == bytearray(b"\x12\x34"))
    assert srv.call(lambda p: p.read("VW0")) == 0x1234
    assert srv.call(lambda p: p.read("QW0")) == 0x1234
    assert client.db_read(1, 0, 2) == bytearray(b"\x12\x34")


def test_a_written_input_holds_and_starts_a_timer(served, client) -> None:
    _, srv = served
    client.write_area(Area.PE, 0, 0, bytearray(b"\x01"))          # I0.0
    # the input holds over the scans (the physical input is written too)
    wait_for(lambda: client.read_area(Area.PA, 0, 1, 1)[0] & 1)   # Q1.0 after T33
    assert client.read_area(Area.PE, 0, 0, 1) == bytearray(b"\x01")
    assert srv.call(lambda p: p.read("I0.0")) == 1
    value = srv.call(lambda p: p.read("T33"))
    assert value >= 20
    # the 200 family's timer area (0x1F) and the S7-300's (0x1D) read the
    # same current value; elements are addressed by number
    (rc1, v1), = read_items(client, [item(0x1F, 33, 1, tsize=0x1F)])
    v2 = client.read_area(Area.TM, 0, 33, 1)
    assert rc1 == 0xFF and struct.unpack(">H", v1)[0] >= value
    assert struct.unpack(">H", bytes(v2))[0] >= value


def test_counter_counts_client_pulses_and_is_read_by_both_codes(served, client) -> None:
    _, srv = served
    for _ in range(3):
        for level in (b"\x01", b"\x00"):                    # I0.1 on, then off
            client.write_area(Area.PE, 0, 1, bytearray(level), WordLen.Bit)
            # the write has landed (its answer came); a scan after this
            # boundary sees it
            before = srv.call(lambda p: p.scans)
            wait_for(lambda: srv.call(lambda p: p.scans) > before)
    assert srv.call(lambda p: p.read("C5")) == 3
    (rc, v), = read_items(client, [item(0x1E, 5, 1, tsize=0x1E)])
    assert (rc, v) == (0xFF, b"\x00\x03")
    assert client.read_area(Area.CT, 0, 5, 1) == bytearray(b"\x00\x03")
    wait_for(lambda: client.read_area(Area.PA, 0, 1, 1)[0] & 2)      # Q1.1: C5 reached 3
    # a client writes a counter's current value (0x1E, octet string)
    assert write_items(client, [(item(0x1E, 5, 1, tsize=0x1E), 0x09, b"\x00\x07")]) == [0xFF]
    assert srv.call(lambda p: p.read("C5")) == 7


def test_m_bits_and_words(served, client) -> None:
    _, srv = served
    client.write_area(Area.MK, 0, 0, bytearray(b"\x01"), WordLen.Bit)      # M0.0
    wait_for(lambda: client.read_area(Area.MK, 0, 1, 1, WordLen.Bit) == bytearray(b"\x01"))
    assert srv.call(lambda p: p.read("M0.1")) == 1
    client.write_area(Area.MK, 0, 20, bytearray(b"\xbe\xef"))
    assert srv.call(lambda p: p.read("MW20")) == struct.unpack(">h", b"\xbe\xef")[0]
    # MB10 counts scans: two reads a while apart differ
    a = client.read_area(Area.MK, 0, 10, 1)[0]
    wait_for(lambda: client.read_area(Area.MK, 0, 10, 1)[0] != a)


def test_real_and_dword_transport_sizes(served, client) -> None:
    _, srv = served
    client.write_area(Area.DB, 1, 100, bytearray(struct.pack(">f", 3.25)), WordLen.Real)
    assert srv.call(lambda p: p.read("VD100:REAL")) == 3.25
    raw = client.read_area(Area.DB, 1, 100, 1, WordLen.Real)
    assert struct.unpack(">f", bytes(raw))[0] == 3.25
    (rc, v), = read_items(client, [item(0x84, 100 * 8, 1, tsize=0x06, db=1)])
    assert rc == 0xFF and v == struct.pack(">f", 3.25)


def test_read_multi_vars_over_areas_is_one_scan_boundary(served, client) -> None:
    _, srv = served
    client.db_write(1, 10, bytearray(b"\xaa\xbb\xcc"))
    client.use_optimizer = False
    code, data = client.read_multi_vars([
        {"area": Area.DB, "db_number": 1, "start": 10, "size": 3},
        {"area": Area.PA, "start": 0, "size": 2},
        {"area": Area.MK, "start": 0, "size": 4},
    ])
    assert code == 0 and data[0] == bytearray(b"\xaa\xbb\xcc")
    # raw: items of several areas, sizes and fill bytes in one request
    out = read_items(client, [item(0x84, 80, 3, db=1), item(0x83, 0, 1, tsize=0x01),
                              item(0x83, 10 * 8, 1), item(0x05, 0, 1, tsize=0x01)])
    assert [rc for rc, _ in out] == [0xFF] * 4
    assert out[0][1] == b"\xaa\xbb\xcc"
    assert out[3][1] == b"\x01"                    # SM0.0: always on in RUN


def test_write_multi_items_land_together(served, client) -> None:
    _, srv = served
    codes = write_items(client, [
        (item(0x84, 200 * 8, 3, db=1), 0x04, b"\x01\x02\x03"),
        (item(0x83, 30 * 8 + 3, 1, tsize=0x01), 0x03, b"\x01"),
        (item(0x07, 4 * 8, 1, tsize=0x04), 0x04, b"\x12\x34"),       # AQW4
    ])
    assert codes == [0xFF, 0xFF, 0xFF]
    got = srv.call(lambda p: (p.read("VB200"), p.read("VB202"), p.read("M30.3"), p.read("AQW4")))
    assert got == (1, 3, 1, 0x1234)


def test_analog_inputs_written_and_read(served, client) -> None:
    _, srv = served
    assert write_items(client, [(item(0x06, 2 * 8, 1, tsize=0x04), 0x04, b"\x7d\x00")]) == [0xFF]
    assert srv.call(lambda p: p.read("AIW2")) == 0x7D00
    (rc, v), = read_items(client, [item(0x06, 2 * 8, 1, tsize=0x04)])
    assert (rc, v) == (0xFF, b"\x7d\x00")


def test_identity_and_mode_through_the_szl(served, client) -> None:
    info = client.get_cpu_info()
    assert info.ModuleTypeName == b"CPU ST40 DC/DC/DC"
    assert info.ModuleName == b"CPU ST40"
    order = client.get_order_code()
    assert order.OrderCode == b"6ES7 288-1ST40-0AA0"
    assert (order.V1, order.V2, order.V3) == (2, 7, 0)
    assert cpu_mode(client) == 0x08


def test_reads_see_a_scan_boundary_never_half_a_scan(served, client) -> None:
    # MB10 counts scans, MB11 copies it at the end of each scan: read at a
    # scan boundary they are equal; a read in the middle of a scan would
    # see them differ
    seen = set()
    for _ in range(200):
        mb10, mb11 = client.read_area(Area.MK, 0, 10, 2)
        assert mb10 == mb11
        seen.add(mb10)
    assert len(seen) > 1          # the PLC ran meanwhile


def test_in_lockstep_a_write_waits_for_the_next_scan() -> None:
    # the PLC does not run by itself: what a client writes is in the image
    # at once (at this boundary) and reaches the program at the next scan
    with plcrt.serve(load(), s7=0, speed="lockstep") as srv:
        c = connect(srv.port("s7"))
        c.db_write(1, 0, bytearray(b"\x07\x00"))
        assert srv.call(lambda p: (p.scans, p.read("VW0"), p.read("QW0"))) == (0, 0x700, 0)
        assert c.read_area(Area.PA, 0, 0, 2) == bytearray(2)
        srv.call(lambda p: p.scan(1))
        assert c.read_area(Area.PA, 0, 0, 2) == bytearray(b"\x07\x00")
        c.disconnect()
