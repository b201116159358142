"""One EM253 module in an expansion slot: two axes and their terminals.

Process image map (EM253 manual, chapter 1: "one module occupies 16 DI and
16 DO"; plcrt places them after the CPU's own I/O and the modules before
it, slot by slot):

* inputs: ``IB(n)`` axis 0, ``IB(n+1)`` axis 1, with n = CPU input bytes +
  2 x slot (CPU 226: module 0 at IB3/IB4).  Bits: .0 STF, .1 RPS, .2 L+,
  .3 L-, .4 Z.
* outputs: ``QB(m)`` axis 0, ``QB(m+1)`` axis 1, m = CPU output bytes + 2 x
  slot (CPU 226: QB2/QB3).  Bits: .0 En (SevOn), .1 CLR, .2 P (pulsing),
  .3 D (direction positive).

The module writes its inputs to the physical image PI (the next scan reads
them) and its output terminal states into Q.
"""

from __future__ import annotations

from typing import Any, Optional

from ...engine.device import AxisState
from ...errors import PlcConfigError
from .axis import NEVER, Axis, AxisPlant

CLR_PULSE_US = 200_000  #: CLR output pulse length (manual 2.1: "about 200 ms")
SINGLE_ENDED_MAX_HZ = 200_000
DIFFERENTIAL_MAX_HZ = 500_000


