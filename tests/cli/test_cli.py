"""Tests of the ``plcrt`` command line (:mod:`plcrt.cli`).

``main([...])`` is called in-process with pytest's ``capsys``; one test runs
``python -m plcrt --help`` in a subprocess to cover the module entry point.
Every error path must end in a message and exit status 1 (2 for a PLC
run-time fault), never in a traceback.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from plcrt import PlcConfigError
from plcrt.compiler.cache import programs
from plcrt.cli import main, parse_value

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"
SEAL_IN = str(PROGRAMS / "seal_in.awl")
TIMERS = str(PROGRAMS / "timers.awl")


@pytest.fixture(autouse=True)
def _empty_disk_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each test runs as on a machine where no run has left machine code
    (a program marked on disk is native from its first scan)."""
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path / "plcrt-cache"))


def write(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def ob1(*networks: str) -> str:
    """A program text with one OB1 whose networks are the given bodies."""
    body = "".join(f"Network {i}\n{n.strip()}\n" for i, n in enumerate(networks, 1))
    return f"ORGANIZATION_BLOCK MAIN:OB1\nTITLE=test\nBEGIN\n{body}END_ORGANIZATION_BLOCK\n"


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


# ---------------------------------------------------------------------------
# check
# ---------------------------------------------------------------------------

def test_check_clean_program(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "check", SEAL_IN)
    assert code == 0
    assert out == ""
    assert err.strip() == (f"{SEAL_IN}: 0 errors, 0 warnings "
                           f"(1 block(s), 2 network(s), 6 instruction(s))")


def test_check_lists_unknown_and_unimplemented_with_locations(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "p.awl", ob1(
        "LD     I0.0\nLDX    I0.1\n=      Q0.0",
        "LD     SM0.1\nFOO    VB0\nXMT    VB100, 2",
    ))
    code, _, err = run_cli(capsys, "check", prog)
    assert code == 1
    lines = err.splitlines()
    assert f"{prog}:6:1: error: unknown instruction 'LDX' [OB1 network 1]" in lines
    assert f"{prog}:10:1: error: unknown instruction 'FOO' [OB1 network 2]" in lines
    assert f"{prog}:11:1: error: XMT: PORT 2: the CPU226 has ports 0 and 1 [OB1 network 2]" in lines
    assert lines[-1] == f"{prog}: 3 errors, 0 warnings"


def test_check_reports_warnings_but_succeeds(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    # A 100 ms timer box executed from two places gains time: a warning.
    prog = write(tmp_path, "w.awl", ob1(
        "LD     I0.0\nTON    T37, +10",
        "LD     I0.1\nTON    T37, +10",
    ))
    code, _, err = run_cli(capsys, "check", prog)
    assert code == 0
    assert f"{prog}:9:1: warning:" in err
    assert "0 errors, 1 warning " in err


def test_check_syntax_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "s.awl", "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\n"
                                    "LD     I0.0\n")
    code, out, err = run_cli(capsys, "check", prog)
    assert code == 1
    assert out == ""
    assert err.startswith(f"{prog}:")
    assert ": error: " in err
    assert err.splitlines()[-1] == f"{prog}: 1 error, 0 warnings"


def test_check_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = str(tmp_path / "nope.awl")
    code, _, err = run_cli(capsys, "check", missing)
    assert code == 1
    assert f"{missing}:1:1: error: cannot read file: no such file" in err


def test_check_binary_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bin.awl"
    path.write_bytes(bytes(range(256)) * 4)
    code, _, err = run_cli(capsys, "check", str(path))
    assert code == 1
    assert ": error: " in err


def test_check_directory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "check", str(tmp_path))
    assert code == 1
    assert "directory" in err


