"""The S7 server's refusals and limits, seen by python-snap7's client: the
200 family's item return codes, read-only and allow-listed writes, PDU
negotiation and PDU limits, connection resources, RUN/STOP and the SZL."""

from __future__ import annotations

import socket
import struct
from collections.abc import Iterator
from typing import Any

import pytest

import plcrt
from plcrt.net.options import Listen
from plcrt.net.s7 import S7Identity, S7Options

from .s7_support import connect, cpu_mode, cr_frame, dt_frame, exchange, header_error, item, \
    job, load, read_items, recv_frames, snap7, wait_for, write_items

Area = snap7.type.Area
WordLen = snap7.type.WordLen


@pytest.fixture
def served() -> Iterator[Any]:
    with plcrt.serve(load(), s7=0) as srv:
        yield srv


@pytest.fixture
def client(served: Any) -> Iterator[Any]:
    c = connect(served.port("s7"))
    yield c
    c.disconnect()


# -- return codes --------------------------------------------------------------
@pytest.mark.parametrize("spec, code", [
    (item(0x84, 0, 2, db=2), 0x03),                 # DB2: the 200 family has DB1 only
    (item(0x84, 0, 2, db=0), 0x03),
    (item(0x80, 0, 2), 0x03),                       # direct peripheral access: not served
    (item(0x03, 0, 2), 0x03),                       # 200 family "system info"
    (item(0x84, 10240 * 8 - 8, 2, db=1), 0x05),     # past the end of V (CPU 226: 10 KiB)
    (item(0x81, 16 * 8, 1), 0x05),                  # IB16
    (item(0x1F, 256, 1, tsize=0x1F), 0x05),         # T256
    (item(0x84, 3, 2, db=1), 0x05),                 # a byte item on a bit address
    (item(0x83, 0, 2, tsize=0x01), 0x03),           # a bit item longer than one bit
    (item(0x83, 0, 2, tsize=0x1F), 0x06),           # a timer size on M
    (item(0x1E, 0, 1, tsize=0x02), 0x06),           # a byte size on the counters
    (item(0x83, 0, 1, tsize=0x42), 0x06),           # no such transport size
])
def test_item_return_codes(client, spec, code) -> None:
    assert read_items(client, [spec]) == [(code, b"")]


def test_python_snap7_reports_the_codes(client) -> None:
    with pytest.raises(Exception, match="0x03"):
        client.db_read(2, 0, 4)
    with pytest.raises(Exception, match="0x05"):
        client.db_read(1, 10238, 4)


def test_one_bad_item_does_not_spoil_the_others(client, served) -> None:
    client.db_write(1, 0, bytearray(b"\x55"))
    out = read_items(client, [item(0x84, 0, 1, db=1), item(0x84, 0, 1, db=9),
                              item(0x82, 0, 1)])
    assert out[0] == (0xFF, b"\x55") and out[1] == (0x03, b"") and out[2][0] == 0xFF


def test_write_size_mismatch_and_read_only_special_memory(client, served) -> None:
    assert write_items(client, [(item(0x84, 0, 2, db=1), 0x04, b"\x01\x02\x03")]) == [0x07]
    # SMB0..SMB29 are read-only on the CPU; SMB30 onwards (port setup) is not
    assert write_items(client, [(item(0x05, 0, 1), 0x04, b"\xff"),
                                (item(0x05, 30 * 8, 1), 0x04, b"\x09")]) == [0x03, 0xFF]
    assert served.call(lambda p: (p.read("SMB30"), p.read("VB0"))) == (9, 0)


def test_read_only_server_refuses_writes_and_mode_changes() -> None:
    with plcrt.serve(load(), s7=0, read_only=True) as srv:
        c = connect(srv.port("s7"))
        assert write_items(c, [(item(0x84, 0, 1, db=1), 0x04, b"\x01")]) == [0x03]
        with pytest.raises(Exception):
            c.db_write(1, 0, bytearray(b"\x01"))
        with pytest.raises(Exception):
            c.plc_stop()
        assert srv.call(lambda p: (p.read("VB0"), p.mode)) == (0, "RUN")
        assert c.db_read(1, 0, 1) == bytearray(b"\x00")      # reads still work
        c.disconnect()


