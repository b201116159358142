"""The CPU's pulse outputs Q0.0 and Q0.1: PTO and PWM (the PLS instruction).

What it is: :class:`PulseOutput`, one generator per output, driven by its
SM bytes (System Manual, "Pulse Output (PLS)", "Using the high-speed
outputs")::

    output  status  control  cycle   pulse width  pulse count  segment  profile
    Q0.0    SMB66   SMB67    SMW68   SMW70        SMD72        SMB166   SMW168
    Q0.1    SMB76   SMB77    SMW78   SMW80        SMD82        SMB176   SMW178

Control byte: .0 update the cycle time, .1 update the pulse width, .2
update the pulse count, .3 time base (0 = 1 µs, 1 = 1 ms), .4 PWM update
(0 asynchronous, 1 synchronous), .5 PTO multi-segment, .6 0 = PTO, 1 = PWM,
.7 enable.  Status byte: .4 delta calculation error, .5 aborted by the
user, .6 pipeline overflow, .7 PTO idle.

* PTO, single segment: a train of N pulses of 50 % duty at the cycle time;
  one more train may wait in the pipeline and starts at the exact end of
  the running one; a third is refused (pipeline overflow, SM66.6).
* PTO, multi-segment: the profile table in V memory at the offset in
  SMW168 — the number of segments (byte), then per segment the initial
  cycle time (word), the signed change per pulse (word) and the pulse count
  (double word).  The cycle time of pulse k of a segment is initial + k x
  delta, so the segment lasts N x initial + delta x N(N-1)/2 time units: a
  closed form, never pulse by pulse.
* PWM: the cycle time and the pulse width; a width of 0 keeps the output
  off, one of at least the cycle keeps it on.  A synchronous update takes
  effect at the end of the running cycle, an asynchronous one at once.
* Disabling (enable bit 0, PLS) aborts a PTO (SM66.5) or stops the PWM.
* At the end of a PTO (the pipeline empty) the generator is idle (SM66.7)
  and posts event 19 (Q0.0) or 20 (Q0.1), the PTO-complete interrupt.
* While a generator runs it drives the output terminal, not the image bit;
  the terminal's state at a time is the pulse's level then (high for the
  first half of each PTO cycle, for the pulse width of each PWM cycle).

What it is not: no counter (a high-speed counter wired to the output counts
with :meth:`pulses_until`), no wizard code (PTOx_* blocks).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Optional

__all__ = ["PulseOutput", "Train", "SM_BASE"]

#: output -> (status byte, profile offset word, current segment byte)
SM_BASE = {0: (66, 168, 166), 1: (76, 178, 176)}
#: PTO complete interrupt events (System Manual, table of interrupt events)
COMPLETE_EVENT = {0: 19, 1: 20}

IDLE, USER_ABORT, OVERFLOW, DELTA_ERROR = 0x80, 0x20, 0x40, 0x10
MIN_CYCLE_US = 50          #: shortest PTO/PWM cycle at the 1 µs time base (CPU 22x: 20 kHz)
#: CPUs whose Q0.0/Q0.1 make 100 kHz (data sheet: CPU 224XP high-speed outputs)
FAST_OUTPUTS = {"CPU224XP": 10}


@dataclass
class Train:
    """One PTO segment in time: pulses of cycle ``c0 + k * delta`` (µs)."""

    start: int              #: µs of the first pulse's rising edge
    count: int              #: pulses
    c0: int                 #: cycle of the first pulse, µs
    delta: int = 0          #: change of the cycle per pulse, µs
    segment: int = 0        #: multi-segment: its number (0 for single)

    end: int = 0            #: µs after the last pulse (set from the others)

    def __post_init__(self) -> None:
        self.shift(0)

    def shift(self, dt: int) -> None:
        """Move the train by *dt* µs (perf: its end is kept, not recomputed)."""
        self.start += dt
        self.end = self.rise(self.count)

    def rise(self, j: int) -> int:
        """The rising edge of pulse *j* (0 = the first): start + j·c0 + Δ·j(j−1)/2;
        ``rise(count)`` is the train's end."""
        return self.start + j * self.c0 + self.delta * j * (j - 1) // 2

    def cycle(self, j: int) -> int:
        """The cycle of pulse *j*, µs."""
        return self.c0 + j * self.delta

    def pulses_started(self, t: int) -> int:
        """Rising edges in [start, t] (closed form; never pulse by pulse)."""
        if t < self.start:
            return 0
        if t >= self.end:
            return self.count
        if self.delta == 0:
            return min(self.count, (t - self.start) // self.c0 + 1)
        # the largest k with rise(k) <= t
        lo, hi = 0, self.count - 1
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if self.rise(mid) <= t:
                lo = mid
            else:
                hi = mid - 1
        return lo + 1

    def level(self, t: int) -> int:
        """The output's level at *t* (high for the first half of a cycle)."""
        if not self.start <= t < self.end:
            return 0
        if self.delta == 0:             # perf: a constant cycle inline
            return 1 if (t - self.start) % self.c0 < self.c0 // 2 else 0
        k = self.pulses_started(t) - 1
        return 1 if t - self.rise(k) < self.cycle(k) // 2 else 0


class PulseOutput:
    """The PTO/PWM generator of Q0.*number*.

    *post(event, t)* posts an interrupt event; *warn(message, key)* reports
    a diagnostic once."""

    def __init__(self, number: int, sm: bytearray, v: bytearray,
                 post: Callable[[int, int], None], warn: Callable[[str, str], None],
                 min_cycle_us: int = MIN_CYCLE_US) -> None:
        self.number = number
        self.min_cycle = min_cycle_us
        self.sm, self.v = sm, v
        self.post, self.warn = post, warn
        self.status, self.profile, self.segment_byte = SM_BASE[number]
        self.control = self.status + 1
        self.mode = ""                     #: "", "PTO" or "PWM"
        self.trains: list[Train] = []      #: the running train and what follows it
        self.pending: Optional[list[Train]] = None  #: the pipeline (single segment)
        self.pwm: tuple[int, int, int] = (0, 0, 0)  #: (start, cycle µs, width µs)
        self.pwm_next: Optional[tuple[int, int]] = None  #: a synchronous update
        self.pwm_asked = 0                 #: when it was asked for
        self.sent = 0                      #: pulses of finished trains (for counters)
        self.sm[self.status] |= IDLE

    # ------------------------------------------------------------ SM access
    def _word(self, offset: int) -> int:
        return self.sm[offset] << 8 | self.sm[offset + 1]

    def _dword(self, offset: int) -> int:
        return int.from_bytes(self.sm[offset:offset + 4], "big")

    #: its events change what counters on it will do (the scheduler asks them again)
    moves_others = True
    #: its next event changes only by PLS or its own events (the scheduler keeps it)
    cacheable = True

    def live(self) -> bool:
        """Whether it has events to come (a train, a synchronous PWM update)."""
        return bool(self.trains) or self.pwm_next is not None

    @property
    def running(self) -> bool:
        return bool(self.trains) or self.mode == "PWM"

    # ------------------------------------------------------------ PLS
    def pls(self, t: int) -> None:
        """PLS Q0.n at time *t*: act on the control byte."""
        ctrl = self.sm[self.control]
        unit = 1000 if ctrl & 0x08 else 1
        if not ctrl & 0x80:
            self._disable(t)
            return
        if ctrl & 0x40:
            self._pwm(t, ctrl, unit)
        else:
            self._pto(t, ctrl, unit)

    def _disable(self, t: int) -> None:
        if self.trains:
            self.sent += sum(tr.pulses_started(t) for tr in self.trains)
            self.trains, self.pending = [], None
            self.sm[self.status] |= USER_ABORT | IDLE
        self.mode = ""
        self.pwm_next = None

    def _cycle(self, ctrl: int, unit: int, what: str) -> Optional[int]:
        cycle = self._word(self.control + 1) * unit
        if cycle < self.min_cycle:
            self.warn(f"Q0.{self.number} {what}: cycle time {cycle} µs is below the "
                      f"{self.min_cycle} µs the outputs can make; nothing is started "
                      f"(SMW{self.control + 1})", f"pls-cycle-{self.number}")
            return None
        return cycle

    def _pto(self, t: int, ctrl: int, unit: int) -> None:
        if self.mode == "PWM":
            self.warn(f"Q0.{self.number}: PLS in PTO mode while PWM runs: the PWM stops "
                      f"first", f"pls-mode-{self.number}")
            self._disable(t)
        if ctrl & 0x20:
            trains = self._profile(t, unit)
        else:
            cycle = self._cycle(ctrl, unit, "PTO")
            if cycle is None:
                return
            count = self._dword(self.control + 5) or 1   # 0 counts as 1 (manual)
            trains = [Train(t, count, cycle)]
        if not trains:
            return
        self.mode = "PTO"
        if not self.trains:
            self._start(trains, t)
        elif self.pending is None:
            self.pending = trains
        else:
            self.sm[self.status] |= OVERFLOW
            self.warn(f"Q0.{self.number}: PTO pipeline overflow at {t / 1e6:.6f} s: a train "
                      f"runs and one waits, this one is ignored (SM{self.status}.6)",
                      f"pls-overflow-{self.number}")

    def _start(self, trains: list[Train], t: int) -> None:
        shift = t - trains[0].start
        for tr in trains:
            tr.shift(shift)
        self.trains = trains
        self.sm[self.status] &= ~(IDLE | USER_ABORT | OVERFLOW | DELTA_ERROR) & 0xFF
        self.sm[self.segment_byte] = trains[0].segment

    def _profile(self, t: int, unit: int) -> list[Train]:
        base = self._word(self.profile)
        v = self.v
        if base >= len(v):
            self.warn(f"Q0.{self.number}: profile table at VB{base} (SMW{self.profile}) is "
                      f"outside V memory", f"pls-table-{self.number}")
            return []
        n = v[base]
        trains, start = [], t
        for k in range(n):
            off = base + 1 + 8 * k
            if off + 8 > len(v):
                self.warn(f"Q0.{self.number}: segment {k} of the profile at VB{base} runs "
                          f"past the end of V memory", f"pls-table-{self.number}")
                return []
            c0 = (v[off] << 8 | v[off + 1]) * unit
            delta = int.from_bytes(v[off + 2:off + 4], "big", signed=True) * unit
            count = int.from_bytes(v[off + 4:off + 8], "big") or 1
            last = c0 + (count - 1) * delta
            if c0 < self.min_cycle or last < self.min_cycle or last > 65535 * unit:
                self.sm[self.status] |= DELTA_ERROR | IDLE
                self.warn(f"Q0.{self.number}: segment {k} of the profile at VB{base} takes "
                          f"its cycle from {c0} to {last} µs, outside {self.min_cycle}.."
                          f"{65535 * unit} µs: the profile is aborted (SM{self.status}.4, "
                          f"delta calculation error)", f"pls-delta-{self.number}")
                return []
            tr = Train(start, count, c0, delta, k)
            trains.append(tr)
            start = tr.end
        return trains

    def _pwm(self, t: int, ctrl: int, unit: int) -> None:
        if self.trains:
            self.warn(f"Q0.{self.number}: PLS in PWM mode while a PTO runs: the PTO is "
                      f"aborted", f"pls-mode-{self.number}")
            self._disable(t)
        cycle = self._cycle(ctrl, unit, "PWM")
        if cycle is None:
            return
        width = self._word(self.control + 3) * unit
        if self.mode == "PWM" and ctrl & 0x10:
            self.pwm_next = (cycle, width)          # synchronous: at the end of this cycle
            self.pwm_asked = t
            return
        self.mode = "PWM"
        self.pwm = (t, cycle, width)
        self.pwm_next = None

    # ------------------------------------------------------------ time
    def next_time(self, after: int, until: int) -> Optional[int]:
        """The end of the running train, or the cycle end of a synchronous
        PWM update, in (*after*, *until*]."""
        if self.trains:
            te = self.trains[-1].end
            return te if after < te <= until else None
        if self.pwm_next is not None:
            start, cycle, _ = self.pwm
            since = max(after, self.pwm_asked)      # the cycle end after the request
            te = start + ((since - start) // cycle + 1) * cycle
            return te if te <= until else None
        return None

    def fire(self, t: int) -> None:
        if self.trains and self.trains[-1].end == t:
            self.sent += sum(tr.count for tr in self.trains)
            self.trains = []
            if self.pending is not None:
                trains, self.pending = self.pending, None
                self._start(trains, t)
                return
            self.sm[self.status] |= IDLE
            self.mode = ""
            self.post(COMPLETE_EVENT[self.number], t)
        elif self.pwm_next is not None:
            cycle, width = self.pwm_next
            self.pwm, self.pwm_next = (t, cycle, width), None

    def edge_after(self, after: int, rising: bool) -> Optional[int]:
        """The terminal's first rising (or falling) edge after *after*, while
        a PTO runs (a pulse is high for the first half of its cycle)."""
        k = self.pulses_until(after)              # pulses risen by *after*
        for j in ((k + 1,) if rising else (k, k + 1)):
            at = self._pulse(j)
            if at is None:
                continue
            rise, cycle = at
            te = rise if rising else rise + cycle // 2
            if te > after:
                return te
        return None

    def _pulse(self, k: int) -> Optional[tuple[int, int]]:
        """(rise, cycle) of the *k*-th pulse since power-up in a running train."""
        k -= self.sent
        for tr in self.trains:
            if k <= 0:
                return None
            if k <= tr.count:
                return tr.rise(k - 1), tr.cycle(k - 1)
            k -= tr.count
        return None

    def time_of_pulse(self, k: int) -> Optional[int]:
        """The time of the *k*-th rising edge since power-up, if a running
        train makes it (closed form)."""
        at = self._pulse(k)
        return None if at is None else at[0]

    def pulses_until(self, t: int) -> int:
        n = self.sent
        for tr in self.trains:          # perf: no generator on the event path
            if t < tr.start:
                break
            if t >= tr.end:
                n += tr.count
            elif tr.delta == 0:
                # perf: the constant-cycle train inline (t < end: never past count)
                n += (t - tr.start) // tr.c0 + 1
            else:
                n += tr.pulses_started(t)
        return n

    def level(self, t: int) -> int:
        """The terminal's level at *t*."""
        if self.trains:
            # perf: no generator per scan (levels are 0 or 1)
            for tr in self.trains:
                if tr.level(t):
                    return 1
            return 0
        if self.mode == "PWM":
            start, cycle, width = self.pwm
            if width <= 0:
                return 0
            if width >= cycle:
                return 1
            return 1 if (t - start) % cycle < width else 0
        return 0

    def retire(self, t: int) -> None:
        """Count the trains that ended by *t* as sent and drop them (the
        running train and what follows stay).  Nothing asks about a time
        before *t* afterwards (the engine calls it at a scan's end for the
        next scan's start)."""
        trains = self.trains
        # perf: a wizard ramp is many short trains; counters walk this list
        while len(trains) > 1 and trains[0].end <= t:
            self.sent += trains.pop(0).count

    def update_segment(self, t: int) -> None:
        """SMB166/176: the number of the segment running at *t*."""
        for tr in self.trains:
            if tr.start <= t < tr.end:
                self.sm[self.segment_byte] = tr.segment
                return

    # ------------------------------------------------------------ wizard blocks
    # The Position Control and PWM wizards' subroutines (PTOx_*, PWMx_RUN;
    # plcrt.devices.ptowizard) drive the generator with whole trains.

    def pulse_in_progress(self, t: int) -> Optional[Train]:
        """The pulse running at *t* (its rise <= t < the end of its cycle) as
        a one-pulse train, or None when no PTO runs then."""
        for tr in self.trains:
            if tr.start <= t < tr.end:
                k = tr.pulses_started(t) - 1
                return Train(tr.rise(k), 1, tr.cycle(k), 0, tr.segment)
        return None

    def run_trains(self, trains: list[Train]) -> None:
        """Run *trains* (end to end, from the first one's start) in place of
        the running PTO; the old trains' pulses that rose before that start
        count as sent, a PWM stops.  Everything else is as for a PTO that
        PLS started: SM66.7, the segment byte, the counters on the output,
        the PTO-complete event at the end."""
        first = trains[0].start
        if self.trains:
            self.sent += sum(tr.pulses_started(first - 1) for tr in self.trains)
        self.pending = None
        self.pwm_next = None
        self.mode = "PTO"
        self._start(trains, first)

    def stop_now(self, t: int) -> None:
        """Stop the pulses at *t* as PLS with the enable bit 0 does (a PTO:
        SM66.5 and idle, no PTO-complete event; a PWM: the output off)."""
        self._disable(t)

    def pwm_run(self, t: int, cycle: int, width: int) -> None:
        """Start a PWM of *cycle* and *width* µs, or change the running one
        with a synchronous update (at the end of the running cycle).  The
        caller checks the cycle against ``min_cycle``."""
        if self.trains:
            self.warn(f"Q0.{self.number}: PWM started while a PTO runs: the PTO is "
                      f"aborted", f"pls-mode-{self.number}")
            self._disable(t)
        if self.mode == "PWM":
            target = self.pwm_next if self.pwm_next is not None else self.pwm[1:]
            if (cycle, width) != tuple(target):
                self.pwm_next = (cycle, width)
                self.pwm_asked = t
            return
        self.mode = "PWM"
        self.pwm = (t, cycle, width)
        self.pwm_next = None


def make_outputs(plc: Any) -> list[PulseOutput]:
    """Both pulse outputs of *plc*'s CPU, posting to its interrupts."""
    sm, v = plc.mem.areas["SM"], plc.mem.areas["V"]
    fast = FAST_OUTPUTS.get(plc.model.name, MIN_CYCLE_US)
    return [PulseOutput(n, sm, v, plc.interrupts.post, plc._irq_warn, fast) for n in (0, 1)]