def test_check_with_symbols_and_several_files(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    main_awl = write(tmp_path, "main.awl", ob1("LD     Start\nCALL   SBR_0"))
    sbr_awl = write(tmp_path, "sbr.awl",
                    "SUBROUTINE_BLOCK SBR_0:SBR0\nTITLE=sub\nBEGIN\nNetwork 1\n"
                    "LD     Start\n=      Motor\nEND_SUBROUTINE_BLOCK\n")
    sdf = write(tmp_path, "sym.sdf", '"Symbol","Address","Comment"\n'
                                     '"Start","I0.0","start button"\n"Motor","Q0.0",""\n')
    code, _, err = run_cli(capsys, "check", main_awl, sbr_awl, "--symbols", sdf)
    assert code == 0, err
    assert "2 block(s)" in err
    code, _, err = run_cli(capsys, "check", main_awl, sbr_awl)  # without the table
    assert code == 1
    assert "unknown symbol 'Start'" in err


def test_check_bad_cpu(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "check", SEAL_IN, "--cpu", "CPU999")
    assert code == 1
    assert "unknown CPU model" in err


# ---------------------------------------------------------------------------
# run
# ---------------------------------------------------------------------------

def test_run_plain_output(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "run", SEAL_IN, "--scans", "3", "--set", "I0.0=1",
                             "--watch", "I0.0", "--watch", "Q0.0")
    assert code == 0
    assert err == ""
    assert out.splitlines() == [
        f"{SEAL_IN}: 3 scan(s), 0.03 s simulated, mode RUN",
        "address  value",
        "I0.0     1",  # a --set input keeps its value over the scans
        "Q0.0     1",
    ]


def test_run_json(capsys: pytest.CaptureFixture[str]) -> None:
    programs.clear()      # a first load, as a new process makes it
    code, out, _ = run_cli(capsys, "run", TIMERS, "--seconds", "2.5", "--set", "I0.0=1",
                           "--watch", "T37", "--watch", "Q0.0", "--json")
    assert code == 0
    obj = json.loads(out)
    # the default backend, auto: these 250 short scans run on the Python
    # build while the native one would still be waiting to be compiled
    assert obj == {"program": TIMERS, "scans": 250, "time_s": 2.5, "mode": "RUN",
                   "values": {"T37": 24, "Q0.0": 1}, "clock": "2024-01-01T00:00:02",
                   "dled": False, "backend": "python", "python_scans": 250}


@pytest.mark.parametrize("backend", ["python", "native", "auto"])
def test_run_says_which_backend_ran(backend: str, capsys: pytest.CaptureFixture[str]) -> None:
    """--json carries the backend that ran, --verbose says it on stderr
    (auto runs Python first: three scans never reach the native build)."""
    programs.clear()
    ran = "native" if backend == "native" else "python"
    code, out, _ = run_cli(capsys, "run", TIMERS, "--scans", "3", "--json", "--backend", backend)
    assert code == 0 and json.loads(out)["backend"] == ran
    assert json.loads(out).get("python_scans") == (3 if backend == "auto" else None)
    programs.clear()
    code, out, err = run_cli(capsys, "run", TIMERS, "--scans", "3", "--verbose",
                             "--backend", backend)
    assert code == 0
    line = next(x for x in err.splitlines() if x.startswith("backend: "))
    if backend == "auto":
        assert line == "backend: python (native not ready yet)"
    elif ran == "python":
        assert line == "backend: python"
    else:
        assert re.fullmatch(r"backend: native \(\d+ pieces as machine code, \d+ in Python\)",
                            line), line
        assert line != "backend: native (0 pieces as machine code, 0 in Python)"


def test_run_verbose_says_when_the_native_build_took_over(
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """A run long enough for the native build says after how many scans
    it took over (the background job starts at once here)."""
    from plcrt.engine import tiering
    programs.clear()
    monkeypatch.setattr(tiering, "START_AFTER_S", 0.0)
    monkeypatch.setattr(tiering, "LOAD_FACTOR", 0.0)
    monkeypatch.setattr(tiering, "LLVM_START_S", 0.0)
    monkeypatch.setattr(tiering, "CHUNK_SCANS", 1)
    import threading
    real = tiering._start

    def started(key, make):   # wait for the job, so that the switch comes in this run
        fut = real(key, make)
        fut.exception()
        return fut
    monkeypatch.setattr(tiering, "_start", started)
    code, out, err = run_cli(capsys, "run", TIMERS, "--scans", "50", "--verbose")
    assert code == 0
    line = next(x for x in err.splitlines() if x.startswith("backend: "))
    assert re.fullmatch(r"backend: native \(\d+ pieces as machine code, \d+ in Python, "
                        r"after 1 scans in Python\)", line), line
    assert not threading.current_thread().daemon


def test_run_json_value_kinds(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "k.awl", ob1(
        "LD     SM0.0\nMOVW   -2, VW0\nMOVB   200, VB10\nMOVR   1.5, VD20\nMOVD   -70000, VD30"))
    code, out, _ = run_cli(capsys, "run", prog, "--scans", "1", "--json",
                           "--watch", "VW0", "--watch", "VB10", "--watch", "VD20:REAL",
                           "--watch", "VD30", "--watch", "V0.0", "--watch", "SM0.0")
    assert code == 0
    values = json.loads(out)["values"]
    assert values == {"VW0": -2, "VB10": 200, "VD20:REAL": 1.5, "VD30": -70000,
                      "V0.0": 1, "SM0.0": 1}
    assert isinstance(values["VD20:REAL"], float)


def _strict_json(text: str) -> object:
    """json.loads that refuses the NaN/Infinity tokens Python's json writes by default."""
    def refuse(token: str) -> object:
        raise AssertionError(f"non-standard JSON token {token}")
    return json.loads(text, parse_constant=refuse)


def test_run_json_is_strict_and_spells_non_finite_reals(
        capsys: pytest.CaptureFixture[str]) -> None:
    """NaN and the infinities are the strings "NaN", "Infinity", "-Infinity"
    (JSON has no token for them), and --set takes the same spellings back."""
    watches = ["--watch", "VD0:REAL", "--watch", "VD4:REAL", "--watch", "VD8:REAL",
               "--watch", "VD12:REAL"]
    sets = ["--set", "VD0=NaN", "--set", "VD4=Infinity", "--set", "VD8=-Infinity",
            "--set", "VD12=1.5"]
    code, out, err = run_cli(capsys, "run", SEAL_IN, "--scans", "1", "--json", *sets, *watches)
    assert code == 0, err
    assert _strict_json(out)["values"] == {  # type: ignore[index]
        "VD0:REAL": "NaN", "VD4:REAL": "Infinity", "VD8:REAL": "-Infinity", "VD12:REAL": 1.5}
    code, out, err = run_cli(capsys, "run", SEAL_IN, "--scans", "1", *sets, *watches)
    assert code == 0, err
    assert out.splitlines()[2:] == ["VD0:REAL   NaN", "VD4:REAL   Infinity",
                                    "VD8:REAL   -Infinity", "VD12:REAL  1.5"]


@pytest.mark.parametrize(("setting", "watch", "expected"), [
    ("VW0=16#FF", "VW0", 255),
    ("VW0=2#1010_0101", "VW0", 0xA5),
    ("VW0=-12", "VW0", -12),
    ("VB0=255", "VB0", 255),
    ("VD0=2.5", "VD0:REAL", 2.5),
    ("VD0=-1e3", "VD0:REAL", -1000.0),
    ("M0.3=1", "M0.3", 1),
    ("VW0=65535", "VW0", -1),           # a WORD and an INT are the same word
    ("VW0=2.0", "VW0", 2),              # a whole real is its integer, as in plc.write
    ("VD0=3.4e38", "VD0:REAL", pytest.approx(3.4e38, rel=1e-7)),
    ("VD0=Infinity", "VD0:REAL", "Infinity"),
])
def test_run_set_values(setting: str, watch: str, expected: float,
                        capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "run", SEAL_IN, "--scans", "1", "--json",
                             "--set", setting, "--watch", watch)
    assert code == 0, err
    assert json.loads(out)["values"][watch] == expected


def test_run_with_data_block(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "d.awl", ob1("LD     SM0.0\nMOVW   VW0, VW2\n+I     +1, VW2"))
    data = write(tmp_path, "d.txt", "VW0     41\n")
    code, out, err = run_cli(capsys, "run", prog, "--data", data, "--scans", "1",
                             "--json", "--watch", "VW2")
    assert code == 0, err
    assert json.loads(out)["values"] == {"VW2": 42}


def test_run_scan_ms(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(capsys, "run", TIMERS, "--seconds", "3", "--scan-ms", "100",
                           "--set", "I0.0=1", "--watch", "Q0.0", "--json")
    assert code == 0
    obj = json.loads(out)
    assert obj["scans"] == 30 and obj["time_s"] == pytest.approx(3.0)
    assert obj["values"]["Q0.0"] == 1


def test_run_stop_instruction(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "stop.awl", ob1("LD     SM0.0\nINCW   VW0", "LD     I0.0\nSTOP"))
    code, out, _ = run_cli(capsys, "run", prog, "--scans", "10", "--set", "I0.0=1",
                           "--watch", "VW0", "--json")
    assert code == 0  # STOP is the program's choice, not a fault
    obj = json.loads(out)
    assert obj["mode"] == "STOP"
    assert obj["values"]["VW0"] == 1


FAULT = ob1("LD     SM0.0\n=      Q0.0", "LD     I0.0\nMOVD   +0, AC1\nMOVW   *AC1, VW0")


def test_run_runtime_fault_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "f.awl", FAULT)
    code, out, err = run_cli(capsys, "run", prog, "--scans", "5", "--set", "I0.0=1",
                             "--watch", "Q0.0")
    assert code == 2
    assert "mode STOP" in out
    assert f"{prog}:10:1: error: " in err
    assert "[OB1 network 2]" in err


def test_run_runtime_fault_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "f.awl", FAULT)
    code, _, _ = run_cli(capsys, "run", prog, "--scans", "5", "--json")
    assert code == 0  # I0.0 off: the faulting network never runs
    code, out, err = run_cli(capsys, "run", prog, "--scans", "5", "--set", "I0.0=1",
                             "--json", "--watch", "VW0")
    assert code == 2
    obj = json.loads(out)
    assert obj["mode"] == "STOP"
    assert obj["error"].startswith(f"{prog}:10:1: error: ")
    assert obj["values"] == {"VW0": 0}
    assert err  # the message goes to stderr as well


def test_run_compile_error_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "e.awl", ob1("LD     I0.0\nFOO    Q0.0"))
    code, out, err = run_cli(capsys, "run", prog, "--scans", "1", "--json")
    assert code == 1
    obj = json.loads(out)
    assert "unknown instruction 'FOO'" in obj["error"]
    assert obj["mode"] is None
    assert "unknown instruction 'FOO'" in err


