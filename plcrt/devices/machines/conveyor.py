"""A conveyor belt with parts, photo-eyes, a stopper gate and a diverter
into two bins.

Parts arrive from a feeder at the belt's start (position 0) at fixed
times: the first at ``first`` s, then one every ``interval`` s, of the
kinds the ``pattern`` names in turn (``T`` tall, ``S`` short).  A part
that arrives while the belt's start is still covered waits in the feeder
and enters the moment the part before it has moved its own length on.
With ``motor`` on the belt moves at ``speed`` mm/s and carries every part
with it, unless it is held: by the closed stopper gate (output ``gate``
off: a part's leading edge stops at ``gate_at``), by the part ahead
(parts queue nose to tail), or by a jam.  A part whose leading edge
reaches ``divert_at`` while ``divert`` is on is pushed into the diverted
bin; every other part drops into the straight bin once its tail leaves the
belt's end (``length``).

Photo-eyes (inputs on while a part breaks the beam): ``eye_entry`` and,
mounted higher at the same place, ``eye_tall`` (only tall parts break it),
``eye_gate`` just before the gate, ``eye_exit`` before the end.  A beam at
``s`` is broken while a part's leading edge ``x`` satisfies ``x - part < s <= x``.

Where each part is: ``x(t) = min(x + speed·t, S)``, with ``S`` the
position it is held at (the gate, the part ahead's tail, its own place if
it is jammed), so every edge time is one integer division.

What it is not: parts with friction, slip or different lengths; the gate
closing onto a part that is already under it lets that part go on.
"""

from __future__ import annotations

from typing import Any

from .base import NM, MachineDevice, ceil_div
from .config import Param

__all__ = ["Conveyor"]

_BIG = 1 << 62
_EYES = ("eye_entry", "eye_tall", "eye_gate", "eye_exit")


