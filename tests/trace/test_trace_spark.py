"""Terminal quick looks: :func:`sparkline` and :func:`trend`, exact text."""

from __future__ import annotations

import math

import numpy as np
import pytest

import plcrt
from plcrt.trace import Trace, sparkline, trend
from stl_helpers import ob1_text


def test_sparkline_levels_one_per_value() -> None:
    assert sparkline(range(8), width=8) == "▁▂▃▄▅▆▇█"
    assert sparkline([7, 6, 5, 4, 3, 2, 1, 0], width=8) == "█▇▆▅▄▃▂▁"
    assert sparkline([-1.0, 0.0, 1.0], width=3) == "▁▅█"   # 3.5 rounds half up


def test_sparkline_stretches_short_input() -> None:
    assert sparkline([0, 7], width=6) == "▁▁▁███"
    assert sparkline([0, 7, 0], width=7) == "▁▁▁██▁▁"   # column j shows value j*n//width
    assert sparkline([5], width=4) == "▁▁▁▁"            # a constant number


def test_sparkline_downsamples_by_mean() -> None:
    # 16 values into 8 columns: pairs (0, 2), (4, 6), ... averaged to 1, 5,
    # 9, 13, scaled on the range of the values (0..14), not of the means
    values = [0, 2, 4, 6, 8, 10, 12, 14, 14, 12, 10, 8, 6, 4, 2, 0]
    assert sparkline(values, width=8) == "▂▄▆██▆▄▂"


def test_sparkline_bits() -> None:
    assert sparkline([0, 0, 1, 1, 0, 1], width=6) == "▁▁██▁█"
    assert sparkline([1, 1, 1], width=3) == "███"    # a bit stuck at 1 is high
    assert sparkline([0, 0], width=2) == "▁▁"
    # a one-sample pulse among 100 samples still shows in 10 columns
    pulse = [0] * 100
    pulse[42] = 1
    assert sparkline(pulse, width=10) == "▁▁▁▁█▁▁▁▁▁"
    # ... but as a number (bits=False) it is averaged away
    assert sparkline(pulse, width=10, bits=False) == "▁▁▁▁▂▁▁▁▁▁"


def test_sparkline_width_and_special_values() -> None:
    assert sparkline([], width=10) == ""
    assert len(sparkline(np.arange(1000), width=60)) == 60
    assert sparkline([0.0, math.nan, 1.0, 0.5], width=4) == "▁ █▅"
    with pytest.raises(ValueError):
        sparkline([1, 2], width=0)


def test_trend_exact() -> None:
    plc = plcrt.load(ob1_text("LD I0.0\nTON T33, +5", "LD T33\n= Q0.0",
                              "LD SM0.0\n+R 0.25, VD200"), scan_ms=10)
    tr = Trace(plc, ["I0.0", "T33", "Q0.0", "VD200:REAL"])
    plc["I0.0"] = 1
    plc.scan(8)
    assert trend(tr, width=8) == "\n".join([
        "8 samples, t = 0.01..0.08 s",
        "I0.0        1..1     ████████  last=1",
        "T33         0..7     ▁▂▃▄▅▆▇█  last=7",
        "Q0.0        0..1     ▁▁▁▁▁███  last=1",
        "VD200:REAL  0.25..2  ▁▂▃▄▅▆▇█  last=2",
    ])


def test_trend_empty_and_negative() -> None:
    plc = plcrt.load(ob1_text("LD SM0.0\n-I 1000, VW0"))
    tr = Trace(plc, ["VW0"])
    assert trend(tr) == "0 samples"
    plc.scan(1)
    assert trend(tr, width=4) == "1 sample, t = 0.01..0.01 s\nVW0  -1000..-1000  ▁▁▁▁  last=-1000"


def test_trend_range_of_infinite_and_nan_reals() -> None:
    # A REAL that is +inf all along used to show the range "nan".
    plc = plcrt.load(ob1_text("LD SM0.0\nMOVR VD0, VD4"))
    tr = Trace(plc, ["VD4:REAL", "VD8:REAL"])
    plc.write("VD0", float("inf"))
    plc.write("VD8", float("nan"))
    plc.scan(2)
    lines = trend(tr, width=4).splitlines()
    assert lines[1] == "VD4:REAL  inf..inf        last=inf"
    assert lines[2] == "VD8:REAL  nan             last=nan"