@pytest.mark.parametrize(("args", "message"), [
    (["--set", "I0.0=abc"], "bad value 'abc'"),
    (["--set", "I0.0"], "--set needs ADDR=VALUE"),
    (["--set", "VW0=1.5"], "a real value needs a double word"),
    (["--set", "VW0=70000"], "does not fit"),
    (["--set", "XQ9=1"], "not an address"),
    (["--set", "VB99999=1"], "VB99999"),
    (["--watch", "XQ9"], "not an address"),
    (["--watch", "VW0:REAL"], "double word"),
    (["--watch", "VW0:BCD"], "--watch VW0:BCD: unknown suffix ':BCD' (:REAL reads"),
    (["--scan-ms", "0"], "scan time"),
    (["--scans", "-1"], "must not be negative"),
    # used to set the bit to 1 silently
    (["--set", "I0.0=5"], "--set I0.0=5: I0.0: a bit takes 0 or 1, got 5"),
    # used to end in "internal error: OverflowError"
    (["--set", "VD0=-1e39"], "--set VD0=-1e39: -1e39 is out of the range of a REAL"),
    # used to store infinity, while 3.5e38 was refused
    (["--set", "VD0=1e999"], "--set VD0=1e999: 1e999 is out of the range of a REAL"),
    # used to store 255: the S7-200 byte is unsigned
    (["--set", "VB0=-1"], "--set VB0=-1: VB0: -1 does not fit in a byte (BYTE), which takes "
                          "0 to 255; an S7-200 byte is unsigned"),
    # used to be ignored silently: the CPU rewrites SMB0 at every scan
    (["--set", "SM0.0=0"], "--set SM0.0=0: SM0.0: SMB0 (SM0.0 always on"),
    (["--set", "SMB0=1"], "is set by the CPU at the start of every scan"),
    # used to end in "internal error: ValueError" (more digits than int() converts)
    (["--set", "VW0=" + "9" * 5000], "too long for a number"),
    (["--set", "VW0=99999999999999999999"], "99999999999999999999 does not fit in a word"),
])
def test_run_bad_options(args: list[str], message: str,
                         capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["run", SEAL_IN, *args]
    if "--scans" not in args:
        argv += ["--scans", "1"]
    code, out, err = run_cli(capsys, *argv)
    assert code == 1
    assert message in err
    assert out == ""


def test_run_needs_exactly_one_duration(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "run", SEAL_IN)
    assert code == 1
    assert "--seconds" in err
    code, _, err = run_cli(capsys, "run", SEAL_IN, "--scans", "1", "--seconds", "1")
    assert code == 1
    assert "not allowed with" in err


def test_run_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "run", str(tmp_path / "x.awl"), "--scans", "1")
    assert code == 1
    assert out == ""
    assert "no such file" in err


