"""The pytest plugin (plcrt.testing.plugin), run as installed: every test
writes a small project into a pytester directory and runs pytest on it in a
subprocess, so the ``pytest11`` entry point is what loads the plugin.

Each subprocess costs about a second, so each test here checks several
things of one run."""

from __future__ import annotations

import json
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from plcrt.testing.coverage_report import merge_store, report_lines

pytest_plugins = ["pytester"]

SEAL = """\
ORGANIZATION_BLOCK OB1
TITLE=Seal-in
BEGIN
Network 1 // Motor seal-in
LD     I0.0
O      Q0.0
AN     I0.1
=      Q0.0
Network 2 // Running lamp
LD     Q0.0
=      Q0.1
END_ORGANIZATION_BLOCK
"""

# I0.0 starts a 1 s on-delay (T37 is a 100 ms timer) that switches Q0.0.
TIMER = """\
ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     I0.0
TON    T37, +10
Network 2
LD     T37
=      Q0.0
END_ORGANIZATION_BLOCK
"""

BAD = """\
ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     I0.0
FOO    Q0.0
END_ORGANIZATION_BLOCK
"""

# Network 3 is jumped over unless I0.7 is on, SBR0 runs only with I0.6 on,
# and nothing sets M0.0: the coverage report must show all three.
COVERED = """\
ORGANIZATION_BLOCK OB1
BEGIN
Network 1 // Seal-in
LD     I0.0
O      Q0.0
AN     I0.1
=      Q0.0
Network 2 // Skip the horn unless in service mode
LDN    I0.7
JMP    1
Network 3 // Horn
LD     I0.2
=      Q0.2
Network 4
LBL    1
Network 5 // Service
LD     I0.6
CALL   SERVICE
Network 6 // Lamp
LD     M0.0
=      Q0.1
END_ORGANIZATION_BLOCK
SUBROUTINE_BLOCK SERVICE:SBR0
BEGIN
Network 1 // Count service calls
LD     SM0.0
INCW   VW0
END_SUBROUTINE_BLOCK
"""


def _write(pytester: pytest.Pytester, path: str, text: str) -> None:
    p = pytester.path / path
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(text, encoding="utf-8")


def _run(pytester: pytest.Pytester, *args: str) -> pytest.RunResult:
    """Inner pytest in a subprocess.  Hypothesis's plugin alone costs about a
    second of start-up and the inner tests do not use it."""
    return pytester.runpytest_subprocess(*args, "-p", "no:cacheprovider",
                                         "-p", "no:hypothesispytest")


