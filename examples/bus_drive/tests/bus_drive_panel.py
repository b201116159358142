"""What the bus drive example's tests share: the program's files and
options, the two axes with the values their panel and plant give them
(data block bus_drive.db, plant.toml), and small helpers."""

from __future__ import annotations

from dataclasses import dataclass

PROGRAM = dict(symbols="../bus_drive_symbols.txt", data="../bus_drive.db",
               plant="../plant.toml")
FILES = ["../bus_drive.awl", "library/cia402/drive_lib.awl"]


@dataclass(frozen=True)
class Axis:
    """One drive of the example: its symbols' prefix, node, model and the
    values the panel and the plant give it."""

    prefix: str
    node: int
    model: str
    image: int
    abs_target: int
    rel_distance: int
    jog: int
    home_point: int            #: the plant position the homing method ends on
    offset_sign: int           #: the count at home is offset_sign * 607Ch
    homed_word: int            #: 6041h after the homing
    pp_idle_homed: int         #: 6041h at rest on a target after the homing
    to_switch: int             #: counts from the home point to the home switch's edge

    def __getitem__(self, name: str) -> str:
        return f"{self.prefix}_{name}"


AXES = [
    # HCFA: method 19, the home switch 10000..12000 as a positive level
    # switch, home at its edge 10000 - 1; 6064h = +607Ch there (HCFA §7.5.4)
    Axis("D1", 1, "hcfa-am0520b", 1000, 50000, -20000, -30000, 9999, +1, 0x1637, 0x8637, +1),
    # Kinco: method 5, the home switch -6000..-4000 as a negative level
    # switch, home at the first index pulse right of -4000 + 1: -3900;
    # 6099h:05 = 1: 6064h = -607Ch there (Kinco §2.3-3); bit 15 = homed
    Axis("D2", 2, "kinco-servo", 1100, 80000, 15000, 25000, -3900, -1, 0x9637, 0x8637, -100),
]


def mechanical(plc, axis: Axis) -> int:
    """Where the drive's axis stands in the plant (the switches' frame)."""
    sim = plc.plc.module(0).drive(axis.node)
    return sim.axis.mechanical(sim.now)


def press(plc, button: str, until: str, timeout: float = 30) -> float:
    """Press a push button for 50 ms (5 scans) and wait for a lamp or a flag."""
    plc.pulse(button, scans=5)
    return plc.run_until(until, timeout=timeout)
