"""The ``plc`` fixture compiles a program once per test run and gives each
test a fork of one power-up PLC (plcrt.testing.plugin._pristine): nothing a
test does reaches the next one."""

from __future__ import annotations

import pytest

pytest_plugins = ["pytester"]

# I0.0 starts a 1 s on-delay (T37) that switches Q0.0; C0 counts I0.1's edges;
# the data block gives VW50 its start value.
PROGRAM = """\
ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD     I0.0
TON    T37, +10
Network 2
LD     T37
=      Q0.0
Network 3
LD     I0.1
LD     I0.2
CTU    C0, +100
END_ORGANIZATION_BLOCK
"""

TESTS = """\
import pytest
from plcrt.compiler.cache import programs

pytestmark = pytest.mark.plc("prog.awl", data="data.txt", watch=["Q0.0"])
FIRST = []


def test_changes_everything(plc):
    FIRST.append(plc.plc)
    plc.force("I0.0", 1)
    plc.pulse("I0.1").scan().pulse("I0.1")
    plc.write("VW50", 7)
    plc.run("2s")
    assert plc.read("Q0.0") == 1 and plc.read("C0") == 2 and plc.read("VW50") == 7


@pytest.mark.parametrize("i", range(3))
def test_starts_at_power_up(plc, i):
    p = plc.plc
    assert p is not FIRST[0] and p.scans == 0 and p.time == 0.0 and not p.forces
    assert p.timers is not FIRST[0].timers and p.mem.areas["V"] is not FIRST[0].mem.areas["V"]
    assert plc.read("VW50") == 1234 and plc.read("C0") == 0 and plc.watched == ["Q0.0"]
    plc.run("2s")
    assert plc.read("Q0.0") == 0 and plc.read("T37") == 0   # I0.0 is not forced here
    plc.write("VW50", 9)


def test_compiled_once(plc):
    # one compile for the whole run, one entry in the process's cache
    assert programs.misses == 1 and programs.hits == 0 and len(programs) == 1


def test_other_options_other_plc(plc_factory):
    other = plc_factory("prog.awl", data="data.txt", cpu="CPU224")
    assert other.plc.model.name != "CPU226" and other.read("VW50") == 1234
    assert programs.misses == 2
"""


def test_each_test_gets_a_fork_of_one_compile(pytester: pytest.Pytester) -> None:
    (pytester.path / "prog.awl").write_text(PROGRAM, encoding="utf-8")
    (pytester.path / "data.txt").write_text("VW50 1234\n", encoding="utf-8")
    (pytester.path / "test_inner.py").write_text(TESTS, encoding="utf-8")
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-p", "no:hypothesispytest",
                                           "-p", "no:xdist")
    result.assert_outcomes(passed=6)
