"""S7-200 timers (TON, TONR, TOF) with the resolution rules of the manual.

S7-200 System Manual, "Timer instructions" / "Understanding how resolution
affects the timer action".  The resolution is fixed by the timer number:

=========  =========================  ===========================
           TONR                       TON / TOF
=========  =========================  ===========================
1 ms       T0, T64                    T32, T96
10 ms      T1-T4, T65-T68             T33-T36, T97-T100
100 ms     T5-T31, T69-T95            T37-T63, T101-T255
=========  =========================  ===========================

Update rules, as plcrt implements them (time is integer microseconds):

* 100 ms: the current value changes only when the timer instruction runs; it
  adds the 100 ms ticks that elapsed between the previous scan start and this
  scan start.  Skipped instruction -> time lost; executed twice -> time
  gained (the manual's warning, reproduced on purpose)::

      scan starts   |     |     |     |        (scan 100 ms)
      IN            __/‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾
      CV (PT=2)     0  0  1  2            bit on at CV >= PT

* 10 ms: running timers advance at the start of every scan by the 10 ms
  ticks since the previous scan start, whether or not the instruction runs;
  the instruction only starts, stops or resets them.
* 1 ms: on the hardware they advance every millisecond, asynchronously.
  Simulated program execution takes no time, so the milliseconds of a scan
  are applied at its start, like the 10 ms timers, and also at the time of
  every interrupt inside the scan interval (:meth:`TimerBank.refresh_1ms`),
  so a routine reads the value of its moment (see docs/decisions.md).

The visible state (current value words ``TV`` and bits ``TB``) lives in the
memory image, so ``LD T37`` and ``MOVW T37, VW0`` are plain reads; this class
keeps only the hidden state (running, preset, previous IN).
"""

from __future__ import annotations

from array import array
from struct import Struct

_H = Struct(">h")
_UH = Struct(">H")

from ..memory.hardware import MAX_CV, resolution_ms, timer_kind_ok  # noqa: E402, F401


