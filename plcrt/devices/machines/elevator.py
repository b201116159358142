"""A three-floor elevator: a car with an up/down motor, floor sensors,
call buttons and a car door with a door motor and two door sensors.

The car's height runs between the buffers at ``-overtravel`` mm and
``2·floor_height + overtravel`` mm; floor *n*'s level is
``(n - 1)·floor_height``.  With ``up`` on (and ``down`` off) the car rises
at ``speed`` mm/s, with ``down`` on it falls; it stops on a buffer (the
machine notes the crash).  Both on: the brake holds (noted).  The door
opens from 0 to ``door_width`` mm at ``door_speed`` mm/s with
``door_open`` on and closes with ``door_close`` on; both on: it stays.

Inputs: ``floor_1`` .. ``floor_3`` (on while the car is within ``band``
mm of the floor's level), ``door_opened`` (the door fully open),
``door_closed`` (fully closed), and the call buttons ``call_1`` ..
``call_3``.  Outputs: ``up``, ``down``, ``door_open``, ``door_close``.

What the machine notes (:meth:`~plcrt.devices.machines.base.Machine.notes`)
and counts: the car moving while its door is not closed (``unsafe_moves``),
the door opening away from a floor, a buffer crash.

What it is not: a car with acceleration, a counterweight or a load; hall
and car calls are one button per floor.
"""

from __future__ import annotations

from typing import Any

from .base import NM, MachineDevice, crossing, moved
from .config import Param

__all__ = ["Elevator"]

FLOORS = (1, 2, 3)


class Elevator(MachineDevice):
    KIND = "elevator"
    INPUTS = {"floor_1": "I0.0", "floor_2": "I0.1", "floor_3": "I0.2",
              "door_opened": "I0.3", "door_closed": "I0.4",
              "call_1": "I0.5", "call_2": "I0.6", "call_3": "I0.7"}
    OUTPUTS = {"up": "Q0.0", "down": "Q0.1", "door_open": "Q0.2", "door_close": "Q0.3"}
    BUTTONS = ("call_1", "call_2", "call_3")
    PARAMS = {
        "floor_height": Param(3000, 500, 100_000, doc="between two floors, mm"),
        "speed": Param(500, 1, 10_000, doc="car speed, mm/s"),
        "band": Param(10, 1, 200, doc="a floor sensor is on within this of the level, mm"),
        "overtravel": Param(300, 20, 5000, doc="the buffers beyond the end floors, mm"),
        "door_width": Param(800, 100, 5000, doc="door opening, mm"),
        "door_speed": Param(400, 1, 10_000, doc="door speed, mm/s"),
        "start_floor": Param(1, 1, 3, doc="the floor the car is at at power-up"),
    }
    OWN_FAULTS = {"door_jam": "the car door is stuck where it is"}

    def setup(self) -> None:
        p = self.p
        self.h = p["floor_height"] * NM
        self.y = (p["start_floor"] - 1) * self.h
        self.lo = -p["overtravel"] * NM
        self.hi = 2 * self.h + p["overtravel"] * NM
        self.band = p["band"] * NM
        self.w = p["door_width"] * NM
        self.d = 0
        self.unsafe_moves = 0
        self.crashes = 0
        self.flags = {"unsafe": False, "both": False, "between": False, "crash": False}

    def _car_v(self) -> int:
        o = self.out
        if bool(o["up"]) == bool(o["down"]):
            return 0
        return self.p["speed"] if o["up"] else -self.p["speed"]

    def _door_v(self) -> int:
        o = self.out
        if "door_jam" in self.active or bool(o["door_open"]) == bool(o["door_close"]):
            return 0
        return self.p["door_speed"] if o["door_open"] else -self.p["door_speed"]

    def _car_stop(self, v: int) -> int:
        return self.hi if v > 0 else self.lo

    def _floor(self) -> int | None:
        for n in FLOORS:
            if abs(self.y - (n - 1) * self.h) <= self.band:
                return n
        return None

    def _flag(self, key: str, now: bool, t: int, text: str) -> bool:
        new = now and not self.flags[key]
        if new:
            self.note(t, text)
        self.flags[key] = now
        return new

    def began(self, t: int) -> None:
        v = self._car_v()
        moving = v != 0 and self.y != self._car_stop(v)
        if self._flag("unsafe", moving and self.d > 0, t, "the car moves with its door open"):
            self.unsafe_moves += 1
        self._flag("both", bool(self.out["up"] and self.out["down"]), t,
                   "up and down both on")
        self._flag("between", (self.d > 0 or self._door_v() > 0) and self._floor() is None, t,
                   "the door opens away from a floor")
        if self._flag("crash", v != 0 and self.y == self._car_stop(v), t,
                      "the car hit a buffer"):
            self.crashes += 1

    def advance(self, dt: int) -> None:
        v = self._car_v()
        self.y = moved(self.y, v, dt, self._car_stop(v))
        dv = self._door_v()
        self.d = moved(self.d, dv, dt, self.w if dv > 0 else 0)

    def next_event(self, t: int) -> int | None:
        best = None
        v = self._car_v()
        marks = tuple(m for n in FLOORS for m in ((n - 1) * self.h - self.band,
                                                  (n - 1) * self.h + self.band))
        dt = crossing(self.y, v, (*marks, self.lo, self.hi), self._car_stop(v))
        if dt is not None:
            best = t + dt
        dv = self._door_v()
        dt = crossing(self.d, dv, (0, self.w), self.w if dv > 0 else 0)
        if dt is not None:
            best = t + dt if best is None else min(best, t + dt)
        return best

    def event(self, t: int) -> None:
        self.began(t)

    def sense(self) -> dict[str, int]:
        at = self._floor()
        out = {f"floor_{n}": int(at == n) for n in FLOORS}
        out["door_opened"] = int(self.d >= self.w)
        out["door_closed"] = int(self.d <= 0)
        return out

    def details(self) -> dict[str, Any]:
        v = self._car_v()
        return {"floor_height": self.p["floor_height"], "car": self.y / NM,
                "floor": self._floor() or 0, "velocity": v,
                "moving": v != 0 and self.y != self._car_stop(v),
                "door": self.d / self.w, "door_width": self.p["door_width"],
                "unsafe_moves": self.unsafe_moves, "crashes": self.crashes}
