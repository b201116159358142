"""The event samples of programs/events/ (interrupts, PTO, HSC), pinned."""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt

EVENTS = Path(__file__).resolve().parents[2] / "programs" / "events"


def test_timed_interrupt_samples_every_millisecond_and_ob1_averages():
    """1000 samples a second whatever the scan time, and the mean of a
    steady input is the input."""
    for scan_ms in (10, 3, 1, 7.5):
        plc = plcrt.load(EVENTS / "timed_interrupt.awl", scan_ms=scan_ms)
        plc["AIW0"] = 1234
        plc.run(1.0)
        assert plc["VD120"] == round(plc.time * 1000)
        assert plc["VW110"] == 1234 and plc["VW112"] >= 9


def test_timed_interrupt_mean_of_two_levels():
    plc = plcrt.load(EVENTS / "timed_interrupt.awl", scan_ms=10)
    plc["AIW0"] = 1000
    plc.run("50ms")          # samples at 1..50 ms read 1000
    plc["AIW0"] = 3000
    plc.run("50ms")          # 51..100 ms read 3000; the mean is taken at 100 ms
    plc.scan()
    assert plc["VW112"] == 1 and plc["VW110"] == 2000


def test_pto_counted_by_hsc0_exactly():
    """5000 pulses of 200 µs from t = 0 on Q0.0, wired to I0.0: HSC0 reaches
    PV 2500 at pulse 2500, t = 2499 x 200 µs = 499.8 ms (T32 reads 499);
    the train ends at 1.0 s with the PTO-complete interrupt."""
    plc = plcrt.load(EVENTS / "pto_count.awl", plant=EVENTS / "pto_count_plant.toml")
    plc["M0.0"] = 1
    plc.run("0.5s")
    assert (plc["VD200"], plc["VW204"]) == (2500, 499)
    assert plc["M1.0"] == 0
    plc.run("0.5s")
    assert (plc["M1.0"], plc["VW206"]) == (1, 1)
    plc.scan()
    assert plc["VD208"] == 5000 and plc["SM66.7"] == 1


@pytest.mark.parametrize("name", ["timed_interrupt.awl", "pto_count.awl"])
def test_the_event_samples_check_clean(name):
    from plcrt.cli import main
    assert main(["check", str(EVENTS / name)]) == 0


def test_run_reports_the_pulse_outputs_and_counters_in_use(capsys) -> None:
    """`plcrt run` lists the pulse outputs PLS used (pulses sent, idle or
    running) and the counters HDEF defined (mode, CV, PV), as text and JSON."""
    import json

    from plcrt.cli import main

    args = ["run", str(EVENTS / "pto_count.awl"), "--plant",
            str(EVENTS / "pto_count_plant.toml"), "--seconds", "1.2",
            "--set", "M0.0=1"]
    assert main(args) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[-4:] == ["output  mode  pulses  state", "Q0.0    -       5000  idle",
                        "counter  mode    CV    PV  state", "HSC0        0  5000  2500  counting"]
    assert main(args + ["--json"]) == 0
    obj = json.loads(capsys.readouterr().out)
    assert obj["pulse_outputs"] == [{"output": "Q0.0", "mode": "-", "pulses": 5000,
                                     "state": "idle"}]
    assert obj["counters"] == [{"counter": "HSC0", "mode": 0, "CV": 5000, "PV": 2500,
                                "state": "counting"}]
