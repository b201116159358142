"""Statements of the two drive manuals (HCFA AM0520B, Kinco homing note)
that the other CiA 402 tests do not pin.

Each test names the manual's section and the statement it pins (or the
decision of docs/decisions.md it follows where the manual is silent or
wrong); docs/cia402.md ("Audit against the manuals") lists every statement
of both manuals with its test or decision.  The last two tests here check
that table: every test it names exists, every decision it quotes is in the
decisions log, and its counts are the table's.  The statements of the other
audit files: test_cia402_audit_od.py (the object tables), _hcfa.py, _kinco.py.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.od import SdoAbort
from plcrt.devices.cia402.plant import DrivePlant
from plcrt.devices.cia402.statemachine import State

from cia402_drive_helpers import enable

DOCS = Path(__file__).resolve().parents[3] / "docs" / "cia402.md"


def pp_move(d: Drive, target: int, relative: bool = False) -> None:
    d.write(0x607A, 0, target)
    d.write(0x6040, 0, 0x5F if relative else 0x1F)
    d.write(0x6040, 0, 0x0F)


# ---------------------------------------------------------------- limit switches

@pytest.mark.parametrize("model", ["hcfa-am0520b", "kinco-servo"])
def test_pp_move_ending_exactly_on_a_limit_switch_stops_at_the_limit(model):
    """HCFA §7.4.2 bit 11, §7.5.3 note 1: a limit switch that becomes active
    in a move toward it is an abnormal stop (bits 8 and 11), also when the
    move's target is the switch's own first count."""
    d = enable(Drive(model, plant=DrivePlant(pos_limit=10_000)), 1,
               x6081=20_000, x6083=100_000, x6084=100_000)
    pp_move(d, 10_000)
    d.advance(3_000_000)
    assert d.position == 10_000
    assert d.statusword & 0x0900 == 0x0900           # bits 8 (abnormal stop) and 11 (limit)
    assert [e.t_us for e in d.log if "limit switch (PLS) active" in e.text] == [700_000]
    pp_move(d, 20_000)                                # further toward it: refused
    d.advance(4_000_000)
    assert d.position == 10_000
    pp_move(d, 0)                                     # away from it: allowed
    d.advance(6_000_000)
    assert d.position == 0 and not d.statusword & 0x0900


# ---------------------------------------------------------------- HCFA §7.5.1: objects that act

def test_60c5h_60c6h_limit_the_pp_ramps():
    """HCFA §7.5.1: 60C5h / 60C6h (max acceleration / deceleration) act in PP:
    6083h = 6084h = 400 000 P/s² limited to 100 000 / 50 000 P/s²: 10 000
    counts at 20 000 P/s take 0.2 s up, 0.4 s down and 0.2 s cruise."""
    d = enable(Drive(), 1, x6081=20_000, x6083=400_000, x6084=400_000,
               x60C5=100_000, x60C6=50_000)
    pp_move(d, 10_000)
    d.advance(199_999)
    assert d.read(0x606C) < 20_000
    d.advance(200_000)
    assert d.read(0x606C) == 20_000 and d.read(0x6064) == 2000
    d.advance(800_000)
    assert d.position == 10_000 and d.statusword & 0x0400
    d.advance(799_999 + 1)
    texts = [e.text for e in d.log]
    assert any("6083h = 400000 P/s² above 60C5h (max acceleration) = 100000" in x for x in texts)
    assert any("6084h = 400000 P/s² above 60C6h (max deceleration) = 50000" in x for x in texts)


def test_pp_ramps_below_60c5h_60c6h_are_untouched():
    """HCFA §7.5.1: the defaults (all ones) limit nothing: 6083h = 6084h =
    100 000 P/s², 10 000 counts at 20 000 P/s end at 0.7 s."""
    d = enable(Drive(), 1, x6081=20_000, x6083=100_000, x6084=100_000)
    pp_move(d, 10_000)
    d.advance(699_999)
    assert d.position < 10_000
    d.advance(700_000)
    assert d.position == 10_000
    assert not any("60C5h" in e.text or "60C6h" in e.text for e in d.log)


def test_60c5h_zero_is_no_limit():
    """HCFA §7.5.1 gives 60C5h no range: 0 would never move, so it limits
    nothing, and the log says so."""
    d = enable(Drive(), 1, x6081=20_000, x6083=100_000, x6084=100_000, x60C5=0)
    pp_move(d, 10_000)
    d.advance(700_000)
    assert d.position == 10_000
    assert any("60C5h (max acceleration) = 0 is no limit" in e.text for e in d.log)


def test_60c5h_and_6080h_limit_homing():
    """HCFA §7.5.1, §7.5.4: 6080h caps the homing speeds and 60C5h/60C6h the
    homing acceleration 609Ah.  Method 35 is no motion, so method 17 (NLS
    edge): 6099h:01 = 50 000 P/s capped to 6080h = 10 000, 609Ah
    = 1 000 000 capped to 60C6h = 20 000 P/s²: the speed never exceeds
    10 000 P/s, and reaching it takes 0.5 s."""
    d = enable(Drive(plant=DrivePlant(neg_limit=-100_000)), 6, x6098=17, x6099_01=50_000,
               x6099_02=2000, x609A=1_000_000, x6080=10_000, x60C6=20_000)
    d.write(0x6040, 0, 0x1F)
    d.advance(499_999)
    assert -10_000 < d.read(0x606C) < 0
    d.advance(500_000)
    assert d.read(0x606C) == -10_000
    d.advance(3_000_000)
    assert d.read(0x606C) == -10_000
    texts = [e.text for e in d.log]
    assert any("6099h:01 = 50000, 6099h:02 = 2000 P/s limited to 6080h (max motor speed) "
               "= 10000" in x for x in texts)
    assert any("609Ah = 1000000 P/s² above 60C6h (max deceleration) = 20000" in x
               for x in texts)


def test_6063h_and_606bh_read_the_axis_live():
    """HCFA §7.5.1 (6063h position actual internal value), §7.5.2 / §8.3
    (606Bh velocity demand): they read the axis, not 0.  Without a factor
    group 6063h = 6064h; 606Bh is the demand's speed."""
    d = enable(Drive(), 1, x6081=20_000, x6083=100_000, x6084=100_000)
    pp_move(d, 10_000)
    d.advance(300_000)
    assert d.read(0x6063) == d.read(0x6064) == 4000
    assert d.read(0x606B) == d.read(0x606C) == 20_000
    d.advance(1_000_000)
    assert d.read(0x6063) == 10_000 and d.read(0x606B) == 0


