"""The runner: a served PLC's thread.  Simulated time never runs ahead of
the wall clock in real time, stands still in STOP and in lockstep, and is
not caught up after a STOP; speeds are checked; a fault stops the CPU and
the runner goes on serving."""

from __future__ import annotations

import time

import pytest

import plcrt
from plcrt.errors import PlcConfigError
from plcrt.net.runner import Runner, advance, parse_speed

BLINK = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD SM0.5
= Q0.0
Network 2
LD SM0.0
+I 1, VW0
END_ORGANIZATION_BLOCK
"""


@pytest.mark.parametrize("text, speed", [
    ("realtime", "realtime"), ("MAX", "max"), (" lockstep ", "lockstep"), ("2", 2.0),
    ("0.5x", 0.5), (10000, 10000.0), (0.01, 0.01)])
def test_speeds(text: object, speed: object) -> None:
    assert parse_speed(text) == speed


@pytest.mark.parametrize("bad", ["fast", "", "nan", "inf", "0", 0, -1, 10001, True, None,
                                 [1], "1e400"])
def test_bad_speeds_are_refused(bad: object) -> None:
    with pytest.raises(PlcConfigError):
        parse_speed(bad)


def test_real_time_never_runs_ahead_of_the_wall_clock() -> None:
    plc = plcrt.load(BLINK)
    runner = Runner(plc, speed="realtime").start()
    t0 = time.monotonic()
    try:
        for _ in range(5):
            time.sleep(0.05)
            sim, wall = runner.door.post(lambda p: p.now_us).result(5) / 1e6, \
                time.monotonic() - t0
            # a chunk is at most one display frame (1/15 s) of simulated time
            assert sim <= wall + 1 / 15 + 0.01
        assert sim > 0
    finally:
        runner.close()
    assert not runner.alive


def test_stop_stands_still_and_run_goes_on_from_now() -> None:
    plc = plcrt.load(BLINK)
    runner = Runner(plc, speed="realtime").start()
    call = lambda job: runner.door.post(job).result(5)  # noqa: E731
    try:
        time.sleep(0.1)
        call(lambda p: p.set_mode("STOP"))
        t_stop, q = call(lambda p: (p.now_us, p.mem.areas["PQ"][0]))
        assert q == 0                       # the outputs' STOP state
        time.sleep(0.3)
        assert call(lambda p: p.now_us) == t_stop
        call(lambda p: p.set_mode("RUN"))
        time.sleep(0.05)
        t_run = call(lambda p: p.now_us)
        # the 0.3 s in STOP are not caught up
        assert t_stop < t_run <= t_stop + 200_000
    finally:
        runner.close()


def test_lockstep_runs_only_what_a_client_asks() -> None:
    plc = plcrt.load(BLINK)
    runner = Runner(plc, speed="lockstep").start()
    try:
        time.sleep(0.1)
        assert runner.door.post(lambda p: p.scans).result(5) == 0
        assert runner.door.post(lambda p: advance(p, scans=7)).result(5) == 7
        assert runner.door.post(lambda p: advance(p, to_us=155_000)).result(5) == 9
        assert runner.door.post(lambda p: (p.scans, p.now_us, p["VW0"])).result(5) == \
            (16, 160_000, 16)
    finally:
        runner.close()


@pytest.mark.parametrize("kw", [{}, {"scans": 1, "seconds": 1}, {"to_us": -1},
                                {"to_us": True}, {"to_us": 1.5}, {"scans": -1},
                                {"to_us": 10 ** 30}])
def test_bad_advances_are_refused(kw: dict) -> None:
    with pytest.raises(PlcConfigError):
        advance(plcrt.load(BLINK), **kw)


def test_a_fault_stops_the_cpu_and_the_runner_keeps_serving() -> None:
    # a loop that never ends once I0.0 is on: the watchdog stops the CPU
    plc = plcrt.load("""ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LBL 1
Network 2
LD I0.0
JMP 1
END_ORGANIZATION_BLOCK
""")
    runner = Runner(plc, speed="max").start()
    try:
        runner.door.post(lambda p: p.write("I0.0", 1)).result(5)
        deadline = time.monotonic() + 5
        while not runner.errors and time.monotonic() < deadline:
            time.sleep(0.01)
        assert runner.errors and runner.errors[0].message
        assert runner.door.post(lambda p: p.mode).result(5) == "STOP"
    finally:
        runner.close()
