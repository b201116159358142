"""The CPU's high-speed counters HSC0–HSC5 (HDEF and HSC).

What it is: :class:`HighSpeedCounter`, one per counter (System Manual,
"High-Speed Counter instructions", tables of modes, inputs and SM bytes)::

    counter  status  control  new CV  new PV   inputs (clock/up/A, dir/down/B, reset, start)
    HSC0     SMB36   SMB37    SMD38   SMD42    I0.0 I0.1 I0.2 -
    HSC1     SMB46   SMB47    SMD48   SMD52    I0.6 I0.7 I1.0 I1.1
    HSC2     SMB56   SMB57    SMD58   SMD62    I1.2 I1.3 I1.4 I1.5
    HSC3     SMB136  SMB137   SMD138  SMD142   I0.1 -    -    -
    HSC4     SMB146  SMB147   SMD148  SMD152   I0.3 I0.4 I0.5 -
    HSC5     SMB156  SMB157   SMD158  SMD162   I0.4 -    -    -

Modes (``HDEF HSC, MODE``): 0–2 one clock, direction from control bit 3;
3–5 one clock, direction from the second input; 6–8 up and down clocks;
9–11 A/B quadrature (×4, or ×1 with control bit 2); the second and third
of each family add the reset input, the third the start input; 12 counts
the pulses of the pulse output (HSC0: Q0.0, HSC3: Q0.1).  Control byte:
.0 reset active low, .1 start active low, .2 quadrature ×1, .3 direction up,
.4 update the direction, .5 update PV, .6 update CV, .7 enable.  Status:
.5 counting up, .6 CV = PV, .7 CV > PV.

Where the counts come from:

* a pulse output (mode 12, or a clock input wired to Q0.0/Q0.1 in the
  plant): counted in closed form from the generator, and CV = PV happens at
  the exact µs of the pulse that reaches it — an event of the scan's time
  line;
* any other input signal changes between scans (``--set``, the harness,
  stimuli): its edges are counted at the next scan's start, where their
  events happen too.

* an encoder of the plant (``[[cpu.encoder]]``: inputs, frequency, start,
  stop, direction) on the clock input, or on A/B in the quadrature modes:
  its edges come at exact times (edge k of a segment at start + k / rate),
  counted in closed form, CV = PV at the exact µs as well.

What it is not: no wizard code; a PWM on a wired clock is not counted.
"""

from __future__ import annotations

import struct
from typing import Any, Optional

__all__ = ["HighSpeedCounter", "Encoder", "SM_HSC", "INPUTS", "MODES", "make_counters"]

#: counter -> (status byte, control byte, new CV dword, new PV dword)
SM_HSC = {0: (36, 37, 38, 42), 1: (46, 47, 48, 52), 2: (56, 57, 58, 62),
          3: (136, 137, 138, 142), 4: (146, 147, 148, 152), 5: (156, 157, 158, 162)}
#: counter -> its inputs (clock/up/A, direction/down/B, reset, start) as I bit numbers
INPUTS: dict[int, tuple[Optional[int], ...]] = {
    0: (0, 1, 2, None), 1: (6, 7, 8, 9), 2: (10, 11, 12, 13),
    3: (1, None, None, None), 4: (3, 4, 5, None), 5: (4, None, None, None)}
#: counter -> the modes it has
from ..memory.hardware import MODES  # noqa: E402
#: counter -> interrupt events (CV=PV, direction changed, external reset)
EVENTS: dict[int, tuple[Optional[int], ...]] = {
    0: (12, 27, 28), 1: (13, 14, 15), 2: (16, 17, 18), 3: (32, None, None),
    4: (29, 30, 31), 5: (33, None, None)}
#: mode 12: the pulse output a counter counts
INTERNAL_PTO = {0: 0, 3: 1}

UP, EQUAL, GREATER = 0x20, 0x40, 0x80
_I32 = 2**31


_UD = struct.Struct(">I")


