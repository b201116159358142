"""The speed of a served PLC (the panel's, the network servers'): how many
scans the next chunk runs, and how fast the simulated time is going.

``realtime`` paces simulated time to the wall clock, ``factor`` runs N
simulated seconds per wall second, ``max`` runs as fast as it can in
chunks of about :data:`CHUNK_S` wall seconds (the chunk size follows the
time the last chunk took).  A lag of more than :data:`MAX_LAG_S` is given
up rather than caught up.

What it is: arithmetic on the wall clock and the PLC's simulated time, with
the clock and the sleep handed in (tests pass their own).  What it is not:
the loops that run the chunks (:mod:`plcrt.net.runner`,
:mod:`plcrt.web.running`) or their threads; it never scans.
"""

from __future__ import annotations

from collections.abc import Callable

from ..errors import PlcConfigError

#: frames per wall second
DISPLAY_HZ = 15.0
#: wall seconds one chunk of scans takes at most in "as fast as possible"
CHUNK_S = 0.05
#: real time that may be lost before the pacing starts again from now
MAX_LAG_S = 0.5


class Pacer:
    """The speed mode and the pacing of simulated time to the wall clock.

    Args:
        clock, sleep: the wall clock and how to wait on it.
        display_hz: frames per wall second (a paced chunk is at most one
            frame period of simulated time, a wait at most one period).
        sim_us: the PLC's simulated time now (the start of the rate).
    """

    def __init__(self, clock: Callable[[], float], sleep: Callable[[float], None],
                 display_hz: float, sim_us: int) -> None:
        self.clock, self.sleep = clock, sleep
        self.display_hz = display_hz
        self.mode = "realtime"
        self.factor = 1.0
        #: scans per chunk in "as fast as possible"
        self.chunk = 1
        self._anchor: tuple[float, int] | None = None
        self._rate = 0.0
        self._rate_mark: tuple[float, int] = (clock(), sim_us)

    def set(self, mode: str, factor: float | None, sim_us: int) -> None:
        """Change the speed (the ``speed`` message); pacing starts again
        from now."""
        if mode == "factor" and factor is None:
            raise PlcConfigError("speed factor needs a factor (simulated s per wall s)")
        self.mode = mode
        self.factor = factor if mode == "factor" and factor is not None else 1.0
        self.anchor(sim_us)

    def anchor(self, sim_us: int) -> None:
        """Pace from now on: ``sim_us`` is simulated time at this wall time."""
        self._anchor = (self.clock(), sim_us)

    def scans(self, sim_us: int, scan_us: int, *, stepping: bool, left: int | None) -> int:
        """How many scans the next chunk runs (0: none yet, after a short
        sleep).  ``stepping``: a step of ``left`` scans is on."""
        if stepping and self.mode == "max":
            return min(left or 1, self.chunk)
        if self.mode == "max":
            return self.chunk
        now = self.clock()
        sim = sim_us
        if self._anchor is None:
            self._anchor = (now, sim)
        w0, s0 = self._anchor
        factor = self.factor if self.mode == "factor" else 1.0
        target = s0 + (now - w0) * factor * 1e6
        lag = (target - sim) / 1e6 / factor
        if lag > MAX_LAG_S:   # too far behind: pace from here on
            self._anchor = (now, sim)
            target = sim + scan_us
        n = int((target - sim) // scan_us)
        if n <= 0:
            wait = (sim + scan_us - target) / 1e6 / factor
            self.sleep(min(wait, 1 / self.display_hz, 0.02))
            return 0
        cap = max(1, int(factor * 1e6 / self.display_hz / scan_us) + 1)
        return min(n, cap)

    def took(self, n: int, dt: float) -> None:
        """A chunk of ``n`` scans took ``dt`` wall seconds: in "as fast as
        possible" the next one is sized to :data:`CHUNK_S`."""
        if self.mode == "max" and n > 0:
            per = dt / n if dt > 0 else 1e-6
            self.chunk = max(1, min(100000, int(CHUNK_S / per)))

    def rate(self, now: float, sim_us: int) -> float:
        """Simulated seconds per wall second, measured over half a second
        or more (``now``: the wall clock)."""
        w0, s0 = self._rate_mark
        if now - w0 >= 0.5:
            self._rate = (sim_us - s0) / 1e6 / (now - w0) if now > w0 else 0.0
            self._rate_mark = (now, sim_us)
        return self._rate

    def to_dict(self) -> dict[str, object]:
        """The speed as a frame carries it."""
        return {"mode": self.mode, "factor": self.factor}