def test_allow_list_lets_only_its_ranges_be_written() -> None:
    with plcrt.serve(load(), s7=0, allow_writes="VB0-VB9,Q0.0-Q0.7,C0-C9") as srv:
        c = connect(srv.port("s7"))
        codes = write_items(c, [(item(0x84, 8 * 8, 2, db=1), 0x04, b"\x01\x02"),   # VB8-9
                                (item(0x84, 9 * 8, 2, db=1), 0x04, b"\x01\x02"),   # VB9-10
                                (item(0x82, 3, 1, tsize=0x01), 0x03, b"\x01"),     # Q0.3
                                (item(0x82, 8 + 3, 1, tsize=0x01), 0x03, b"\x01"),  # Q1.3
                                (item(0x1E, 5, 1, tsize=0x1E), 0x09, b"\x00\x02"),  # C5
                                (item(0x1E, 10, 1, tsize=0x1E), 0x09, b"\x00\x02")])
        assert codes == [0xFF, 0x03, 0xFF, 0x03, 0xFF, 0x03]
        assert srv.call(lambda p: (p.read("VB9"), p.read("VB10"), p.read("C5"), p.read("C10"))) \
            == (2, 0, 2, 0)
        c.disconnect()


# -- PDU size ------------------------------------------------------------------
@pytest.mark.parametrize("ours, asked, got", [(240, 480, 240), (240, 960, 240),
                                              (480, 480, 480), (480, 240, 240)])
def test_pdu_size_is_the_smaller_of_asked_and_ours(ours, asked, got) -> None:
    opts = S7Options(identity=S7Identity(pdu_size=ours))
    with plcrt.serve(load(), s7=opts) as srv:
        c = connect(srv.port("s7"), pdu=asked)
        assert c.pdu_length == got
        c.disconnect()


def test_the_tpdu_size_bounds_the_pdu_size() -> None:
    opts = S7Options(identity=S7Identity(pdu_size=960))
    with plcrt.serve(load(), s7=opts) as srv:
        with socket.create_connection(("127.0.0.1", srv.port("s7")), timeout=5) as s:
            # TPDU 512 asked: the CC says 512 (code 9), and an S7 PDU of
            # 960 would not fit one TPDU: setup answers 509
            setup = job(struct.pack(">BBHHH", 0xF0, 0, 1, 1, 960))
            s.sendall(cr_frame(tpdu=0x09) + dt_frame(setup))
            s.shutdown(socket.SHUT_WR)
            (cc, answer), _ = recv_frames(s)
        assert cc[5] == 0xD0 and b"\xc0\x01\x09" in cc
        assert struct.unpack(">H", answer[-2:])[0] == 509


def test_a_read_larger_than_the_pdu_is_refused_and_python_snap7_splits(served, client) -> None:
    served.call(lambda p: p.mem.areas["V"].__setitem__(slice(0, 1000),
                                                       bytes(i % 251 for i in range(1000))))
    # one item of 300 bytes does not fit a 240-byte PDU: the whole request
    # is answered with the header error 0x8500
    ans = exchange(client, job(bytes([0x04, 1]) + item(0x84, 0, 300, db=1)))
    assert header_error(ans) == 0x8500
    # 222 bytes fit exactly (240 - 18 bytes of headers)
    (rc, data), = read_items(client, [item(0x84, 0, 222, db=1)])
    assert rc == 0xFF and data == bytes(i % 251 for i in range(222))
    # the client splits a long read by the negotiated PDU; the bytes are V's
    assert client.db_read(1, 0, 1000) == bytearray(i % 251 for i in range(1000))


