"""Plots of a trace (:func:`plcrt.trace.plot`): PNG and SVG files, steps for
bits and integers, lines for REALs, reproducible output, and the message
when matplotlib is missing."""

from __future__ import annotations

import re
import struct
import sys
from pathlib import Path

import pytest

import plcrt
from plcrt.errors import PlcConfigError
from plcrt.trace import Trace, plot
from stl_helpers import ob1_text

pytest.importorskip("matplotlib")

SIGNALS = ["I0.0", "Q0.0", "T33", "VD200:REAL"]


@pytest.fixture()
def trace() -> Trace:
    plc = plcrt.load(ob1_text("LD I0.0\nTON T33, +5", "LD T33\n= Q0.0",
                              "LD SM0.0\n+R 0.5, VD200"), scan_ms=10)
    tr = Trace(plc, SIGNALS)
    plc["I0.0"] = 1
    plc.scan(10)
    plc["I0.0"] = 0
    plc.scan(5)
    return tr


def _points(svg: str, gid: str) -> list[tuple[float, float]]:
    """The vertices of the path drawn for the line with id ``gid``."""
    m = re.search(rf'<g id="{gid}">\s*<path d="([^"]*)"', svg)
    assert m, f"no path for {gid}"
    nums = [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?", m.group(1))]
    return list(zip(nums[0::2], nums[1::2]))


def test_png(trace: Trace, tmp_path: Path) -> None:
    path = tmp_path / "t.png"
    assert plot(trace, path, title="toggle") == path
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", data[16:24])   # the IHDR chunk
    assert width == 1000 and 300 < height < 1000
    assert 5_000 < len(data) < 500_000


def test_svg_names_and_steps(trace: Trace, tmp_path: Path) -> None:
    path = tmp_path / "t.svg"
    plot(trace, str(path))
    svg = path.read_text(encoding="utf-8")
    assert svg.lstrip().startswith("<?xml")
    for name in SIGNALS:
        assert f">{name}<" in svg            # the y labels are text
    assert "time (s)" in svg
    # Q0.0 (a bit) is drawn as steps: every segment is horizontal or
    # vertical, and its two changes are vertical jumps
    q = _points(svg, "signal-1")
    assert all(a[0] == b[0] or a[1] == b[1] for a, b in zip(q, q[1:]))
    jumps = [(a, b) for a, b in zip(q, q[1:]) if a[0] == b[0] and a[1] != b[1]]
    assert len(jumps) == 2
    # T33 (an integer) also steps
    t = _points(svg, "signal-2")
    assert all(a[0] == b[0] or a[1] == b[1] for a, b in zip(t, t[1:]))
    # the REAL ramp is a line: its segments are slanted
    r = _points(svg, "signal-3")
    assert any(a[0] != b[0] and a[1] != b[1] for a, b in zip(r, r[1:]))


def test_svg_is_reproducible(trace: Trace, tmp_path: Path) -> None:
    a, b = tmp_path / "a.svg", tmp_path / "b.svg"
    plot(trace, a)
    plot(trace, b)
    assert a.read_bytes() == b.read_bytes()
    assert "<dc:date>" not in a.read_text(encoding="utf-8")


def test_png_is_reproducible(trace: Trace, tmp_path: Path) -> None:
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    plot(trace, a)
    plot(trace, b)
    assert a.read_bytes() == b.read_bytes()


def test_signal_subset(trace: Trace, tmp_path: Path) -> None:
    path = tmp_path / "q.svg"
    plot(trace, path, signals=["Q0.0"], title="only Q0.0")
    svg = path.read_text(encoding="utf-8")
    assert ">Q0.0<" in svg and ">only Q0.0<" in svg
    assert ">T33<" not in svg
    assert 'id="signal-1"' not in svg


def test_errors(trace: Trace, tmp_path: Path) -> None:
    with pytest.raises(PlcConfigError, match=r"must end in \.png or \.svg"):
        plot(trace, tmp_path / "t.pdf")
    with pytest.raises(PlcConfigError, match="cannot plot 'VW0': it is not a signal"):
        plot(trace, tmp_path / "t.png", signals=["VW0"])
    empty = Trace(plcrt.load(ob1_text("LD I0.0\n= Q0.0")), ["Q0.0"])
    with pytest.raises(PlcConfigError, match="no samples"):
        plot(empty, tmp_path / "t.png")
    assert list(tmp_path.iterdir()) == []


def test_missing_matplotlib(trace: Trace, tmp_path: Path,
                            monkeypatch: pytest.MonkeyPatch) -> None:
    # None in sys.modules makes `import matplotlib` raise ImportError
    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(PlcConfigError) as info:
        plot(trace, tmp_path / "t.png")
    assert "install the 'plot' extra: " in info.value.message
    assert not (tmp_path / "t.png").exists()


def test_a_title_with_a_lone_surrogate_or_a_control_is_drawn_escaped(trace: Trace,
                                                                     tmp_path: Path) -> None:
    """A title holding what undecodable bytes become (a lone surrogate) or a
    control character is drawn with escapes, never a renderer's TypeError
    (found by the API fuzz)."""
    path = tmp_path / "t.svg"
    plot(trace, path, title="pump\ud800 \x1b[31m")
    text = path.read_text()
    assert "pump\\ud800 \\x1b[31m" in text
