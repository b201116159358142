"""Exercise 7's requirements: the main road's yellow light blinks at 1 Hz.

Each test is one requirement, its docstring the requirement as the page
lists it; a failure says what the crossing showed (lamps, times) so you
can act on it.  Time is simulated (10 ms scans); the lamps are read from
the machine (``plc.machine("traffic").state()["lamps"]``) scan by scan.
``PLCRT_EXERCISE_PROGRAM`` grades another program than ``lesson.awl``.
"""

from __future__ import annotations

import os

import pytest

pytestmark = pytest.mark.plc(os.environ.get("PLCRT_EXERCISE_PROGRAM") or "lesson.awl",
                             plant="plant.toml", watch=["Q0.0", "Q0.1", "Q0.2", "SM0.5"])

SECONDS = 4.0


def lamp_record(plc, seconds=SECONDS):
    """Every lamp's changes over ``seconds`` from power-up: lamp -> [(t, lit)]
    (the first entry is the lamp at 0 s)."""
    traffic = plc.machine("traffic")
    changes = {k: [(0.0, v)] for k, v in traffic.state()["lamps"].items()}
    while plc.time < seconds - 1e-9:
        plc.run(scans=1)
        for k, v in traffic.state()["lamps"].items():
            if v != changes[k][-1][1]:
                changes[k].append((round(plc.time, 3), v))
    return changes


def shown(record):
    return ", ".join(f"{'on' if v else 'off'} at {t:.2f} s" for t, v in record[:8])


def test_the_yellow_light_blinks_at_1_hz(plc):
    """The main road's yellow light blinks at 1 Hz: 0.5 s on, 0.5 s off."""
    yellow = lamp_record(plc)["main_yellow"]
    assert len(yellow) >= 7, (
        f"in {SECONDS:g} s the yellow light changed only {len(yellow) - 1} time(s) "
        f"({shown(yellow)}); blinking at 1 Hz it changes every 0.5 s")
    halves = [round(b[0] - a[0], 3) for a, b in zip(yellow[1:], yellow[2:])]
    assert all(abs(h - 0.5) <= 0.02 for h in halves), (
        f"the yellow light stayed on or off for {halves} s ({shown(yellow)}); "
        f"each should be 0.5 s")


def test_the_blinking_starts_at_power_up(plc):
    """The yellow light is lit within the first second after power-up."""
    yellow = lamp_record(plc, 1.0)["main_yellow"]
    on = [t for t, v in yellow if v]
    assert on, f"the yellow light stayed dark for the first second ({shown(yellow)})"


def test_every_other_lamp_stays_dark(plc):
    """No other lamp lights while the yellow light blinks."""
    record = lamp_record(plc)
    lit = {k: shown(v) for k, v in record.items()
           if k != "main_yellow" and any(lit for _, lit in v)}
    assert not lit, f"other lamps lit: {lit}"