class EM253Module:
    """Device: an EM253 in slot ``cfg.slot``."""

    def __init__(self, plc: Any, cfg: Any) -> None:
        self.plc = plc
        self.slot = cfg.slot
        self.configured = set(cfg.axes)
        self.axes = [Axis(cfg.axes.get(i, AxisPlant())) for i in (0, 1)]
        #: perf: a step to a time before this one has nothing to compute:
        #: no axis is due (Axis.wake), no scripted input event, no CLR
        #: pulse pending or shown.  Computed after every exact step; 0
        #: (look again) whenever an axis's wake is set or a CLR pulse starts
        self.quiet_to = 0
        for ax in self.axes:
            ax.module = self
        model = plc.model
        if self.slot >= model.max_modules:
            raise PlcConfigError(
                f"the {model.name} takes {model.max_modules} expansion module(s); "
                f"an EM253 in slot {self.slot} is not possible")
        self.di = model.onboard_di_bytes + 2 * self.slot
        self.do = model.onboard_do_bytes + 2 * self.slot
        if self.di + 2 > model.i_bytes or self.do + 2 > model.q_bytes:
            raise PlcConfigError(
                f"an EM253 in slot {self.slot} needs IB{self.di}-IB{self.di + 1} and "
                f"QB{self.do}-QB{self.do + 1}, beyond the {model.name} process image")
        self.enabled_scan = -1       #: scan number in which MOTION_EN3 last ran
        self.differential = False
        self.clr_until: list[Optional[int]] = [None, None]
        self.clr_pending = False
        self.stf_any = False
        self._cache: list[tuple[int, int] | None] = [None, None]
        self._events = [list(a.plant.events) for a in self.axes]
        #: perf: bound once; fork() maps these buffers to the twin's
        self._pi = plc.mem.areas["PI"]
        self._q = plc.mem.areas["Q"]
        self._di2 = slice(self.di, self.di + 2)
        self._do2 = slice(self.do, self.do + 2)
        #: the terminal bytes last written (perf: bytearrays, never handed
        #: out: a slice store from a bytearray copies its bytes at once,
        #: one from bytes first makes a bytearray of them)
        self._in2, self._out2 = bytearray(2), bytearray(2)
        #: perf: the runs a quiet step stores (plcrt.devices.Device)
        self.held = ((self._pi, self._di2, self._in2), (self._q, self._do2, self._out2))
        self._plant_next = NEVER   #: time of the next scripted input (STF) event
        self._clr_shown = False    #: a CLR output bit is on in the bytes last written
        self._write_terminals(0)
        self._plant_next = min((evs[0][0] for evs in self._events if evs), default=NEVER)

    @property
    def max_hz(self) -> int:
        return DIFFERENTIAL_MAX_HZ if self.differential else SINGLE_ENDED_MAX_HZ

    def step(self, plc: Any, t_from: int, t_to: int) -> None:
        """Advance both axes over (t_from, t_to] and write the terminals."""
        # perf: inside the quiet time (quiet_to: nothing due on either axis,
        # no scripted input event, no CLR pulse pending and none shown) the
        # terminals are the bytes of the last step, written again as every
        # scan does
        if t_to < self.quiet_to:
            self._pi[self._di2] = self._in2
            self._q[self._do2] = self._out2
            return
        self.step_exact(t_from, t_to)

    def step_exact(self, t_from: int, t_to: int) -> None:
        """:meth:`step` without the shortcut: every event up to ``t_to`` in
        time order, then the terminals."""
        for i, ax in enumerate(self.axes):
            evs = self._events[i]
            while evs and evs[0][0] <= t_to:
                te, name, value = evs.pop(0)
                te = max(te, t_from)
                ax.advance(te)
                if name == "STF":
                    self.set_stf(i, te, value)
            ax.advance(t_to)
        self._write_terminals(t_to, t_from)
        self._plant_next = min((evs[0][0] for evs in self._events if evs), default=NEVER)
        a0, a1 = self.axes
        self.quiet_to = 0 if self.clr_pending or self._clr_shown else \
            min(a0.wake, a1.wake, self._plant_next)

    def set_stf(self, i: int, t: int, value: bool) -> None:
        """Hardware emergency stop: pulses stop at once, no ramp (manual 2.1)."""
        ax = self.axes[i]
        ax.stf = value
        ax.wake = 0
        self.stf_any = any(a.stf for a in self.axes)
        if value and ax.moving:
            ax.stop_now(t)
            self.plc.warn(f"EM253 slot {self.slot} axis {i}: STF emergency stop at "
                          f"{t / 1e6:.6f} s, pulses stopped without deceleration",
                          None, f"stf-{self.slot}-{i}-{t}")

    def _write_terminals(self, t: int, t_from: int | None = None) -> None:
        """Input terminals into PI, output terminals into Q, for time ``t``.

        The bytes are written every scan (the module owns them), but only
        recomputed when the axis's wake time has come (a change, an event,
        an input bit reached: :meth:`Axis.next_change`) or its CLR bit
        changes (perf).
        """
        t_from = t if t_from is None else t_from
        cache = self._cache
        for i, ax in enumerate(self.axes):
            until = self.clr_until[i]
            clr = until is not None and t_from < until
            cached = cache[i]
            if t >= ax.wake or cached is None or bool(cached[1] & 2) != clr:
                cache[i] = self._bytes(ax, t, clr)
                ax.wake = ax.next_change(t)
        (b0, o0), (b1, o1) = cache  # type: ignore[misc]
        # in place: the bytearrays are those of ``held``
        self._in2[0], self._in2[1] = b0, b1
        self._out2[0], self._out2[1] = o0, o1
        self._pi[self._di2] = self._in2
        self._q[self._do2] = self._out2
        # a CLR bit on: the next step must see MOTION_EN3 end the pulse
        self._clr_shown = bool((o0 | o1) & 2)

    @staticmethod
    def _bytes(ax: Axis, t: int, clr: bool) -> tuple[int, int]:
        p = ax.plant
        m = ax.mechanical(t)
        b = 1 if ax.stf else 0
        if p.rps is not None and p.rps[0] <= m <= p.rps[1]:
            b |= 2
        if p.limit_pos is not None and m >= p.limit_pos:
            b |= 4
        if p.limit_neg is not None and m <= p.limit_neg:
            b |= 8
        if p.z_period and (m - p.z_offset) % p.z_period == 0:
            b |= 16
        o = 1 if ax.masked else 0
        if clr:
            o |= 2
        if ax.segs and not ax.masked:
            o |= 4
        if ax.direction > 0 and not ax.masked:
            o |= 8
        return b, o

    def snapshot(self, t: int) -> list[AxisState]:
        out = []
        for i, ax in enumerate(self.axes):
            if i not in self.configured:
                continue
            out.append(AxisState(
                slot=self.slot, axis=i,
                position=ax.position(t), mechanical=ax.mechanical(t),
                speed=ax.speed(t),
                status="moving" if ax.moving else "stopped",
                masked=ax.masked, stf=ax.stf,
            ))
        return out
