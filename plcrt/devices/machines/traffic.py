"""A crossing of a main road and a side road with traffic lights, a
pedestrian crossing with two request buttons, and queues of cars.

The lamps are the program's outputs: ``main_red``, ``main_yellow``,
``main_green``, ``side_red``, ``side_yellow``, ``side_green``, ``walk`` and
``dont_walk``.  The machine's inputs are the two pedestrian buttons
``button_a`` and ``button_b`` (one each side of the road) and a car
detector loop per road, ``car_main`` and ``car_side`` (on while a car
waits at the stop line).

Conflicts: a vehicle signal *goes* on green or yellow.  Main going with
side going, or ``walk`` lit with either road going, is a conflict; the
machine counts each one, notes it with its exact start
(:meth:`~plcrt.devices.machines.base.Machine.notes`) and keeps the time
spent in conflict.  What counts is the lamps as lit (a broken lamp wire
shows nothing, so it conflicts with nothing).

Cars: the first car of a road arrives at ``main_first`` / ``side_first``
s and then one every ``main_every`` / ``side_every`` s and joins its
road's queue (at most 50 wait; more are turned away and counted).  While a
road's green is lit the car at the head of its queue leaves ``headway`` s
after it got there or the light turned green, whichever is later.

What it is not: a traffic simulation with speeds or turning traffic.
"""

from __future__ import annotations

from typing import Any

from .base import MachineDevice
from .config import Param

__all__ = ["Traffic"]

MAX_QUEUE = 50
ROADS = ("main", "side")
#: pairs of lamp groups that must never be lit together
CONFLICTS = (("main_go", "side_go"), ("main_go", "walk"), ("side_go", "walk"))


class Traffic(MachineDevice):
    KIND = "traffic"
    INPUTS = {"button_a": "I0.0", "button_b": "I0.1", "car_main": "I0.2", "car_side": "I0.3"}
    OUTPUTS = {"main_red": "Q0.0", "main_yellow": "Q0.1", "main_green": "Q0.2",
               "side_red": "Q0.3", "side_yellow": "Q0.4", "side_green": "Q0.5",
               "walk": "Q0.6", "dont_walk": "Q0.7"}
    BUTTONS = ("button_a", "button_b")
    PARAMS = {
        "main_first": Param(1.0, 0, 3600, integer=False, doc="first car on the main road, s"),
        "main_every": Param(4.0, 0.1, 3600, integer=False, doc="then one every, s"),
        "side_first": Param(2.0, 0, 3600, integer=False, doc="first car on the side road, s"),
        "side_every": Param(9.0, 0.1, 3600, integer=False, doc="then one every, s"),
        "headway": Param(2.0, 0.1, 60, integer=False, doc="a car leaves on green after, s"),
    }

    def setup(self) -> None:
        us = {k: max(0, int(round(v * 1e6))) for k, v in self.p.items()}
        self.first = {r: us[f"{r}_first"] for r in ROADS}
        self.every = {r: max(1, us[f"{r}_every"]) for r in ROADS}
        self.headway = max(1, us["headway"])
        self.arrived = {r: 0 for r in ROADS}
        self.queue = {r: 0 for r in ROADS}
        self.passed = {r: 0 for r in ROADS}
        self.turned_away = {r: 0 for r in ROADS}
        self.lead_since = {r: 0 for r in ROADS}
        self.green_since: dict[str, int | None] = {r: None for r in ROADS}
        self.conflict: tuple[str, ...] = ()
        self.conflicts = 0
        self.conflict_us = 0

    def _groups(self) -> dict[str, bool]:
        o = self.out
        return {"main_go": bool(o["main_green"] or o["main_yellow"]),
                "side_go": bool(o["side_green"] or o["side_yellow"]),
                "walk": bool(o["walk"])}

    def began(self, t: int) -> None:
        g = self._groups()
        now = tuple(f"{a}+{b}" for a, b in CONFLICTS if g[a] and g[b])
        if now and now != self.conflict:
            self.conflicts += 1
            self.note(t, "conflict: " + ", ".join(now))
        self.conflict = now
        for r in ROADS:
            if self.out[f"{r}_green"]:
                if self.green_since[r] is None:
                    self.green_since[r] = t
            else:
                self.green_since[r] = None

    def advance(self, dt: int) -> None:
        if self.conflict:
            self.conflict_us += dt

    def _times(self, r: str) -> tuple[int, int | None]:
        arrive = self.first[r] + self.arrived[r] * self.every[r]
        since = self.green_since[r]
        leave = None
        if since is not None and self.queue[r]:
            leave = max(since, self.lead_since[r]) + self.headway
        return arrive, leave

    def next_event(self, t: int) -> int | None:
        best = None
        for r in ROADS:
            for te in self._times(r):
                if te is not None:
                    te = max(te, t + 1)
                    best = te if best is None else min(best, te)
        return best

    def event(self, t: int) -> None:
        for r in ROADS:
            arrive, leave = self._times(r)
            if leave is not None and leave <= t:
                self.queue[r] -= 1
                self.passed[r] += 1
                self.lead_since[r] = t
            if arrive <= t:
                self.arrived[r] += 1
                if self.queue[r] >= MAX_QUEUE:
                    self.turned_away[r] += 1
                else:
                    if not self.queue[r]:
                        self.lead_since[r] = t
                    self.queue[r] += 1

    def sense(self) -> dict[str, int]:
        return {"car_main": int(self.queue["main"] > 0),
                "car_side": int(self.queue["side"] > 0)}

    def details(self) -> dict[str, Any]:
        return {"lamps": {k: bool(v) for k, v in self.out.items()},
                "conflict": bool(self.conflict), "conflicts": self.conflicts,
                "conflict_time": self.conflict_us / 1e6,
                "queue": dict(self.queue), "passed": dict(self.passed),
                "turned_away": dict(self.turned_away)}
