"""A failing PLC test shows the test's lines and plcrt's message, not
plcrt's internals (plcrt.testing.frames, hooked into the plugin's report):
a mistyped symbol names the closest symbols, and neither it nor a
``max_time`` limit, a timeout or a ``stays`` failure shows a frame from a
file of the plcrt package.  ``--full-trace`` and other exceptions (a bug
of a condition function, of plcrt) keep every frame."""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt

pytest_plugins = ["pytester"]

PACKAGE = str(Path(plcrt.__file__).resolve().parent)

MOTOR = """\
ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     Start
=      Motor
END_ORGANIZATION_BLOCK
"""

SYMBOLS = "Start\tI0.0\nMotor\tQ0.0\nMotor_Fault\tI0.5\nPump\tQ0.1\n"

TESTS = """\
import pytest

pytestmark = pytest.mark.plc("motor.awl", symbols="motor.sym", max_time="0.05s")


def test_typo(plc):
    plc["Start"] = 1
    plc.scan()
    assert plc["Motr"] == 1


def test_typo_in_a_condition(plc):
    plc.run_until(lambda: plc["Motr"] == 1, timeout="0.02s")


def test_max_time(plc):
    plc.run("1s")


def test_stays(plc):
    plc["Start"] = 1
    plc.scan()
    plc["Start"] = 0
    plc.stays(lambda: plc["Motor"] == 1, "0.03s")


def test_not_ours(plc):
    plc.stays(lambda: 1 / 0, "0.03s")
"""


def _run(pytester: pytest.Pytester, *args: str) -> pytest.RunResult:
    (pytester.path / "motor.awl").write_text(MOTOR, encoding="utf-8")
    (pytester.path / "motor.sym").write_text(SYMBOLS, encoding="utf-8")
    (pytester.path / "test_motor.py").write_text(TESTS, encoding="utf-8")
    return pytester.runpytest_subprocess(*args, "-p", "no:cacheprovider",
                                         "-p", "no:hypothesispytest")


def _section(out: str, test: str) -> str:
    """The failure report of one test."""
    start = out.index(f"_ {test} _")
    end = out.find("\n___", start + 1)
    return out[start:end if end > 0 else len(out)]


def test_failures_show_the_tests_lines_and_no_plcrt_frames(pytester: pytest.Pytester) -> None:
    result = _run(pytester, "-k", "not not_ours")
    result.assert_outcomes(failed=4)
    out = result.stdout.str()
    typo = _section(out, "test_typo")
    assert ("'Motr' is not an address and not in the symbol table; did you mean 'Motor'?"
            in typo)
    assert '>       assert plc["Motr"] == 1' in typo
    condition = _section(out, "test_typo_in_a_condition")
    assert "did you mean 'Motor'?" in condition
    assert 'plc.run_until(lambda: plc["Motr"] == 1' in condition   # the test's own frame
    assert "the test ran past its limit of 0.05 s" in _section(out, "test_max_time")
    assert ("expected 'lambda: plc[\"Motor\"] == 1' to stay true for 0.03 s from t = 0.010 s; "
            "it became false 0.010 s later" in _section(out, "test_stays"))
    assert PACKAGE not in out


def test_full_trace_and_unexpected_exceptions_keep_plcrt_frames(
        pytester: pytest.Pytester) -> None:
    result = _run(pytester, "-k", "typo or not_ours", "--full-trace")
    result.assert_outcomes(failed=3)
    assert PACKAGE in _section(result.stdout.str(), "test_typo")
    result = _run(pytester, "-k", "not_ours")
    result.assert_outcomes(failed=1)
    out = result.stdout.str()
    assert "ZeroDivisionError" in out and PACKAGE in out
