"""The scan loop of :class:`plcrt.engine.runtime.Plc`: one scan, scan after scan.

One scan, as on the S7-200 (System Manual, "The scan cycle"):

1. copy the physical inputs (PI) into the input image I;
2. special memory: SM0.0, SM0.1/SM0.3 on the first scan, the SM0.4/SM0.5
   clocks and SM0.6 scan clock from simulated time, scan-time words;
3. advance running 1 ms / 10 ms timers (100 ms timers advance in their box);
4. execute OB1 (and the subroutines it calls);
5. step simulated devices;
6. copy the output image Q to the physical outputs (PQ);
7. a STOP instruction executed in this scan switches to STOP mode now.

Simulated time is integer microseconds, advanced by a fixed scan time after
each scan: deterministic, no sleeping.  ``pace="realtime"`` sleeps to keep
wall-clock pace (for demos); it never changes results.

What it is: :class:`ScanLoop`, a mixin of ``Plc`` holding :meth:`~ScanLoop.scan`
(with its plain path: the hot loop), the scan's start and end, the time
line of a scan interval and the flag that says which path a scan takes.
What it is not: building a PLC (:mod:`.runtime`), the routines and calls
the time line runs (:mod:`.eventcalls`), faults (:mod:`.faults`).
"""

from __future__ import annotations

import time as _time

from ..errors import PlcConfigError
from ..safetext import shown_value
from .values import MAX_STEPS, Duration, scan_number, scan_total

__all__ = ["ScanLoop", "SMB0"]


