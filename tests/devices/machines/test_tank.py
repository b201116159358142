"""The tank: switch edges at exact times, the analog level and flow, mass
balance, overflow, the leak and the stuck inlet (docs/machines.md)."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from machine_helpers import example, manual, outputs


def nl(x: float) -> int:
    """A state's millilitres as the whole nanolitres they are."""
    return round(x * 1e6)


@pytest.mark.parametrize("inflow", [2000, 1999, 7])
def test_switch_edges_at_the_exact_microsecond(inflow: int) -> None:
    plc, m = manual("tank", inflow=inflow, capacity=1000, low=100, high=900)
    outputs(plc, m, inlet=1)
    plc.run(seconds=1000 / inflow + 0.1)
    low = -(-100 * 10**6 // inflow)              # ceil(100 mL / inflow), µs
    high = -(-900 * 10**6 // inflow)
    assert m.edges("low") == [(low / 1e6, "low", 1)]
    assert m.edges("high") == [(high / 1e6, "high", 1)]


def test_the_analog_level_and_flow_are_0_to_32000() -> None:
    plc, m = manual("tank", capacity=1000, low=100, high=900, inflow=100)
    outputs(plc, m, inlet=1)
    plc.run(seconds=2.5)           # 250 mL of 1000
    assert plc["AIW0"] == 8000 and plc["AIW2"] == 32000
    outputs(plc, m, inlet=0)
    plc.run(seconds=0.1)
    # the next scan (at 2.5 s) wrote the output: the inlet shut at 2.5 s
    assert plc["AIW0"] == 8000 and plc["AIW2"] == 0


def test_overflow_spills_and_an_empty_tank_runs_the_pump_dry() -> None:
    plc, m = manual("tank", capacity=1000, low=100, high=900, inflow=500, start=900)
    outputs(plc, m, inlet=1)
    plc.run(seconds=1)
    s = m.state()
    assert s["volume"] == 1000 and s["spilled"] == 400      # 900 + 500 in 1 s
    assert [n for _, n in m.notes()] == ["the tank overflows"]
    outputs(plc, m, pump=1)
    plc.run(seconds=2)
    s = m.state()
    assert s["volume"] == 0 and s["dry_run"] and m.notes()[-1][1] == "the pump runs dry"


def test_leak_and_stuck_inlet() -> None:
    plc, m = manual("tank", faults=["leak"], start=50_000, leak=250)
    plc.run(seconds=4)
    assert m.state()["volume"] == 49_000 and m.state()["leaked"] == 1000
    m.fault("leak", on=False)
    m.fault("inlet_stuck_open")
    plc.run(seconds=1)
    assert m.state()["volume"] == 51_000
    assert plc["AIW2"] == 32000            # the flow meter shows it, the output is off
    assert m.state()["outputs"]["inlet"] == 0


def test_the_example_program_cycles_between_the_switches() -> None:
    plc, m = example("tank")
    m.press("start")
    plc.run(seconds=300)
    on = [t for t, s, v in m.edges() if s == "high" and v]
    assert len(on) >= 3
    s = m.state()
    assert s["spilled"] == 0 and s["volume"] <= 90_000 and not m.notes()


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(st.tuples(st.integers(1, 60), st.integers(0, 7)), min_size=1, max_size=10),
       st.integers(0, 1000), st.booleans())
def test_level_stays_in_range_and_mass_balance_is_exact(segments, start, leak):
    plc, m = manual("tank", scan_ms=100, capacity=1000, low=100, high=900, inflow=97,
                    outflow=41, pump=133, start=start, faults=["leak"] if leak else [])
    for scans, bits in segments:
        plc["VB0"] = bits
        for _ in range(scans):
            plc.scan()
            s = m.state()
            assert 0 <= s["volume"] <= 1000
            assert nl(s["volume"]) == nl(start) + nl(s["total_in"]) - nl(s["total_out"]) \
                - nl(s["spilled"])
            assert plc["AIW0"] == nl(s["volume"]) * 32000 // nl(1000)
            # the switches as the terminals show them (the program reads them next scan)
            assert s["inputs"]["low"] == (s["volume"] >= 100)
            assert s["inputs"]["high"] == (s["volume"] >= 900)
