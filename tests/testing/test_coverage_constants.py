"""Coverage goals leave out what no test can change: a contact on a bit
that is constant in RUN (SM0.0, by address or as Always_On) and a rung
outcome that is constant because of it (plcrt.compiler.constpower), so a
program that uses the always-on bit can reach 100 %.  SM0.1 (first scan)
is not constant and stays a goal."""

from __future__ import annotations

from plcrt.testing import Harness
from plcrt.testing.coverage_report import entry_from_map, merge_entry, report_lines

PROGRAM = """\
ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1 // values set every scan
LD     SM0.0
MOVW   +5, VW0
MOVW   +6, VW2
=      M0.0
Network 2 // a real condition behind the always-on bit
LD     I0.0
A      Always_On
=      Q0.0
Network 3 // a parallel always-on branch makes the coil constant
LD     I0.1
O      SM0.0
=      Q0.1
Network 4 // branches of an always-on rung
LD     SM0.0
LPS
A      I0.2
=      Q0.2
LPP
=      Q0.3
Network 5 // the first-scan bit is a goal like any input
LD     SM0.1
=      M0.1
Network 6 // never powered because of the always-on bit
LDN    SM0.0
=      M0.2
END_ORGANIZATION_BLOCK
"""


def covered(h: Harness) -> list[str]:
    store: dict = {}
    merge_entry(store, "p.awl", entry_from_map(h.coverage))
    return report_lines(store)


def test_a_program_using_the_always_on_bit_reaches_100_percent() -> None:
    h = Harness.load(PROGRAM, instrument=True)
    h.scan(2)                               # first scan and one more: SM0.1 both ways
    for inputs in ((1, 1, 1), (0, 0, 0)):
        h.set(dict(zip(("I0.0", "I0.1", "I0.2"), inputs)))
        h.scan()
    assert covered(h) == [
        "p.awl: networks 6/6 (100.0 %), branches 6/6 (100.0 %), contacts 8/8 (100.0 %)"]


def test_the_goals_are_the_contacts_and_outputs_that_can_change() -> None:
    h = Harness.load(PROGRAM, instrument=True)
    contacts = [(c.mnemonic, c.operand) for c in h.coverage.contacts]
    outputs = [(o.mnemonic, o.operand) for o in h.coverage.outputs]
    assert contacts == [("LD", "I0.0"), ("LD", "I0.1"), ("A", "I0.2"), ("LD", "SM0.1")]
    assert outputs == [("=", "Q0.0"), ("=", "Q0.2"), ("=", "M0.1")]
    h.scan()
    lines = covered(h)
    assert "SM0.0" not in "\n".join(lines) and "MOVW" not in "\n".join(lines)
    assert "  OB1/5 line 24: LD SM0.1 never open" in lines