def _wrap(v: int) -> int:
    return (v + _I32) % 2**32 - _I32


class Encoder:
    """A plant signal on a counter's inputs: *hz* cycles per second of the
    clock (A) from *start* until *stop* (µs, None: for ever), *direction* +1
    (A leads B) or -1.  Its edges, as a counter counts them, come in closed
    form: ``per_cycle`` edges per cycle (1; 4 for quadrature ×4)."""

    def __init__(self, a: int, b: Optional[int], hz: int, start: int, stop: Optional[int],
                 direction: int) -> None:
        self.a, self.b = a, b
        self.hz, self.start, self.stop, self.direction = hz, start, stop, direction
        self.per_cycle = 1

    def _edges(self, t: int) -> int:
        """Counted edges in [start, t], the first at start (integer arithmetic)."""
        if t < self.start:
            return 0
        if self.stop is not None and t > self.stop:
            t = self.stop
        rate = self.hz * self.per_cycle
        return (t - self.start) * rate // 1_000_000 + 1

    def pulses_until(self, t: int) -> int:
        return self._edges(t)

    def time_of_pulse(self, k: int) -> Optional[int]:
        """The time of counted edge *k* (1 = the first), if the signal makes it."""
        rate = self.hz * self.per_cycle
        te = self.start + (-(-(k - 1) * 1_000_000 // rate))      # ceil
        if k < 1 or (self.stop is not None and te > self.stop):
            return None
        return te

    def live(self) -> bool:
        return True

    def level(self, t: int, bit: int) -> int:
        """The level of input *bit* (A, or B a quarter period behind A, ahead
        when the direction is down) at *t*: A is high in the first half of
        each period from start."""
        if t < self.start or (self.stop is not None and t >= self.stop):
            return 0
        phase = 0 if bit == self.a else (1 if self.direction > 0 else 3)
        q = (t - self.start) * 4 * self.hz // 1_000_000
        return 1 if (q - phase) % 4 in (0, 1) and q >= phase else 0

    @property
    def trains(self) -> list:        # the interface of a pulse output the counter reads
        return [self]


class HighSpeedCounter:
    """HSC*number*: its mode, current and preset value, direction, source."""

    def __init__(self, number: int, plc: Any) -> None:
        self.number = number
        self.plc = plc
        self.sm, self.hc = plc.mem.areas["SM"], plc.mem.areas["HC"]
        self.status, self.control, self.new_cv, self.new_pv = SM_HSC[number]
        self.mode: Optional[int] = None
        self.enabled = False
        self.cv = 0
        self.pv = 0
        self.direction = 1
        self.pulse: Any = None           #: the pulse output counted (mode 12 / wired)
        self.base = 0                    #: pulses of that output at the last sync
        self.inputs = 0                  #: the input bits as last sampled (4 bits)
        self.reset_held = False
        self.fired_at: Optional[int] = None   #: the time of the last CV=PV event
        self._hc_at = 4 * number              #: HCn's offset in the HC area
        self._signal_bits = 0                 #: input bits a counted signal drives
        #: (input byte, bit, position in the 4-bit sample) of each input it has
        self._taps = tuple((bit // 8, bit % 8, k) for k, bit in enumerate(INPUTS[number])
                           if bit is not None)

    # ------------------------------------------------------------ helpers
    def _dword(self, offset: int) -> int:
        return int.from_bytes(self.sm[offset:offset + 4], "big", signed=True)

    def _publish(self) -> None:
        _UD.pack_into(self.hc, self._hc_at, self.cv & 0xFFFFFFFF)
        st = UP if self.direction > 0 else 0
        if self.cv == self.pv:
            st |= EQUAL
        elif self.cv > self.pv:
            st |= GREATER
        self.sm[self.status] = self.sm[self.status] & 0x1F | st

    def _post(self, k: int, t: int) -> None:
        event = EVENTS[self.number][k]
        if event is not None:
            self.plc.interrupts.post(event, t)

    # ------------------------------------------------------------ instructions
    def hdef(self, mode: int, t: int) -> None:
        """HDEF: the counter's mode (once per counter after RUN)."""
        if self.mode is not None:
            self.plc._irq_warn(f"HDEF of HSC{self.number} executed again: the mode is set "
                               f"once after RUN (it stays {self.mode}; System Manual, HDEF "
                               f"error 000A)", f"hdef-{self.number}")
            return
        self.mode = mode
        clock = INPUTS[self.number][0]
        source = INTERNAL_PTO.get(self.number) if mode == 12 else self.plc.wiring.get(clock)
        encoder = self.plc.encoders.get(clock)
        if mode == 12 or (source in (0, 1) and mode < 9):
            # a pulse output (Q0.0 / Q0.1) on the clock: counted in closed form
            self.pulse = self.plc.pulse[source]
        elif encoder is not None and mode not in (6, 7, 8):
            self.pulse = encoder
        if self.pulse is not None:
            # the inputs the signal drives: the clock (A), and B in quadrature
            self._signal_bits = 0x0F if mode == 12 else 0x03 if mode >= 9 else 0x01
        self.inputs = self._sample(self.plc.mem.areas["PI"])

    def hsc(self, t: int) -> None:
        """HSC: apply the control byte."""
        if self.mode is None:
            self.plc._irq_warn(f"HSC {self.number} before HDEF: the counter has no mode; "
                               f"nothing happens (System Manual, HSC)", f"hsc-nodef-{self.number}")
            return
        self.sync(t)
        ctrl = self.sm[self.control]
        if not ctrl & 0x80:
            self.enabled = False
            self._publish()
            return
        if ctrl & 0x10 and (self.mode in (0, 1, 2, 12)):
            new = 1 if ctrl & 0x08 else -1
            if new != self.direction:
                self.direction = new
        if isinstance(self.pulse, Encoder) and self.mode is not None and self.mode >= 9:
            # quadrature from an encoder: its direction, x4 or x1 (control bit 2)
            self.pulse.per_cycle = 1 if ctrl & 0x04 else 4
            self.direction = self.pulse.direction
        if ctrl & 0x20:
            self.pv = self._dword(self.new_pv)
        if ctrl & 0x40:
            self.cv = self._dword(self.new_cv)
        if not self.enabled:
            self.enabled = True
            self.inputs = self._sample(self.plc.mem.areas["PI"])
            if self.mode in (3, 4, 5):          # the direction input's level now
                self.direction = 1 if self.inputs & 2 else -1
            if self.pulse is not None:
                self.base = self.pulse.pulses_until(t)
        self._publish()

    # ------------------------------------------------------------ counting
    def counting(self) -> bool:
        """Whether the start input (modes 2, 5, 8, 11) lets it count."""
        if self.mode is None or self.mode == 12 or self.mode % 3 != 2:
            return True
        active_low = self.sm[self.control] & 0x02
        return bool(self.inputs >> 3 & 1) != bool(active_low)

    #: its next event changes only by HDEF/HSC, the scan start or its own events
    cacheable = True

    def live(self) -> bool:
        """Whether it counts a running pulse output or an encoder (events to come)."""
        return self.enabled and self.pulse is not None and bool(self.pulse.trains)

    def sync(self, t: int) -> None:
        """Count the wired pulse output's pulses up to *t*."""
        pulse = self.pulse
        if pulse is None or not self.enabled:
            return
        now = pulse.pulses_until(t)
        if now != self.base:
            # perf: the start input is read only in the modes that have one
            if not self.reset_held and (self.mode == 12 or self.mode % 3 != 2
                                        or self.counting()):
                cv = self.cv + self.direction * (now - self.base)
                # perf: wrapped only when it leaves the DINT range
                self.cv = cv if -_I32 <= cv < _I32 else _wrap(cv)
            self.base = now
            self._publish()

    def next_time(self, after: int, until: int) -> Optional[int]:
        """When a counted pulse output brings CV to PV, in (*after*, *until*]."""
        if self.pulse is None or not self.enabled or self.reset_held or not self.counting():
            return None
        # perf: CV at *after* without publishing it
        cv = self.cv + self.direction * (self.pulse.pulses_until(after) - self.base)
        steps = (self.pv - cv) * self.direction
        if steps <= 0:
            return None
        te = self.pulse.time_of_pulse(self.pulse.pulses_until(after) + steps)
        if te is not None and te == self.fired_at:
            return None                 # this crossing has had its event
        return te if te is not None and after < te <= until else None

    def fire(self, t: int) -> None:
        self.sync(t)
        if self.cv == self.pv:
            self.fired_at = t
            self._post(0, t)

    def _sample(self, pi: bytearray) -> int:
        v = 0
        for byte, bit, k in self._taps:       # perf: no generator per scan
            v |= (pi[byte] >> bit & 1) << k
        return v

    def scan_start(self, pi: bytearray, t: int) -> bool:
        """Edges of the counter's inputs since the last scan (the outside
        world changes them between scans), counted at *t*; whether its
        inputs changed (its next event may have moved)."""
        if self.mode is None:
            return False
        new = self._sample(pi)
        old, self.inputs = self.inputs, new
        if not self.enabled:
            return old != new
        self._scan_start(old, new, t)
        # perf: a clock that a pulse output or an encoder drives was counted
        # in closed form; its level changing moves no event
        return bool((old ^ new) & ~self._signal_bits)

    def _scan_start(self, old: int, new: int, t: int) -> None:
        self.sync(t)
        mode = self.mode
        if mode != 12 and mode % 3 >= 1:                 # the reset input
            active_low = self.sm[self.control] & 0x01
            active = bool(new >> 2 & 1) != bool(active_low)
            if active and not self.reset_held:
                self.cv = 0
                self._post(2, t)
            self.reset_held = active
        if self.reset_held or not self.counting() or old == new or mode == 12:
            self._publish()
            return
        delta = 0
        family = mode // 3
        if family == 0 and self.pulse is None:
            delta = self.direction if (new & 1) and not (old & 1) else 0
        elif family == 1:
            direction = 1 if new & 2 else -1
            if direction != self.direction:
                self.direction = direction
                self._post(1, t)
            if self.pulse is None and (new & 1) and not (old & 1):
                delta = direction
        elif family == 2:
            delta = (1 if (new & 1) and not (old & 1) else 0) - \
                (1 if (new & 2) and not (old & 2) else 0)
        elif family == 3 and self.pulse is None:
            delta = self._quadrature(old & 3, new & 3, t)
        if delta:
            self.cv = _wrap(self.cv + delta)
            if self.cv == self.pv:
                self._post(0, t)
        self._publish()

    def _quadrature(self, old: int, new: int, t: int) -> int:
        """A/B phase: the Gray step from *old* to *new* (bit 0 A, bit 1 B)."""
        order = (0, 1, 3, 2)            # A leads B: 00 -> 01 -> 11 -> 10 counts up
        step = (order.index(new) - order.index(old)) % 4
        if step == 0:
            return 0                    # A and B as they were (another input changed)
        if step == 2:
            self.plc._irq_warn(f"HSC{self.number}: A and B changed together between two "
                               f"scans; the step cannot be counted (change them one at a "
                               f"time)", f"hsc-ab-{self.number}")
            return 0
        direction = 1 if step == 1 else -1
        if direction != self.direction:
            self.direction = direction
            self._post(1, t)
        if self.sm[self.control] & 0x04:             # ×1: A rising only
            return direction if (new & 1) and not (old & 1) else 0
        return direction


def make_counters(plc: Any) -> list[HighSpeedCounter]:
    return [HighSpeedCounter(n, plc) for n in range(plc.model.hsc)]
