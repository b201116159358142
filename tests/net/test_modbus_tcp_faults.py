"""Faults at the Modbus TCP server: malformed MBAP frames (lying lengths,
another protocol id, truncated, random bytes), clients that leave in the
middle of a request or stay silent, and a bounded flood — the server
answers or closes that connection only, other clients are served, the PLC
keeps scanning and memory stays flat (docs/network.md, "Modbus TCP")."""

from __future__ import annotations

import asyncio
import socket
import struct
import threading
import time
import tracemalloc

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

pytest.importorskip("pymodbus")
from pymodbus.client import AsyncModbusTcpClient, ModbusTcpClient  # noqa: E402

import plcrt  # noqa: E402

from .modbus_net_helpers import REACT, closed, mbap, recv_frame, wait_for  # noqa: E402


@pytest.fixture(scope="module")
def served():
    plc = plcrt.load(REACT)
    with plcrt.serve(plc, modbus=0, max_connections=64, idle_timeout=1.0) as s:
        yield s


def connect(s) -> socket.socket:
    return socket.create_connection(("127.0.0.1", s.port("modbus")), timeout=5)


def healthy(s) -> None:
    """A new pymodbus client is served and the PLC scans on."""
    scans = s.call(lambda p: p.scans)
    with ModbusTcpClient("127.0.0.1", port=s.port("modbus"), timeout=5) as c:
        r = c.read_holding_registers(0, count=4)
        assert not r.isError(), r
    wait_for(lambda: s.call(lambda p: p.scans) > scans, what="the PLC scans on")


@pytest.mark.parametrize("length", [0, 1, 255, 0xFFFF])
def test_a_length_field_that_cannot_frame_closes_that_connection(served, length):
    with connect(served) as k, connect(served) as other:
        k.sendall(mbap(bytes((3, 0, 0, 0, 1)), length=length))
        assert closed(k)
        other.sendall(mbap(bytes((3, 0, 0, 0, 1))))     # the other client is served
        assert recv_frame(other) == bytes((3, 2, 0, 0))
    healthy(served)


def test_another_protocol_id_is_dropped_and_the_connection_stays(served):
    with connect(served) as k:
        k.sendall(mbap(bytes((3, 0, 0, 0, 1)), tid=5, proto=1))
        k.sendall(mbap(bytes((3, 0, 0, 0, 1)), tid=6))
        head = k.recv(7)
        assert struct.unpack(">H", head[:2])[0] == 6      # frame 5 got no answer
    assert served.services["modbus"].stats["bad_frames"] >= 1


def test_a_truncated_frame_ends_at_the_idle_timeout(served):
    with connect(served) as k:
        k.sendall(mbap(bytes((3, 0, 0, 0, 1)))[:9])       # 2 of 5 PDU bytes
        t0 = time.monotonic()
        assert closed(k, timeout=5)
        assert 0.8 <= time.monotonic() - t0 < 4            # idle_timeout = 1 s
    healthy(served)


