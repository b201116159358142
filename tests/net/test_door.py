"""The scan-boundary door: jobs run in order in the thread that serves it,
a job's error reaches its own client only, the queue is bounded, a closed
door fails what waits, and the PLC thread's wait wakes for a job or a
wake-up (and, inside a scan, not for a job)."""

from __future__ import annotations

import threading
import time

import pytest

from plcrt.errors import PlcConfigError
from plcrt.net.door import DoorBusy, DoorClosed, ScanDoor


def test_jobs_run_in_order_in_the_serving_thread_with_the_plc_it_hands() -> None:
    door = ScanDoor()
    seen: list[tuple[int, object, str]] = []
    futs = [door.post(lambda plc, i=i: seen.append((i, plc, threading.current_thread().name))
                      or i * 10) for i in range(5)]
    assert not any(f.done() for f in futs)
    plc = object()
    served: list[int] = []
    t = threading.Thread(target=lambda: served.append(door.serve(plc)), name="plc-thread")
    t.start()
    t.join()
    assert served == [5]
    assert [f.result(0) for f in futs] == [0, 10, 20, 30, 40]
    assert [s[0] for s in seen] == [0, 1, 2, 3, 4]
    assert all(s[1] is plc and s[2] == "plc-thread" for s in seen)
    assert door.serve(plc) == 0 and door.served == 5


def test_a_jobs_error_goes_to_its_future_and_the_others_still_run() -> None:
    door = ScanDoor()
    bad = door.post(lambda plc: 1 // 0)
    good = door.post(lambda plc: "ok")
    door.serve(None)
    with pytest.raises(ZeroDivisionError):
        bad.result(0)
    assert good.result(0) == "ok"


def test_a_job_posted_while_jobs_run_waits_for_the_next_boundary() -> None:
    door = ScanDoor()
    later = []
    door.post(lambda plc: later.append(door.post(lambda plc: "next")))
    assert door.serve(None) == 1
    assert not later[0].done()
    assert door.serve(None) == 1 and later[0].result(0) == "next"


def test_the_door_is_bounded_and_refuses_at_once() -> None:
    door = ScanDoor(limit=3)
    for _ in range(3):
        door.post(lambda plc: None)
    with pytest.raises(DoorBusy) as e:
        door.post(lambda plc: None)
    assert isinstance(e.value, PlcConfigError) and door.refused == 1
    door.serve(None)
    door.post(lambda plc: None)     # room again


def test_closing_fails_the_waiting_jobs_and_refuses_new_ones() -> None:
    door = ScanDoor()
    fut = door.post(lambda plc: None)
    door.close()
    with pytest.raises(DoorClosed):
        fut.result(0)
    with pytest.raises(DoorClosed):
        door.post(lambda plc: None)


def test_wait_ends_when_a_job_arrives_or_on_wake_and_not_for_jobs_inside_a_scan() -> None:
    door = ScanDoor()
    t0 = time.monotonic()
    assert door.wait(0.05) is False
    assert time.monotonic() - t0 >= 0.04          # nothing came: the whole timeout

    threading.Timer(0.05, lambda: door.post(lambda plc: None)).start()
    t0 = time.monotonic()
    assert door.wait(5.0) is True
    assert time.monotonic() - t0 < 2.0

    # a job waits; paused inside a scan the thread must not wake for it ...
    t0 = time.monotonic()
    door.wait(0.05, jobs=False)
    assert time.monotonic() - t0 >= 0.04
    # ... but a wake-up (a command of the panel) ends the wait
    threading.Timer(0.05, door.wake).start()
    t0 = time.monotonic()
    door.wait(5.0, jobs=False)
    assert time.monotonic() - t0 < 2.0
