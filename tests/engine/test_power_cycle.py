"""Plc.power_cycle: what survives switching the CPU off and on.

S7-200 System Manual, chapter 4, "Saving and restoring data": at power-up
the retentive ranges keep their values (timers and counters only their
current values), V outside them is restored from the data block, the
rest of memory is cleared; SM0.1 and SM0.3 are on for the first scan, and
SM0.2 too when the retentive data was lost.  The start-up mode decides
RUN or STOP.  The ranges and the mode come from the plant file's [cpu]
table here (tests/project/test_project_sysblock.py: from a project's
system block).
"""

from __future__ import annotations

import re

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

import plcrt
from plcrt.engine.runtime import parse_sources
from plcrt.errors import PlcConfigError
from plcrt.loader import read_plant
from plcrt.memory import cpu_model
from plcrt.testing import Harness

PROGRAM = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     I0.0
TONR   T5, +10
Network 2
LD     I0.1
LD     I0.2
CTU    C3, +2
Network 3
LD     I0.3
=      Q0.0
S      S0.0, 1
END_ORGANIZATION_BLOCK
"""
DATA = "VW100\t7\nVW200\t9\n"


def _plc(table: dict | None = None, **kw) -> plcrt.Plc:
    """The program with the data block and a plant file's [cpu] ``table``."""
    plant = {"cpu": table} if table is not None else None
    return plcrt.load(PROGRAM, data=DATA, plant=plant, **kw)


def test_without_settings_the_default_system_block_is_kept() -> None:
    """Micro/WIN's default ranges: all of V, MB14..MB31, T0-T31, T64-T95,
    all counters; MB0..MB13, the other timers, S and Q are cleared."""
    plc = _plc()
    assert [str(r) for r in plc.retentive] == ["VB0:10240", "MB14:18", "T0:32", "T64:32",
                                               "C0:256"]
    plc["VW300"] = 3
    plc["MB13"], plc["MB14"], plc["MB31"] = 1, 2, 3
    plc["T37"], plc["T64"], plc["T96"] = 4, 5, 6
    plc["I0.3"] = 1
    plc.scan()
    assert plc["Q0.0"] == 1 and plc["S0.0"] == 1
    plc.power_cycle()
    assert (plc["VW300"], plc["MB13"], plc["MB14"], plc["MB31"]) == (3, 0, 2, 3)
    assert (plc["T37"], plc["T64"], plc["T96"]) == (0, 5, 0)
    assert plc["Q0.0"] == 0 and plc["S0.0"] == 0 and plc.scans == 0


def test_retentive_ranges_survive_and_v_comes_back_from_the_data_block() -> None:
    plc = _plc({"retentive": ["VB100:2", "MB4:1"]})
    plc["VW100"], plc["VW200"], plc["VW300"] = 1, 2, 3
    plc["MB4"], plc["MB5"] = 4, 5
    plc.scan(3)
    plc.power_cycle()
    # VW100 retentive; VW200 back to the data block's 9; VW300 cleared
    assert (plc["VW100"], plc["VW200"], plc["VW300"]) == (1, 9, 0)
    assert (plc["MB4"], plc["MB5"]) == (4, 0)


def test_first_scan_bits_after_power_up() -> None:
    plc = _plc()
    plc.scan(5)
    plc.power_cycle()
    plc.scan()
    assert (plc["SM0.1"], plc["SM0.2"], plc["SM0.3"]) == (1, 0, 1)
    plc.scan()
    assert (plc["SM0.1"], plc["SM0.2"], plc["SM0.3"]) == (0, 0, 0)


def test_retentive_data_lost_keeps_only_the_data_block_and_sets_sm0_2() -> None:
    plc = _plc({"retentive": ["VB100:4", "MB0:32"]})
    plc["VW100"], plc["VW102"], plc["MB0"] = 1, 2, 3
    plc.power_cycle(retentive_lost=True)
    assert (plc["VW100"], plc["VW102"], plc["MB0"]) == (7, 0, 0)
    plc.scan()
    assert (plc["SM0.1"], plc["SM0.2"], plc["SM0.3"]) == (1, 1, 1)
    plc.scan()
    assert plc["SM0.2"] == 0
    plc.power_cycle()           # the next power cycle with data kept: SM0.2 off
    plc.scan()
    assert plc["SM0.2"] == 0


