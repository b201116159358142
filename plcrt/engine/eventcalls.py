"""What the generated code and the time line call in the CPU: interrupts,
HSC, PLS, the ports and the Ethernet interface.

What it is: :class:`EventCalls`, a mixin of :class:`plcrt.engine.runtime.Plc`:
running an interrupt routine, the end of an instant of the time line,
the calls of HDEF/HSC/PLS, XMT/RCV, NETR/NETW, GET/PUT, ATCH/DTCH/ENI, and
a source joining the time line.  Each forwards to the engine's model of
the thing (:mod:`.interrupts`, :mod:`.hsc`, :mod:`.pulse`, :mod:`.ports`,
:mod:`.netjobs`) at the time the running code executes at.

What it is not: those models, nor the time line (:mod:`.events`).
"""

from __future__ import annotations

from typing import Any

from .netjobs import netr_netw

__all__ = ["EventCalls"]


class EventCalls:
    """The CPU's side of events and communication (a mixin of
    :class:`plcrt.engine.runtime.Plc`)."""

    def _run_interrupt(self, number: int) -> None:
        """Run INT *number* now.  The CPU saves and restores the
        accumulators and the status bits SMB1 around a routine (System
        Manual, "System support for interrupts")."""
        fn = self._int_fns.get(number)
        if fn is None:
            return
        acc, sm = self._acc_sm
        saved_ac, saved_sm1 = bytes(acc), sm[1]
        try:
            fn(self._int_l)
        finally:
            acc[:] = saved_ac
            sm[1] = saved_sm1

    def _instant(self, t: int) -> None:
        """After the events of one instant: 1 ms timers and counters current,
        then the routines."""
        timers = self.timers
        if timers._fast:                # perf: no call without a running 1 ms timer
            timers.refresh_1ms(t)
        for c in self._counted:
            c.sync(t)
        irq = self.interrupts
        if irq.queued:                  # perf: nothing to run for an unattached event
            self._irq_t = t
            irq.dispatch(t)

    def _hdef(self, number: int, mode: int) -> None:
        self._sources_on = True
        counter = self.hsc[number]
        counter.hdef(mode, self._irq_t)
        if counter.mode is not None and counter not in self._defined:
            self._defined.append(counter)
        self.scheduler.touch()
        if counter.pulse is not None and counter not in self._counted:
            self._counted.append(counter)
            self.scheduler.add(counter)

    def _hsc(self, number: int) -> None:
        self.hsc[number].hsc(self._irq_t)
        self.scheduler.touch()

    def _pls(self, number: int) -> None:
        self.pulse[number].pls(self._irq_t)
        self._sources_on = True
        self.scheduler.touch()

    def _wake(self, source: Any) -> None:
        """A port's (or the Ethernet interface's) next event moved: a
        character on its way, a job; it joins the time line the first time."""
        self._sources_on = True
        if source.joined:
            self.scheduler.touch()
        else:
            source.joined = True
            self.scheduler.add(source)

    def _xmt(self, port: int, ptr: int) -> bool:
        return self.ports[port].xmt(self._irq_t, ptr)

    def _rcv(self, port: int, ptr: int) -> bool:
        return self.ports[port].rcv(self._irq_t, ptr)

    def _net(self, port: int, ptr: int, kind: str) -> bool:
        return netr_netw(self.ports[port], self._irq_t, ptr, kind)

    def _getput(self, ptr: int, kind: str) -> bool:
        return self.ethernet.get_put(self._irq_t, ptr, kind)

    def _irq_warn(self, message: str, key: str) -> None:
        self.warn(message, None, key)

    def _irq_attach(self, number: int, event: int) -> None:
        self.interrupts.attach(number, event, self._irq_t)
        if event in (21, 22) or (event < 8 and (self.wiring or self.encoders
                                                 or self._edge_mask != 0x0F)):
            self._sources_on = True
        self.scheduler.touch()
        self._replain()   # a timed interrupt

    def _irq_detach(self, event: int) -> None:
        self.interrupts.detach(event)
        self.scheduler.touch()
        self._replain()

    def _irq_enable(self) -> None:
        self.interrupts.enable(self._irq_t)