class Conveyor(MachineDevice):
    KIND = "conveyor"
    INPUTS = {"eye_entry": "I0.0", "eye_tall": "I0.1", "eye_gate": "I0.2",
              "eye_exit": "I0.3", "start": "I0.4", "stop": "I0.5"}
    OUTPUTS = {"motor": "Q0.0", "gate": "Q0.1", "divert": "Q0.2"}
    BUTTONS = ("start", "stop")
    PARAMS = {
        "length": Param(2000, 200, 20_000, doc="belt length, mm"),
        "speed": Param(250, 1, 10_000, doc="belt speed, mm/s"),
        "part": Param(100, 50, 1000, doc="part length, mm"),
        "first": Param(0.5, 0, 3600, integer=False, doc="first part arrives, s"),
        "interval": Param(3.0, 0.01, 3600, integer=False, doc="one part every, s"),
        "count": Param(0, 0, 1_000_000, doc="parts in all (0: no end)"),
        "pattern": Param("ST", 0, 0, text="[TS]{1,64}", doc="kinds in turn, T tall, S short"),
        "eye_entry_at": Param(150, 1, 20_000, doc="entry eyes (entry, tall), mm"),
        "gate_at": Param(1000, 1, 20_000, doc="stopper gate, mm"),
        "divert_at": Param(1500, 1, 20_000, doc="diverter, mm"),
        "eye_exit_at": Param(1900, 1, 20_000, doc="exit eye, mm"),
    }
    OWN_FAULTS = {"jam": "the front part on the belt (else the next to enter) sticks "
                         "where it is; the parts behind queue against it"}

    @classmethod
    def check_params(cls, p: dict[str, Any], where: str) -> None:
        from ...errors import PlcConfigError
        order = ("eye_entry_at", "gate_at", "divert_at", "eye_exit_at", "length")
        for a, b in zip(order, order[1:]):
            if not p[a] < p[b]:
                raise PlcConfigError(f"{where}: {a} ({p[a]}) must be below {b} ({p[b]})")
        if p["gate_at"] - p["part"] // 2 <= p["eye_entry_at"]:
            raise PlcConfigError(f"{where}: gate_at must be more than half a part past "
                                 f"eye_entry_at")

    def setup(self) -> None:
        p = self.p
        self.P = p["part"] * NM
        self.L = p["length"] * NM
        self.G = p["gate_at"] * NM
        self.D = p["divert_at"] * NM
        e = p["eye_entry_at"] * NM
        self.eyes = {"eye_entry": e, "eye_tall": e,
                     "eye_gate": self.G - self.P // 2, "eye_exit": p["eye_exit_at"] * NM}
        self.first_us = int(round(p["first"] * 1e6))
        self.every_us = max(1, int(round(p["interval"] * 1e6)))
        #: parts on the belt, front first: [id, tall, x (nm), divert decided]
        self.parts: list[list[Any]] = []
        self.arrived = 0         #: parts that entered the belt
        self.jammed: int | None = None
        self.jam_next = False
        self.bins = {"straight_tall": 0, "straight_short": 0,
                     "diverted_tall": 0, "diverted_short": 0}

    # -- the feeder -----------------------------------------------------------
    def _arrival(self) -> int | None:
        """The time the next part reaches the feeder, None when all have come."""
        if self.p["count"] and self.arrived >= self.p["count"]:
            return None
        return self.first_us + self.arrived * self.every_us

    def _entry_clear(self) -> bool:
        return not self.parts or self.parts[-1][2] >= self.P

    # -- motion -----------------------------------------------------------
    def _speed(self) -> int:
        return self.p["speed"] if self.out["motor"] else 0

    def _holds(self) -> list[int]:
        """Where each part stops if the outputs stay as they are (front first)."""
        gate_closed = not self.out["gate"]
        ahead = _BIG
        out = []
        for part in self.parts:
            s = ahead
            if part[0] == self.jammed:
                s = min(s, part[2])
            if gate_closed and part[2] <= self.G:
                s = min(s, self.G)
            s = max(s, part[2])      # a part never moves back
            out.append(s)
            ahead = s - self.P
        return out

    def advance(self, dt: int) -> None:
        v = self._speed()
        if not v or not self.parts:
            return
        for part, s in zip(self.parts, self._holds()):
            part[2] = min(part[2] + v * dt, s)

    def next_event(self, t: int) -> int | None:
        best = None
        arrival = self._arrival()
        if arrival is not None and self._entry_clear():
            best = max(arrival, t + 1)
        v = self._speed()
        if v and self.parts:
            last = len(self.parts) - 1
            for i, (part, s) in enumerate(zip(self.parts, self._holds())):
                x = part[2]
                marks = [self.L + self.P] if part[3] else [self.D, self.L + self.P]
                for name, e in self.eyes.items():
                    if name != "eye_tall" or part[1]:
                        marks += (e, e + self.P)
                if i == last and arrival is not None and arrival <= t:
                    marks.append(self.P)     # the waiting part can enter
                for m in marks:
                    if x < m <= s:
                        te = t + ceil_div(m - x, v)
                        best = te if best is None else min(best, te)
        return best

    def event(self, t: int) -> None:
        keep = []
        for part in self.parts:
            tall = "tall" if part[1] else "short"
            if not part[3] and part[2] >= self.D:
                part[3] = True
                if self.out["divert"]:
                    self.bins[f"diverted_{tall}"] += 1
                    self._gone(part)
                    continue
            if part[2] >= self.L + self.P:
                self.bins[f"straight_{tall}"] += 1
                self._gone(part)
                continue
            keep.append(part)
        self.parts = keep
        arrival = self._arrival()
        if arrival is not None and arrival <= t and self._entry_clear():
            pattern = self.p["pattern"]
            n = self.arrived
            self.parts.append([n, pattern[n % len(pattern)] == "T", 0, False])
            self.arrived += 1
            if self.jam_next:
                self.jammed, self.jam_next = n, False

    def _gone(self, part: list[Any]) -> None:
        if part[0] == self.jammed:
            self.jammed = None

    def fault_changed(self, name: str, on: bool) -> None:
        if not on:
            self.jammed, self.jam_next = None, False
        elif self.parts:
            self.jammed = self.parts[0][0]
        else:
            self.jam_next = True

    # -- sensing and state ----------------------------------------------------
    def sense(self) -> dict[str, int]:
        P = self.P
        out = {}
        for name, e in self.eyes.items():
            out[name] = int(any(x - P < e <= x and (tall or name != "eye_tall")
                                for _, tall, x, _ in self.parts))
        return out

    def details(self) -> dict[str, Any]:
        return {
            "length": self.p["length"], "part": self.p["part"],
            "speed": self._speed(), "gate_at": self.p["gate_at"],
            "divert_at": self.p["divert_at"],
            "eyes": {k: v / NM for k, v in self.eyes.items()},
            "parts": [{"id": i, "kind": "tall" if tall else "short", "x": x / NM,
                       "jammed": i == self.jammed} for i, tall, x, _ in self.parts],
            "arrived": self.arrived, "bins": dict(self.bins)}