def test_too_many_items_are_refused(client) -> None:
    ans = exchange(client, job(bytes([0x04, 21]) + item(0x83, 0, 1) * 21))
    assert header_error(ans) == 0x8500
    assert len(read_items(client, [item(0x83, 0, 1)] * 19)) == 19


# -- connections ---------------------------------------------------------------
def test_the_pg_connection_is_exclusive_and_other_types_have_their_limits() -> None:
    ident = S7Identity(connections={"PG": 1, "OP": 2, "basic": 1})
    with plcrt.serve(load(), s7=S7Options(identity=ident)) as srv:
        port = srv.port("s7")
        pg = connect(port, ctype=1)
        with pytest.raises(Exception):
            connect(port, ctype=1)
        ops = [connect(port, ctype=2) for _ in range(2)]
        with pytest.raises(Exception):
            connect(port, ctype=2)
        basic = connect(port, ctype=3)
        with pytest.raises(Exception):
            connect(port, ctype=3)
        stats = srv.services["s7"].stats
        assert (stats["refused_PG"], stats["refused_OP"], stats["refused_basic"]) == (1, 1, 1)
        # the ones connected are served; a freed slot is free again
        assert pg.db_read(1, 0, 1) == ops[1].db_read(1, 0, 1) == basic.db_read(1, 0, 1)
        pg.disconnect()
        wait_for(lambda: srv.services["s7"].by_type["PG"] == 0)
        pg = connect(port, ctype=1)
        assert pg.db_read(1, 0, 1) == bytearray(1)
        for c in (pg, basic, *ops):
            c.disconnect()


def test_beyond_max_connections_a_client_is_closed_at_once() -> None:
    opts = S7Options(listen=Listen(port=0), max_connections=2)
    with plcrt.serve(load(), s7=opts) as srv:
        a, b = connect(srv.port("s7"), ctype=2), connect(srv.port("s7"), ctype=3)
        with pytest.raises(Exception):
            connect(srv.port("s7"), ctype=3)
        assert srv.services["s7"].stats["refused"] == 1
        assert a.db_read(1, 0, 1) == b.db_read(1, 0, 1)
        a.disconnect()
        b.disconnect()


# -- RUN / STOP ------------------------------------------------------------------
def test_stop_and_start_switch_the_engines_mode(served, client) -> None:
    # (QB0: QB1 holds the timer's and the counter's coils)
    client.db_write(1, 0, bytearray(b"\x05\x00"))
    wait_for(lambda: served.call(lambda p: p.read("QW0")) == 0x500)
    client.plc_stop()
    assert served.call(lambda p: p.mode) == "STOP"
    assert cpu_mode(client) == 0x04
    # in STOP the program does not run and the physical outputs are off
    assert served.call(lambda p: bytes(p.mem.areas["PQ"][:2])) == b"\x00\x00"
    scans = served.call(lambda p: p.scans)
    client.db_write(1, 0, bytearray(b"\x06\x00"))
    assert client.read_area(Area.MK, 0, 10, 1) == client.read_area(Area.MK, 0, 10, 1)
    assert served.call(lambda p: p.scans) == scans
    client.plc_hot_start()
    assert served.call(lambda p: p.mode) == "RUN"
    assert cpu_mode(client) == 0x08
    wait_for(lambda: served.call(lambda p: p.read("QW0")) == 0x600)
    assert served.call(lambda p: p.scans) > scans


def test_stop_when_stopped_says_so(served, client) -> None:
    client.plc_stop()
    ans = exchange(client, job(b"\x29\x00\x00\x00\x00\x00\x09P_PROGRAM"))
    assert header_error(ans) == 0 and ans[12:14] == b"\x29\x07"
    ans = exchange(client, job(bytes.fromhex("28000000000000fd000009") + b"P_PROGRAM"))
    assert header_error(ans) == 0 and ans[12:14] == b"\x28\x00"
    assert served.call(lambda p: p.mode) == "RUN"


def test_other_pi_services_are_not_implemented(client, served) -> None:
    ans = exchange(client, job(bytes.fromhex("28000000000000fd000005") + b"_GARB"))
    assert header_error(ans) == 0x8104
    assert served.call(lambda p: p.mode) == "RUN"


