"""The lockstep protocol with its own client: a plant simulator on another
socket steps the PLC deterministically; requests are checked and answered
with errors naming the problem; a client that misbehaves (garbage, a line
without end, a flood it never reads) costs only its own connection."""

from __future__ import annotations

import socket
import time

import pytest

import plcrt
from plcrt.net.client import LockstepClient, LockstepError

TANK = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1 // fill below the low switch, stop at the high one
LD I0.0
O Q0.0
AN I0.1
= Q0.0
Network 2 // count the fillings
LD Q0.0
EU
+I 1, VW10
END_ORGANIZATION_BLOCK
"""


def _cosimulate(steps: int) -> list[tuple[int, int, int]]:
    """A tank: +3 per step while the valve (Q0.0) is open, -1 otherwise; its
    switches are the PLC's inputs.  One PLC scan per plant step."""
    plc = plcrt.load(TANK)
    level, trace = 50, []
    with plcrt.serve(plc, lockstep=0, speed="lockstep") as served, \
            LockstepClient("127.0.0.1", served.port("lockstep")) as c:
        for _ in range(steps):
            c.write({"I0.0": int(level < 10), "I0.1": int(level > 90)})
            c.advance(scans=1)
            valve = c.read("Q0.0")["Q0.0"]
            level += 3 if valve else -1
            trace.append((level, valve, c.state()["now_us"]))
        fillings = c.read("VW10")["VW10"]
    trace.append((fillings, 0, 0))
    return trace


def test_a_plant_steps_the_plc_deterministically() -> None:
    a = _cosimulate(300)
    assert a == _cosimulate(300)
    levels = [lv for lv, _, _ in a[:-1]]
    # the program keeps the tank between its switches (with one step's overshoot)
    assert 6 <= min(levels) and max(levels) <= 94
    assert a[-1][0] >= 2                        # it filled more than once
    assert [t for _, _, t in a[:-1]] == [10_000 * (i + 1) for i in range(300)]


@pytest.fixture
def served():
    plc = plcrt.load(TANK)
    with plcrt.serve(plc, lockstep=0, speed="lockstep", idle_timeout=5) as s:
        yield s


def _raw(port: int, data: bytes) -> bytes:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
        s.sendall(data)
        s.shutdown(socket.SHUT_WR)
        out = b""
        while chunk := s.recv(65536):
            out += chunk
        return out


@pytest.mark.parametrize("line, error", [
    (b"{}", "op"), (b"[1]", "op"), (b"not json", "JSON"), (b"\xff\xfe", "UTF-8"),
    (b'{"op":"fly"}', "no operation fly"),
    (b'{"op":"read"}', "needs addresses"),
    (b'{"op":"read","addresses":[]}', "1 to 1000"),
    (b'{"op":"read","addresses":["VW0"],"x":1}', "takes no x"),
    (b'{"op":"read","addresses":["XX9"]}', "XX9"),
    (b'{"op":"write","values":{"VW0":"a"}}', "numbers"),
    (b'{"op":"write","values":{"VW0":70000}}', "VW0"),
    (b'{"op":"advance"}', "exactly one"),
    (b'{"op":"advance","scans":-2}', "scans"),
    (b'{"op":"mode","mode":"HALT"}', "RUN or STOP"),
    (b'{"op":"state","id":[1]}', "id"),
    (b'{"op":"state","a":' + b"[" * 50 + b"]" * 50 + b"}", "deep"),
])
def test_bad_requests_get_an_error_answer_and_the_connection_goes_on(
        served, line: bytes, error: str) -> None:
    out = _raw(served.port("lockstep"), line + b'\n{"op":"state","id":7}\n')
    first, second = out.split(b"\n")[:2]
    assert b'"ok":false' in first and error.encode() in first
    assert b'"ok":true' in second and b'"id":7' in second


def test_the_id_is_echoed_also_with_an_error(served) -> None:
    out = _raw(served.port("lockstep"), b'{"op":"fly","id":"a1"}\n')
    assert b'"id":"a1"' in out and b'"ok":false' in out


def test_a_line_without_end_closes_only_that_connection(served) -> None:
    port = served.port("lockstep")
    with LockstepClient("127.0.0.1", port) as good:
        out = _raw(port, b"x" * 70_000)          # longer than a request may be
        assert out == b""
        assert good.advance(scans=2) == 2


def test_a_client_that_never_reads_does_not_stop_the_plc_or_the_others() -> None:
    plc = plcrt.load(TANK)
    with plcrt.serve(plc, lockstep=0, speed="max") as served:
        port = served.port("lockstep")
        flood = socket.create_connection(("127.0.0.1", port))
        try:
            flood.setblocking(False)
            sent = 0
            line = b'{"op":"read","addresses":["VW0","VW2","VW4","VW6"]}\n'
            for _ in range(10_000):             # bounded flood, never read
                try:
                    flood.send(line)
                    sent += 1
                except BlockingIOError:
                    break
            assert sent > 100
            with LockstepClient("127.0.0.1", port) as other:
                s1 = other.state()["scans"]
                time.sleep(0.2)
                s2 = other.state()["scans"]
            assert s2 > s1                      # the PLC kept scanning
        finally:
            flood.close()


def test_writes_obey_read_only_and_the_allow_list() -> None:
    plc = plcrt.load(TANK)
    with plcrt.serve(plc, lockstep=0, speed="lockstep", allow_writes="I0.0-I0.7,T37") as s, \
            LockstepClient("127.0.0.1", s.port("lockstep")) as c:
        c.write({"I0.0": 1, "I0.1": 0, "T37": 5})
        with pytest.raises(LockstepError, match="allow-list"):
            c.write({"I0.0": 0, "VW10": 3})     # all or nothing
        assert c.read("I0.0", "VW10") == {"I0.0": 1, "VW10": 0}
    with plcrt.serve(plc, lockstep=0, speed="lockstep", read_only=True) as s, \
            LockstepClient("127.0.0.1", s.port("lockstep")) as c:
        with pytest.raises(LockstepError, match="read-only"):
            c.write({"I0.0": 0})
        with pytest.raises(LockstepError, match="read-only"):
            c.set_mode("STOP")


def test_advance_is_refused_while_the_plc_runs_by_itself() -> None:
    plc = plcrt.load(TANK)
    with plcrt.serve(plc, lockstep=0, speed="max") as s, \
            LockstepClient("127.0.0.1", s.port("lockstep")) as c:
        with pytest.raises(LockstepError, match="runs by itself"):
            c.advance(scans=1)
        assert c.hello()["speed"] == "max"


def test_the_connection_limit_refuses_one_more() -> None:
    plc = plcrt.load(TANK)
    with plcrt.serve(plc, lockstep=0, speed="lockstep", max_connections=2) as s:
        port = s.port("lockstep")
        with LockstepClient("127.0.0.1", port) as a, LockstepClient("127.0.0.1", port) as b:
            a.state(), b.state()
            with pytest.raises(LockstepError):
                LockstepClient("127.0.0.1", port).state()
        svc = s.services["lockstep"]
        assert svc.stats["refused"] == 1
