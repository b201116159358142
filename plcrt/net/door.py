"""The scan-boundary door: how anything outside the PLC's thread reads and
writes a running PLC.

A client of a server (an S7 read, a Modbus write, a lockstep step) never
touches the PLC itself.  It posts a *job* — a function of the PLC — and
gets a :class:`concurrent.futures.Future`; the thread that runs the PLC
calls :meth:`ScanDoor.serve` between two scans (at a scan boundary) and
runs every waiting job there, in order.  So:

- a read sees one consistent image, taken at a scan boundary, never half
  of a scan;
- a write is applied at the next scan boundary, before the next scan reads
  its inputs;
- the scan never waits for a client: a job is a few microseconds of byte
  copying, and what a client does with the answer (sending it, slowly or
  never) happens in the server's own thread.

The door is bounded (:data:`MAX_WAITING` jobs): beyond that a post is
refused at once with :class:`DoorBusy` and the server answers "busy" or
closes that connection; the PLC's thread never queues unboundedly.

What it is: the queue, its wake-up and the running of jobs.  What it is
not: the thread that runs the PLC (:mod:`plcrt.net.runner`, or the panel's
session), nor any protocol.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any, TypeVar

from ..errors import PlcConfigError

__all__ = ["DoorBusy", "DoorClosed", "MAX_WAITING", "ScanDoor"]

T = TypeVar("T")

#: jobs waiting at most (every connection has at most a few requests in
#: flight: S7's negotiated "max AmQ", one Modbus request at a time per
#: connection in the servers here), so the bound is only ever reached by a
#: flood
MAX_WAITING = 4096


class DoorBusy(PlcConfigError):
    """More jobs are waiting than :data:`MAX_WAITING`: this one is refused."""


class DoorClosed(PlcConfigError):
    """The PLC is not served any more (its runner stopped)."""


class ScanDoor:
    """Jobs for the PLC's thread, run at the next scan boundary.

    Any thread may :meth:`post`; exactly one thread — the one running the
    PLC — calls :meth:`serve` and :meth:`wait`.
    """

    def __init__(self, limit: int = MAX_WAITING) -> None:
        self._jobs: deque[tuple[Callable[[Any], Any], Future[Any]]] = deque()
        self._cond = threading.Condition()
        self._limit = limit
        self._closed = False
        self._poked = False
        #: how the thread serving the door runs the PLC: a runner's speed
        #: (``"realtime"``, ``"max"``, ``"lockstep"``, a factor) or ``"panel"``
        self.speed: str | float = "panel"
        #: jobs run so far (a figure for benches and the panel)
        self.served = 0
        #: jobs refused because the door was full
        self.refused = 0

    def post(self, job: Callable[[Any], T]) -> Future[T]:
        """Queue ``job(plc)`` for the next scan boundary.

        Raises:
            DoorBusy: :data:`MAX_WAITING` jobs are waiting already.
            DoorClosed: the door is closed.
        """
        fut: Future[T] = Future()
        with self._cond:
            if self._closed:
                raise DoorClosed("the PLC is not served any more")
            if len(self._jobs) >= self._limit:
                self.refused += 1
                raise DoorBusy(f"more than {self._limit} requests wait for the PLC")
            self._jobs.append((job, fut))
            self._cond.notify()
        return fut

    @property
    def waiting(self) -> int:
        """Jobs queued and not yet run."""
        return len(self._jobs)

    def serve(self, plc: Any) -> int:
        """Run every waiting job on ``plc`` (in the calling thread, which
        runs the PLC and is at a scan boundary); a job's exception goes to
        its future, never to the caller.  Returns the number of jobs run.

        Jobs posted while these run wait for the next call, so one flood
        cannot hold the PLC's thread for longer than what was waiting when
        it came.
        """
        with self._cond:
            if not self._jobs:
                return 0
            batch = list(self._jobs)
            self._jobs.clear()
        for job, fut in batch:
            if not fut.set_running_or_notify_cancel():
                continue
            try:
                fut.set_result(job(plc))
            except BaseException as e:  # noqa: B902 - handed to the client's future
                fut.set_exception(e)
        self.served += len(batch)
        return len(batch)

    def wait(self, timeout: float, *, jobs: bool = True) -> bool:
        """Block up to ``timeout`` seconds until a job waits (True), the
        door is woken (:meth:`wake`) or closed; the PLC thread's sleep
        between chunks.  ``jobs=False``: waiting jobs do not end the wait
        (the thread is inside a scan, paused at a breakpoint, and must not
        serve them now)."""
        with self._cond:
            if not (jobs and self._jobs or self._poked or self._closed):
                self._cond.wait(timeout)
            self._poked = False
            return bool(self._jobs)

    def wake(self) -> None:
        """End a :meth:`wait` now (something else for the PLC's thread
        arrived: a command of the panel)."""
        with self._cond:
            self._poked = True
            self._cond.notify_all()

    def close(self) -> None:
        """Refuse new jobs; those waiting fail with :class:`DoorClosed`."""
        with self._cond:
            self._closed = True
            batch = list(self._jobs)
            self._jobs.clear()
            self._cond.notify_all()
        for _, fut in batch:
            if fut.set_running_or_notify_cancel():
                fut.set_exception(DoorClosed("the PLC is not served any more"))

    @property
    def closed(self) -> bool:
        return self._closed
