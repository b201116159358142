"""The traffic crossing: every conflict of greens is reported at its
start; cars queue and pass on green; the example program is safe and
serves the pedestrians (docs/machines.md)."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings, strategies as st

from machine_helpers import example, manual

#: the default lamps' bits in QB0
MAIN_GREEN, MAIN_YELLOW, SIDE_YELLOW, SIDE_GREEN, WALK = 0x04, 0x02, 0x10, 0x20, 0x40


def conflicting(q: int) -> bool:
    main = bool(q & (MAIN_GREEN | MAIN_YELLOW))
    side = bool(q & (SIDE_GREEN | SIDE_YELLOW))
    walk = bool(q & WALK)
    return (main and side) or (walk and (main or side))


def test_a_conflict_is_noted_with_its_start_and_its_duration_kept() -> None:
    plc, m = manual("traffic")
    plc.run(seconds=1)
    plc["VB0"] = MAIN_GREEN | SIDE_GREEN
    plc.run(seconds=0.5)
    plc["VB0"] = MAIN_GREEN
    plc.run(seconds=1)
    s = m.state()
    assert s["conflicts"] == 1 and s["conflict_time"] == 0.5 and not s["conflict"]
    assert m.notes() == [(1.0, "conflict: main_go+side_go")]


def test_a_dark_lamp_conflicts_with_nothing() -> None:
    plc, m = manual("traffic", faults=["broken:side_green"])
    plc["VB0"] = MAIN_GREEN | SIDE_GREEN
    plc.run(seconds=1)
    assert m.state()["conflicts"] == 0 and m.state()["lamps"]["side_green"] is False


def test_cars_queue_and_pass_on_green() -> None:
    plc, m = manual("traffic", main_first=1.0, main_every=4.0, headway=2.0)
    plc.run(seconds=10)                          # red: cars at 1, 5, 9 s wait
    assert m.state()["queue"]["main"] == 3 and plc["I0.2"] == 1
    plc["VB0"] = MAIN_GREEN
    plc.run(seconds=4.005)                       # green from 10 s: one leaves at 12, one at 14
    assert m.state()["passed"]["main"] == 2
    assert [e for e in m.edges("car_main")] == [(1.0, "car_main", 1)]


def walk_seconds(plc, seconds: float) -> float:
    """Seconds the walk lamp is lit over the next *seconds*."""
    lit = 0
    for _ in range(round(seconds / 0.01)):
        plc.scan()
        lit += plc["Q0.6"]
    return lit * 0.01


def test_the_example_program_never_conflicts_and_serves_pedestrians() -> None:
    plc, m = example("traffic")
    assert walk_seconds(plc, 30) == 0            # nobody asked
    m.press("button_b")
    assert walk_seconds(plc, 30) == 5.0          # 24..29 s of the next cycle
    plc.run(seconds=30)
    s = m.state()
    assert s["conflicts"] == 0 and not m.notes()
    assert s["passed"]["main"] > 5 and s["passed"]["side"] > 2


def q_key(q: int) -> tuple[str, ...]:
    """Which pairs conflict: a change of them is a new episode."""
    main = bool(q & (MAIN_GREEN | MAIN_YELLOW))
    side = bool(q & (SIDE_GREEN | SIDE_YELLOW))
    walk = bool(q & WALK)
    return tuple(k for k, on in (("ms", main and side), ("mw", main and walk),
                                 ("sw", side and walk)) if on)


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(st.tuples(st.integers(1, 20), st.integers(0, 255)), min_size=1, max_size=15))
def test_no_conflict_goes_unreported(segments):
    plc, m = manual("traffic", scan_ms=50)
    starts, prev = [], ()
    for scans, q in segments:
        t = plc.time          # the next scan writes the lamps at this instant
        plc["VB0"] = q
        plc.scan(scans)
        key = q_key(q)
        assert conflicting(q) == bool(key) == m.state()["conflict"]
        if key and key != prev:
            starts.append(t)
        prev = key
    assert m.state()["conflicts"] == len(starts)
    assert [t for t, _ in m.notes()] == starts
