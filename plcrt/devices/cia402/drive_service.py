"""What a drive engineer does to a simulated CiA 402 drive besides the bus.

What it is: :class:`Service`, a base of :class:`~.drive.Drive` with the
test surface around the master's objects:

* :meth:`Service.inject_fault` raises a fault by name (``"following_error"``,
  ``"limit"``, ``"overcurrent"``, ``"encoder"``, ``"power_stage"``, ...) or
  by alarm number / 603Fh code, the code each model reports
  (:data:`INJECTABLE`); ``persist=True`` keeps the cause until
  :meth:`Service.clear_fault_cause`;
* :meth:`Service.power_cycle`: the pending "after power-up" parameters
  (HCFA §5.1 再次通电) take effect, every alarm clears (also those only a power
  cycle clears, HCFA §4.7 "否"), the drive starts again at transitions 0 and 1
  and ESM INIT; the count restarts at 0 where the axis stands (an
  incremental count), the PDO mapping stays as the store holds it;
* :meth:`Service.set_input`: the level of a digital input DI1–DI5, read
  through its function P02.01–05 and polarity P02.10 (HCFA §5.1, §8.2): an
  E-stop function (8) faults the drive (603Fh 0x5441) while active;
* the P18 display parameters read live (:data:`DISPLAY`, HCFA §5.1, §8.2);
* alarm 83 when a master writes a parameter that acts after power-up
  (HCFA §4.7);
* :class:`TouchProbe`: 60B8h–60BDh latching the index pulse or a probe input
  of the plant (HCFA §8.3, CiA 402), at exact positions.

What it is not: the process data path, the time line or the modes; it is a
base class of :class:`~.drive.Drive` and works on a drive's attributes.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Callable, Optional

from ...errors import PlcConfigError
from .reactions import FAULT_CODES
from .statemachine import State
from .store import Write

__all__ = ["Service", "TouchProbe", "INJECTABLE", "DISPLAY", "DI_FUNCTIONS", "cite"]

#: Faults by name and model -> 603Fh code (HCFA §4.7 where the manual numbers
#: them; CiA 402 codes, marked so in reactions.FAULT_CODES, otherwise).
INJECTABLE: dict[str, dict[str, int]] = {
    "hcfa-am0520b": {"following_error": 0x8611, "limit": 0x8612, "overcurrent": 20704,
                     "encoder": 10256, "power_stage": 20640, "phase_loss": 8,
                     "under_voltage": 12828, "over_voltage": 12827, "communication": 17,
                     "parameter_storage": 4, "estop": 0x5441},
    "kinco-servo": {"following_error": 0x8611, "limit": 0x8612, "overcurrent": 0x2310,
                    "encoder": 0x7305, "power_stage": 0x5400, "under_voltage": 0x3220,
                    "over_voltage": 0x3210, "estop": 0x5441},
}

#: The manual each model's log lines cite, and the other model's citations
#: it must not carry: a Kinco event follows CiA 402 where the Kinco note is
#: silent, never "HCFA §7.2" (the HCFA tables are the standard's own rows).
MANUALS = {"hcfa-am0520b": ("HCFA", "Kinco"), "kinco-servo": ("Kinco", "HCFA")}
_OTHER = {other: re.compile(other + r" §[\w.]+(?:(?:,| and| /) §[\w.]+)*")
          for _, other in MANUALS.values()}


def cite(model: str, text: str, section: str) -> tuple[str, str]:
    """*text* and *section* of a log line of a *model* drive, with the other
    model's manual taken out of both (CiA 402 said instead; "CiA 402;
    <model> manual silent" when nothing is left of the section)."""
    own, other = MANUALS.get(model, ("", ""))
    if not other or other not in section + text:
        return text, section
    pat = _OTHER[other]
    parts = []
    for part in section.split(";"):
        part = part.strip()
        if other in part:
            part = part[:part.index(other)].rstrip(" ,(")
        if part:
            parts.append(part)
    section = "; ".join(parts) or f"CiA 402; {own} manual silent"
    return pat.sub("CiA 402", text), section


