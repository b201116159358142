"""A garage door: a motor that opens and closes it, two limit switches, a
safety edge on its bottom rail, buttons, a key switch and an obstacle.

The door's opening (its bottom rail's height) runs from 0 (closed) to
``travel`` mm.  With ``motor_open`` on it rises at ``speed`` mm/s, with
``motor_close`` on it falls, until it is at an end: it never moves past 0
or ``travel``.  Both on at once: the motor does not turn (the machine
notes it).  An obstacle (``hold("obstacle")``) stands ``obstacle_at`` mm
high under the door: a closing door stops on it.  The safety edge is a
normally closed contact (the input is on while the edge is clear, so that
a broken wire reads as "pressed"); it opens while the rail is at most
``edge`` mm above the obstacle.  A motor that keeps closing on the
obstacle is noted.

Inputs: ``limit_open`` (on within ``band`` mm of fully open),
``limit_closed`` (on within ``band`` mm of closed), ``safety_edge`` (NC),
the buttons ``button_open``, ``button_close``, ``button_stop``, and the
key switch ``key`` (held: ``hold("key")``).  Outputs: ``motor_open``,
``motor_close``, ``lamp`` (the warning light; shown only).

What it is not: a door with inertia, a motor current or a slack cable.
"""

from __future__ import annotations

from typing import Any

from ...errors import PlcConfigError
from .base import NM, MachineDevice, crossing, moved
from .config import Param

__all__ = ["GarageDoor"]


class GarageDoor(MachineDevice):
    KIND = "garage"
    INPUTS = {"limit_open": "I0.0", "limit_closed": "I0.1", "safety_edge": "I0.2",
              "button_open": "I0.3", "button_close": "I0.4", "button_stop": "I0.5",
              "key": "I0.6"}
    OUTPUTS = {"motor_open": "Q0.0", "motor_close": "Q0.1", "lamp": "Q0.2"}
    BUTTONS = ("button_open", "button_close", "button_stop", "key")
    WORLD = ("obstacle",)
    PARAMS = {
        "travel": Param(2400, 100, 100_000, doc="full opening, mm"),
        "speed": Param(200, 1, 10_000, doc="door speed, mm/s"),
        "start": Param(0, 0, 100_000, doc="opening at power-up, mm"),
        "band": Param(10, 1, 1000, doc="a limit switch is on within this of its end, mm"),
        "obstacle_at": Param(500, 1, 100_000, doc="the obstacle's height, mm"),
        "edge": Param(20, 1, 1000, doc="the safety edge opens this far above the obstacle, mm"),
    }
    OWN_FAULTS = {"jam": "the door is stuck where it is; the motor turns in vain"}

    @classmethod
    def check_params(cls, p: dict[str, Any], where: str) -> None:
        if p["start"] > p["travel"]:
            raise PlcConfigError(f"{where}.start ({p['start']}) is past travel ({p['travel']})")
        if not p["band"] * 2 < p["travel"] or not p["obstacle_at"] + p["edge"] < p["travel"]:
            raise PlcConfigError(f"{where}: band and obstacle_at + edge must fit in travel")

    def setup(self) -> None:
        self.x = self.p["start"] * NM
        self.T = self.p["travel"] * NM
        self.B = self.p["band"] * NM
        self.H = self.p["obstacle_at"] * NM
        self.E = self.p["edge"] * NM
        self.both = False
        self.pressing = False

    def _velocity(self) -> int:
        o = self.out
        if "jam" in self.active or bool(o["motor_open"]) == bool(o["motor_close"]):
            return 0
        return self.p["speed"] if o["motor_open"] else -self.p["speed"]

    def _blocked(self) -> bool:
        """The obstacle is under the door (it only fits where the door is above it)."""
        return self.pressed["obstacle"] and self.x >= self.H

    def _stop(self, v: int) -> int:
        if v > 0:
            return self.T
        return self.H if self._blocked() else 0

    def began(self, t: int) -> None:
        both = bool(self.out["motor_open"] and self.out["motor_close"])
        if both and not self.both:
            self.note(t, "both motor directions on")
        self.both = both
        pressing = self._velocity() < 0 and self._blocked() and self.x == self.H
        if pressing and not self.pressing:
            self.note(t, "the door presses on the obstacle")
        self.pressing = pressing

    def advance(self, dt: int) -> None:
        v = self._velocity()
        self.x = moved(self.x, v, dt, self._stop(v))

    def next_event(self, t: int) -> int | None:
        v = self._velocity()
        marks = (self.B, self.T - self.B, self.H + self.E, self.H, 0, self.T)
        dt = crossing(self.x, v, marks, self._stop(v))
        return None if dt is None else t + dt

    def event(self, t: int) -> None:
        self.began(t)

    def sense(self) -> dict[str, int]:
        edge_pressed = self._blocked() and self.x <= self.H + self.E
        return {"limit_open": int(self.x >= self.T - self.B),
                "limit_closed": int(self.x <= self.B),
                "safety_edge": int(not edge_pressed)}

    def details(self) -> dict[str, Any]:
        v = self._velocity()
        return {"travel": self.p["travel"], "opening": self.x / NM, "open": self.x / self.T,
                "moving": v != 0 and self.x != self._stop(v), "velocity": v,
                "obstacle": self.pressed["obstacle"], "obstacle_at": self.p["obstacle_at"],
                "lamp": bool(self.out["lamp"])}
