"""``run_with_progress``: the same results as ``plc.run``; a bar only on a
terminal, for long runs, when not quiet; rich only imported for the bar."""

from __future__ import annotations

import io
import sys

import pytest

import plcrt
from plcrt.errors import PlcConfigError, PlcRuntimeError
from plcrt.trace import Trace, run_with_progress
from plcrt.term.progress import MIN_SCANS_FOR_BAR, scan_count
from stl_helpers import ob1_text

PROGRAM = ob1_text("LD SM0.0\nINCW VW0", "LD I0.0\nTON T37, +20", "LD T37\n= Q0.0",
                   "LD SM0.0\n+R 0.5, VD10")


class Terminal(io.StringIO):
    """A stream that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def state(plc: plcrt.Plc) -> tuple:
    return (plc.scans, plc.time, plc.mode, {k: bytes(v) for k, v in plc.mem.areas.items()})


def pair(scan_ms: float = 10.0) -> tuple[plcrt.Plc, plcrt.Plc]:
    a, b = (plcrt.load(PROGRAM, scan_ms=scan_ms) for _ in range(2))
    for p in (a, b):
        p["I0.0"] = 1
    return a, b


@pytest.mark.parametrize("kw", [dict(scans=3000), dict(seconds=25.0), dict(scans=0)])
def test_not_a_terminal_is_silent_and_identical(kw: dict) -> None:
    a, b = pair()
    stream = io.StringIO()
    run_with_progress(a, stream=stream, **kw)
    b.run(**kw)
    assert stream.getvalue() == ""
    assert state(a) == state(b)


def test_terminal_shows_a_bar_and_results_are_identical() -> None:
    a, b = pair()
    ta, tb = Trace(a, ["VW0", "T37", "VD10:REAL"]), Trace(b, ["VW0", "T37", "VD10:REAL"])
    stream = Terminal()
    run_with_progress(a, scans=5000, stream=stream)
    b.run(scans=5000)
    assert "running" in stream.getvalue()
    assert state(a) == state(b)
    for name in ta.names:   # every scan was observed, in chunks or not
        assert ta[name].tolist() == tb[name].tolist()
    assert ta.time.tolist() == tb.time.tolist()


@pytest.mark.parametrize("kw", [dict(scans=MIN_SCANS_FOR_BAR), dict(scans=5000, quiet=True)])
def test_short_or_quiet_runs_show_nothing(kw: dict) -> None:
    a, b = pair()
    stream = Terminal()
    run_with_progress(a, stream=stream, **kw)
    b.run(scans=kw["scans"])
    assert stream.getvalue() == ""
    assert state(a) == state(b)


def test_rich_not_imported_without_bar(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("rich", "rich.console", "rich.progress"):
        monkeypatch.setitem(sys.modules, name, None)   # importing would fail
    a, _ = pair()
    run_with_progress(a, scans=3000, stream=io.StringIO())
    assert a.scans == 3000


def test_seconds_round_up_like_run() -> None:
    a, b = pair(scan_ms=7)
    run_with_progress(a, seconds=20.0, stream=Terminal())
    b.run(seconds=20.0)
    assert a.scans == b.scans == scan_count(b, seconds=20.0) == 2858
    assert state(a) == state(b)


def test_stop_instruction_ends_the_bar_run() -> None:
    prog = ob1_text("LD SM0.0\nINCW VW0", "LDW>= VW0, 2500\nSTOP")
    a, b = plcrt.load(prog), plcrt.load(prog)
    run_with_progress(a, scans=10000, stream=Terminal())
    b.run(scans=10000)
    assert a.mode == "STOP" and state(a) == state(b)
    assert a.read("VW0") == 2500


def test_fault_propagates() -> None:
    plc = plcrt.load(ob1_text("LD SM0.0\nINCW VW0",
                              "LDW>= VW0, 3000\nMOVD +0, AC1\nMOVW *AC1, VW10"))
    with pytest.raises(PlcRuntimeError):
        run_with_progress(plc, scans=10000, stream=Terminal())
    assert plc.mode == "STOP" and plc.read("VW0") == 3000


@pytest.mark.parametrize("kw", [dict(), dict(seconds=1.0, scans=3), dict(seconds=-1.0),
                                dict(scans=-2)])
def test_bad_arguments(kw: dict) -> None:
    with pytest.raises(PlcConfigError):
        run_with_progress(plcrt.load(PROGRAM), **kw)