def test_606bh_is_the_demand_speed_against_a_mechanical_end():
    """CiA 402 606Bh: with the axis held at a mechanical end, 606Ch is 0 and
    606Bh the speed the demand goes on at (Kinco, PP toward pos_stop)."""
    d = enable(Drive("kinco-servo", plant=DrivePlant(pos_stop=5000)), 1,
               x6081=20_000, x6083=100_000, x6084=100_000)
    pp_move(d, 100_000)
    d.advance(600_000)
    assert d.read(0x6064) == 5000 and d.read(0x606C) == 0
    assert d.read(0x606B) == 20_000


# ---------------------------------------------------------------- HCFA §7.5.4: homing

def test_6098h_zero_sets_bit_14_not_alarm_62():
    """HCFA §7.5.4 bit 14: "a parameter is 0 (6098h, 6099h:01, 6099h:02 or
    609Ah)": 6098h = 0 refuses the start with bit 14 and no fault."""
    d = enable(Drive(), 6, x6098=0)
    d.write(0x6040, 0, 0x1F)
    assert d.sm.state is State.OPERATION_ENABLED and d.read(0x603F) == 0
    assert d.statusword & 0x4000
    assert any("6098h" in e.text and "bit 14" in e.text for e in d.log)
    d.write(0x6040, 0, 0x0F)
    d.write(0x6098, 0, 99)                        # not a method: alarm 62 stays for that
    d.write(0x6040, 0, 0x1F)
    assert d.read(0x603F) == 62


# ---------------------------------------------------------------- Kinco §2.6: bit 13

def test_kinco_pp_against_a_mechanical_end_sets_bit_13_following_error():
    """Kinco §2.6: statusword bit 13 = following error.  PP into pos_stop =
    5000 with 6065h = 1000: bit 13 is set from the µs 60F4h exceeds 6065h
    until the fault (6066h = 100 ms); the HCFA drive (§7.5.3, no bit 13 in PP)
    keeps it clear."""
    for model, expect in (("kinco-servo", 0x2000), ("hcfa-am0520b", 0)):
        d = enable(Drive(model, plant=DrivePlant(pos_stop=5000)), 1, x6081=20_000,
                   x6083=100_000, x6084=100_000, x6065=1000, x6066=100)
        pp_move(d, 100_000)
        d.advance(300_000)                         # 4000 counts: within the window
        assert not d.statusword & 0x2000
        d.advance(450_000)                         # demand 7000, axis at 5000
        assert d.statusword & 0x2000 == expect, model
        d.advance(2_000_000)
        assert d.read(0x603F) == 0x8611