def test_timers_and_counters_keep_their_current_values_not_their_bits() -> None:
    plc = _plc({"retentive": ["T5:1", "C3:1"]})
    plc["I0.0"] = 1
    plc.run(1.5)                      # TONR T5 (100 ms) reaches its preset 10
    for _ in range(3):                # three counts of C3 (preset 2)
        plc["I0.1"] = 1
        plc.scan()
        plc["I0.1"] = 0
        plc.scan()
    t5, c3 = plc["T5"], plc["C3"]
    assert t5 >= 10 and plc.mem.areas["TB"][0] >> 5 & 1 == 1
    assert c3 == 3 and plc.mem.areas["CB"][0] >> 3 & 1 == 1
    plc.power_cycle()
    assert (plc["T5"], plc["C3"]) == (t5, 3)
    bits = plc.mem.areas["TB"][0] >> 5 & 1, plc.mem.areas["CB"][0] >> 3 & 1
    assert bits == (0, 0)
    plc.scan()                        # the TONR runs on from its kept value
    assert plc["T5"] >= t5 and plc.mem.areas["TB"][0] >> 5 & 1 == 1


@pytest.mark.parametrize("startup, before, after", [
    ("RUN", "STOP", "RUN"), ("STOP", "RUN", "STOP"), ("LAST", "RUN", "RUN"),
    ("LAST", "STOP", "STOP")])
def test_the_startup_mode_decides_the_mode_after_power_up(startup: str, before: str,
                                                          after: str) -> None:
    plc = _plc({"startup": startup})
    assert plc.mode == "RUN"          # a load is a download followed by RUN
    plc.set_mode(before)
    plc.power_cycle()
    assert plc.mode == after
    plc["I0.3"] = 1
    plc.scan()
    assert plc["Q0.0"] == (after == "RUN")
    if after == "STOP":               # RUN later: a first scan, not one from power-up
        plc.set_mode("RUN")
        plc.scan()
        assert (plc["SM0.1"], plc["SM0.3"], plc["Q0.0"]) == (1, 0, 1)


def test_a_fault_is_cleared_by_a_power_cycle() -> None:
    plc = _plc({"startup": "LAST"})
    plc.set_mode("STOP")
    plc.fault = PlcConfigError("stands for a fatal error")
    with pytest.raises(PlcConfigError):
        plc.set_mode("RUN")
    plc.power_cycle()
    assert plc.fault is None
    plc.set_mode("RUN")


def test_inputs_time_clock_and_forces_go_on() -> None:
    plc = _plc(clock="2026-01-01T00:00:00")
    plc["I0.3"] = 1
    plc.force("I0.2", 1)
    plc.run(2.0)
    t, seconds = plc.time, plc.clock.seconds(plc.now_us)
    plc.power_cycle()
    assert plc.time == t and plc.clock.seconds(plc.now_us) == seconds == 820540802
    plc.scan()
    assert plc["Q0.0"] == 1 and plc["I0.2"] == 1 and plc.forces == {"I0.2": 1}


def test_a_fork_power_cycles_to_the_same_data_block() -> None:
    plc = _plc({"retentive": []})
    plc["VW200"] = 1
    twin = plc.fork()
    twin.power_cycle()
    assert twin["VW200"] == 9 and plc["VW200"] == 1


def test_the_harness_power_cycles_its_plc() -> None:
    h = Harness(_plc({"retentive": ["VB100:2"]}))
    h.set({"VW100": 5, "VW300": 6})
    assert h.power_cycle() is h
    assert h["VW100"] == 5 and h["VW300"] == 0


