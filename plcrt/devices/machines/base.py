"""What every machine shares: its terminals, its faults, its buttons, its
time line inside a step, and :class:`Machine`, what tests and a page see.

A machine is a device of the scan's time line (:class:`plcrt.engine.device.Device`,
``slot = None``): the scheduler steps it over sub-intervals of the scan
that join exactly.  Inside a step, :meth:`MachineDevice.step` runs the
machine's own events in time order -- a part's edge reaching a photo-eye,
a level reaching a switch, a door reaching a limit, a button released --
each at the exact microsecond it happens, computed in closed form from
integer positions (nanometres, so a speed in mm/s is nm per µs and every
motion is exact integer arithmetic).  The machine sees the outputs the
program left in the output image at the scan's instant (the program runs
in zero simulated time at the scan's start), and writes its sensors into
the physical inputs (PI) and analog inputs (AIW), which the next scan
reads; a sensor edge inside the scan is logged with its exact time
(:meth:`Machine.edges`).

Faults (:meth:`Machine.fault`): on every signal ``stuck_on:S``,
``stuck_off:S`` and ``broken:S`` (a broken wire: an input reads 0, an
output reaches the machine as 0; ``stuck_on`` on an output is a welded
contact), plus each machine's own (``jam`` ...).

What it is not: a model of wiring delays, contact bounce or sensor
hysteresis (an edge is an instant), nor a second time line: it runs inside
the device layer's step.
"""

from __future__ import annotations

import copy
from collections import deque
from typing import Any, ClassVar

from ...errors import PlcConfigError, PlcKeyError, PlcRuntimeError
from ...safetext import shown_value
from .config import MachineConfig, Param, show_address

__all__ = ["Machine", "MachineDevice", "NM", "ceil_div", "crossing", "moved"]

#: nanometres (or nanolitres) per millimetre (millilitre): positions are
#: integers in nm, so that a speed in mm/s moves exactly ``speed`` nm per µs
NM = 1_000_000
#: the edges a machine keeps (the oldest go first)
EDGE_LOG = 4096
#: at most this many events in one step (a guard; real steps have a few)
MAX_EVENTS = 1_000_000
#: the longest button press, seconds
MAX_PRESS_S = 3600.0
_FAULT_KINDS = ("stuck_on", "stuck_off", "broken")