# ---------------------------------------------------------------- 605Ah

@pytest.mark.parametrize("model", ["hcfa-am0520b", "kinco-servo"])
def test_605ah_out_of_range_aborts_with_too_high_or_too_low(model):
    """HCFA §8.3 gives 605Ah as "0–65535"; the codes 0–8 are CiA 402's.  A
    value outside 0..8 is refused as every ranged object is (CiA 301:
    0x06090031 above the maximum, 0x06090032 below the minimum), as
    docs/cia402.md says; nothing changes."""
    d = Drive(model)
    for value, code in ((9, 0x06090031), (-1, 0x06090032)):
        with pytest.raises(SdoAbort) as e:
            d.write(0x605A, 0, value)
        assert e.value.code == code
    assert d.read(0x605A) == 2
    text = DOCS.read_text(encoding="utf-8")
    assert "setting 605Ah outside 0–8 is refused (SDO abort 0x06090031 above, 0x06090032 " \
           "below)" in text


# ---------------------------------------------------------------- the audit table

def audit_rows() -> list[str]:
    """The statement rows of docs/cia402.md's "Audit against the manuals"."""
    text = DOCS.read_text(encoding="utf-8")
    section = text.split("## Audit against the manuals", 1)[1].split("\n## ", 1)[0]
    return [line for line in section.splitlines()
            if line.startswith("| ") and not line.startswith("| manual | statement")]


def decisions_log() -> str:
    return DOCS.read_text(encoding="utf-8").split("## Decisions log", 1)[1]


def test_every_test_the_audit_table_names_exists():
    """docs/cia402.md, "Audit against the manuals": each row names a test of
    tests/devices/cia402/ that exists, or quotes a decision (“…”) that the
    decisions log holds, or both."""
    rows = audit_rows()
    assert len(rows) >= 150
    here = Path(__file__).parent
    defined = set()
    for f in here.glob("test_*.py"):
        defined |= set(re.findall(r"^def (test_[a-z0-9_]+)", f.read_text(encoding="utf-8"),
                                  re.M))
    log = decisions_log()
    missing, unlogged, bare = set(), set(), []
    for row in rows:
        last = row.rstrip(" |").rsplit(" | ", 1)[1]
        named = re.findall(r"`(test_[a-z0-9_]+)`", last)
        quoted = re.findall(r"decision “([^”]+)”", last)
        missing |= set(named) - defined
        unlogged |= {q for q in quoted if q not in log}
        if not named and not quoted:
            bare.append(row)
    assert sorted(missing) == [] and sorted(unlogged) == [] and bare == []


def test_the_audit_counts_are_the_tables():
    """The counts paragraph of the audit says what the tables hold: rows with
    a test (and how many of them also follow a decision), rows with a
    decision alone, the OD rows of test_cia402_audit_od.py and the parts of
    the manuals that are not simulated."""
    text = DOCS.read_text(encoding="utf-8")
    section = text.split("## Audit against the manuals", 1)[1].split("\n## ", 1)[0]
    rows = audit_rows()
    tested = [r for r in rows if "`test_" in r.rsplit(" | ", 1)[1]]
    both = [r for r in tested if "decision “" in r.rsplit(" | ", 1)[1]]
    od = sum(int(n) for n in re.findall(r"(?:§[\d.]+|tables|units) (\d+)",
                                         section.split("OD rows: ", 1)[1].split(")", 1)[0]))
    parts = section.split("### Not simulated", 1)[1].split("\n### ", 1)[0].count("\n- ")
    total = od + len(rows) + parts
    line = (f"{total} statements: {od} rows of the manuals' object tables, "
            f"{len(rows)} rows of the tables below ({len(tested)} honoured with a test, "
            f"{len(both)} of them a logged decision's reading; {len(rows) - len(tested)} "
            f"logged decisions alone) and {parts} parts of the manuals that are not simulated")
    assert line in " ".join(section.split()), line
