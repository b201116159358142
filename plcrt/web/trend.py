"""The panel's trend: one sample of its signals per scan, in simulated time.

The samples are taken by an observer of the PLC (:attr:`plcrt.Plc.
observers`, called after every scan), kept in a ring of
:data:`TREND_MAX`, and carried to the pages in two ways: a frame carries
only the samples that are new since the previous frame (thinned out to
:data:`TREND_TAIL`), and the ``trend`` message carries them all (a new
signal list, a power-up reset, a page that skipped a frame).

What it is: the samples and those two messages.  What it is not: when
frames are sent (:mod:`plcrt.web.session`) or how the page draws them.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any

from ..engine.runtime import Plc
from ..testing.harness import reader
from .protocol import finite

#: trend samples kept (one per scan)
TREND_MAX = 20000
#: trend samples one frame carries at most (more are thinned out)
TREND_TAIL = 2000


class Trend:
    """The signals every page shares and their samples."""

    def __init__(self) -> None:
        self.signals: list[str] = []
        self.readers: list[Callable[[], Any]] = []
        self.t: deque[float] = deque(maxlen=TREND_MAX)
        self.rows: deque[list[Any]] = deque(maxlen=TREND_MAX)
        self.count = 0          #: samples recorded since the trend started
        self.sent = 0           #: samples already carried by a frame

    def start(self, plc: Plc, signals: list[str]) -> None:
        """Record ``signals`` (none: stop) from now on, from one sample of
        now; every signal is checked before anything changes."""
        signals = list(dict.fromkeys(signals))
        readers = [reader(plc, s) for s in signals]   # all checked first
        self.signals, self.readers = signals, readers
        self.clear(plc)
        obs = plc.observers
        if self.sample in obs:
            obs.remove(self.sample)
        if signals:
            obs.append(self.sample)

    def clear(self, plc: Plc) -> None:
        """Start again from one sample of now (after a power-up reset)."""
        self.t.clear()
        self.rows.clear()
        self.count = self.sent = 0
        if self.signals:
            self.sample(plc)

    def rebind(self, plc: Plc) -> None:
        """Read the signals from ``plc`` (another build of the same program)."""
        self.readers = [reader(plc, s) for s in self.signals]

    def sample(self, plc: Plc) -> None:
        """The observer: one sample after each scan."""
        self.t.append(plc.now_us / 1e6)
        self.rows.append([finite(r()) for r in self.readers])
        self.count += 1

    def message(self) -> dict[str, Any]:
        """Every sample kept, as the ``trend`` message."""
        return {"type": "trend", "signals": self.signals, "end": self.count,
                "t": list(self.t), "v": list(self.rows)}

    def tail(self) -> dict[str, Any]:
        """The samples no frame carried yet (thinned out to TREND_TAIL), as
        a frame's ``trend``; they count as carried from now on."""
        new = min(self.count - self.sent, len(self.t))
        tail_t, tail_v = list(self.t)[len(self.t) - new:], list(self.rows)[len(self.rows) - new:]
        if new > TREND_TAIL:
            step = -(-new // TREND_TAIL)
            tail_t, tail_v = tail_t[::step] + tail_t[-1:], tail_v[::step] + tail_v[-1:]
        start = self.count - new
        self.sent = self.count
        return {"signals": self.signals, "start": start, "end": self.count,
                "t": tail_t, "v": tail_v}