@pytest.mark.parametrize(("text", "value"), [
    ("0", 0), ("+50", 50), ("-13", -13), ("16#4E4F", 0x4E4F), ("16#ffff_0000", 0xFFFF0000),
    ("2#1010", 10), ("3.25", 3.25), (".5", 0.5), ("-1.0", -1.0), ("1E3", 1000.0),
])
def test_parse_value(text: str, value: float) -> None:
    result = parse_value(text)
    assert result == value
    assert type(result) is type(value)


@pytest.mark.parametrize("text", ["", "abc", "16#", "16#XYZ", "2#102", "nanx", "infinit",
                                  "1.2.3", "0x10", "1e", "1e999", "-3.5e38", "9" * 65])
def test_parse_value_rejects(text: str) -> None:
    with pytest.raises(PlcConfigError):
        parse_value(text)


@pytest.mark.parametrize(("text", "expected"), [
    ("NaN", "nan"), ("nan", "nan"), ("Infinity", "inf"), ("-Infinity", "-inf"),
    ("inf", "inf"), ("-INF", "-inf"), ("+Infinity", "inf"),
])
def test_parse_value_non_finite_reals(text: str, expected: str) -> None:
    """NaN and the infinities are written as JSON output writes them (and as
    the API stores a float('nan')); a finite literal beyond the REAL range
    is refused instead of becoming infinity."""
    result = parse_value(text)
    assert isinstance(result, float)
    assert repr(result) == expected