#: P02.01–05 function codes (HCFA §5.1, §8.2) -> the signal's name
DI_FUNCTIONS = {1: "home_switch", 2: "pos_limit", 4: "neg_limit", 8: "estop", 16: "probe2"}
_DI_COUNT = 5


def _rpm(d: Any, speed: int) -> int:
    """|speed| (P/s) in rpm at P00.02 pulses per revolution, as a U16."""
    per_rev = max(1, d.param(0x2000, 2))
    return min(0xFFFF, abs(speed) * 60 // per_rev)


#: P18 display parameters computed when read (HCFA §5.1, §8.2 P18.nn):
#: subindex -> value of the drive
DISPLAY: dict[int, Callable[[Any], int]] = {
    1: lambda d: _rpm(d, int(d.store.get(0x606C))),          # speed feedback (rpm)
    3: lambda d: _rpm(d, int(d.store.get(0x606B))),          # speed command (rpm)
    9: lambda d: int(d.store.get(0x6060)) & 0xFFFF,          # mode set by the master
    21: lambda d: d.di_levels(),                             # DI monitor, bit n = DI n+1
    36: lambda d: int(d.esm.state),                          # EtherCAT state
    37: lambda d: d.esm.al_code & 0xFFFF,                    # AL status code (ETG.1000.6)
    39: lambda d: int(d.store.get(0x6041)) & 0xFFFF,         # CoE 402 state: 6041h
}


@dataclass(slots=True)
class TouchProbe:
    """60B8h (function) and 60B9h (status) of probes 1 and 2, CiA 402 bits:
    enable (0 / 8), continuous (1 / 9), source index pulse (2 / 10; 0 = the
    probe input), latch rising (4 / 12) and falling (5 / 13) edges; 60B9h
    enabled (0 / 8), rising stored (1 / 9), falling stored (2 / 10)."""

    function: int = 0
    status: int = 0
    last: Optional[int] = None       #: mechanical position at the last look

    def configure(self, function: int, position: int) -> None:
        self.function, self.last = function, position
        status = 0
        for shift in (0, 8):
            if function >> shift & 1:
                status |= 1 << shift
        self.status = status

    def crossings(self, plant: Any, p0: int, p1: int, probe: int) -> list[tuple[str, int]]:
        """The probe's edges between *p0* and *p1* (mechanical counts, a
        straight path), in order: ("rise" | "fall", position)."""
        shift = 0 if probe == 1 else 8
        if self.function >> (shift + 2) & 1:                  # the index (zero) pulse
            period = plant.index_period
            if period is None or p0 == p1:
                return []
            step = 1 if p1 > p0 else -1
            # the first pulse past p0 in the direction of motion
            k = (p0 - plant.index_phase) // period + (1 if step > 0 else 0)
            if step < 0 and (p0 - plant.index_phase) % period == 0:
                k -= 1
            out = []
            x = plant.index_phase + k * period
            while (x - p0) * step > 0 and (p1 - x) * step >= 0 and len(out) < 4:
                out += [("rise", x), ("fall", x)]
                x += step * period
            return out
        zone = plant.probe if probe == 1 else plant.probe2
        if zone is None or p0 == p1:
            return []
        lo, hi = zone
        out = []
        if p1 > p0:
            if p0 < lo <= p1:
                out.append(("rise", lo))
            if p0 <= hi < p1:
                out.append(("fall", hi + 1))
        else:
            if p1 <= hi < p0:
                out.append(("rise", hi))
            if p1 < lo <= p0:
                out.append(("fall", lo - 1))
        return out


class Service:
    """The test surface of a :class:`~.drive.Drive` (see the module docstring)."""

    # the attributes it reads of the drive (set by Drive.__init__)
    model: str
    now: int
    store: Any
    sm: Any
    esm: Any
    axis: Any
    plant: Any
    probe: TouchProbe
    log: list

    # ---------------------------------------------------------------- faults
    def inject_fault(self, fault: str | int, *, persist: bool = False, why: str = "") -> int:
        """Raise a fault now: by name (``INJECTABLE[model]``) or by alarm
        number / 603Fh code (``reactions.FAULT_CODES``).  *persist*: the
        cause stays, a fault reset is refused until :meth:`clear_fault_cause`
        (a power cycle clears it too).  Returns the 603Fh code.

        Raises:
            PlcConfigError: unknown name or code.
        """
        names = INJECTABLE[self.model]
        if isinstance(fault, str):
            code = names.get(fault)
            if code is None:
                raise PlcConfigError(f"inject_fault: unknown fault {fault[:40]!r} for "
                                     f"{self.model}; names: {', '.join(names)}")
        elif isinstance(fault, int) and not isinstance(fault, bool) and fault in FAULT_CODES:
            code = fault
        else:
            raise PlcConfigError(f"inject_fault: {fault!r} is no fault name or 603Fh code "
                                 f"of {self.model}; names: {', '.join(names)}; codes: "
                                 + ", ".join(str(c) for c in FAULT_CODES))
        fc = FAULT_CODES[code]
        t = self.now
        with self.store.lock:
            res = self.sm.raise_fault(code, fc.alarm, why or "injected", t / 1e6,
                                      cause_active=persist)
            self._do(t, res)                                  # type: ignore[attr-defined]
            self.publish()                                    # type: ignore[attr-defined]
        return code

    def clear_fault_cause(self) -> None:
        """The injected fault's cause is gone: a fault reset (15) may clear it."""
        self.sm.clear_fault_cause()

    # ---------------------------------------------------------------- power
    def power_cycle(self) -> list[str]:
        """Switch the drive off and on at the present time (see the module
        docstring).  Returns the texts of the parameters that took effect."""
        t = self.now
        with self.store.lock:
            applied = [ev.text for ev in self.store.power_cycle()]
            was = self.sm.error_code
            mech = self.axis.mechanical(t)
            self.axis.stop_at_once(t)
            self.axis.shift = -mech                   # the count restarts at 0 here
            for index in (0x6040, 0x6060, 0x60B8):    # process data start from their defaults
                if self.od.find(index, 0) is not None:  # type: ignore[attr-defined]
                    self.store.set(index, 0, self.od.entry(index, 0).default)  # type: ignore
            self._power_up(t)                         # type: ignore[attr-defined]
            self.probe.configure(0, mech)
            self.note(t, "HCFA §4.7, §5.1",           # type: ignore[attr-defined]
                      "power cycle: " + ("; ".join(applied) if applied else
                                         "no parameter waited for it")
                      + (f"; alarm 603Fh = {was} cleared" if was else ""), "drive")
            self._mirror()                            # type: ignore[attr-defined]
            self._published = (None, None)
            self.publish()                            # type: ignore[attr-defined]
        return applied

    def _pending_write(self, w: Write) -> None:
        """A master wrote a parameter that acts after power-up: alarm 83
        (HCFA §4.7 "变更参数需要重新接通电源生效"); the value waits."""
        e = w.entry
        if w.value == self.store.get(e.index, e.sub):
            return                      # the active value again: nothing waits
        self.fault(self.now, 83, 83,                      # type: ignore[attr-defined]
                       f"{e.index:04X}h:{e.sub:02X} ({e.name}) := {w.value} acts after the "
                       f"next power cycle; the drive keeps {w.old} until then")

    # ---------------------------------------------------------------- inputs
    def _di_function(self, di: int) -> int:
        sub = di
        return self.param(0x2002, sub) if self.od.find(0x2002, sub) else 0  # type: ignore

    def di_levels(self) -> int:
        """P18.21: bit n = DI n+1 active as the drive reads it (its function's
        signal from the plant or :meth:`set_input`, then P02.10 polarity)."""
        pos = self.axis.mechanical(self.now)
        polarity = self.param(0x2002, 10) if self.od.find(0x2002, 10) else 0  # type: ignore
        out = 0
        for di in range(1, _DI_COUNT + 1):
            level = self._signal(self._di_function(di), pos, di)
            if level ^ bool(polarity >> (di - 1) & 1):
                out |= 1 << (di - 1)
        return out

    def _signal(self, function: int, pos: int, di: int) -> bool:
        forced = self.forced_inputs.get(di)                   # type: ignore[attr-defined]
        if forced is not None:
            return forced
        name = DI_FUNCTIONS.get(function)
        p = self.plant
        if name == "neg_limit":
            return p.nls(pos)
        if name == "pos_limit":
            return p.pls(pos)
        if name == "home_switch":
            return p.home(pos)
        if name == "probe2":
            return p.probe2 is not None and p.probe2[0] <= pos <= p.probe2[1]
        return False

    def set_input(self, di: int | str, level: bool) -> None:
        """Set the electrical level of DI *di* (1–5, or the name of the
        function one of P02.01–05 gives it, e.g. ``"estop"``).  An E-stop
        input active (after P02.10) faults the drive, 603Fh 0x5441, until it
        is released and the fault reset."""
        if isinstance(di, str):
            found = [n for n in range(1, _DI_COUNT + 1)
                     if DI_FUNCTIONS.get(self._di_function(n)) == di]
            if not found:
                raise PlcConfigError(f"set_input: no DI has the function {di[:40]!r} "
                                     f"(P02.01–05; functions: {', '.join(DI_FUNCTIONS.values())})")
            di = found[0]
        if isinstance(di, bool) or not isinstance(di, int) or not 1 <= di <= _DI_COUNT:
            raise PlcConfigError(f"set_input: DI {di!r} is not 1..{_DI_COUNT} (HCFA §5.1)")
        self.forced_inputs[di] = bool(level)                  # type: ignore[attr-defined]
        with self.store.lock:
            active = bool(self.di_levels() >> (di - 1) & 1)
            if DI_FUNCTIONS.get(self._di_function(di)) == "estop":
                if active and self.sm.state not in (State.FAULT, State.FAULT_REACTION_ACTIVE):
                    self.inject_fault(0x5441, persist=True,
                                      why=f"E-stop input DI{di} active (P02.0{di} = 8)")
                elif not active:
                    self.sm.clear_fault_cause()
            self.publish()                                    # type: ignore[attr-defined]

    # ---------------------------------------------------------------- display
    def _display(self, index: int, sub: int) -> None:
        """Refresh a P18 display parameter before it is read."""
        f = DISPLAY.get(sub) if index == 0x2012 else None
        if f is not None and self.od.find(index, sub) is not None:  # type: ignore[attr-defined]
            self.store.set(index, sub, f(self))

    # ---------------------------------------------------------------- touch probe
    def _probe_update(self, t: int, mech: int) -> None:
        """60B8h as the master holds it, then the edges since the last look
        (:class:`TouchProbe`); 60B9h–60BDh written when they change."""
        probe, fn = self.probe, int(self._live.get((0x60B8, 0)) or 0)  # type: ignore
        if fn != probe.function:
            probe.configure(fn, mech)
            self.store.set(0x60B9, 0, probe.status)
            return
        p0, probe.last = probe.last, mech
        if p0 is None or p0 == mech:
            return
        shift = self.axis.shift
        for n, sh, rise_at, fall_at in ((1, 0, 0x60BA, 0x60BB), (2, 8, 0x60BC, 0x60BD)):
            if not fn >> sh & 1:
                continue
            for edge, x in probe.crossings(self.plant, p0, mech, n):
                bit, index, wanted = ((1, rise_at, 4) if edge == "rise" else (2, fall_at, 5))
                if not fn >> (sh + wanted) & 1:
                    continue
                stored = probe.status >> (sh + bit) & 1
                if stored and not fn >> (sh + 1) & 1:
                    continue                        # first event only (bit 1 / 9 = 0)
                probe.status |= 1 << (sh + bit)
                self.store.set(index, 0, x + shift)
                self.note(t, "HCFA §8.3; CiA 402 60B8h",  # type: ignore[attr-defined]
                          f"touch probe {n} latched the {edge} of "
                          f"{'the index pulse' if fn >> (sh + 2) & 1 else f'probe input {n}'} "
                          f"at count {x + shift}", "probe")
        self.store.set(0x60B9, 0, probe.status)