class TimerBank:
    """Hidden state of all timers plus the per-scan tick deltas."""

    def __init__(self, tv: bytearray, tb: bytearray, count: int = 256) -> None:
        self.tv = tv
        self.tb = tb
        # running, preset and prev_in are arrays, not lists: the native
        # backend's TON and R (plcrt.compiler.native.lower) use them in place
        self.running = bytearray(count)
        self.preset = array("h", bytes(2 * count))
        self.prev_in = bytearray(count)
        self.kind = [""] * count
        self.res = [resolution_ms(n) for n in range(count)]
        self.d1 = self.d10 = self.d100 = 0  #: ticks since previous scan start
        self.d100_buf = array("i", [0])     #: d100 for the native backend
        self._fast: set[int] = set()        #: running 1 ms / 10 ms timers
        self.ms1: int | None = None         #: the ms the 1 ms timers are advanced to
        #: perf: scan starts in [quiet_lo, quiet_hi) change nothing but ms1
        #: while no 1 ms / 10 ms timer runs: d100 is 0 and stays 0 until the
        #: next 100 ms tick (see quiet())
        self.quiet_lo = self.quiet_hi = 0

    # -- engine side ----------------------------------------------------
    def start_scan(self, prev_us: int | None, now_us: int) -> None:
        """Compute tick deltas and advance running 1 ms / 10 ms timers."""
        ms1 = now_us // 1000
        if prev_us is None or now_us == prev_us:
            self.d100 = d100 = 0
            if self._fast:
                self.d1 = self.d10 = 0
        else:
            self.d100 = d100 = now_us // 100000 - prev_us // 100000
            # perf: d1 and d10 only matter to running 1 ms / 10 ms timers
            if self._fast:
                # the 1 ms timers may have been advanced inside the interval already
                self.d1 = ms1 - (prev_us // 1000 if self.ms1 is None else self.ms1)
                self.d10 = now_us // 10000 - prev_us // 10000
        self.d100_buf[0] = d100
        self.ms1 = ms1
        if self._fast:
            for n in list(self._fast):
                self._advance(n, self.d1 if self.res[n] == 1 else self.d10)
        elif d100 == 0:
            self.quiet_lo, self.quiet_hi = now_us, (now_us // 100000 + 1) * 100000

    def quiet(self, now_us: int) -> bool:
        """Whether :meth:`start_scan` at *now_us* has nothing to do but set
        ``ms1``: no 1 ms or 10 ms timer runs and no 100 ms tick has passed
        since the last scan start that found d100 = 0 (the engine then sets
        ``ms1`` itself, and keeps the window to test it inline,
        ``Plc._calm_start``)."""
        return not self._fast and self.quiet_lo <= now_us < self.quiet_hi

    def refresh_1ms(self, t_us: int) -> None:
        """Advance the running 1 ms timers to *t_us* (an interrupt's time:
        on the CPU they count every millisecond, whatever the program does)."""
        if self.ms1 is None or not self._fast:
            return
        d = t_us // 1000 - self.ms1
        if d <= 0:
            return
        self.ms1 = t_us // 1000
        for n in list(self._fast):
            if self.res[n] == 1:
                self._advance(n, d)

    def ct_pt_time(self, n: int) -> int | None:
        """When running 1 ms timer *n* reaches its preset (µs), if it will."""
        if not self.running[n] or self.res[n] != 1 or self.ms1 is None:
            return None
        left = self.preset[n] - self._cv(n)
        return (self.ms1 + left) * 1000 if left > 0 else None

    def _set(self, n: int, cv: int, bit: int) -> None:
        _UH.pack_into(self.tv, n * 2, cv & 0xFFFF)
        mask = 1 << (n & 7)
        if bit:
            self.tb[n >> 3] |= mask
        else:
            self.tb[n >> 3] &= ~mask & 0xFF

    def _cv(self, n: int) -> int:
        return _H.unpack_from(self.tv, n * 2)[0]

    def _advance(self, n: int, d: int) -> None:
        cv = self._cv(n)
        if cv < 0:  # a program wrote a negative value: treat like the CPU, count up from it
            pass
        cv = min(cv + d, MAX_CV)
        kind = self.kind[n]
        if kind == "TOF":
            if cv >= self.preset[n]:
                self._set(n, cv, 0)
                self._stop(n)
            else:
                self._set(n, cv, 1)
        else:
            self._set(n, cv, cv >= self.preset[n])

    def _stop(self, n: int) -> None:
        self.running[n] = False
        self._fast.discard(n)

    def _start(self, n: int) -> None:
        self.running[n] = True
        if self.res[n] != 100:
            self._fast.add(n)

    def reset(self, n: int) -> None:
        """``R Tn``: clear current value and bit, stop timing."""
        self._stop(n)
        self.prev_in[n] = 0
        self._set(n, 0, 0)

    # -- instruction side -----------------------------------------------
    def ton(self, n: int, en: int, pt: int) -> None:
        """TON: on-delay.  IN=0 clears the current value and the bit."""
        # perf: a running timer with no new tick and the same preset changes
        # nothing -- unless the program wrote its current value (MOVW ..., Tn),
        # so the bit must still agree with CV >= PT.
        if en and self.running[n] and pt == self.preset[n] and (
                self.d100 == 0 or self.res[n] != 100) and self.kind[n] == "TON" \
                and (self.tb[n >> 3] >> (n & 7) & 1) == (self._cv(n) >= pt):
            return
        self.preset[n] = pt
        self.kind[n] = "TON"
        if not en:
            if self.running[n] or self.tb[n >> 3] >> (n & 7) & 1 or self._cv(n):
                self._stop(n)
                self._set(n, 0, 0)
            return
        if not self.running[n]:
            self._start(n)
            self._set(n, self._cv(n), self._cv(n) >= pt)
            return
        cv = self._cv(n)
        if self.res[n] == 100:
            cv = min(cv + self.d100, MAX_CV)
        self._set(n, cv, cv >= pt)

    def tonr(self, n: int, en: int, pt: int) -> None:
        """TONR: retentive on-delay; IN=0 keeps the value, only R clears it."""
        self.preset[n] = pt
        self.kind[n] = "TONR"
        if not en:
            if self.running[n]:
                self._stop(n)
            return
        cv = self._cv(n)
        if not self.running[n]:
            self._start(n)
        elif self.res[n] == 100:
            cv = min(cv + self.d100, MAX_CV)
        self._set(n, cv, cv >= pt)

    def tof(self, n: int, en: int, pt: int) -> None:
        """TOF: off-delay.  IN=1 sets the bit and clears the value; the
        falling edge of IN starts timing; at PT the bit goes off."""
        self.preset[n] = pt
        self.kind[n] = "TOF"
        prev = self.prev_in[n]
        self.prev_in[n] = 1 if en else 0
        if en:
            if self.running[n]:
                self._stop(n)
            self._set(n, 0, 1)
            return
        if prev:
            self._start(n)
            self._set(n, 0, 1)
            return
        if self.running[n] and self.res[n] == 100:
            cv = min(self._cv(n) + self.d100, MAX_CV)
            if cv >= pt:
                self._set(n, cv, 0)
                self._stop(n)
            else:
                self._set(n, cv, 1)