class ScanLoop:
    """The scan loop of a PLC (a mixin of :class:`plcrt.engine.runtime.Plc`,
    which sets up every attribute it reads)."""

    # -- which path a scan takes ---------------------------------------------
    @property
    def stop_requested(self) -> bool:
        """A STOP instruction ran: the CPU goes to STOP at the scan's end."""
        return self._stop

    @stop_requested.setter
    def stop_requested(self, value: bool) -> None:
        if not isinstance(value, (bool, int)):   # an array's truth is no answer
            raise PlcConfigError(f"stop_requested is True or False, not {shown_value(value)}")
        self._stop = bool(value)
        self._replain()

    @property
    def _sources_on(self) -> bool:
        """A PLS, HDEF, a T32/T96 or port ATCH or a port's traffic ran: the
        scan's time line has event sources (perf: see :meth:`_timeline`).
        Devices and blocks set it; the engine reads ``_sources``."""
        return self._sources

    @_sources_on.setter
    def _sources_on(self, value: bool) -> None:
        self._sources = value
        self._replain()

    def _replain(self) -> None:
        """Whether a scan can take the plain path of :meth:`scan`: no HSC
        defined, no force, no event source on the time line (PLS, HDEF,
        a timed or port interrupt, port traffic), no STOP requested, no
        plant wires or encoders, no watchdog counting, and an OB1.

        perf: the scan loop tests this one flag, so it is recomputed by
        every change of what it depends on: force/unforce, the
        ``_sources_on`` and ``stop_requested`` setters (HDEF, PLS and the
        ports set ``_sources_on``), ATCH/DTCH, a restore.  The observers
        are tested at each scan's end."""
        self._plain = not (self._defined or self._force_slots or self._sources or self._stop
                           or self.interrupts.timed_next or self.encoders or self.wiring
                           or self._wd_used or self._ob1 is None)

    # -- time -----------------------------------------------------------
    @property
    def time(self) -> float:
        """Simulated time in seconds since power-up."""
        return self._t_us / 1e6

    # -- scanning -------------------------------------------------------
    def scan(self, n: int = 1) -> None:
        """Run ``n`` scan cycles (nothing happens in STOP mode).

        Raises:
            PlcConfigError: ``n`` is not a non-negative whole number.
            PlcRuntimeError: on a fatal fault; the CPU is left in STOP.
        """
        if type(n) is not int or not 0 <= n <= MAX_STEPS:  # perf: one test for scan(1)
            n = scan_number(n)
        if self.network is not None:
            raise PlcConfigError("this PLC is linked to others: run them together with the "
                                 "network's run() (plcrt.link), not scan() or run()")
        if self._tier is not None:   # backend="auto" on its Python build (engine/tiering.py)
            self._tiered_scan(n)
            return
        if self.pace == "realtime":
            for _ in range(n):
                if self.mode != "RUN":
                    return
                t0 = _time.perf_counter()
                self._scan_once()
                left = self.scan_us / 1e6 - (_time.perf_counter() - t0)
                if left > 0:
                    _time.sleep(left)
            return
        # perf: the plain scan (_replain) inline: _scan_begin's work for a
        # program without forces, HSCs, watchdog counting or event sources,
        # the devices stepped in place of the time line (_timeline), the
        # usual scan end (_scan_end: no forces, pulse generator, plant
        # wires, STOP or observers); the buffers and methods looked up once
        i_img, pi, sm, l_ob1 = self._bufs_begin
        q, pq = self._bufs_end[1:]
        steps = [dev.step for dev in self.devices]
        # perf: one device (an EM253, a drive...) is called without a loop,
        # and its quiet steps (plcrt.devices.Device: before ``quiet_to`` a
        # step stores its two ``held`` byte runs again, nothing else) are
        # done here without calling it, while ``held`` is still the tuple
        # seen now (a restore replaces it) and the device's step is its
        # class's
        step1 = steps.pop() if len(steps) == 1 else None
        dev1 = self.devices[0] if step1 is not None else None
        held = getattr(dev1, "held", None)
        if getattr(step1, "__func__", None) is not getattr(type(dev1), "step", None):
            held = None   # its step replaced on the instance (a wrapper): call it
        if held is not None and len(held) == 2:
            (hb0, hs0, hd0), (hb1, hs1, hd1) = held
        else:
            dev1 = _NOT_QUIET   # never quiet: the test below is always False
        irq, timers, ob1 = self.interrupts, self.timers, self._ob1
        scan_us, edge_mask = self.scan_us, self._edge_mask
        if self.mode != "RUN":
            return
        for _ in range(n):
            now = self._t_us
            if not self._plain:
                self._scan_once()
                if self.mode != "RUN":
                    return
                continue
            # perf: the raw byte against the one last seen here first (any
            # stale value only costs the exact test below)
            if pi[0] != self._pi0_raw or irq.queued:
                self._pi0_raw = pi[0]
                if pi[0] & edge_mask != self._pi0 or irq.queued:
                    self._input_edges(now, pi[0] & edge_mask)
            i_img[:] = pi
            scans = self.scans
            # perf: time only moves forward and a restore clears the window,
            # so the window's start (_calm_lo) is never above ``now`` here
            if now < self._calm_hi and not timers._fast:
                # perf: SMB0 for this scan's parity, the timer bank's
                # millisecond (see _calm_start)
                sm[0] = self._smb0[scans & 1]
                timers.ms1 = now // 1000
            else:
                self._calm_start(sm, scans, now)
            self._prev_start = self._irq_t = now
            try:
                ob1(l_ob1)
            except Exception as e:
                self._fault(e)
            t_to = now + scan_us
            if self._plain:   # the program can end it (ATCH, PLS, HDEF, STOP...)
                try:
                    if t_to < dev1.quiet_to and dev1.held is held:
                        hb0[hs0] = hd0
                        hb1[hs1] = hd1
                    elif step1 is not None:
                        step1(self, now, t_to)
                    else:
                        for step in steps:
                            step(self, now, t_to)
                except Exception as e:
                    self._fault(e)
                if self._plain and not self.observers:
                    pq[:] = q
                    self.scans = scans + 1
                    self._t_us = t_to
                    continue
            else:
                self._timeline(now, t_to, True)
            self._scan_end(now)   # only _scan_end can end RUN mode, else a fault raises
            if self.mode != "RUN":
                return

    def set_mode(self, mode: str) -> None:
        """Switch the CPU to ``"RUN"`` or ``"STOP"``, as the mode switch or a
        programming device does (System Manual, "Selecting the operating
        mode of the S7-200").

        STOP: the program stops at this scan boundary and the outputs take
        their STOP state (off, as after a STOP instruction).  RUN from STOP:
        the next scan is a first scan (SM0.1 on, SM0.3 off: SM0.3 is for
        RUN entered from power-up); memory keeps its values.  A CPU stopped
        by a fatal error stays in STOP (the real CPU needs a power cycle).

        Raises:
            PlcConfigError: ``mode`` is neither, or RUN after a fatal error.
        """
        if not isinstance(mode, str) or mode not in ("RUN", "STOP"):
            raise PlcConfigError(f"CPU mode must be RUN or STOP, not {shown_value(mode)}")
        if mode == self.mode:
            return
        if mode == "STOP":
            self.mode = "STOP"
            pq = self._bufs_end[2]
            pq[:] = bytes(len(pq))
            return
        if self.fault is not None:
            raise PlcConfigError("the CPU stopped on a fatal error and stays in STOP until "
                                 "it is powered up again (reset)")
        self.stop_requested = False
        self._entered_run = True
        self._calm_hi = 0       # the next scan start recomputes SMB0 (_calm_start)
        self.mode = "RUN"

    def run(self, seconds: Duration | None = None, scans: int | None = None) -> None:
        """Run for a simulated duration (``1.5``, ``"1.5s"``, ``"200ms"``,
        rounded up to whole scans) or a number of ``scans``.

        Raises:
            PlcConfigError: neither or both given, or a bad value (negative,
                NaN, infinite, not a number).
        """
        self.scan(scan_total(self.scan_us, seconds, scans))

    def _scan_once(self) -> None:
        now = self._t_us
        self._scan_begin()
        # perf: the time line only once a source may have events (a timed
        # interrupt attached, or ever a PLS, an HDEF, a CT=PT interrupt or
        # a port's traffic), or a device runs
        if self.interrupts.timed_next or self._sources or self.devices:
            self._timeline(now, now + self.scan_us, True)
        self._scan_end(now)

    def _scan_begin(self) -> None:
        """A scan up to and including the main program, at its start instant."""
        # perf: buffers are bound once in __init__ (self._bufs_begin)
        i_img, pi, sm, l_ob1 = self._bufs_begin
        now = self._t_us
        if self._defined:
            for c in self._defined:
                if c.scan_start(pi, now):
                    self.scheduler.touch()
        pi0 = pi[0] & self._edge_mask
        if pi0 != self._pi0 or self.interrupts.queued:
            self._input_edges(now, pi0)
        i_img[:] = pi
        if self._force_slots:
            self._apply_forces()
        scans = self.scans
        timers = self.timers
        if not timers._fast and self._calm_lo <= now < self._calm_hi:
            # perf: SMB0 is its byte for this scan's parity, the timer bank
            # needs only its millisecond (see _calm_start)
            sm[0] = self._smb0[scans & 1]
            timers.ms1 = now // 1000
        else:
            self._calm_start(sm, scans, now)
        self._prev_start = self._irq_t = now
        if self._wd_used:   # perf: only code that counts on them reads them
            wd = self.wd
            wd[0] = wd[2] = wd[3] = 0
        try:
            if self._ob1 is not None:
                self._ob1(l_ob1)
        except Exception as e:
            self._fault(e)

    def _input_edges(self, now: int, pi0: int) -> None:
        """Input edges from the outside world (I0.0-I0.3 now ``pi0``) and
        queued interrupts at a scan's start: their routines run before the
        image is read (System Manual: the routine runs when the edge occurs;
        the image changes next scan)."""
        irq = self.interrupts
        self._irq_t = now
        try:
            self.timers.refresh_1ms(now)
            irq.edges(self._pi0, pi0, now)
            self._pi0 = pi0
            irq.dispatch(now)
        except Exception as e:
            self._fault(e)

    def _calm_start(self, sm: bytearray, scans: int, now: int) -> None:
        """SMB0 and the timer bank at a scan start, and the window of scan
        starts (_calm_lo .. _calm_hi) that change neither but SMB0's scan
        parity bit and the bank's millisecond: inside the half second the
        clocks SM0.4 and SM0.5 hold (_clock) and the bank's quiet window
        (TimerBank.quiet), never including the first scan."""
        # SM0.0 and SM0.7, SM0.1/SM0.3 on the first scan, SM0.6 on every
        # other scan, the clocks SM0.4 and SM0.5
        if not self._clk_lo <= now < self._clk_hi:
            self._clock(now)
        if scans and not self._entered_run:
            sm[0] = self._smb0[scans & 1]
        elif self._entered_run:   # RUN entered from STOP (set_mode): SM0.1 on, SM0.3 off
            # SM0.2 (retentive data lost) on the first scan after power-up
            sm[0] = 0x83 | 0x40 | self._smb0[0] | (0 if scans else self._sm0_lost)
            self._entered_run = False
            scans = 0   # no calm window for this first scan
        else:             # the first scan from power-up: SM0.1, SM0.3 (and SM0.2) on
            sm[0] = 0x8B | 0x40 | self._smb0[0] | self._sm0_lost
        timers = self.timers
        if timers.quiet(now):
            timers.ms1 = now // 1000
        else:
            timers.start_scan(self._prev_start, now)
        self._calm_lo = max(self._clk_lo, timers.quiet_lo)
        self._calm_hi = min(self._clk_hi, timers.quiet_hi) if scans else 0

    def _clock(self, now: int) -> None:
        """SMB0 by scan parity (_smb0) with SM0.4 (on for the second half of
        every minute) and SM0.5 (on for the second half of every second) at
        *now*, and the half second (_clk_lo .. _clk_hi) they hold for."""
        clk = (0x10 if now % 60_000_000 >= 30_000_000 else 0) | \
            (0x20 if now % 1_000_000 >= 500_000 else 0)
        self._smb0 = (SMB0[0] | clk, SMB0[1] | clk)
        self._clk_lo = now - now % 500_000
        self._clk_hi = self._clk_lo + 500_000

    def _timeline(self, t_from: int, t_to: int, first: bool) -> None:
        """The scan's time line over (t_from, t_to]: events, routines, devices
        (*first*: t_from is the scan's start; a linked network runs a scan's
        time line in pieces, plcrt.engine.link)."""
        try:
            # perf: the time line only once a source may have events (a timed
            # interrupt attached, or ever a PLS, an HDEF, a CT=PT interrupt or
            # a port's traffic)
            if self.interrupts.timed_next or self._sources:
                self.scheduler.run(t_from, t_to, first)
            elif self.devices:
                for dev in self.devices:
                    dev.step(self, t_from, t_to)
        except Exception as e:
            self._fault(e)

    def _scan_end(self, now: int) -> None:
        """The scan's end: forces, outputs, the plant's wires, time."""
        pi, q, pq = self._bufs_end
        if self._force_slots:
            self._apply_forces()
        pq[:] = q
        # perf: the generators' own fields, not their `running` property,
        # and only once a PLS has run (_sources_on)
        if self._sources and any(po.trains or po.mode == "PWM" for po in self.pulse):
            # a running generator drives its terminal, not the image bit
            t_end = now + self.scan_us
            for po in self.pulse:
                if po.running:
                    _put_bit(pq, po.number, po.level(t_end))
                    po.update_segment(t_end)
                    po.retire(t_end - 1)
        if self.encoders:
            t_end = now + self.scan_us
            for enc in self.encoders.values():        # the plant's encoders: their levels
                for inp in (enc.a, enc.b):
                    if inp is not None:
                        _put_bit(pi, inp, enc.level(t_end, inp))
        if self.wiring:
            for inp, out in self.wiring.items():      # the plant's wires: output -> input
                _put_bit(pi, inp, pq[out // 8] >> (out % 8) & 1)
        self.scans += 1
        self._t_us = now + self.scan_us
        if self._stop:
            # STOP instruction: the scan completes, then the CPU switches to
            # STOP and the outputs take their STOP state (off).
            self.mode = "STOP"
            pq[:] = bytes(len(pq))
        if self.observers:
            for fn in self.observers:
                fn(self)


class _NotQuiet:
    """The scan loop's stand-in for a device without held runs: never quiet."""

    quiet_to = -1
    held = None


_NOT_QUIET = _NotQuiet()

#: SMB0 of every scan but the first, by the scan count's parity: SM0.0
#: (always on), SM0.7 (RUN switch position), SM0.6 (on every other scan)
SMB0 = (0x81 | 0x40, 0x81)


def _put_bit(buf: bytearray, n: int, level: int) -> None:
    """Bit *n* of *buf* (byte n // 8, bit n % 8) := *level*."""
    mask = 1 << (n % 8)
    buf[n // 8] = buf[n // 8] | mask if level else buf[n // 8] & ~mask & 0xFF