# ---------------------------------------------------------------------------
# dump
# ---------------------------------------------------------------------------

def test_dump_shows_networks_and_stl_lines(capsys: pytest.CaptureFixture[str]) -> None:
    # the Python backend's module layout (native: the runner calls segments)
    code, out, err = run_cli(capsys, "dump", SEAL_IN, "--backend", "python")
    assert code == 0
    assert err == ""
    lines = out.splitlines()
    assert lines[0] == f"# plcrt dump of {SEAL_IN}"
    assert "# ==== OB1 network 1: Motor seal-in ====" in lines
    assert "# ==== OB1 network 2: Running lamp ====" in lines
    assert "    # [0] line 10: LD     I0.0" in lines
    assert "    # [3] line 13: =      Q0.0" in lines
    # the block's runner: here its one function (both networks) under the block's name
    assert "pou_OB1 = g_OB1_0_0" in lines
    # each marker is followed by that instruction's code (a run of contacts
    # may be folded into one expression after its markers, and a bit the
    # run reads again is read into a local first)
    i = lines.index("    # [0] line 10: LD     I0.0")
    end = lines.index("# ==== OB1 network 2: Running lamp ====")
    code = [line for line in lines[i + 1:end] if not line.lstrip().startswith("#")]
    assert "I[0] & 1" in code[1] and "bQ0_0" in code[1]      # LD I0.0, O Q0.0, AN I0.1


