"""The thread that runs a served PLC: chunks of scans paced to the wall
clock, and the scan-boundary door served between them.

Speeds (:class:`Speed`): ``realtime`` (simulated time follows the wall
clock: what an HMI or a plant simulator expects of a CPU), a factor
(``2.0``: two simulated seconds per wall second), ``max`` (as fast as the
machine can) and ``lockstep`` (the PLC does not run by itself; clients
advance it with :func:`advance` jobs, as PLCSIM Advanced's single-step
mode does for virtual commissioning).

Between two chunks, and whenever the pacing waits for the wall clock, the
runner runs the door's jobs (:class:`plcrt.net.door.ScanDoor`): a client's
request is answered at the next scan boundary, at once when the PLC is
idle between chunks.  In STOP mode the PLC does not scan and simulated
time stands still; the door is still served (a client may read, write or
switch the CPU to RUN).

What it is: the thread, the loop and the pacing of one PLC.  What it is
not: the servers (each in its own module of :mod:`plcrt.net`), the panel's
own run modes (:mod:`plcrt.web.running`, which serves the same door from
its own thread when the panel runs the PLC).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

from ..engine.runtime import Plc
from ..engine.values import MAX_STEPS, Duration, scan_total
from ..errors import PlcConfigError, PlcError
from ..safetext import shown_value
from .door import ScanDoor
from .pacing import DISPLAY_HZ, Pacer

__all__ = ["Runner", "Speed", "advance", "parse_speed"]

#: ``"realtime"``, ``"max"``, ``"lockstep"`` or simulated seconds per wall second
Speed = str | float

#: longest wait of the idle loop (s): how soon a closed runner notices
IDLE_WAIT = 0.05


def parse_speed(speed: Any) -> Speed:
    """A checked speed: ``"realtime"``, ``"max"``, ``"lockstep"``, or a
    factor between 0.01 and 10 000 (a number or its text, ``"2"``, ``"2x"``).

    Raises:
        PlcConfigError: anything else.
    """
    if isinstance(speed, str):
        text = speed.strip().lower()
        if text in ("realtime", "max", "lockstep"):
            return text
        try:
            speed = float(text[:-1] if text.endswith("x") else text)
        except ValueError:
            raise PlcConfigError(f"speed must be realtime, max, lockstep or a factor "
                                 f"such as 2 or 0.5, not {shown_value(speed)}") from None
    if isinstance(speed, bool) or not isinstance(speed, (int, float)) \
            or not 0.01 <= speed <= 10000:
        raise PlcConfigError(f"a speed factor is 0.01 to 10000 simulated seconds per wall "
                             f"second, not {shown_value(speed)}")
    return float(speed)


def advance(plc: Plc, *, scans: int | None = None, seconds: Duration | None = None,
            to_us: int | None = None) -> int:
    """Run ``scans`` scans, ``seconds`` of simulated time, or up to the
    simulated instant ``to_us`` (µs, whole scans: up to the first scan end
    at or after it) — a lockstep step, run as a door job in the thread
    that runs the PLC.  Returns the scans run (fewer if the CPU stops).

    Raises:
        PlcConfigError: none or more than one of them, or a bad value.
    """
    given = [x is not None for x in (scans, seconds, to_us)]
    if sum(given) != 1:
        raise PlcConfigError("advance by scans, seconds or to a time: exactly one")
    if to_us is not None:
        if isinstance(to_us, bool) or not isinstance(to_us, int) or to_us < 0:
            raise PlcConfigError(f"a time to advance to is whole µs >= 0, "
                                 f"not {shown_value(to_us)}")
        left = to_us - plc.now_us
        n = 0 if left <= 0 else -(-left // plc.scan_us)
        if n > MAX_STEPS:
            raise PlcConfigError(f"advancing to {shown_value(to_us)} µs would run {n} scans; "
                                 f"at most {MAX_STEPS} at once")
    else:
        n = scan_total(plc.scan_us, seconds, scans)
    before = plc.scans
    plc.scan(n)
    return plc.scans - before


class Runner:
    """Runs ``plc`` in a thread of its own at ``speed``, serving ``door``.

    Args:
        plc: the PLC (the runner's thread is the only one that touches it
            while the runner runs; everyone else goes through the door).
        speed: see the module doc.
        door: the door to serve (a new one if not given).
        on_error: called (in the runner's thread) with a fatal fault's
            error; the CPU is in STOP then and the runner keeps serving.
    """

    def __init__(self, plc: Plc, *, speed: Any = "realtime", door: ScanDoor | None = None,
                 on_error: Callable[[PlcError], None] | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.plc = plc
        self.speed = parse_speed(speed)
        self.door = door if door is not None else ScanDoor()
        self.on_error = on_error
        self.errors: list[PlcError] = []
        self.clock = clock
        self.pacer = Pacer(clock, self._sleep, DISPLAY_HZ, plc.now_us)
        self._apply_speed()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # -- speed -------------------------------------------------------------
    def _apply_speed(self) -> None:
        s = self.door.speed = self.speed
        if isinstance(s, float):
            self.pacer.set("factor", s, self.plc.now_us)
        elif s in ("realtime", "max"):
            self.pacer.set(s, None, self.plc.now_us)

    def set_speed(self, speed: Any) -> None:
        """Change the speed (from the runner's thread: a door job)."""
        self.speed = parse_speed(speed)
        self._apply_speed()

    # -- the thread --------------------------------------------------------
    def start(self) -> "Runner":
        """Start the thread (once)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._loop, name="plcrt-runner",
                                            daemon=True)
            self._thread.start()
        return self

    def close(self, timeout: float = 5.0) -> None:
        """Stop the thread after its current chunk; the door refuses new jobs
        and fails the waiting ones."""
        self._stop.set()
        self.door.close()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout)

    @property
    def alive(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def _sleep(self, seconds: float) -> None:
        # the pacing's wait: wakes early for a client's job
        if seconds > 0:
            self.door.wait(seconds)

    def _loop(self) -> None:
        door, stop = self.door, self._stop
        while not stop.is_set():
            try:
                self.tick()
            except PlcError as e:      # a fault: the CPU is in STOP now
                self.errors.append(e)
                if self.on_error is not None:
                    self.on_error(e)
        door.close()

    def tick(self) -> None:
        """One round: the door's jobs, then a chunk of scans (or a short
        wait when the PLC does not run by itself)."""
        plc, door = self.plc, self.door
        door.serve(plc)
        if self.speed == "lockstep" or plc.mode != "RUN":
            door.wait(IDLE_WAIT)
            # time stood still: pacing starts again from now, not catching up
            self.pacer.anchor(plc.now_us)
            return
        n = self.pacer.scans(plc.now_us, plc.scan_us, stepping=False, left=None)
        if n <= 0:
            return
        t0 = self.clock()
        plc.scan(n)
        self.pacer.took(n, self.clock() - t0)
