"""Axis signals (``axis<slot>.<axis>.<quantity>``) with the EM253 example
``programs/em253/pos_goto_r.awl``: M2.0 starts a 1 000 000-pulse move with
4800 ms ramps from 5 kHz to 80 kHz (programs/em253/README.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import plcrt
from plcrt.errors import PlcAddressError
from plcrt.trace import Trace

EM253 = Path(__file__).resolve().parents[2] / "programs" / "em253"


def load() -> plcrt.Plc:
    plc = plcrt.load(EM253 / "pos_goto_r.awl", plant=EM253 / "plant.toml", scan_ms=1)
    plc["M2.0"] = 1
    return plc


def test_speed_ramp_and_position() -> None:
    plc = load()
    tr = Trace(plc, ["axis0.0.speed", "axis0.0.position", "axis0.0.mechanical", "VW106"])
    plc.run(seconds=18)
    assert len(tr) == 18000
    speed = tr["axis0.0.speed"]
    assert speed.dtype == np.float64 and tr["axis0.0.position"].dtype == np.int64
    # the ramp rises by 75 000 Hz in 4.8 s, i.e. exactly 1000 Hz every 64 ms
    ramp_times = np.arange(1, 76) * 0.064
    idx = np.round(ramp_times * 1000).astype(int) - 1
    assert np.allclose(tr.time[idx], ramp_times)
    assert speed[idx].tolist() == [5000.0 + 1000 * k for k in range(1, 76)]
    assert speed[0] == 5015.0                       # 5 kHz + 15 625 Hz/s * 1 ms
    up, cruise = speed[:4800], speed[4800:12200]
    assert np.all(np.diff(up) >= 0) and set(cruise.tolist()) == {80000.0}
    down = speed[12200:17000]
    assert np.all(np.diff(down) <= 0) and down[-2] == 5015.0
    assert set(speed[16999:].tolist()) == {0.0}     # done after exactly 17 s
    # positions: the README's 620 000 after 10 s, 1 000 000 at the end
    pos = tr["axis0.0.position"]
    assert pos[9999] == 620000 and pos[-1] == 1000000
    assert np.array_equal(pos, tr["axis0.0.mechanical"])   # the plant starts at 0
    assert np.all(np.diff(pos) >= 0)
    # C_Status becomes 8 when the block runs after the last pulse
    assert tr.changes("VW106").tolist() == [17.001]
    assert tr.last(1)[0][1:] == (0.0, 1000000, 1000000, 8)


def test_axis_signal_matches_plc_axis() -> None:
    plc = load()
    tr = Trace(plc, ["axis0.0.speed", "axis0.0.position", "axis0.1.position"])
    for _ in range(5):
        plc.scan(700)
        a = plc.axis(0, 0)
        assert tr.last(1)[0] == (plc.time, float(a["speed"]), a["position"],
                                 plc.axis(0, 1)["position"])


def test_axis_signal_every() -> None:
    plc = load()
    tr = Trace(plc, ["axis0.0.speed"], every=1000)
    plc.run(seconds=5)
    assert tr.time.tolist() == [1.0, 2.0, 3.0, 4.0, 5.0]
    assert tr["axis0.0.speed"].tolist() == [20625.0, 36250.0, 51875.0, 67500.0, 80000.0]


@pytest.mark.parametrize(("signal", "text"), [
    ("axis1.0.speed", "no module in slot 1"),
    ("axis0.2.position", "axis 2 of slot 0 is not configured"),
])
def test_missing_axis(signal: str, text: str) -> None:
    with pytest.raises(PlcAddressError, match=text):
        Trace(load(), [signal])