def test_dump_subroutine_block_names(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(capsys, "dump", str(PROGRAMS / "subroutine.awl"))
    assert code == 0
    assert "# ==== SBR0 network 3: High limit ====" in out
    assert "# ==== SBR0 (SCALE): runs its networks in order ====" in out
    assert "line 34: =      #High" in out


def test_dump_stl_text_stays_in_comments(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    # A code comment that looks like Python must not become code in the dump.
    prog = write(tmp_path, "c.awl", ob1("LD     I0.0  // __import__('os')\n=      Q0.0"))
    code, out, _ = run_cli(capsys, "dump", prog)
    assert code == 0
    hits = [line for line in out.splitlines() if "__import__" in line]
    assert hits and all(line.lstrip().startswith("#") for line in hits)


def test_dump_compile_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "e.awl", ob1("LD     I0.0\nFOO    Q0.0"))
    code, out, err = run_cli(capsys, "dump", prog)
    assert code == 1
    assert out == ""
    assert f"{prog}:6:1: error: unknown instruction 'FOO'" in err


# ---------------------------------------------------------------------------
# top level
# ---------------------------------------------------------------------------

def test_no_command_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys)
    assert code == 1
    assert "usage:" in err


def test_unknown_command(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "frobnicate")
    assert code == 1
    assert "invalid choice" in err


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(capsys, "--version")
    assert code == 0
    assert out.startswith("plcrt ")


