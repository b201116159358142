"""Power-up and the power cycle: retentive ranges, start-up mode.

What it is: a mixin of :class:`plcrt.engine.runtime.Plc` that applies the
settings of a system block (:class:`plcrt.memory.system.SystemSettings`,
from the project or the plant file's ``[cpu]`` table) at load, and
:meth:`PowerCycle.power_cycle`, which switches the CPU off and on again as
the S7-200 System Manual describes it (chapter 4, "Saving and restoring
data", "Retaining memory at power-on"):

* with the retentive data kept (the super capacitor held it): the
  retentive ranges keep their values (timers and counters only their
  current values; their bits are cleared); V outside them is restored
  from the permanent copy (the data block); the rest of M, T, C, S, Q,
  SM, L and the accumulators are cleared;
* with the retentive data lost (``retentive_lost=True``, an outage longer
  than the capacitor lasts): everything is cleared, V is restored from
  the data block, and SM0.2 is on for the first scan;
* the first scan has SM0.1 and SM0.3 on; the CPU starts in the start-up
  mode (RUN, STOP, or LAST: the mode it was in).  A load is a download
  followed by RUN, whatever the start-up mode: it applies at power-up.

What stays: the wiring of the outside world (the inputs as the tests set
them, the plant's devices are started again), the real-time clock (kept
by the capacitor or battery), simulated time (a power cycle takes none),
forces, observers.  What it is not: the scan loop or a file reader.
"""

from __future__ import annotations

from typing import Any

from ..errors import PlcConfigError
from ..memory.cpu import model_named
from ..memory.system import (RetentiveRange, SystemSettings, check_range, clipped,
                             default_ranges)

__all__ = ["PowerCycle"]

#: area of a range -> (memory area, bytes per element)
_AREA = {"V": ("V", 1), "M": ("M", 1), "T": ("TV", 2), "C": ("CV", 2)}
#: SM0.2 (Retentive_Lost) in SMB0
SM0_2 = 0x04
#: the PPI rates a port runs at (as the plant file's ppi_baud)
PPI_BAUDS = (9600, 19200, 187500)


def project_cpu(program: Any) -> str | None:
    """The CPU model a project file's system block names (``CPU 224 REL
    02.01`` runs as CPU224), or None (an export, or a CPU plcrt has no
    model of: the default CPU226)."""
    system = getattr(program, "system", None)
    return model_named(getattr(system, "cpu", "") or "")


class PowerCycle:
    """Power-up settings and the power cycle (a mixin of ``Plc``)."""

    mem: Any
    model: Any
    station: Any
    program: Any
    mode: str

    def _power_up_settings(self, plant: Any, data: Any) -> None:
        """Take the system block's settings: the plant file's ``[cpu]``
        values, else the project's system block, else the defaults."""
        me: Any = self
        project = getattr(self.program, "system", None)
        project = getattr(project, "settings", project)
        given = getattr(plant, "system", None)
        ranges: tuple[RetentiveRange, ...] | None = None
        startup = None
        addresses: dict[int, int] = {}
        bauds: dict[int, int] = {}
        for settings in (project, given):      # the plant file's values win
            if not isinstance(settings, SystemSettings):
                continue
            if settings.ranges is not None:
                strict = settings is given      # a project's ranges are clipped
                ranges = tuple(_checked(r, self.model, settings.source, strict)
                               for r in settings.ranges)
            startup = settings.startup or startup
            addresses.update(settings.addresses)
            bauds.update(settings.bauds)
        #: the retentive ranges this CPU keeps through :meth:`power_cycle`
        self.retentive: tuple[RetentiveRange, ...] = (
            ranges if ranges is not None else default_ranges(self.model))
        #: the start-up mode: "RUN", "STOP" or "LAST"
        self.startup: str = startup or "RUN"
        #: the data block: V memory's permanent copy, restored at power-up
        self._permanent = data
        self._sm0_lost = 0
        # a port the plant file has a [port.N] table for is set up by it
        ports = [p for p in me.ports if p.number not in (getattr(plant, "ports", None) or {})]
        for port in ports:
            if port.number in addresses:
                port.address = addresses[port.number]
                self.station.addresses[port.number] = port.address
            if bauds.get(port.number) in PPI_BAUDS:
                port.ppi_baud = bauds[port.number]
        # the load itself is a download followed by RUN (as Micro/WIN offers
        # at its end); the start-up mode is the mode at power-up (power_cycle)

    def power_cycle(self, *, retentive_lost: bool = False) -> None:
        """Switch the CPU off and on again (see the module's docstring).

        Args:
            retentive_lost: the retentive data was lost (SM0.2 on for the
                first scan; nothing but the data block survives).

        Raises:
            PlcConfigError: ``retentive_lost`` not a bool, or the PLC is
                linked to others (power-cycle it before linking).
        """
        if not isinstance(retentive_lost, bool):
            raise PlcConfigError(f"retentive_lost must be True or False, got "
                                 f"{type(retentive_lost).__name__}")
        me: Any = self
        if me.network is not None:
            raise PlcConfigError("a linked PLC cannot be power-cycled: what it exchanged with "
                                 "the others would break; power-cycle it before linking")
        twin = type(me)(me.program, **me._config, _entry=me._entry, _parts=me._parts)
        old, new = me.mem.areas, twin.mem.areas
        for name in ("PI", "AI"):                 # the outside world's signals stay
            new[name][:] = old[name]
        if self._permanent is not None:
            self._permanent.apply(new["V"])
        if not retentive_lost:
            for r in self.retentive:
                area, width = _AREA[r.area]
                lo, hi = r.start * width, (r.start + r.count) * width
                new[area][lo:hi] = old[area][lo:hi]
        twin._sm0_lost = SM0_2 if retentive_lost else 0
        twin._permanent = self._permanent
        twin.mode = "STOP" if self.startup == "STOP" or (
            self.startup == "LAST" and me.mode != "RUN") else "RUN"
        twin._t_us = twin._irq_t = me._t_us       # a power cycle takes no simulated time
        for key, value in me.forces.items():
            twin.force(key, value)
        clock = dict(me.clock.__dict__)           # the clock runs on through the cycle
        observers = me.observers
        twin._copy_state(me)
        me.clock.__dict__.update(clock)
        me.observers = observers
        me._sm0_lost = twin._sm0_lost
        me._replain()


def _checked(r: RetentiveRange, model: Any, source: str, strict: bool) -> RetentiveRange:
    if strict:
        check_range(r, model, f"{source}: cpu.retentive")
        return r
    return clipped(r, model)