@pytest.mark.parametrize("cpu, message", [
    ({"retentive": "VB0:10"}, "cpu.retentive must be a list"),
    ({"retentive": ["XB0:10"]}, "cpu.retentive: 'XB0:10' is not a range"),
    ({"retentive": ["VB0"]}, "cpu.retentive: 'VB0' is not a range"),
    ({"retentive": ["VB0:1"] * 7}, "7 ranges, the system block holds at most 6"),
    ({"retentive": ["VB8000:500"]}, "cpu.retentive: the range VB8000:500 runs past the end "
                                    "of CPU224's V area"),
    ({"retentive": ["T250:10"]}, "T250:10 runs past"),
    ({"startup": "HALT"}, "cpu.startup must be \"RUN\", \"STOP\" or \"LAST\""),
])
def test_bad_settings_name_their_key(cpu: dict, message: str) -> None:
    with pytest.raises(PlcConfigError, match=re.escape(message)):
        _plc(cpu, cpu="CPU 224")


def test_power_cycle_refuses_a_bad_argument_and_a_linked_plc() -> None:
    plc = _plc()
    with pytest.raises(PlcConfigError, match="retentive_lost must be True or False"):
        plc.power_cycle(retentive_lost=1)
    plcrt.link(plc, 0, _plc(), 0)
    with pytest.raises(PlcConfigError, match="a linked PLC cannot be power-cycled"):
        plc.power_cycle()


_PROGRAM = parse_sources(PROGRAM)
_MODEL = cpu_model(None)
_SIZES = {"V": ("V", 1, _MODEL.v_bytes), "M": ("M", 1, _MODEL.m_bytes),
          "T": ("TV", 2, _MODEL.timers), "C": ("CV", 2, _MODEL.counters)}
_LETTERS = {"V": "VB", "M": "MB", "T": "T", "C": "C"}


@st.composite
def _ranges(draw) -> list[tuple[str, int, int]]:
    out = []
    for _ in range(draw(st.integers(0, 6))):
        area = draw(st.sampled_from("VMTC"))
        size = _SIZES[area][2]
        start = draw(st.integers(0, size))
        out.append((area, start, draw(st.integers(0, size - start))))
    return out


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(ranges=_ranges(), seed=st.integers(0, 255), lost=st.booleans())
def test_property_retentive_bytes_survive_everything_else_is_cleared(
        ranges: list[tuple[str, int, int]], seed: int, lost: bool) -> None:
    """Any range list: after a power cycle every byte of V, M and the
    timers' and counters' current values is its old value inside a range
    (unless the retentive data was lost) and zero outside; the timer and
    counter bits, Q, S and the accumulators are zero."""
    plant = read_plant({"cpu": {"retentive": [f"{_LETTERS[a]}{s}:{n}" for a, s, n in ranges]}})
    plc = plcrt.Plc(_PROGRAM, plant=plant)
    areas = plc.mem.areas
    for k, name in enumerate(("V", "M", "TV", "CV", "TB", "CB", "Q", "S", "AC")):
        areas[name][:] = bytes((seed + 7 * k + 13 * i) % 255 + 1 for i in range(len(areas[name])))
    before = {name: bytes(buf) for name, buf in areas.items()}
    plc.power_cycle(retentive_lost=lost)
    for area, (name, width, _) in _SIZES.items():
        kept = bytearray(len(areas[name]))
        for a, s, n in ranges:
            if a == area and not lost:
                kept[s * width:(s + n) * width] = b"\1" * (n * width)
        want = bytes(b if k else 0 for b, k in zip(before[name], kept))
        assert areas[name] == want, area
    for name in ("TB", "CB", "Q", "S", "AC"):
        assert not any(areas[name]), name


def test_a_plc_with_machines_and_modules_power_cycles() -> None:
    """The plant's devices start again with the CPU; the program runs on."""
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    plc = plcrt.load(root / "examples/machines/conveyor.awl",
                     plant=root / "examples/machines/conveyor.toml")
    plc.run(1.0)
    devices = [type(d) for d in plc.devices]
    plc.power_cycle()
    assert [type(d) for d in plc.devices] == devices and not any(plc.mem.areas["Q"])
    plc.run(1.0)
    assert plc.fault is None and plc.mode == "RUN" and plc.time == 2.0
