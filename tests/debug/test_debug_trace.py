"""The debugger's trace commands (:mod:`plcrt.debug.trace_commands`):
``trace``, ``trend``, ``csv`` and ``plot`` over :class:`plcrt.trace.Trace`.

Sessions load their program from the repository root and then work in
``tmp_path``, so the files they write have short names in the golden
transcripts.  Besides the golden comparison each test asserts the lines
that carry its point (see ``debug_helpers.py`` for ``PLCRT_UPDATE_GOLDEN=1``).
"""

from __future__ import annotations

import csv
import io
import sys
from pathlib import Path

import pytest
from debug_helpers import DATA, ROOT, check_golden, commands, session

import plcrt
from plcrt.debug import Session
from plcrt.debug.session import COMMANDS

STEPS = str(DATA / "steps.awl")


@pytest.fixture(autouse=True)
def _in_root(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def _run_in(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, program: str,
            script: str) -> tuple[str, int, Session]:
    """Load ``program`` from the repository root, then run ``script`` with
    ``tmp_path`` as the current folder."""
    s, out = session(program)
    monkeypatch.chdir(tmp_path)
    status = s.run(script.strip("\n").splitlines())
    text = out.getvalue()
    assert "Traceback" not in text
    return text, status, s


def test_trace_trend_csv_plot_on_the_timers(tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("matplotlib")
    text, status, s = _run_in(tmp_path, monkeypatch, "programs/timers.awl", """
        trace
        trend
        trace T37 Q0.0
        set I0.0=1
        run 3s
        trace
        trend 40
        csv out.csv
        plot out.svg
        trace T37 Lamp       # a bad signal: the running trace goes on
        trace T37 VD4:FOO
        plot out.pdf
        csv nodir/out.csv
        plot nodir/out.svg
        csv .
        trace stop
        run 1s
        trace
        status
        trend 20
        trace clear
        scan 2
        trace T37:BIT I0.0   # replaces the trace
        plot empty.png
    """)
    check_golden("trace", text)
    assert status == 1
    cmds = commands(text)
    out = dict(cmds)   # the last answer of a command given twice
    assert cmds[0] == ("trace", "no trace (start one with 'trace SIG...')\n")
    assert out["trace T37 Q0.0"] == ("tracing T37, Q0.0: a sample at the end of every scan, "
                                     "from scan 1 on\n")
    assert out["trend"].startswith("error: no trace yet")
    # what a teacher shows after `run 3s`: T37 counts to 29, Q0.0 is on from 2.01 s
    trend = out["trend 40"].splitlines()
    assert trend[0] == "300 samples, t = 0.01..3.0 s"
    assert trend[1].startswith("T37   0..29  ▁") and trend[1].endswith("█  last=29")
    assert trend[2].startswith("Q0.0  0..1   ▁") and trend[2].endswith("█  last=1")
    assert len(trend[1].split()[2]) == 40
    assert out["csv out.csv"] == "wrote 300 samples of T37, Q0.0 to out.csv\n"
    assert out["plot out.svg"] == "plotted T37, Q0.0 (300 samples) to out.svg\n"

    with open(tmp_path / "out.csv", encoding="utf-8", newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["time_s", "T37", "Q0.0"]
    assert len(rows) == 301
    assert rows[1] == ["0.01", "0", "0"]
    assert rows[200] == ["2.0", "19", "0"]
    assert rows[201] == ["2.01", "20", "1"]     # the end of the scan the timer expired in
    assert rows[300] == ["3.0", "29", "1"]
    svg = (tmp_path / "out.svg").read_text(encoding="utf-8")
    assert svg.lstrip().startswith(("<?xml", "<svg"))
    for name in ("T37", "Q0.0", "signal-0", "signal-1"):
        assert name in svg

    assert out["trace T37 Lamp"] == "error: trace signal 'Lamp': 'Lamp' is not an address\n"
    assert out["trace T37 VD4:FOO"].startswith("error: trace signal 'VD4:FOO': ")
    assert out["plot out.pdf"] == ("error: cannot plot to 'out.pdf': the file name must end "
                                   "in .png or .svg\n")
    assert out["csv nodir/out.csv"] == ("error: cannot write the trace to 'nodir/out.csv': "
                                        "No such file or directory\n")
    assert out["plot nodir/out.svg"].startswith("error: cannot write the plot to "
                                                "'nodir/out.svg': ")
    assert out["csv ."].startswith("error: cannot write the trace to '.': ")
    assert not (tmp_path / "out.pdf").exists()
    # the bad signals left the trace as it was; stop keeps its samples
    assert out["trace stop"] == ("stopped the trace of T37, Q0.0 (300 samples kept for "
                                 "trend, csv and plot)\n")
    assert "samples  300, t = 0.01..3.0 s\n" in text     # after 'run 1s': nothing added
    assert "trace        T37, Q0.0 (300 samples, stopped)\n" in out["status"]
    assert out["trace clear"] == ("cleared 300 samples; tracing T37, Q0.0 again, "
                                  "from scan 401 on\n")
    assert out["trace T37:BIT I0.0"] == (
        "replaced the trace of T37, Q0.0 (2 samples dropped)\n"
        "tracing T37:BIT, I0.0: a sample at the end of every scan, from scan 403 on\n")
    assert out["plot empty.png"] == "error: nothing to plot: the trace has no samples yet\n"
    assert s._trace is not None and s._trace.names == ["T37:BIT", "I0.0"]
    assert s.plc.observers.count(s._trace._record) == 1   # one recorder attached, no more


def test_trace_commands_while_paused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    text, status, s = _run_in(tmp_path, monkeypatch, STEPS, """
        set I0.0=1
        break 2
        scan 3
        trace VW0 Q0.0     # paused in scan 1: records from its end on
        trend
        continue
        trace
        trend 10
        csv paused.csv
        trace stop         # paused in scan 2: its end is not recorded
        continue
        continue
        trace
    """)
    check_golden("trace_paused", text)
    assert status == 0
    out = commands(text)
    assert out[3] == ("trace VW0 Q0.0",
                      "tracing VW0, Q0.0: a sample at the end of every scan, from scan 1 on\n")
    assert out[4][1].startswith("0 samples\n")
    assert out[6] == ("trace", "signals  VW0, Q0.0\n"
                               "state    recording, a sample at the end of every scan\n"
                               "samples  1, t = 0.01..0.01 s\n")
    assert (tmp_path / "paused.csv").read_text(encoding="utf-8") == "time_s,VW0,Q0.0\n0.01,1,1\n"
    assert out[-1][1].endswith("samples  1, t = 0.01..0.01 s\n")
    assert s.plc.scans == 3


def test_plot_without_matplotlib_is_an_error_line(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    s, out = session(STEPS)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, "matplotlib", None)   # import matplotlib fails
    status = s.run(["trace Q0.0", "scan", "plot q.png", "csv q.csv"])
    text = out.getvalue()
    assert ("(plcrt) plot q.png\nerror: plotting needs matplotlib, which is not installed; "
            "install the 'plot' extra: ") in text
    assert "Traceback" not in text and "internal error" not in text
    assert text.endswith("wrote 1 sample of Q0.0 to q.csv\n")
    assert not (tmp_path / "q.png").exists()
    assert status == 1


def test_trace_stop_when_the_program_has_a_symbol_stop(tmp_path: Path) -> None:
    symbols = tmp_path / "s.sym"
    symbols.write_text("Stop\tI0.1\tstop button\n", encoding="utf-8")
    plc = plcrt.load(Path(STEPS), symbols=symbols, instrument=True)
    out = io.StringIO()
    status = Session(plc, out, echo=True).run(["trace Stop", "trace I0.1 Q0.0", "scan",
                                               "trace Stop", "trend 5"])
    text = out.getvalue()
    note = "note: 'trace Stop' means 'trace stop'; to record the symbol Stop, give its address: "
    assert f"(plcrt) trace Stop\n{note}trace I0.1\nerror: no trace to stop\n" in text
    assert f"(plcrt) trace Stop\n{note}trace I0.1\nstopped the trace of I0.1, Q0.0" in text
    assert status == 1


@pytest.mark.parametrize("command", ["trace", "trend", "csv", "plot"])
def test_trace_commands_are_in_the_table_and_read_only(command: str) -> None:
    cmd = COMMANDS[command]
    assert not cmd.runs_scans and not cmd.paused_only
    assert cmd.summary and cmd.usage.startswith(command)


def test_trend_and_file_arguments() -> None:
    s, out = session(STEPS)
    status = s.run(["trace Q0.0", "trend 0", "trend 501", "trend 5 6", "csv", "csv a b",
                    "plot", "scan", "trend 1"])
    text = out.getvalue()
    assert text.count("error: trend takes a width in columns (1..500)") == 3
    assert "(plcrt) csv\nerror: write 'csv FILE' (one file name, without spaces)\n" in text
    assert "(plcrt) csv a b\nerror: write 'csv FILE'" in text
    assert "(plcrt) plot\nerror: write 'plot FILE.png|FILE.svg'" in text
    assert text.endswith("(plcrt) trend 1\n1 sample, t = 0.01..0.01 s\nQ0.0  0..0  ▁  last=0\n")
    assert status == 1