def ceil_div(a: int, b: int) -> int:
    """⌈a / b⌉ for integers, b > 0."""
    return -(-a // b)


def crossing(x: int, v: int, marks: tuple[int, ...], stop: int) -> int | None:
    """The µs after which a position *x* (nm) moving at *v* (nm/µs, signed)
    and held at *stop* first reaches or first passes one of *marks*: the
    instants a switch "on at and above m" or "on at and below m" changes."""
    best = None
    if v > 0:
        for m in marks:
            if x < m <= stop:
                dt = ceil_div(m - x, v)
                best = dt if best is None else min(best, dt)
            if x <= m < stop:
                dt = (m - x) // v + 1
                best = dt if best is None else min(best, dt)
    elif v < 0:
        w = -v
        for m in marks:
            if stop <= m < x:
                dt = ceil_div(x - m, w)
                best = dt if best is None else min(best, dt)
            if stop < m <= x:
                dt = (x - m) // w + 1
                best = dt if best is None else min(best, dt)
    return best


def moved(x: int, v: int, dt: int, stop: int) -> int:
    """Where *x* is after *dt* µs at *v*, held at *stop*."""
    return min(x + v * dt, stop) if v > 0 else max(x + v * dt, stop) if v < 0 else x


class MachineDevice:
    """The base of the machines: terminals, faults, buttons, the step loop.

    A subclass sets ``KIND``, ``INPUTS`` / ``OUTPUTS`` (signal -> default
    address), ``ANALOG`` (the analog inputs), ``BUTTONS`` (inputs a person
    presses), ``WORLD`` (conditions of the world that are no terminal, such
    as an obstacle), ``PARAMS``, ``OWN_FAULTS``, and implements
    :meth:`next_event`, :meth:`advance`, :meth:`event`, :meth:`sense` and
    :meth:`details`.
    """

    slot = None                          #: not an expansion module
    KIND: ClassVar[str] = ""
    INPUTS: ClassVar[dict[str, str | None]] = {}
    OUTPUTS: ClassVar[dict[str, str | None]] = {}
    ANALOG: ClassVar[dict[str, bool]] = {}
    BUTTONS: ClassVar[tuple[str, ...]] = ()
    WORLD: ClassVar[tuple[str, ...]] = ()
    PARAMS: ClassVar[dict[str, Param]] = {}
    OWN_FAULTS: ClassVar[dict[str, str]] = {}

    def __init__(self, plc: Any, cfg: MachineConfig) -> None:
        self.name, self.kind = cfg.name, cfg.kind
        self.p = dict(cfg.params)
        self.pi = plc.mem.areas["PI"]
        self.ai = plc.mem.areas["AI"]
        self.q = plc.mem.areas["Q"]
        self.in_map = dict(cfg.inputs)
        self.out_map = dict(cfg.outputs)
        for sig, addr in (*self.in_map.items(), *self.out_map.items()):
            if addr is None:
                continue
            size = len(self.ai) if addr[0] == "AIW" else len(self.pi) * 8
            if addr[1] + (2 if addr[0] == "AIW" else 1) > size:
                raise PlcConfigError(f"{cfg.where}: {sig} = {show_address(addr)} is outside "
                                     f"this CPU's process image")
        self.t: int = getattr(plc, "_t_us", 0)
        self.scan_us: int = getattr(plc, "scan_us", 10_000)
        #: I0.0–I0.3 this machine drives: the time line runs their edge
        #: interrupts at the edges' own instants (engine/edges.py)
        self.edge_bits = tuple(a[1] for s, a in self.in_map.items()
                               if a is not None and a[0] == "I" and a[1] < 4)
        self._bit_signal = {a[1]: s for s, a in self.in_map.items()
                            if a is not None and a[0] == "I"}
        #: the edges a copy ran into: (course, until µs, edges) (input_edge_after)
        self._ahead: tuple[Any, int, list[tuple[int, str, int]]] | None = None
        self.active: set[str] = set()
        #: what the machine sees of each output (after faults)
        self.out = {s: 0 for s in self.OUTPUTS}
        #: a person's actions: button or world condition -> held
        self.pressed = {s: False for s in (*self.BUTTONS, *self.WORLD)}
        #: (release time µs, button) of the presses in progress
        self.releases: list[tuple[int, str]] = []
        #: what the terminals show: input signal -> level (0/1) or counts
        self.levels: dict[str, int] = {}
        self.log: deque[tuple[int, str, int]] = deque(maxlen=EDGE_LOG)
        #: (time µs, text) of what the machine noticed (a conflict, a crash)
        self.notes: deque[tuple[int, str]] = deque(maxlen=EDGE_LOG)
        self.setup()
        for f in cfg.faults:
            self.set_fault(f, True)
        self.event(self.t)      # what is due at power-up (a part arriving at 0 s)
        self.levels = self.terminals()
        self.publish()

    # -- what a subclass provides ------------------------------------------
    @classmethod
    def check_params(cls, params: dict[str, Any], where: str) -> None:
        """Checks across parameters (a threshold below another); PlcConfigError."""

    def setup(self) -> None:
        """The machine's state at power-up (parameters are in ``self.p``)."""

    def next_event(self, t: int) -> int | None:
        """The time (µs, after *t*) of the machine's next event with the
        outputs it sees now, or None."""
        return None

    def advance(self, dt: int) -> None:
        """Move the continuous state on by *dt* µs (no event inside)."""

    def event(self, t: int) -> None:
        """What happens at the event time *t* (a part drops into a bin ...)."""

    def sense(self) -> dict[str, int]:
        """The sensors' levels now (before faults): signal -> 0/1 or counts."""
        return {}

    def details(self) -> dict[str, Any]:
        """The machine's own fields of :meth:`Machine.state`."""
        return {}

    def began(self, t: int) -> None:
        """The outputs were read at *t* (a step's start): note what they
        mean now (conflicting greens, both motor directions on)."""

    def fault_changed(self, name: str, on: bool) -> None:
        """A machine fault was switched (a jam picks its part)."""

    def note(self, t: int, text: str) -> None:
        self.notes.append((t, text))

    # -- faults and terminals -------------------------------------------------
    @classmethod
    def fault_names(cls, inputs: dict[str, Any] | None = None,
                    outputs: dict[str, Any] | None = None) -> list[str]:
        sigs = [*(inputs or cls.INPUTS), *(outputs or cls.OUTPUTS)]
        return [*cls.OWN_FAULTS, *(f"{k}:{s}" for s in sigs for k in _FAULT_KINDS)]

    def set_fault(self, name: str, on: bool) -> None:
        if on:
            self.active.add(name)
        else:
            self.active.discard(name)
        if name in self.OWN_FAULTS:
            self.fault_changed(name, on)

    def _faulted(self, sig: str, level: int, high: int) -> int:
        if f"broken:{sig}" in self.active or f"stuck_off:{sig}" in self.active:
            return 0
        if f"stuck_on:{sig}" in self.active:
            return high
        return level

    def terminals(self) -> dict[str, int]:
        """The inputs as the PLC's terminals show them: sensors and buttons, after faults."""
        raw = self.sense()
        for b in self.BUTTONS:
            raw[b] = int(self.pressed[b])
        if not self.active:
            return raw
        return {s: self._faulted(s, v, 32000 if self.ANALOG.get(s) else 1)
                for s, v in raw.items()}

    def read_outputs(self) -> None:
        q, out, active = self.q, self.out, self.active
        for sig, addr in self.out_map.items():
            v = 0 if addr is None else q[addr[1] >> 3] >> (addr[1] & 7) & 1
            out[sig] = self._faulted(sig, v, 1) if active else v

    def publish(self) -> None:
        """Write the terminals' levels into PI and AIW."""
        pi, ai = self.pi, self.ai
        for sig, v in self.levels.items():
            addr = self.in_map.get(sig)
            if addr is None:
                continue
            n = addr[1]
            if addr[0] == "AIW":
                ai[n:n + 2] = (v & 0xFFFF).to_bytes(2, "big")
            elif v:
                pi[n >> 3] |= 1 << (n & 7)
            else:
                pi[n >> 3] &= ~(1 << (n & 7)) & 0xFF

    def _record(self, t: int) -> None:
        new = self.terminals()
        old = self.levels
        for sig, v in new.items():
            if old.get(sig) != v and not self.ANALOG.get(sig):
                self.log.append((t, sig, v))
        self.levels = new

    # -- the time line of a step ---------------------------------------------
    def step(self, plc: Any, t0: int, t1: int) -> None:
        """Advance from *t0* to *t1* (µs), events in time order, then write the inputs."""
        self.read_outputs()
        if plc is not None:
            self.scan_us = plc.scan_us
            if self._ahead is not None and self._ahead[0] != self._course():
                self._ahead = None    # another course: the copy's edges no longer hold
        t = max(t0, self.t)
        self.began(t)
        for _ in range(MAX_EVENTS):
            te = self.next_event(t)
            if self.releases:
                tr = self.releases[0][0]
                te = tr if te is None else min(te, tr)
            if te is None or te > t1:
                break
            if te <= t:
                raise PlcRuntimeError(f"machine {self.name}: an event at {te} µs is not "
                                      f"after {t} µs (internal error)")
            self.advance(te - t)
            t = te
            while self.releases and self.releases[0][0] <= t:
                self.pressed[self.releases.pop(0)[1]] = False
            self.event(t)
            self._record(t)
        else:
            raise PlcRuntimeError(f"machine {self.name}: more than {MAX_EVENTS} events in "
                                  f"one step")
        if t1 > t:
            self.advance(t1 - t)
            t = t1
            self._record(t)   # analog values moved
        self.t = t
        self.publish()

    def snapshot(self, t: int) -> list[Any]:
        return []

    def _course(self) -> tuple[Any, ...]:
        """What the machine's future depends on besides its state: the
        outputs as the image holds them, the faults, the buttons."""
        q = self.q
        outs = tuple(0 if a is None else q[a[1] >> 3] >> (a[1] & 7) & 1
                     for a in self.out_map.values())
        return outs, frozenset(self.active), tuple(self.pressed.values()), tuple(self.releases)

    def input_edge_after(self, bit: int, after: int, rising: bool) -> int | None:
        """The time of the first rising (falling) edge of the input *bit*
        after *after* µs with the outputs as they are now: one already made
        (a button pressed between two scans), else one a copy of the machine
        runs into ahead (the time line asks again at each instant)."""
        sig, want = self._bit_signal.get(bit), int(rising)
        found = None
        for t, s, v in reversed(self.log):
            if t <= after:
                break
            if s == sig and v == want:
                found = t
        if found is not None:
            return found
        course = self._course()
        need = max(after, self.t) + self.scan_us
        ahead = self._ahead
        if ahead is None or ahead[0] != course or ahead[1] < need:
            # perf: a copy runs four scans ahead; its edges hold while the
            # course stays the same (the machine is deterministic), so the
            # instants of those scans are answered from them
            memo = {id(self.pi): bytearray(self.pi), id(self.ai): bytearray(self.ai),
                    id(self.q): self.q, id(self.log): deque(maxlen=EDGE_LOG),
                    id(self.notes): deque(maxlen=EDGE_LOG), id(self._ahead): None}
            twin = copy.deepcopy(self, memo)
            until = need + 3 * self.scan_us
            twin.step(None, twin.t, until)
            ahead = self._ahead = (course, until, list(twin.log))
        return next((t for t, s, v in ahead[2] if t > after and s == sig and v == want), None)

    def view(self) -> Machine:
        """What :meth:`plcrt.Plc.machine` hands out."""
        return Machine(self)


def _seconds(v: Any, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not \
            0 < v <= MAX_PRESS_S or v != v:
        raise PlcConfigError(f"{what} must be seconds, more than 0 and at most "
                             f"{MAX_PRESS_S:g}, got {shown_value(v)}")
    return float(v)


class Machine:
    """A machine of the plant as tests and a page see it
    (``plc.machine("conveyor")``): its state, its faults, its buttons.

    Every call takes effect at the PLC's current time (between two scans):
    a pressed button is on the input terminal the next scan reads.
    """

    __slots__ = ("_dev",)

    def __init__(self, device: MachineDevice) -> None:
        if not isinstance(device, MachineDevice):
            raise PlcConfigError(f"a Machine shows a machine of a plant, not "
                                 f"{type(device).__name__}")
        self._dev = device

    @property
    def name(self) -> str:
        """The machine's name in the plant (``[machine.NAME]``)."""
        return self._dev.name

    @property
    def kind(self) -> str:
        """Its kind: conveyor, tank, traffic, garage, elevator."""
        return self._dev.kind

    def state(self) -> dict[str, Any]:
        """A JSON-ready dict of numbers, booleans and short names (docs/machines.md):
        ``kind``, ``name``, ``t`` (s), ``inputs`` / ``outputs`` (signal -> level
        as the terminals show it), ``faults`` (the active ones), and the
        machine's own fields."""
        d = self._dev
        return {"kind": d.kind, "name": d.name, "t": d.t / 1e6,
                "inputs": dict(d.levels), "outputs": dict(d.out),
                "faults": sorted(d.active), **d.details()}

    def wiring(self) -> dict[str, str]:
        """Signal -> address (``"I0.3"``, ``"Q0.0"``, ``"AIW0"``; ``""`` not wired)."""
        d = self._dev
        return {s: show_address(a) for s, a in (*d.in_map.items(), *d.out_map.items())}

    def faults(self) -> list[str]:
        """Every fault this machine knows (``jam``, ``stuck_on:eye_exit`` ...)."""
        d = self._dev
        return d.fault_names(d.in_map, d.out_map)

    def fault(self, name: str, on: bool = True) -> None:
        """Switch a fault on (or off with ``on=False``) now.

        Raises:
            PlcConfigError: an unknown fault name, or *on* not a bool.
        """
        d = self._dev
        if not isinstance(on, bool):
            raise PlcConfigError(f"on must be True or False, got {shown_value(on)}")
        if not isinstance(name, str) or name not in self.faults():
            raise PlcConfigError(f"machine {d.name} has no fault {shown_value(name)} "
                                 f"(its faults: {', '.join(self.faults()[:12])} ...)")
        d.read_outputs()
        d.set_fault(name, on)
        d._record(d.t)
        d.publish()

    def buttons(self) -> list[str]:
        """What a person can press or hold: buttons, key switches, world
        conditions (the garage's ``obstacle``)."""
        return list(self._dev.pressed)

    def _actor(self, name: Any) -> str:
        d = self._dev
        if not isinstance(name, str) or name not in d.pressed:
            raise PlcKeyError(f"machine {d.name} has no button {shown_value(name)} "
                              f"(its buttons: {', '.join(d.pressed) or 'none'})")
        return name

    def _set(self, name: str, on: bool) -> None:
        d = self._dev
        d.pressed[name] = on
        d.releases = [r for r in d.releases if r[1] != name]
        d.read_outputs()
        d._record(d.t)
        d.publish()

    def press(self, name: str, seconds: float = 0.3) -> None:
        """Press a button for *seconds* (released at that exact time); the
        next scan sees it pressed.

        Raises:
            PlcKeyError: no such button; PlcConfigError: a bad duration.
        """
        name = self._actor(name)
        dur = int(round(_seconds(seconds, "seconds") * 1e6))
        self._set(name, True)
        d = self._dev
        d.releases = sorted([*d.releases, (d.t + max(1, dur), name)])

    def hold(self, name: str) -> None:
        """Keep a button pressed (a key switch on, an obstacle in place) until :meth:`release`."""
        self._set(self._actor(name), True)

    def release(self, name: str) -> None:
        """Let go of a button held or pressed."""
        self._set(self._actor(name), False)

    def edges(self, signal: str | None = None) -> list[tuple[float, str, int]]:
        """The input edges the machine made, oldest first, as
        ``(seconds, signal, level)`` with the exact time (the last 4096)."""
        d = self._dev
        if signal is not None and (not isinstance(signal, str) or signal not in d.in_map):
            raise PlcKeyError(f"machine {d.name} has no input {shown_value(signal)} "
                              f"(its inputs: {', '.join(d.in_map)})")
        return [(t / 1e6, s, v) for t, s, v in d.log if signal is None or s == signal]

    def notes(self) -> list[tuple[float, str]]:
        """What the machine noticed, as ``(seconds, text)``: a conflict of greens,
        a car moving with its door open, both motor directions on (the last 4096)."""
        return [(t / 1e6, text) for t, text in self._dev.notes]

    def __repr__(self) -> str:
        return f"<Machine {self._dev.name} ({self._dev.kind})>"
