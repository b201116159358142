"""Plc.recompiled(): the same program built with other probes or another
backend, taking over a running PLC's state without losing a scan.

The test runs a PLC for a while, makes the other build from it, then runs
the original and the new build side by side and compares the whole memory
image after every scan: whatever state the handover missed (timer and
counter banks, edge memory, library blocks, axes in mid-move, time, forces)
shows up as a difference.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt
from plcrt.compiler.native.jit import available as native_available
from plcrt.errors import PlcConfigError
from stl_helpers import ob1_text

ROOT = Path(__file__).resolve().parents[2]

STATEFUL = ob1_text(
    "LD SM0.0\nINCW VW0",                  # scan counter
    "LD I0.1\nTON T37, +5",                # 100 ms timer: state in the bank
    "LD I0.1\nTON T33, +70",               # 10 ms timer
    "LD I0.2\nEU\nINCW VW4",               # edge memory
    "LD I0.3\nLD I0.4\nCTU C1, +3",        # counter
    "LD T37\n= Q0.0",
    "LD C1\n= Q0.1",
)

BUILDS = [dict(instrument=True), dict(instrument=False)]
if native_available():
    BUILDS += [dict(backend="native"), dict(instrument=True, backend="python")]


def _image(plc: plcrt.Plc) -> dict[str, bytes]:
    return {k: bytes(v) for k, v in plc.mem.areas.items()}


def _lockstep(a: plcrt.Plc, b: plcrt.Plc, scans: int, inputs=None) -> None:
    for n in range(scans):
        for addr, value in (inputs(n) if inputs else {}).items():
            a[addr] = value
            b[addr] = value
        a.scan()
        b.scan()
        assert (a.scans, a.now_us) == (b.scans, b.now_us)
        assert _image(a) == _image(b), f"memory differs after scan {n + 1} of the lockstep"


def _toggling(n: int) -> dict[str, int]:
    return {"I0.1": int(n % 40 < 30), "I0.2": n % 3 == 0, "I0.3": n % 5 == 0,
            "I0.4": int(n == 25)}


@pytest.mark.parametrize("first", [dict(), dict(instrument=True)], ids=["plain", "probes"])
@pytest.mark.parametrize("other", BUILDS, ids=lambda d: "-".join(f"{k}={v}" for k, v in d.items()))
def test_other_build_continues_where_the_plc_stands(first, other) -> None:
    """Timers part-way, an edge remembered, a counter counting, a force in
    place: the other build goes on exactly as the original does."""
    a = plcrt.load(STATEFUL, scan_ms=7, **first)
    for n in range(23):
        for addr, value in _toggling(n).items():
            a[addr] = value
        a.scan()
    a.force("VW2", 77)
    b = a.recompiled(**other)
    assert b.forces == {"VW2": 77}
    assert (b.coverage is not None) == other.get("instrument", bool(first))
    _lockstep(a, b, 120, lambda n: _toggling(n + 23))


def test_axis_in_mid_move_is_handed_over() -> None:
    """An EM253 axis in the middle of a homing run: the new build's library
    blocks and module carry on with the same move, pulse for pulse."""
    prog = ROOT / "programs" / "em253" / "homing.awl"
    plant = ROOT / "programs" / "em253" / "homing_plant.toml"
    if not plant.is_file():
        plant = ROOT / "programs" / "em253" / "plant.toml"
    a = plcrt.load(prog, plant=plant, scan_ms=1)
    for bit in ("M4.0", "M4.2"):
        a[bit] = 1
    a.run(scans=700)
    b = a.recompiled(instrument=True)
    assert b.axes()[0].position == a.axes()[0].position
    _lockstep(a, b, 1500)
    assert [x.position for x in b.axes()] == [x.position for x in a.axes()]


def test_breakpoints_work_in_the_instrumented_build() -> None:
    """The instrumented build has probes: a breakpoint stops before its
    network; the original had none."""
    a = plcrt.load(STATEFUL)
    a.scan(5)
    assert a.coverage is None
    b = a.recompiled(instrument=True)
    seen = []
    b.coverage.on_break = lambda net: seen.append((net.block, net.number))
    b.coverage.breakpoints[b.coverage.find("OB1", 2).index] = 1
    b.scan(2)
    assert seen == [("OB1", 2), ("OB1", 2)]


def test_same_options_give_a_fork() -> None:
    a = plcrt.load(STATEFUL)
    a["I0.1"] = 1
    a.scan(9)
    b = a.recompiled(instrument=False)
    assert b is not a and _image(b) == _image(a)
    assert b._entry is a._entry      # nothing compiled again


def test_bad_backend_is_a_config_error() -> None:
    with pytest.raises(PlcConfigError):
        plcrt.load(STATEFUL).recompiled(backend="fortran")


def test_the_harness_recompiles_too() -> None:
    """The test harness (the ``plc`` fixture) has the same method: a new
    harness over the other build, in the same state, history included."""
    from plcrt.testing import Harness
    h = Harness(plcrt.load(STATEFUL), watch=["VW0"])
    h.run(scans=4)
    h2 = h.recompiled(instrument=True)
    assert h2.coverage is not None and h2["VW0"] == 4 and list(h2.history) == list(h.history)
    h2.run(scans=1)
    assert h2["VW0"] == 5 and h["VW0"] == 4
