"""A tank with an inlet valve, an outlet valve, a pump, two level switches,
an analog level and an analog inflow meter.

The tank holds ``volume`` millilitres of ``capacity``.  With the outputs
as they are, the flows are constant: in = ``inflow`` mL/s while ``inlet``
is on; out = ``outflow`` mL/s while ``outlet`` is on, plus ``pump`` mL/s
while ``pump`` is on (plus ``leak`` mL/s under the fault of that name).
So the volume moves on a straight line, exactly, until the tank is full
(what comes in over what goes out spills over the rim) or empty (only what
comes in goes out; a pump on an empty tank runs dry, and the machine notes
it).  Mass balance is exact: ``volume = start + in - out - spilled``.

Inputs: ``low`` and ``high`` switches (on at and above their volumes),
``level`` on an analog input, 0..32000 for empty..full (the S7-200's
unipolar analog range, EM 231: 0..32000), and ``flow``, the inlet's flow
meter, 0..32000 for 0..``inflow``.  Volumes are integers in nanolitres
(a flow in mL/s is nL per µs), so a switch's edge time is one division.

What it is not: gravity outflow that depends on the level (Torricelli) or
valve dynamics; a valve is open or shut at once.
"""

from __future__ import annotations

from typing import Any

from ...errors import PlcConfigError
from .base import NM, MachineDevice, ceil_div
from .config import Param

__all__ = ["Tank"]

FULL_SCALE = 32000


class Tank(MachineDevice):
    KIND = "tank"
    INPUTS = {"low": "I0.0", "high": "I0.1", "start": "I0.2", "stop": "I0.3",
              "level": "AIW0", "flow": "AIW2"}
    OUTPUTS = {"inlet": "Q0.0", "outlet": "Q0.1", "pump": "Q0.2"}
    ANALOG = {"level": True, "flow": True}
    BUTTONS = ("start", "stop")
    PARAMS = {
        "capacity": Param(100_000, 100, 10**9, doc="tank volume, mL"),
        "start": Param(0, 0, 10**9, doc="volume at power-up, mL"),
        "inflow": Param(2000, 1, 10**7, doc="inlet valve flow, mL/s"),
        "outflow": Param(1000, 1, 10**7, doc="outlet valve flow, mL/s"),
        "pump": Param(1500, 1, 10**7, doc="pump flow, mL/s"),
        "low": Param(10_000, 0, 10**9, doc="low switch on at and above, mL"),
        "high": Param(90_000, 0, 10**9, doc="high switch on at and above, mL"),
        "leak": Param(200, 1, 10**7, doc="flow out of a leak (fault), mL/s"),
    }
    OWN_FAULTS = {"leak": "the tank leaks leak mL/s while not empty",
                  "inlet_stuck_open": "the inlet valve lets inflow through whatever "
                                      "its output says"}

    @classmethod
    def check_params(cls, p: dict[str, Any], where: str) -> None:
        if not 0 < p["low"] < p["high"] <= p["capacity"]:
            raise PlcConfigError(f"{where}: the switches need 0 < low < high <= capacity, "
                                 f"got low {p['low']}, high {p['high']}, "
                                 f"capacity {p['capacity']}")
        if p["start"] > p["capacity"]:
            raise PlcConfigError(f"{where}.start ({p['start']}) is above the capacity")

    def setup(self) -> None:
        p = self.p
        self.C = p["capacity"] * NM
        self.v = p["start"] * NM
        self.v0 = self.v
        self.total_in = self.total_out = self.spilled = self.leaked = 0
        self.dry = False

    def _rates(self) -> tuple[int, int]:
        p, o = self.p, self.out
        q_in = p["inflow"] if o["inlet"] or "inlet_stuck_open" in self.active else 0
        q_out = (p["outflow"] if o["outlet"] else 0) + (p["pump"] if o["pump"] else 0)
        if "leak" in self.active:
            q_out += p["leak"]
        return q_in, q_out

    def began(self, t: int) -> None:
        dry = bool(self.out["pump"]) and self.v == 0 and self._rates()[0] < self.p["pump"]
        if dry and not self.dry:
            self.note(t, "the pump runs dry")
        self.dry = dry

    def advance(self, dt: int) -> None:
        q_in, q_out = self._rates()
        net = q_in - q_out
        self.total_in += q_in * dt
        if net >= 0:
            fill = min(net * dt, self.C - self.v)
            self.spilled += net * dt - fill
            self.v += fill
            self.total_out += q_out * dt
            out = q_out * dt
        else:
            drain = min(-net * dt, self.v)
            self.v -= drain
            out = q_in * dt + drain
            self.total_out += out
        if "leak" in self.active and q_out:
            # the leak's share of what went out
            self.leaked += out * self.p["leak"] // q_out

    def next_event(self, t: int) -> int | None:
        q_in, q_out = self._rates()
        net = q_in - q_out
        if net == 0:
            return None
        marks = (self.p["low"] * NM, self.p["high"] * NM)
        best = None
        if net > 0:
            for m in (*marks, self.C):
                if self.v < m:
                    te = t + ceil_div(m - self.v, net)
                    best = te if best is None else min(best, te)
        else:
            for m in (*marks, 1):      # below a switch; empty (below 1 nL)
                if self.v >= m:
                    te = t + (self.v - m) // -net + 1
                    best = te if best is None else min(best, te)
        return best

    def event(self, t: int) -> None:
        self.began(t)
        if self.v == self.C and self._rates()[0] > self._rates()[1]:
            self.note(t, "the tank overflows")

    def sense(self) -> dict[str, int]:
        q_in = self._rates()[0]
        return {"low": int(self.v >= self.p["low"] * NM),
                "high": int(self.v >= self.p["high"] * NM),
                "level": self.v * FULL_SCALE // self.C,
                "flow": q_in * FULL_SCALE // self.p["inflow"]}

    def details(self) -> dict[str, Any]:
        q_in, q_out = self._rates()
        return {"capacity": self.p["capacity"], "volume": self.v / NM,
                "fill": self.v / self.C, "inflow": q_in,
                "outflow": q_out if self.v or q_in >= q_out else q_in,
                "total_in": self.total_in / NM, "total_out": self.total_out / NM,
                "spilled": self.spilled / NM, "leaked": self.leaked / NM,
                "low_at": self.p["low"], "high_at": self.p["high"], "dry_run": self.dry}
