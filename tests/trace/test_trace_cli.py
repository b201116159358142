"""``plcrt trace`` and ``plcrt run --quiet``, called in-process through
:func:`plcrt.cli.main` (pytest's capture is not a terminal, so no progress
bar is drawn)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from plcrt.cli import main

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"
TIMERS = str(PROGRAMS / "timers.awl")
EM253 = PROGRAMS / "em253"
FAULT = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD SM0.0\nINCW VW0\n"
         "Network 2\nLDW>= VW0, 3\nMOVD +0, AC1\nMOVW *AC1, VW10\nEND_ORGANIZATION_BLOCK\n")


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def test_trace_trend_csv_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("matplotlib")
    csv, svg = tmp_path / "t.csv", tmp_path / "t.svg"
    code, out, err = run_cli(capsys, "trace", TIMERS, "--signal", "I0.0", "--signal", "T37",
                             "--signal", "Q0.0", "--seconds", "3", "--set", "I0.0=1",
                             "--csv", csv, "--plot", svg)
    assert (code, err) == (0, "")
    assert out.splitlines() == [
        f"{TIMERS}: 300 scan(s), 3 s simulated, mode RUN",
        "300 samples, t = 0.01..3.0 s",
        "I0.0  1..1   " + "█" * 60 + "  last=1",
        "T37   0..29  ▁▁▁▁▁▁▂▂▂▂▂▂▂▂▃▃▃▃▃▃▃▃▄▄▄▄▄▄▄▄▅▅▅▅▅▅▅▅▆▆▆▆▆▆▆▆▇▇▇▇▇▇▇▇██████  last=29",
        "Q0.0  0..1   " + "▁" * 40 + "█" * 20 + "  last=1",
    ]
    rows = csv.read_text(encoding="utf-8").splitlines()
    assert rows[:3] == ["time_s,I0.0,T37,Q0.0", "0.01,1,0,0", "0.02,1,0,0"]
    assert rows[-1] == "3.0,1,29,1" and len(rows) == 301
    # Q0.0 comes on in the scan ending at 2.01 s (T37 reaches 20 then)
    assert "2.0,1,19,0" in rows and "2.01,1,20,1" in rows
    svg_text = svg.read_text(encoding="utf-8")
    assert ">T37<" in svg_text and TIMERS in svg_text   # the title names the program


def test_trace_every_and_quiet(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    csv = tmp_path / "t.csv"
    code, out, err = run_cli(capsys, "trace", TIMERS, "--signal", "T37", "--scans", "50",
                             "--every", "10", "--set", "I0.0=1", "--csv", csv, "--quiet")
    assert (code, out, err) == (0, "", "")
    assert csv.read_text(encoding="utf-8") == (
        "time_s,T37\n0.1,0\n0.2,1\n0.3,2\n0.4,3\n0.5,4\n")


def test_trace_axis_signals(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "trace", EM253 / "pos_goto_r.awl",
                             "--plant", EM253 / "plant.toml", "--scan-ms", "1",
                             "--seconds", "5", "--every", "1000", "--set", "M2.0=1",
                             "--signal", "axis0.0.speed", "--signal", "VW106")
    assert (code, err) == (0, "")
    lines = out.splitlines()
    assert lines[1] == "5 samples, t = 1.0..5.0 s"
    assert lines[2].startswith("axis0.0.speed  20625..80000  ")
    assert lines[2].endswith("  last=80000")


@pytest.mark.parametrize(("args", "message"), [
    (["--signal", "X9.9", "--scans", "1"], "trace signal 'X9.9': 'X9.9' is not an address"),
    (["--signal", "VW0:FLOAT", "--scans", "1"], "unknown suffix ':FLOAT'"),
    (["--signal", "axis0.0.speed", "--scans", "1"], "no plant is loaded"),
    (["--signal", "T37", "--scans", "1", "--every", "0"], "--every must be at least 1"),
    (["--signal", "T37", "--scans", "-1"], "--scans must not be negative"),
    (["--signal", "T37", "--scans", "1", "--plot", "t.pdf"], "must end in .png or .svg"),
    (["--signal", "T37", "--scans", "1", "--set", "Q0.0"], "--set needs ADDR=VALUE"),
    (["--scans", "1"], "the following arguments are required: --signal"),
    (["--signal", "T37"], "one of the arguments --seconds --scans is required"),
])
def test_trace_errors_exit_1(args: list[str], message: str, tmp_path: Path,
                             capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "trace", TIMERS, *args)
    assert code == 1
    assert out == ""
    assert message in err


def test_trace_missing_matplotlib_fails_before_running(
        tmp_path: Path, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    csv = tmp_path / "t.csv"
    code, out, err = run_cli(capsys, "trace", TIMERS, "--signal", "T37", "--scans", "5",
                             "--csv", csv, "--plot", tmp_path / "t.png")
    assert code == 1 and out == ""
    assert "-m pip install -e '" in err and "[plot]' (README.md, 'Quick start')" in err
    assert not csv.exists()


def test_trace_fault_exits_2_and_keeps_samples(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    prog = tmp_path / "f.awl"
    prog.write_text(FAULT, encoding="utf-8")
    csv = tmp_path / "t.csv"
    code, out, err = run_cli(capsys, "trace", prog, "--signal", "VW0", "--scans", "10",
                             "--csv", csv)
    assert code == 2
    assert f"{prog}:9:1: error: " in err and "[OB1 network 2]" in err
    assert "mode STOP" in out
    assert csv.read_text(encoding="utf-8") == "time_s,VW0\n0.01,1\n0.02,2\n"


def test_trace_unwritable_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                              monkeypatch: pytest.MonkeyPatch) -> None:
    # A folder that does not exist, or a folder as the file, is refused
    # before the run (which may be long), like a wrong --plot extension.
    for target, why in ((tmp_path / "missing" / "t.csv", "does not exist"),
                        (tmp_path, "this is a folder, not a file")):
        code, out, err = run_cli(capsys, "trace", TIMERS, "--signal", "T37", "--scans", "2",
                                 "--csv", target)
        assert (code, out) == (1, "")
        assert err.startswith(f"plcrt: error: --csv {target}: ") and why in err
    # A failure only writing can show comes after the run: the trend is still shown.
    from plcrt.trace.recorder import Trace

    def full(self: Trace, path: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Trace, "to_csv", full)
    target = tmp_path / "t.csv"
    code, out, err = run_cli(capsys, "trace", TIMERS, "--signal", "T37", "--scans", "2",
                             "--csv", target)
    assert code == 1
    assert f"cannot write '{target}': No space left on device" in err
    assert "2 samples" in out


def test_trace_plot_names_are_not_mathtext(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    # A '$' pair in a program name (the plot's title) or a signal made
    # matplotlib parse mathtext and fail after the run.
    pytest.importorskip("matplotlib")
    prog = tmp_path / "x$\\foo$.awl"
    prog.write_text(Path(TIMERS).read_text(encoding="utf-8"), encoding="utf-8")
    svg = tmp_path / "t.svg"
    code, out, err = run_cli(capsys, "trace", prog, "--signal", "Q0.0", "--scans", "3",
                             "--plot", svg, "--quiet")
    assert (code, out, err) == (0, "", "")
    assert "x$\\foo$.awl" in svg.read_text(encoding="utf-8")


def test_run_quiet(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "run", TIMERS, "--seconds", "2.5", "--set", "I0.0=1",
                             "--watch", "T37", "--quiet")
    assert (code, out, err) == (0, "", "")
    code, out, _ = run_cli(capsys, "run", TIMERS, "--seconds", "2.5", "--set", "I0.0=1",
                           "--watch", "T37", "--quiet", "--json")
    assert code == 0 and '"values": {"T37": 24}' in out
    prog = tmp_path / "f.awl"
    prog.write_text(FAULT, encoding="utf-8")
    code, out, err = run_cli(capsys, "run", prog, "--scans", "10", "--quiet")
    assert code == 2 and out == ""
    assert f"{prog}:9:1: error: " in err


def test_run_quiet_hides_warnings_only(capsys: pytest.CaptureFixture[str]) -> None:
    # pos_run's step 6 asks for 500 kHz: a run-time warning, not an error
    args = ["run", EM253 / "pos_run.awl", "--data", EM253 / "pos_run.db",
            "--plant", EM253 / "plant.toml", "--seconds", "70", "--set", "M3.0=1"]
    code, _, err = run_cli(capsys, *args)
    assert code == 0 and "warning: POS_RUN" in err
    code, out, err = run_cli(capsys, *args, "--quiet")
    assert (code, out, err) == (0, "", "")


def test_run_output_unchanged_without_quiet(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "run", TIMERS, "--seconds", "25", "--set", "I0.0=1",
                             "--watch", "Q0.0")
    assert (code, err) == (0, "")   # 2500 scans, but not a terminal: no bar
    assert out.splitlines() == [f"{TIMERS}: 2500 scan(s), 25 s simulated, mode RUN",
                                "address  value", "Q0.0     1"]


def test_trace_ctrl_c_keeps_the_samples(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    """Ctrl-C during a long run used to end plcrt with "interrupted" and no
    CSV: every sample was lost.  Now the samples so far are written, and a
    sample cut in half by the interruption is dropped."""
    import plcrt.term.progress as progress

    def interrupted(plc, **kw) -> None:
        plc.scan(5)
        trace = plc.observers[0].__self__
        trace._t_us.append(plc._t_us)       # Ctrl-C in the middle of recording
        raise KeyboardInterrupt

    monkeypatch.setattr(progress, "run_with_progress", interrupted)
    csv = tmp_path / "t.csv"
    code, out, err = run_cli(capsys, "trace", TIMERS, "--signal", "T37", "--signal", "Q0.0",
                             "--seconds", "1e6", "--csv", csv)
    assert code == 130
    assert err == ("plcrt: interrupted after 5 scan(s); writing the 5 sample(s) recorded "
                   "so far\n")
    assert csv.read_text(encoding="utf-8").splitlines() == [
        "time_s,T37,Q0.0", "0.01,0,0", "0.02,0,0", "0.03,0,0", "0.04,0,0", "0.05,0,0"]
    assert "5 samples, t = 0.01..0.05 s" in out
