"""Faults on the S7 server's connections: malformed TPKT, COTP and S7
frames (a bounded, seeded fuzz of each layer), clients that disconnect in
the middle of a request, half-open sockets, and a bounded flood.  In every
case the server answers or closes that connection only, never logs a
server error, the PLC keeps scanning, and other clients are served."""

from __future__ import annotations

import os
import random
import socket
import struct
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

import plcrt
from plcrt.net.s7 import S7Identity, S7Options

from .s7_support import SETUP, connect, cr_frame, dt_frame, item, job, load, recv_frames, \
    tpkt, wait_for

#: fuzz cases per layer (seeded: the same cases every run)
CASES = 120


@pytest.fixture
def served() -> Iterator[Any]:
    with plcrt.serve(load(), s7=0, idle_timeout=2.0, max_connections=32) as srv:
        wait_for(lambda: srv.call(lambda p: p.scans) > 0)
        yield srv


def _raw(srv: Any) -> socket.socket:
    return socket.create_connection(("127.0.0.1", srv.port("s7")), timeout=5)


def _healthy(srv: Any) -> None:
    """The server logged no error of its own, the PLC scans, a new client
    is served."""
    svc = srv.services["s7"]
    assert svc.stats["server_errors"] == 0
    before = srv.call(lambda p: p.scans)
    c = connect(srv.port("s7"))
    c.db_write(1, 50, bytearray(b"\x42"))
    assert c.db_read(1, 50, 1) == bytearray(b"\x42")
    c.disconnect()
    wait_for(lambda: srv.call(lambda p: p.scans) > before)
    assert srv.call(lambda p: p.mode) == "RUN"


def _answers_are_s7(frames: list[bytes]) -> None:
    for f in frames:
        body = f[4:]
        if body[1] in (0xD0, 0x80):          # COTP CC or DR
            continue
        assert body[:3] == b"\x02\xf0\x80"
        assert body[3] == 0x32 and body[4] in (0x03, 0x07)


def _mutate(rng: random.Random, data: bytes) -> bytes:
    b = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        kind = rng.randrange(4)
        if kind == 0 and b:
            b[rng.randrange(len(b))] = rng.randrange(256)
        elif kind == 1 and b:
            del b[rng.randrange(len(b)):]
        elif kind == 2:
            b += bytes(rng.randrange(256) for _ in range(rng.randint(1, 30)))
        elif b:
            i = rng.randrange(len(b))
            b[i:i + 2] = struct.pack(">H", rng.choice([0, 1, 0xFF, 0xFFFF, len(b),
                                                      rng.randrange(65536)]))
    return bytes(b)


def _fix_lengths(rng: random.Random, pdu: bytes) -> bytes:
    """Make a mutant's S7 header lengths add up again, so that it reaches
    the parameter and data parsers instead of being closed at the header."""
    if len(pdu) < 10:
        return pdu
    plen = min(pdu[6] << 8 | pdu[7], len(pdu) - 10)
    return pdu[:6] + struct.pack(">HH", plen, len(pdu) - 10 - plen) + pdu[10:]


def _send(srv: Any, data: bytes) -> tuple[list[bytes], bool]:
    with _raw(srv) as s:
        s.sendall(data)
        s.shutdown(socket.SHUT_WR)          # the client has said all it will say
        return recv_frames(s)


def test_fuzz_tpkt(served) -> None:
    rng = random.Random(1006)
    good = cr_frame() + dt_frame(SETUP)
    for _ in range(CASES):
        head = bytes(rng.randrange(256) for _ in range(4)) if rng.random() < 0.5 else \
            struct.pack(">BBH", 3, 0, rng.choice([0, 1, 4, 6, 7, 1031, 1032, 0xFFFF]))
        frames, closed = _send(served, head + good[4:] if rng.random() < 0.5 else head)
        assert closed
        _answers_are_s7(frames)
    _healthy(served)


