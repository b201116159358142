"""Statements of the two drive manuals (HCFA AM0520B, Kinco homing note)
that the other CiA 402 tests do not pin.

Each test names the manual's section and the statement it pins (or the
decision of docs/decisions.md it follows where the manual is silent or
wrong); docs/cia402.md ("Audit against the manuals") lists these statements
with their tests, and the last test here checks that every test it names
exists.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.od import SdoAbort
from plcrt.devices.cia402.plant import DrivePlant
from plcrt.devices.cia402.statemachine import State

DOCS = Path(__file__).resolve().parents[3] / "docs" / "cia402.md"


def enable(d: Drive, mode: int, **params: int) -> Drive:
    """Mode *mode*, objects ``x6081=...`` / ``x6099_01=...``, then 6, 7, 0x0F."""
    d.write(0x6060, 0, mode)
    for name, value in params.items():
        d.write(int(name[1:5], 16), int(name[6:]) if len(name) > 5 else 0, value)
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
    if d.sm.state is State.SWITCHED_ON:
        d.cycle(d.now)
    assert d.sm.state is State.OPERATION_ENABLED
    return d


def pp_move(d: Drive, target: int, relative: bool = False) -> None:
    d.write(0x607A, 0, target)
    d.write(0x6040, 0, 0x5F if relative else 0x1F)
    d.write(0x6040, 0, 0x0F)


# ---------------------------------------------------------------- limit switches

@pytest.mark.parametrize("model", ["hcfa-am0520b", "kinco-servo"])
def test_pp_move_ending_exactly_on_a_limit_switch_stops_at_the_limit(model):
    """HCFA §7.4.2 bit 11, §7.5.3 note 1: a limit switch that becomes active
    in a move toward it is an abnormal stop (bits 8 and 11), also when the
    move's target is the switch's own first count."""
    d = enable(Drive(model, plant=DrivePlant(pos_limit=10_000)), 1,
               x6081=20_000, x6083=100_000, x6084=100_000)
    pp_move(d, 10_000)
    d.advance(3_000_000)
    assert d.position == 10_000
    assert d.statusword & 0x0900 == 0x0900           # bits 8 (abnormal stop) and 11 (limit)
    assert [e.t_us for e in d.log if "limit switch (PLS) active" in e.text] == [700_000]
    pp_move(d, 20_000)                                # further toward it: refused
    d.advance(4_000_000)
    assert d.position == 10_000
    pp_move(d, 0)                                     # away from it: allowed
    d.advance(6_000_000)
    assert d.position == 0 and not d.statusword & 0x0900
