"""The panel's run modes: run, stop, step N scans, run until a condition,
continue after a breakpoint; and a chunk of scans run under them.

The run state is ``stopped``, ``running``, ``stepping``, ``until`` or
``paused`` (inside a scan, at a breakpoint).  A chunk is as many scans as
the :class:`~plcrt.net.pacing.Pacer` allows; a plain run hands it to
:meth:`plcrt.Plc.scan` whole, a step, a run until a condition and a run
with breakpoints scan one scan at a time, to stop at the right one.  A
command given while a scan is paused takes effect when that scan has run
to its end (a stop, a power-up reset).

What it is: the state of one run and the loop over the scans of a chunk.
What it is not: the thread, the command queue or the pause itself (the
session waits for commands while paused, :mod:`plcrt.web.session`), nor
the speed (:mod:`plcrt.net.pacing`).  It tells what happens through the
``notice`` function it is handed and asks for a power-up through
``reset``.
"""

from __future__ import annotations

from collections.abc import Callable

from ..engine.coverage import NetworkRef
from ..engine.runtime import Plc
from ..errors import PlcConfigError, PlcRuntimeError
from ..safetext import printable
from ..net.pacing import Pacer

#: default timeout of ``until`` (simulated seconds)
UNTIL_TIMEOUT = 10.0

#: a run until a condition: its predicate, its text and its deadline (simulated µs)
Until = tuple[Callable[[], bool], str, int]


class RunControl:
    """What the Run, Stop, Scan and Until buttons set, and the scans they run.

    Args:
        pacer: the speed.
        notice: tells every page something (level, message).
        reset: the power-up reset, asked for after a paused scan ends.
    """

    def __init__(self, pacer: Pacer, notice: Callable[[str, str], None],
                 reset: Callable[[], None]) -> None:
        self.pacer = pacer
        self._notice, self._reset = notice, reset
        self.state = "stopped"          #: stopped, running, stepping, until, paused
        self.paused_at: NetworkRef | None = None
        self.left: int | None = None    #: scans left of a step
        self.until: Until | None = None
        self.until_cond = ""            #: the condition's text (to bind it again)
        self.stop_after_scan = False
        self.reset_after_scan = False
        self.before_pause = "running"

    @property
    def busy(self) -> bool:
        """Scans are to run (a run, a step or a run until a condition is on)."""
        return self.state == "running" or self.left is not None or self.until is not None

    # ------------------------------------------------------------------
    # Commands
    # ------------------------------------------------------------------
    def run(self, plc: Plc) -> None:
        self.left, self.until = None, None
        self._go("running", plc)

    def cont(self) -> None:
        if self.state != "paused":
            raise PlcConfigError("continue: no scan is paused at a breakpoint")
        self.state = self.before_pause   # the step, until or run goes on

    def stop(self) -> None:
        self.left, self.until = None, None
        if self.state == "paused":
            self.stop_after_scan = True
        self.state = "stopped"

    def step(self, plc: Plc, scans: int) -> None:
        self.until = None
        if self.state == "paused":   # the paused scan is the first of them
            self.left = scans
            self.state = "stepping"
            return
        self.left = scans
        self._go("stepping", plc)

    def run_until(self, plc: Plc, pred: Callable[[], bool], what: str, cond: str,
                  timeout: float) -> None:
        self.left = None
        self.until = (pred, what, plc.now_us + round(timeout * 1e6))
        self.until_cond = cond
        self._go("until", plc)

    def _go(self, state: str, plc: Plc) -> None:
        self.state = state
        self.pacer.anchor(plc.now_us)

    def reset_later(self) -> bool:
        """A power-up reset asked for while a scan is paused: stop, and
        reset when the scan has ended (True).  False: reset now."""
        if self.state != "paused":
            return False
        self.reset_after_scan = True
        self.stop_after_scan = True
        self.state = "stopped"
        return True

    def halt(self) -> None:
        """Stopped, no step or condition left (after a reset or a fault)."""
        self.state, self.left, self.until = "stopped", None, None

    # ------------------------------------------------------------------
    # A pause inside a scan
    # ------------------------------------------------------------------
    def pause(self, net: NetworkRef) -> str:
        """Paused before ``net``: returns the state the pause interrupted."""
        self.paused_at, before = net, self.state
        self.before_pause = before
        self.state = "paused"
        return before

    def resumed(self, before: str) -> None:
        """The pause ended (``before``: what it interrupted): a step given
        while paused in a run until a condition ends that run."""
        if before == "until" and self.state == "stepping":
            self.until = None

    # ------------------------------------------------------------------
    # Running
    # ------------------------------------------------------------------
    def chunk(self, plc: Plc, breaks: bool) -> None:
        """A chunk of scans sized to the speed; stops at a step's end, a
        condition, a breakpoint's stop, a fault or STOP mode.  ``breaks``:
        breakpoints are set (scan one scan at a time)."""
        if plc.mode != "RUN":
            self.halt()
            self._notice("warning", "the CPU is in STOP mode: scans do nothing")
            return
        n = self.pacer.scans(plc.now_us, plc.scan_us,
                             stepping=self.state == "stepping" or self.left is not None,
                             left=self.left)
        if n <= 0:
            return
        per_scan = self.left is not None or self.until is not None or breaks
        t0 = self.pacer.clock()
        try:
            if per_scan:
                for _ in range(n):
                    plc.scan(1)
                    if self._after_scan(plc):
                        break
            else:
                plc.scan(n)
        except PlcRuntimeError as e:
            self.halt()
            self._notice("error", printable("; ".join(str(d) for d in e.diagnostics)
                                            or e.message))
            return
        self.pacer.took(n, self.pacer.clock() - t0)

    def _after_scan(self, plc: Plc) -> bool:
        """After one scan of a per-scan run: True ends the chunk."""
        if self.reset_after_scan:
            self.reset_after_scan = False
            self._reset()
            return True
        if self.stop_after_scan:
            self.stop_after_scan = False
            self.state = "stopped"
            return True
        if self.left is not None:
            self.left -= 1
            if self.left <= 0:
                self.left = None
                self.state = "stopped"
                return True
        if self.until is not None:
            pred, what, deadline = self.until
            if pred():
                return self._end_until("info", f"'{what}' is true at t={plc.time:g} s")
            if plc.now_us >= deadline:
                return self._end_until("warning", f"'{what}' still false at the timeout "
                                                  f"(t={plc.time:g} s)")
        if self.state not in ("running", "stepping", "until"):
            return True
        return plc.mode != "RUN"

    def _end_until(self, level: str, message: str) -> bool:
        """A run until a condition ends (met or timed out): stop and say so."""
        self.until = None
        self.state = "stopped"
        self._notice(level, printable(message))
        return True