def test_fuzz_cotp(served) -> None:
    rng = random.Random(8073)
    templates = [cr_frame()[4:], cr_frame(0x0101)[4:], b"\x02\xf0\x80" + SETUP,
                 b"\x06\x80\x00\x01\x00\x01\x00", b"\x02\xf0\x00" + SETUP[:5]]
    for _ in range(CASES):
        body = _mutate(rng, rng.choice(templates))[:1020] or b"\x00"
        frames, closed = _send(served, tpkt(body) + dt_frame(SETUP))
        assert closed
        _answers_are_s7(frames)
    _healthy(served)


def test_fuzz_s7(served) -> None:
    rng = random.Random(0x32)
    templates = [
        SETUP,
        job(bytes([0x04, 2]) + item(0x84, 0, 4, db=1) + item(0x1F, 33, 2, tsize=0x1F)),
        job(bytes([0x05, 1]) + item(0x84, 64 * 8, 2, db=1), b"\x00\x04\x00\x10\x12\x34"),
        job(bytes([0x05, 1]) + item(0x83, 3, 1, tsize=0x01), b"\x00\x03\x00\x01\x01"),
        bytes.fromhex("3207000000010008000800011204114401ff09000400110000"),
        bytes.fromhex("320700000002000c000400011208124401010000000000000a000000"),
    ]
    probe = dt_frame(job(bytes([0x04, 1]) + item(0x84, 0, 1, db=1)))
    answered = 0
    for _ in range(CASES):
        pdu = _mutate(rng, rng.choice(templates))[:1000]
        if rng.random() < 0.7:
            pdu = _fix_lengths(rng, b"\x32" + pdu[1:])
        frames, closed = _send(served, cr_frame() + dt_frame(SETUP) + dt_frame(pdu) + probe)
        assert closed
        _answers_are_s7(frames)
        answered += len(frames) == 4          # CC, setup, the mutant's answer, the probe's
    assert answered > CASES // 4              # many mutants are answered, not closed
    _healthy(served)


def test_a_pdu_split_over_cotp_segments_is_reassembled_and_bounded(served) -> None:
    read = job(bytes([0x04, 1]) + item(0x84, 0, 2, db=1))
    with _raw(served) as s:
        s.sendall(cr_frame() + dt_frame(SETUP))
        s.sendall(tpkt(b"\x02\xf0\x00" + read[:7]) + tpkt(b"\x02\xf0\x80" + read[7:]))
        s.shutdown(socket.SHUT_WR)
        frames, closed = recv_frames(s)
    assert closed and len(frames) == 3 and frames[2][7:9] == b"\x32\x03"
    # segments that never end are cut off past the longest PDU
    with _raw(served) as s:
        s.sendall(cr_frame() + tpkt(b"\x02\xf0\x00" + bytes(1000)) * 3)
        frames, closed = recv_frames(s)
    assert closed and len(frames) == 1
    _healthy(served)


def test_client_disconnecting_mid_request(served) -> None:
    read = dt_frame(job(bytes([0x04, 1]) + item(0x84, 0, 200, db=1)))
    for cut in (2, 5, len(read) - 1, len(read)):
        s = _raw(served)
        s.sendall(cr_frame() + dt_frame(SETUP) + read[:cut])
        # a reset, not a polite close: SO_LINGER 0
        s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        s.close()
    wait_for(lambda: served.services["s7"].connections == 0)
    _healthy(served)


def test_half_open_sockets_are_closed_after_the_idle_timeout(served) -> None:
    silent = _raw(served)                          # connected, says nothing
    half = _raw(served)
    half.sendall(cr_frame() + dt_frame(SETUP) + b"\x03\x00")   # half a TPKT header, then silence
    t0 = time.monotonic()
    c = connect(served.port("s7"))                 # others are served meanwhile
    assert c.db_read(1, 0, 1) == bytearray(1)
    for s in (silent, half):
        _, closed = recv_frames(s, timeout=10.0)
        assert closed
        s.close()
    assert 1.5 < time.monotonic() - t0 < 10.0       # idle_timeout=2 s (a loaded machine)
    assert served.services["s7"].stats["idle_or_closed"] >= 2
    c.disconnect()
    _healthy(served)


