"""Shared fixtures of the conveyor's test suite.

Every test module names the program with a module-level marker::

    pytestmark = pytest.mark.plc(*CONVEYOR, **OPTIONS)

Each test then gets a fresh PLC at power-up from plcrt's ``plc`` fixture;
the fixtures below bring that PLC into the states the requirements talk
about.  Times are simulated seconds at the default 10 ms scan.
"""

from __future__ import annotations

import pytest


@pytest.fixture
def ready(plc):
    """The conveyor at rest after power-up: stop button not pressed and the
    emergency-stop chain healthy (both NC inputs read 1), belt stopped."""
    plc.set({"Stop_PB": 1, "EStop_OK": 1})
    plc.scan()
    assert plc["Motor"] == 0
    return plc


@pytest.fixture
def running(ready):
    """The belt running: start pressed for one scan, after the rest state."""
    ready.pulse("Start_PB")
    assert ready["Motor"] == 1
    return ready


@pytest.fixture
def feed(running):
    """``feed(n)``: ``n`` parts pass the part eye, each blocking it for
    0.2 s with 0.3 s between parts (0.5 s per part)."""

    def feed_parts(n: int) -> None:
        for _ in range(n):
            running.stimulus([(0, "Part_Eye", 1), (0.2, "Part_Eye", 0)], until=0.5)

    return feed_parts