def test_clients_that_leave_mid_request_cost_only_their_connection(served):
    for cut in (3, 7, 10):
        k = connect(served)
        k.sendall(mbap(bytes((16, 0, 0, 0, 2, 4, 0, 1, 0, 2)))[:cut])
        k.close()
    # a request sent and the socket closed (with a reset) before the answer
    for _ in range(20):
        k = connect(served)
        k.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        k.sendall(mbap(bytes((3, 0, 0, 0, 120))))
        k.close()
    healthy(served)
    svc = served.services["modbus"]
    wait_for(lambda: svc.connections == 0, what="every connection closed")
    assert svc.stats["server_errors"] == 0


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.one_of(
    st.binary(max_size=300),
    st.builds(lambda tid, pid, unit, pdu: mbap(pdu, tid=tid, unit=unit, proto=pid),
              st.integers(0, 0xFFFF), st.sampled_from([0, 0, 0, 1, 0xFFFF]),
              st.integers(0, 255), st.binary(min_size=0, max_size=260)),
    st.builds(lambda fn, body: mbap(bytes((fn,)) + body),
              st.sampled_from([1, 2, 3, 4, 5, 6, 15, 16, 0, 0x80, 255]),
              st.binary(max_size=12)),
))
def test_fuzzed_frames_get_an_answer_or_a_close_never_a_crash(served, data):
    with connect(served) as k:
        k.sendall(data)
        k.shutdown(socket.SHUT_WR)
        k.settimeout(5)
        got = b""
        while chunk := k.recv(4096):                  # the server answers, then closes
            got += chunk
        while got:                                    # every answer is a well-formed frame
            assert len(got) >= 9 and got[2:4] == b"\0\0"
            n = struct.unpack(">H", got[4:6])[0]
            pdu = got[7:6 + n]
            assert len(pdu) == n - 1
            assert pdu[0] & 0x80 == 0 or (len(pdu) == 2 and pdu[1] in (1, 2, 3))
            got = got[6 + n:]
    svc = served.services["modbus"]
    assert svc.stats["server_errors"] == 0


def test_fuzz_left_the_server_healthy(served):
    healthy(served)


def test_a_flood_of_clients_is_bounded_and_the_plc_scans_on(served):
    """3 200 requests from 8 clients at once (loopback; a warm-up of 800,
    then 2 400 measured): another client is answered meanwhile, the PLC
    scans on, memory stays flat."""
    port = served.port("modbus")

    async def client(n: int) -> int:
        c = AsyncModbusTcpClient("127.0.0.1", port=port, timeout=10)
        await c.connect()
        done = 0
        for i in range(n):
            r = await (c.read_holding_registers(0, count=120) if i % 2 else
                       c.write_register(50, i))
            done += not r.isError()
        c.close()
        return done

    async def flood(per: int) -> list[int]:
        return list(await asyncio.gather(*(client(per) for _ in range(8))))

    other: list[float] = []                           # another client's answer times
    stop = threading.Event()

    def bystander() -> None:
        with ModbusTcpClient("127.0.0.1", port=port, timeout=10) as c:
            while not stop.is_set():
                t = time.monotonic()
                assert not c.read_coils(0, count=16).isError()
                other.append(time.monotonic() - t)

    scans0 = served.call(lambda p: p.scans)
    asyncio.run(flood(100))                            # warm up: every path allocated
    tracemalloc.start()
    side = threading.Thread(target=bystander)
    try:
        before = tracemalloc.get_traced_memory()[0]
        t0 = time.monotonic()
        side.start()
        done = asyncio.run(flood(300))
        wall = time.monotonic() - t0
        stop.set()
        side.join(10)
        healthy(served)
        after = tracemalloc.get_traced_memory()[0]
    finally:
        stop.set()
        tracemalloc.stop()
    assert done == [300] * 8
    assert len(other) >= 10 and max(other) < 5.0, (len(other), max(other, default=0))
    assert after - before < 2_000_000, after - before
    svc = served.services["modbus"]
    assert served.door.waiting == 0 and svc.stats["server_errors"] == 0
    # real time: the PLC ran scans all along (10 ms scans: about wall / 10 ms)
    scans = served.call(lambda p: p.scans) - scans0
    scan_s = served.call(lambda p: p.scan_us) / 1e6
    assert scans >= 0.25 * wall / scan_s, (scans, wall)


def test_a_pipelined_burst_is_answered_in_order(served):
    with connect(served) as k:
        burst = b"".join(mbap(bytes((3, 0, 0, 0, 1)), tid=i) for i in range(2000))
        k.sendall(burst)
        tids = []
        for _ in range(2000):
            head = k.recv(7, socket.MSG_WAITALL)
            tids.append(struct.unpack(">H", head[:2])[0])
            k.recv(struct.unpack(">H", head[4:6])[0] - 1, socket.MSG_WAITALL)
        assert tids == list(range(2000))