# -- SZL -------------------------------------------------------------------------
def test_a_configured_identity_is_answered() -> None:
    ident = S7Identity(order_number="6ES7 288-1SR20-0AA0", firmware=(2, 4, 1),
                       module_name="CPU SR20", module_type="CPU SR20 AC/DC/RLY",
                       serial="LINE3-PLC", station="Line 3")
    with plcrt.serve(load(), s7=S7Options(identity=ident)) as srv:
        c = connect(srv.port("s7"))
        info = c.get_cpu_info()
        assert (info.ModuleName, info.ModuleTypeName, info.SerialNumber, info.ASName) == \
            (b"CPU SR20", b"CPU SR20 AC/DC/RLY", b"LINE3-PLC", b"Line 3")
        order = c.get_order_code()
        assert order.OrderCode == b"6ES7 288-1SR20-0AA0"
        assert (order.V1, order.V2, order.V3) == (2, 4, 1)
        c.disconnect()


def test_an_szl_answer_longer_than_the_pdu_comes_in_parts() -> None:
    with plcrt.serve(load(), s7=0) as srv:
        c = connect(srv.port("s7"), pdu=120)
        assert c.pdu_length == 120
        assert c.get_cpu_info().ModuleTypeName == b"CPU ST40 DC/DC/DC"   # 212 bytes of records
        c.disconnect()


def test_an_unknown_szl_id_is_an_error_the_client_sees(client) -> None:
    with pytest.raises(Exception):
        client.read_szl(0x0F12, 0)
    ids = bytes(b & 0xFF for b in client.read_szl(0x0000, 0).Data[:40])
    n = struct.unpack(">H", ids[2:4])[0]
    served_ids = {struct.unpack(">H", ids[4 + 2 * i:6 + 2 * i])[0] for i in range(n)}
    assert {0x0011, 0x001C, 0x0424} <= served_ids
    # one record by its index: 0x001C index 5, the serial number
    szl = client.read_szl(0x001C, 5)
    one = bytes(b & 0xFF for b in szl.Data[:szl.Header.LengthDR])
    assert struct.unpack(">HH", one[:4]) == (34, 1) and one[4:6] == b"\x00\x05"
    assert one[6:20] == b"PLCRT-00000001"
    with pytest.raises(Exception):
        client.read_szl(0x001C, 6)                 # no record 6
    assert cpu_mode(client) == 0x08             # the connection goes on


def test_a_refused_connection_gets_a_cotp_disconnect() -> None:
    ident = S7Identity(connections={"PG": 0, "OP": 1, "basic": 1})
    with plcrt.serve(load(), s7=S7Options(identity=ident)) as srv:
        with socket.create_connection(("127.0.0.1", srv.port("s7")), timeout=5) as s:
            # CR to TSAP 0x0101 (PG, rack 0 slot 1)
            s.sendall(bytes.fromhex("0300001611e00000000100c1020100c2020101c0010a"))
            answer = s.recv(64)
            assert answer[5] == 0x80             # COTP DR


def test_a_read_without_items_is_answered_with_a_frame_error(client) -> None:
    # the placeholder python-snap7 3.3's get_cpu_state() sends (function
    # 0x04 alone): not a request a CPU can serve
    ans = exchange(client, job(b"\x04"))
    assert header_error(ans) == 0x8500
    assert cpu_mode(client) == 0x08             # the connection goes on


@pytest.mark.parametrize("kw", [{"pdu_size": 1000}, {"firmware": (2, 300, 0)},
                                {"firmware": "V2.7"}, {"hardware": -1},
                                {"connections": {"PG": 1, "OP": 100, "basic": 1}},
                                {"module_name": "x" * 33}, {"serial": "Ünicode"}])
def test_a_bad_identity_is_a_config_error(kw) -> None:
    with pytest.raises(plcrt.PlcConfigError):
        S7Identity(**kw)