def test_a_client_that_never_reads_its_answers_costs_only_its_connection() -> None:
    # 960-byte answers: 9000 of them fill the loopback buffers, and the
    # server's answers to this client back up
    opts = S7Options(identity=S7Identity(pdu_size=960))
    with plcrt.serve(load(), s7=opts) as served:
        svc = served.services["s7"]
        read = dt_frame(job(bytes([0x04, 1]) + item(0x84, 0, 940, db=1)))
        stuck = socket.socket()
        stuck.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        stuck.connect(("127.0.0.1", served.port("s7")))
        stuck.sendall(cr_frame() + dt_frame(job(struct.pack(">BBHHH", 0xF0, 0, 1, 1, 960))))
        stuck.settimeout(0.5)
        try:
            for _ in range(9000):
                stuck.sendall(read)
        except (TimeoutError, OSError):
            pass

        def backed_up() -> bool:
            before = svc.stats["requests"]
            time.sleep(0.3)
            return svc.stats["requests"] == before
        wait_for(backed_up, timeout=30)
        assert svc.stats["requests"] < 9000
        scans = served.call(lambda p: p.scans)
        c = connect(served.port("s7"))
        for _ in range(20):
            assert c.db_read(1, 0, 4) == bytearray(4)
        wait_for(lambda: served.call(lambda p: p.scans) > scans + 5)
        c.disconnect()
        stuck.close()
        assert svc.stats["server_errors"] == 0


def _rss_kib() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * (os.sysconf("SC_PAGE_SIZE") // 1024)


def _flood(served: Any, n: int) -> list[bytes]:
    """``n`` read requests pipelined on one connection while another client
    is served; returns every frame received; asserts the door stays
    bounded and the PLC scans."""
    read = dt_frame(job(bytes([0x04, 1]) + item(0x83, 10 * 8, 2)))
    got: list[bytes] = []
    sock = _raw(served)
    sock.sendall(cr_frame() + dt_frame(SETUP))

    def sender() -> None:
        for _ in range(n):
            sock.sendall(read)

    def receiver() -> None:
        sock.settimeout(30)
        buf = b""
        while len(got) < n + 2:
            chunk = sock.recv(65536)
            if not chunk:
                return
            buf += chunk
            while len(buf) >= 4 and len(buf) >= (buf[2] << 8 | buf[3]):
                k = buf[2] << 8 | buf[3]
                got.append(buf[:k])
                buf = buf[k:]

    scans0 = served.call(lambda p: p.scans)
    threads = [threading.Thread(target=sender), threading.Thread(target=receiver)]
    for t in threads:
        t.start()
    # another client is served during the flood, and the door stays bounded
    other = connect(served.port("s7"), ctype=2)
    waiting = []
    while threads[1].is_alive():
        assert other.db_read(1, 0, 2) == bytearray(2)
        waiting.append(served.door.waiting)
        time.sleep(0.01)
    for t in threads:
        t.join(30)
    sock.close()
    other.disconnect()
    assert max(waiting) <= 4                           # one job per connection in flight
    assert served.call(lambda p: p.scans) > scans0
    return got


@pytest.mark.skipif(not os.path.exists("/proc/self/statm"), reason="needs /proc")
def test_flood_is_bounded_and_the_plc_keeps_scanning(served) -> None:
    n = 4000                                           # requests a round (two: 8000 <= 10 000)
    got = _flood(served, n)
    assert len(got) == n + 2                           # CC, setup, and every read answered
    assert all(f[7:9] == b"\x32\x03" and f[17:19] == b"\x00\x00" for f in got[2:])
    rss = _rss_kib()
    assert len(_flood(served, n)) == n + 2
    assert _rss_kib() - rss < 8 * 1024                 # memory stays flat over the second round
    _healthy(served)