def test_internal_error_is_reported_without_traceback(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    def boom(*args: object, **kw: object) -> None:
        raise RuntimeError("something broke")

    monkeypatch.setattr("plcrt.loader.load", boom)
    monkeypatch.delenv("PLCRT_TRACEBACK", raising=False)
    code, _, err = run_cli(capsys, "check", SEAL_IN)
    assert code == 1
    assert "plcrt: internal error: RuntimeError: something broke" in err
    assert "report" in err


def test_python_m_plcrt_help() -> None:
    result = subprocess.run([sys.executable, "-m", "plcrt", "--help"],
                            capture_output=True, text=True, timeout=60, check=False,
                            cwd=Path(__file__).resolve().parents[2])
    assert result.returncode == 0
    for word in ("check", "run", "dump"):
        assert word in result.stdout
    assert result.stderr == ""


CORPUS = Path(__file__).resolve().parents[2].parent / "shared" / "corpus"
ROUNDTRIP = CORPUS / "bulaofen0036-coder__Smart200-MicroWIN-MCP__roundtrip.awl"


@pytest.mark.skipif(not ROUNDTRIP.is_file(), reason="shared/corpus not available")
def test_check_passes_a_real_export_with_its_symbol_table(capsys) -> None:
    """check on the Micro/WIN SMART roundtrip export (every instruction
    family, 635 instructions) finds nothing to report."""
    symbols = str(Path(__file__).resolve().parents[1] / "data" / "roundtrip_symbols.sdf")
    code, out, err = run_cli(capsys, "check", str(ROUNDTRIP), "--symbols", symbols)
    assert code == 0 and out == ""
    assert err.strip() == (f"{ROUNDTRIP}: 0 errors, 0 warnings "
                           f"(18 block(s), 231 network(s), 635 instruction(s))")


def test_run_without_ob1_is_refused(tmp_path, capsys) -> None:
    """run on a file holding only a subroutine says there is nothing to run."""
    f = tmp_path / "sbr.awl"
    f.write_text("SUBROUTINE_BLOCK S:SBR0\nTITLE=t\nBEGIN\nNetwork 1\nLD     SM0.0\n"
                 "=      Q0.0\nEND_SUBROUTINE_BLOCK\n", encoding="utf-8")
    code, out, err = run_cli(capsys, "run", str(f), "--scans", "1")
    assert code == 1
    assert "no main program block (OB1)" in err


def test_run_realtime_keeps_results(capsys) -> None:
    """--realtime paces the scans on the wall clock without changing results."""
    code, out, err = run_cli(capsys, "run", SEAL_IN, "--scans", "3", "--scan-ms", "1",
                             "--realtime", "--set", "I0.0=1", "--watch", "Q0.0", "--json")
    assert code == 0
    assert json.loads(out)["values"] == {"Q0.0": 1}


# ---------------------------------------------------------------------------
# Untrusted text and narrow terminals
# ---------------------------------------------------------------------------

def test_diagnostics_escape_control_characters_of_the_program(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # an operand may hold any character but blanks, commas, semicolons and
    # quotes; the diagnostic quoting it must not write it raw
    prog = write(tmp_path, "esc.awl", ob1("LD \x1b[2Jx\n= Q0.0", "LD I0.0\nCALL \x1b]0pwn\x07"))
    code, out, err = run_cli(capsys, "check", prog)
    assert code == 1 and out == ""
    assert "\x1b" not in err and "\x07" not in err
    assert "unknown symbol '\\x1b[2Jx'" in err
    assert "no subroutine named '\\x1b]0pwn\\x07'" in err


def test_dump_escapes_control_characters_in_comments(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = write(tmp_path, "t.awl", "ORGANIZATION_BLOCK OB1\nBEGIN\n"
                 "Network 1 // clear\x1b[2J\nLD I0.0\n= Q0.0 // \x1b[31mred\n"
                 "END_ORGANIZATION_BLOCK\n")
    code, out, _ = run_cli(capsys, "dump", prog)
    assert code == 0 and "\x1b" not in out
    assert "# ==== OB1 network 1: clear\\x1b[2J ====" in out
    assert "line 5: = Q0.0 // \\x1b[31mred" in out


def test_run_table_shows_symbol_names_as_written(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """On a terminal the values are a rich table; a symbol name with rich
    markup was rendered as markup ("[bold red]x[/]" became a red "x")."""
    symbols = write(tmp_path, "s.sym", "[bold red]x[/]\tQ0.0\tc\n[reverse]y\tQ0.1\tc\n")
    monkeypatch.setattr(sys.stdout, "isatty", lambda: True)
    code, out, err = run_cli(capsys, "run", SEAL_IN, "--symbols", symbols, "--scans", "1",
                             "--watch", "[bold red]x[/]", "--watch", "[reverse]y")
    assert (code, err) == (0, "")
    assert "│ [bold red]x[/] │" in out and "│ [reverse]y     │" in out


def test_output_that_cannot_encode_box_drawing(tmp_path: Path) -> None:
    # PYTHONIOENCODING=ascii (a legacy terminal) ended in an internal error
    env = {**__import__("os").environ, "PYTHONIOENCODING": "ascii"}
    result = subprocess.run([sys.executable, "-m", "plcrt", "show", SEAL_IN, "--network", "2"],
                            capture_output=True, text=True, timeout=60, check=False, env=env)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    assert "Network 2  Running lamp" in result.stdout
    assert "\\u2503" in result.stdout         # the rail, escaped, not lost


def test_parse_value_takes_any_text_without_crashing() -> None:
    """Any text is a number or a PlcConfigError (never ValueError or
    OverflowError), and a float's repr within the REAL range reads back as
    itself, as do the spellings --json writes for non-finite REALs."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    numbers = st.from_regex(r"[+-]?[0-9]{1,70}(\.[0-9]*)?(e[+-]?[0-9]{1,4})?", fullmatch=True)

    @settings(max_examples=300, deadline=None, database=None)
    @given(st.one_of(st.text(max_size=80), numbers))
    def any_text(text: str) -> None:
        try:
            parse_value(text)
        except PlcConfigError as e:
            assert e.message.startswith(("bad value", text.strip()[:10]))

    @settings(max_examples=300, deadline=None, database=None)
    @given(st.floats(min_value=-3.4e38, max_value=3.4e38))
    def floats(x: float) -> None:
        text = repr(x)
        if "e" not in text and "." not in text:
            text += ".0"
        assert parse_value(text) == x

    any_text()
    floats()
    from plcrt.engine.values import NONFINITE, json_number
    for spelling, value in NONFINITE.items():
        assert json_number(parse_value(spelling)) == spelling
        assert json_number(value) == spelling