def test_plugin_import_is_cheap() -> None:
    code = ("import sys, plcrt.testing.plugin; "
            "print(sorted(m for m in ('lark', 'numpy', 'rich', 'plcrt.engine', "
            "'plcrt.testing.harness', 'plcrt.compiler') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


def test_marker_fixture_trace_and_junitxml(pytester: pytest.Pytester) -> None:
    # programs/seal.awl is found from the rootdir, local.awl next to the test
    _write(pytester, "programs/seal.awl", SEAL)
    _write(pytester, "sub/local.awl", TIMER)
    _write(pytester, "sub/test_basic.py", """\
import pytest

pytestmark = pytest.mark.plc("programs/seal.awl", watch=["I0.0", "I0.1", "Q0.0"])


def test_module_marker(plc):
    assert plc.scans == 0 and plc.coverage is None
    plc.pulse("I0.0")
    plc.scan()
    assert plc["Q0.0"] == 1 and plc["Q0.1"] == 1


def test_each_test_starts_at_power_up(plc):
    assert plc.scans == 0 and plc["Q0.0"] == 0 and plc.time == 0


@pytest.mark.plc("local.awl", scan_ms=5)
def test_function_marker_wins(plc):
    plc["I0.0"] = 1
    assert plc.run_until("Q0.0") == pytest.approx(1.005)
    assert plc.name == "local.awl"


class TestClass:
    pytestmark = pytest.mark.plc("local.awl", scan_ms=2)

    def test_class_marker(self, plc):
        plc.scan()
        assert plc.time == pytest.approx(0.002)


def test_stop_wins(plc):
    plc.pulse("I0.0")
    plc.force("I0.1", 1)
    plc.run("30ms")
    assert plc["Q0.0"] == 1, "the motor should still run"
""")
    result = _run(pytester, "--junitxml=out.xml")
    result.assert_outcomes(passed=4, failed=1)
    out = result.stdout.str()
    result.stdout.fnmatch_lines([
        "*- PLC trace -*",
        "program programs/seal.awl",
        "  simulated time 0.040 s after 4 scan(s) of 10 ms, CPU mode RUN",
        "  forced: I0.1=1",
        "  watched addresses, last 4 scan(s) (values after each scan):",
        "    scan  t [s]  I0.0  I0.1  Q0.0",
        "    ----  -----  ----  ----  ----",
        "       1  0.010     1     0     1",
        "       2  0.020     0     1     0",
        "       4  0.040     0     1     0",
    ])
    assert out.count("PLC trace") == 1          # only the failing test has one
    assert "plcrt coverage" not in out           # no coverage unless asked for

    suite = ET.parse(pytester.path / "out.xml").getroot()
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    assert set(cases) == {"test_module_marker", "test_each_test_starts_at_power_up",
                          "test_function_marker_wins", "test_class_marker", "test_stop_wins"}
    failed = cases["test_stop_wins"]
    assert failed.find("failure") is not None
    props = {p.get("name"): p.get("value") for p in failed.iter("property")}
    assert "forced: I0.1=1" in props["plc_trace"]
    assert "   2  0.020     0     1     0" in props["plc_trace"]
    assert cases["test_module_marker"].find("properties") is None


def test_marker_errors_are_clear(pytester: pytest.Pytester) -> None:
    pytester.makefile(".awl", seal=SEAL, bad=BAD)
    pytester.makepyfile(test_errors="""\
import pytest


@pytest.mark.plc("seal.awl", watchh=["Q0.0"])
def test_unknown_argument(plc):
    pass


@pytest.mark.plc("missing.awl")
def test_missing_program(plc):
    pass


@pytest.mark.plc("seal.awl", watch="Q0.0")
def test_wrong_type(plc):
    pass


@pytest.mark.plc("seal.awl", "bad.awl")
def test_two_positional(plc):
    pass


@pytest.mark.plc("bad.awl")
def test_program_with_an_error(plc):
    pass


def test_no_marker(plc):
    pass
""")
    result = _run(pytester)
    result.assert_outcomes(errors=6)
    result.stdout.fnmatch_lines([
        "test_errors.py::test_unknown_argument: @pytest.mark.plc: unknown argument(s) "
        "'watchh' (did you mean 'watch'?); the options are symbols, data, plant, scan_ms, "
        "cpu, watch, history, max_time, encoding, clock",
        "test_errors.py::test_missing_program: @pytest.mark.plc: program file 'missing.awl' "
        "not found (looked for */missing.awl)",
        "test_errors.py::test_wrong_type: @pytest.mark.plc: watch= must be a list of "
        "addresses such as ['Q0.0', 'VW100'], got 'Q0.0'",
        "test_errors.py::test_two_positional: @pytest.mark.plc: expected one program*",
        "test_errors.py::test_program_with_an_error: @pytest.mark.plc: cannot load bad.awl:",
        "*bad.awl:5:1: error: unknown instruction 'FOO' [[]OB1 network 1]",
        "test_errors.py::test_no_marker: the `plc` fixture needs a @pytest.mark.plc(*",
    ])
    out = result.stdout.str()
    assert "Traceback" not in out and "During handling" not in out
    assert "plcrt/" not in out.replace("\\", "/")     # no frames of plcrt's internals


def test_factory_scan_ms_option_and_ini(pytester: pytest.Pytester) -> None:
    pytester.makefile(".awl", seal=SEAL, timer=TIMER, bad=BAD)
    # a program in two files: OB1 in one, its subroutine in the other
    pytester.makefile(".awl", main="""\
ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     SM0.0
CALL   COUNT
END_ORGANIZATION_BLOCK
""", count="""\
SUBROUTINE_BLOCK COUNT:SBR0
BEGIN
Network 1
LD     SM0.0
INCW   VW0
END_SUBROUTINE_BLOCK
""")
    pytester.makeini("[pytest]\nplc_history = 3\n")
    pytester.makepyfile(test_factory="""\
import pytest
import plcrt


def test_two_programs(plc_factory):
    a = plc_factory("seal.awl")
    b = plc_factory("timer.awl", scan_ms=10)
    assert a.plc.scan_us == 5000 and b.plc.scan_us == 10000
    a.pulse("I0.0")
    b["I0.0"] = 1
    b.run("0.5s")
    assert (a["Q0.0"], b["Q0.0"], b["T37"]) == (1, 0, 4)


def test_list_of_files(plc_factory):
    h = plc_factory(["main.awl", "count.awl"])
    h.scan(4)
    assert h["VW0"] == 4


@pytest.mark.plc("seal.awl")
def test_scan_ms_from_the_command_line(plc):
    assert plc.plc.scan_us == 5000


def test_factory_errors(plc_factory):
    with pytest.raises(plcrt.PlcConfigError, match="did you mean 'scan_ms'"):
        plc_factory("seal.awl", scanms=5)
    with pytest.raises(plcrt.PlcCompileError, match="unknown instruction 'FOO'"):
        plc_factory("bad.awl")


def test_both_programs_in_the_trace(plc_factory):
    a = plc_factory("seal.awl", watch=["Q0.0"])
    b = plc_factory("timer.awl", watch=["T37"])
    a.scan(10)
    b["I0.0"] = 1
    b.scan(10)
    assert b["T37"] > 100
""")
    result = _run(pytester, "--plc-scan-ms=5")
    result.assert_outcomes(passed=4, failed=1)
    result.stdout.fnmatch_lines([
        "*- PLC trace -*",
        "program seal.awl",
        "  simulated time 0.050 s after 10 scan(s) of 5 ms, CPU mode RUN",
        "  forced: none",
        "  watched addresses, last 3 scan(s) (values after each scan):",
        "    scan  t [s]  Q0.0",
        "       8  0.040     0",
        "      10  0.050     0",
        "",
        "program timer.awl",
        "  simulated time 0.050 s after 10 scan(s) of 5 ms, CPU mode RUN",
        "*scan  t [[]s]  T37",
        "      10  0.050    0",
    ])


def test_coverage_report(pytester: pytest.Pytester) -> None:
    pytester.makefile(".awl", cov=COVERED)
    pytester.makepyfile(test_cov="""\
import pytest

pytestmark = pytest.mark.plc("cov.awl")


def test_start_stop(plc):
    assert plc.coverage is not None
    plc.pulse("I0.0")
    plc.pulse("I0.1")


def test_fork_counts_too(plc):
    plc.fork().pulse("I0.0")
""")
    result = _run(pytester, "--plc-coverage-report=out/cov.json")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines([
        "*= plcrt coverage =*",
        "cov.awl: networks 5/7 (71.4 %), branches 5/10 (50.0 %), contacts 9/14 (64.3 %)",
        '  not run: OB1/3 "Horn" (line 11)',
        '  not run: SBR0/1 "Count service calls" (line 25)',
        "  OB1/2 line 9: LDN I0.7 never open",
        "  OB1/2 line 10: JMP 1 never false",
        "  OB1/5 line 17: LD I0.6 never closed",
        "  OB1/5 line 18: CALL SERVICE never true",
        "  OB1/6 line 20: LD M0.0 never closed",
        "  OB1/6 line 21: = Q0.1 never true",
        "coverage JSON written to *cov.json",
    ])
    assert "Q0.0 never" not in result.stdout.str()   # seal-in seen both ways
    assert "I0.1 never" not in result.stdout.str()   # the stop button was pressed
    report = json.loads((pytester.path / "out" / "cov.json").read_text())
    prog = report["programs"]["cov.awl"]
    assert prog["summary"]["networks_run"] == 5 and prog["summary"]["networks_total"] == 7
    assert prog["data"]["networks"]["OB1/3"] == 0
    assert prog["data"]["outputs"]["OB1/1:7:1:="] == 3
    assert prog["data"]["contacts"]["OB1/1:6:1:AN"] == 3        # open and closed
    assert prog["data"]["contacts"]["OB1/5:17:1:LD"] == 1       # only ever open
    assert [n["network"] for n in prog["summary"]["networks_not_run"]] == ["OB1/3", "SBR0/1"]


def test_coverage_is_merged_across_xdist_workers(pytester: pytest.Pytester) -> None:
    pytest.importorskip("xdist")
    pytester.makefile(".awl", seal=SEAL)
    # each file sees Q0.0 one way only; with --dist loadfile and two
    # workers each file runs on its own worker
    body = """\
import os
from pathlib import Path
import pytest


@pytest.mark.plc("seal.awl")
def test_it(plc):
    Path("{name}.worker").write_text(os.environ.get("PYTEST_XDIST_WORKER", "none"))
    {action}
"""
    pytester.makepyfile(test_on=body.format(name="on", action='plc.pulse("I0.0")'),
                        test_off=body.format(name="off", action="plc.scan(3)"))
    result = _run(pytester, "-n", "2", "--dist", "loadfile", "--plc-coverage")
    result.assert_outcomes(passed=2)
    workers = {(pytester.path / f"{n}.worker").read_text() for n in ("on", "off")}
    assert workers == {"gw0", "gw1"}
    out = result.stdout.str()
    assert out.count("plcrt coverage") == 1
    result.stdout.fnmatch_lines([
        "seal.awl: networks 2/2 (100.0 %), branches 4/4 (100.0 %), contacts 6/8 (75.0 %)",
        "  OB1/1 line 6: O Q0.0 never closed",
        "  OB1/1 line 7: AN I0.1 never open",
    ])


def test_report_merges_and_lists() -> None:
    meta = {"networks": {"OB1/1": ["Start", 3], "OB1/2": ["", 8]},
            "outputs": {"OB1/1:5:1:=": ["OB1/1", "=", "Q0.0", 5],
                        "OB1/2:9:1:=": ["OB1/2", "=", "Q0.1", 9]},
            "contacts": {"OB1/1:4:1:LD": ["OB1/1", "LD", "I0.0", 4]}}
    store: dict = {}
    merge_store(store, {"p.awl": {"networks": {"OB1/1": 1, "OB1/2": 0},
                                  "outputs": {"OB1/1:5:1:=": 1, "OB1/2:9:1:=": 0},
                                  "contacts": {"OB1/1:4:1:LD": 1},
                                  "meta": meta}})
    assert report_lines(store) == [
        "p.awl: networks 1/2 (50.0 %), branches 1/4 (25.0 %), contacts 1/2 (50.0 %)",
        "  not run: OB1/2 (line 8)",
        "  OB1/1 line 4: LD I0.0 never closed",
        "  OB1/1 line 5: = Q0.0 never true",
    ]
    merge_store(store, {"p.awl": {"networks": {"OB1/1": 1, "OB1/2": 1},
                                  "outputs": {"OB1/1:5:1:=": 2, "OB1/2:9:1:=": 0},
                                  "contacts": {"OB1/1:4:1:LD": 2},
                                  "meta": meta}})
    assert report_lines(store) == [
        "p.awl: networks 2/2 (100.0 %), branches 2/4 (50.0 %), contacts 2/2 (100.0 %)",
        "  OB1/2 line 9: = Q0.1 never reached",
    ]
    assert report_lines({}) == ["no PLC program was run with coverage"]


def test_watch_and_ob1_problems_fail_setup_with_what_to_fix(pytester: pytest.Pytester) -> None:
    """A watched address that does not exist is a problem of the marker, not
    of loading the program; a file without OB1 (an empty one, say) would
    make every scan do nothing and "stays off" assertions pass."""
    pytester.makefile(".awl", seal=SEAL, bad=BAD, empty="// nothing here\n",
                      sbr="SUBROUTINE_BLOCK SBR0\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\n"
                          "END_SUBROUTINE_BLOCK\n")
    pytester.makepyfile(test_setup="""\
import pytest
import plcrt


@pytest.mark.plc("seal.awl", watch=["Q0.0", "XX9.9"])
def test_watch_unknown_address(plc):
    pass


@pytest.mark.plc("seal.awl", watch=["Q0.0:FOO"])
def test_watch_unknown_kind(plc):
    pass


@pytest.mark.plc("empty.awl")
def test_empty_program(plc):
    plc.stays("not Q0.0", "1s")


@pytest.mark.plc("sbr.awl")
def test_no_ob1(plc):
    pass


@pytest.mark.plc("bad.awl")
def test_compile_error(plc):
    pass


def test_factory_watch(plc_factory):
    with pytest.raises(plcrt.PlcConfigError, match="plc_factory: watch 'XX': 'XX' is not an address"):
        plc_factory("seal.awl", watch=["XX"])
""")
    result = _run(pytester)
    result.assert_outcomes(errors=5, passed=1)
    result.stdout.fnmatch_lines([
        "test_setup.py::test_watch_unknown_address: @pytest.mark.plc: watch 'XX9.9': "
        "'XX9.9' is not an address",
        "test_setup.py::test_watch_unknown_kind: @pytest.mark.plc: watch 'Q0.0:FOO': *"
        "unknown suffix ':FOO'*",
        "test_setup.py::test_empty_program: @pytest.mark.plc: cannot load empty.awl:",
        "*/empty.awl:1:1: error: the file holds no program block (it is empty, or only "
        "comments), so there is nothing to check or run",
        "test_setup.py::test_no_ob1: @pytest.mark.plc: cannot load sbr.awl:",
        "*/sbr.awl:1:1: error: the program has no main program block (OB1), so there is "
        "nothing to run;*",
        "test_setup.py::test_compile_error: @pytest.mark.plc: cannot load bad.awl:",
        "*/bad.awl:5:1: error: unknown instruction 'FOO' [[]OB1 network 1]",
    ])
    out = result.stdout.str()
    assert "cannot load seal.awl" not in out
    assert "Traceback" not in out and "plcrt/" not in out.replace("\\", "/")


def test_p_no_plcrt_switches_the_plugin_off(pytester: pytest.Pytester) -> None:
    pytester.makefile(".awl", seal=SEAL)
    pytester.makepyfile(test_plain="""\
def test_plain():
    assert True
""")
    result = _run(pytester, "-p", "no:plcrt", "-W", "error::pytest.PytestConfigWarning")
    result.assert_outcomes(passed=1)
    assert "plcrt coverage" not in result.stdout.str()
    result = _run(pytester, "-p", "no:plcrt", "--plc-coverage")
    assert result.ret == pytest.ExitCode.USAGE_ERROR   # its options are gone with it
    result.stderr.fnmatch_lines(["*unrecognized arguments: --plc-coverage*"])


def test_max_time_limits_simulated_time_per_test(pytester: pytest.Pytester) -> None:
    """A test whose PLC runs past max_time fails with a PlcTimeout naming
    the limit, whether the marker or --plc-max-time sets it; a bad value
    is a usage error."""
    pytester.makefile(".awl", timer=TIMER)
    pytester.makepyfile(test_limit="""\
import pytest


@pytest.mark.plc("timer.awl", max_time="2s")
def test_waits_too_long(plc):
    plc.run("5s")


@pytest.mark.plc("timer.awl")
def test_option_limit(plc):
    plc.run("1min")


@pytest.mark.plc("timer.awl", max_time="2s")
def test_within_limit(plc):
    plc["I0.0"] = 1
    assert plc.run_until("Q0.0", timeout="1.5s") == pytest.approx(1.01)
""")
    result = _run(pytester, "--plc-max-time=30s")
    result.assert_outcomes(passed=1, failed=2)
    result.stdout.fnmatch_lines([
        "*PlcTimeout: the test ran past its limit of 2 s of simulated time (max_time); "
        "at t = 2.010 s, scan 201",
        "*PlcTimeout: the test ran past its limit of 30 s of simulated time (max_time); "
        "at t = 30.010 s, scan 3001",
    ])
    bad = _run(pytester, "--plc-max-time=soon")
    assert bad.ret == pytest.ExitCode.USAGE_ERROR
    bad.stderr.fnmatch_lines(["*--plc-max-time / plc_max_time: not a duration: 'soon'*"])


def test_plc_backend_option_runs_the_tests_on_the_native_backend(
        pytester: pytest.Pytester) -> None:
    """--plc-backend native: every PLC of the session (its power-up copy and
    each test's fork) runs the lowered networks as machine code."""
    pytest.importorskip("llvmlite")
    _write(pytester, "programs/timer.awl", TIMER)
    _write(pytester, "test_backend.py", """\
import pytest


@pytest.mark.plc("programs/timer.awl")
@pytest.mark.parametrize("run", range(2))
def test_timer(plc, run):
    assert plc.backend["name"] == "native" and plc.backend["pieces"] == 2
    plc["I0.0"] = 1
    assert plc.run_until("Q0.0") == pytest.approx(1.01)   # T37 done at 1.0 s, Q0.0 a scan later
""")
    _run(pytester, "--plc-backend", "native").assert_outcomes(passed=2)
    _write(pytester, "pytest.ini", "[pytest]\nplc_backend = fast\n")
    result = _run(pytester)
    assert "plc_backend must be one of auto, python, native" in result.stderr.str()
