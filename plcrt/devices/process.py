"""A first-order process with dead time between an analog output and an
analog input of the CPU: the plant a PID loop is closed and tuned over.

What it is: :class:`FirstOrderProcess`, a device of the scan's time line
(it is stepped over the same sub-intervals as the modules, so a routine in
a timed interrupt reads the input of its own µs).  Over an interval the
analog output ``u`` (AQWn, a signed word) is held; the process value ``y``
follows

    y(t) = K·u(t − L) + offset      in steady state,
    τ·dy/dt = K·u(t − L) + offset − y,

exactly (the closed form of each piece where the delayed output is
constant), and the analog input (AIWn) is ``y`` rounded and limited to the
input's range::

    [[cpu.process]]
    output = "AQW0"          # what the program drives
    input = "AIW0"           # what the program reads
    gain = 1.0               # K: input counts per output count
    offset = 0               # the input with the output at 0
    tau = 5.0                # time constant, s
    dead_time = 0.5          # L, s
    start = 0                # the input at power-up (default: offset)
    range = [0, 32000]       # the input's limits (unipolar 0..32000)

What it is not: a model of the converters' resolution or noise, or of a
process with more than one lag (chain two loops through the program for
that).
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

__all__ = ["FirstOrderProcess"]


class FirstOrderProcess:
    """One process: AQW -> first-order lag with dead time -> AIW."""

    slot = None        #: not an expansion module (no EmNo)

    def __init__(self, plc: Any, cfg: dict[str, Any]) -> None:
        self.aq = plc.mem.areas["AQ"]
        self.ai = plc.mem.areas["AI"]
        self.out_at, self.in_at = cfg["output"], cfg["input"]
        self.gain, self.offset = float(cfg["gain"]), float(cfg["offset"])
        self.tau_us = cfg["tau"] * 1e6
        self.dead_us = int(round(cfg["dead_time"] * 1e6))
        self.lo, self.hi = cfg["range"]
        self.y = float(cfg["start"])
        #: (time, output) where the delayed output changes; the first is in force
        self.history: deque[tuple[int, int]] = deque([(-(1 << 62), 0)])
        self._publish()

    def _output(self) -> int:
        return int.from_bytes(self.aq[self.out_at:self.out_at + 2], "big", signed=True)

    def _publish(self) -> None:
        value = min(self.hi, max(self.lo, int(round(self.y))))
        self.ai[self.in_at:self.in_at + 2] = (value & 0xFFFF).to_bytes(2, "big")

    def step(self, plc: Any, t0: int, t1: int) -> None:
        """Advance from *t0* to *t1* with the output the program holds."""
        u = self._output()
        if u != self.history[-1][1]:
            self.history.append((t0 + self.dead_us, u))
        hist = self.history
        t = t0
        while t < t1:
            # the delayed output in force at t, and until when
            while len(hist) > 1 and hist[1][0] <= t:
                hist.popleft()
            until = min(t1, hist[1][0]) if len(hist) > 1 else t1
            target = self.gain * hist[0][1] + self.offset
            self.y = target + (self.y - target) * math.exp(-(until - t) / self.tau_us)
            t = until
        self._publish()
