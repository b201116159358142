"""Table tests for plcrt.isa.clock and plcrt.engine.clock: TODR, TODW,
TODRX, TODWX over the simulated real-time clock (S7-200 System Manual,
"Clock instructions": 8 BCD bytes year, month, day, hour, minute, second, 0,
day of week 1 = Sunday, 0 = disabled; SMART: 19 bytes with the
daylight-saving settings), and the clock's start from load(), the CLI and
the plant file."""

from __future__ import annotations

import datetime as dt
import json

import pytest

import plcrt
from plcrt.cli import main
from plcrt.engine.clock import DEFAULT_START
from plcrt.errors import PlcConfigError
from stl_helpers import ob1_text

READ = "LD SM0.0\nTODR VB0"
WRITE = "LD SM0.1\nTODW VB20\nAENO\nS Q0.0, 1"


def _load(body: str = READ, **kw) -> plcrt.Plc:
    return plcrt.load(ob1_text(body), **kw)


def _bytes(p: plcrt.Plc, off: int, n: int = 8) -> bytes:
    return bytes(p.mem.areas["V"][off:off + n])


def test_default_start_is_fixed():
    """Without a start the clock reads 2024-01-01 00:00:00, a Monday (day 2),
    whatever the host's clock says."""
    p = _load()
    p.scan()
    assert DEFAULT_START == dt.datetime(2024, 1, 1)
    assert _bytes(p, 0) == bytes.fromhex("2401010000000002")


@pytest.mark.parametrize("clock", ["2026-12-02T08:00:00", "2026-12-02 08:00",
                                   dt.datetime(2026, 12, 2, 8, 0, 0)])
def test_start_from_load(clock):
    """load(clock=) takes a datetime or ISO text; 2026-12-02 is a Wednesday (4)."""
    p = _load(clock=clock)
    p.scan()
    assert _bytes(p, 0) == bytes.fromhex("2612020800000004")


def test_clock_advances_with_simulated_time():
    """The reading advances with simulated time: seconds, the minute,
    midnight, the day of week and the month and year roll over."""
    p = _load(clock="2025-12-31T23:59:58", scan_ms=500)
    seen = []
    for _ in range(6):
        p.scan()
        seen.append(_bytes(p, 0).hex())
    assert seen == ["2512312359580004", "2512312359580004", "2512312359590004",
                    "2512312359590004", "2601010000000005", "2601010000000005"]


def test_clock_reads_in_an_interrupt_at_its_time():
    """Code runs at the instant of its scan: the scan start (TODR in OB1)."""
    p = _load(clock="2026-02-28T12:00:00", scan_ms=1000)
    p.run(seconds=3600 * 12)
    p.scan()
    assert _bytes(p, 0) == bytes.fromhex("2603010000000001")   # Sunday, March 1st


# TODW: (id, the 8 bytes written, ENO, what TODR reads one scan later)
TODW = [
    ("a Saturday", "9912311230450007", 1, "9912311230450007"),
    ("day of week 0 disables it", "2406150800000000", 1, "2406150800000000"),
    ("wrong weekday kept", "2406150800000003", 1, "2406150800000003"),
    ("February 30 carries on", "2502300800000001", 1, "2503020800000001"),
    ("month 13", "2513010000000001", 0, None),
    ("month 0", "2500010000000001", 0, None),
    ("day 32", "2501320000000001", 0, None),
    ("hour 24", "2501012400000001", 0, None),
    ("second 60", "2501010000600001", 0, None),
    ("non-BCD digit", "2501010A00000001", 0, None),
    ("day of week 8", "2501010000000008", 0, None),
]


@pytest.mark.parametrize("data,eno,reads", [c[1:] for c in TODW], ids=[c[0] for c in TODW])
def test_todw(data, eno, reads):
    """TODW sets the clock from valid BCD; an invalid field is error 0007
    (SM4.3, ENO 0, clock unchanged); the day of week is kept as written."""
    p = plcrt.load(ob1_text(WRITE, READ), scan_ms=100)
    p.mem.areas["V"][20:28] = bytes.fromhex(data)
    p.scan(2)
    assert p["Q0.0"] == eno
    if eno:
        assert _bytes(p, 0).hex() == reads
        assert p["SM4.3"] == 0
    else:
        assert _bytes(p, 0).hex() == "2401010000000002"
        assert p["SM4.3"] == 1
        assert any("0007" in d.message for d in p.diagnostics)


def test_written_day_of_week_counts_on_at_midnight():
    """A weekday written out of step with the date stays out of step: it
    advances by one at midnight (the CPU does not check it)."""
    p = plcrt.load(ob1_text(WRITE, READ), scan_ms=1000)
    p.mem.areas["V"][20:28] = bytes.fromhex("2406152359590003")
    p.scan(2)
    assert _bytes(p, 0).hex() == "2406160000000004"


def test_todw_keeps_running_from_the_new_time():
    """After TODW the clock runs on from the value written."""
    p = plcrt.load(ob1_text(WRITE, READ), scan_ms=1000)
    p.mem.areas["V"][20:28] = bytes.fromhex("3001010000000002")
    p.scan(62)
    assert _bytes(p, 0).hex() == "3001010001010002"


def test_todrx_reads_the_daylight_saving_settings_todwx_wrote():
    """TODWX stores mode and rule (bytes 8..18); TODRX reads them back with
    the time (here just before the rule's start: no shift yet)."""
    p = plcrt.load(ob1_text("LD SM0.1\nTODWX VB40\nAENO\nS Q0.0, 1", "LD SM0.0\nTODRX VB0"))
    data = bytes.fromhex("2603290159000001" + "FF" + "0100" + "03290200" + "10250300")
    p.mem.areas["V"][40:59] = data
    p.scan(2)
    assert p["Q0.0"] == 1
    assert _bytes(p, 0, 19) == data


#: rule bytes 9..18 of a mode without a user rule
NO_RULE = "00" * 10


# (id, mode and rule, the time written, seconds run, the time read): the
# clock jumps forward at the start and back at the end of daylight saving
DST = [
    ("EU UTC+1 spring", "02" + NO_RULE, "2603290159590001", 1, "260329030000"),
    ("EU UTC+1 autumn", "02" + NO_RULE, "2610250259590001", 1, "261025020000"),
    ("EU UTC spring", "01" + NO_RULE, "2603290059590001", 1, "260329020000"),
    ("EU UTC+2 spring", "03" + NO_RULE, "2603290259590001", 1, "260329040000"),
    ("EU UTC-1 spring", "08" + NO_RULE, "2603282359590007", 1, "260329010000"),
    ("US spring", "10" + NO_RULE, "2603080159590001", 1, "260308030000"),
    ("US autumn", "10" + NO_RULE, "2611010159590001", 1, "261101010000"),
    ("Australia spring", "11" + NO_RULE, "2610040159590001", 1, "261004030000"),
    ("Australia autumn", "11" + NO_RULE, "2604050259590001", 1, "260405020000"),
    ("Tasmania spring", "12" + NO_RULE, "2610040159590001", 1, "261004030000"),
    ("New Zealand spring", "13" + NO_RULE, "2609270159590001", 1, "260927030000"),
    ("user rule 30 min", "FF0030" + "06010800" + "09010900", "2606010759590002", 1,
     "260601083000"),
    ("user rule end", "FF0030" + "06010800" + "09010900", "2609010859590003", 1,
     "260901083000"),
    ("summer reads as written", "02" + NO_RULE, "2607011200000004", 3600, "260701130000"),
    ("winter reads as written", "02" + NO_RULE, "2601151200000005", 60, "260115120100"),
    ("mode 0: no shift", "00" + NO_RULE, "2603290159590001", 1, "260329020000"),
]


@pytest.mark.parametrize("extra,written,seconds,reads", [c[1:] for c in DST],
                         ids=[c[0] for c in DST])
def test_daylight_saving(extra, written, seconds, reads):
    """With a daylight-saving mode the clock goes forward by the correction
    at the start and back at the end (EU at 01:00 UTC, US, Australia and
    New Zealand at their civil rules, a user rule at its dates); a time
    written inside the window is the daylight time."""
    p = plcrt.load(ob1_text("LD SM0.1\nTODWX VB40\nAENO\nS Q0.0, 1", "LD SM0.0\nTODR VB0"),
                   scan_ms=1000)
    p.mem.areas["V"][40:59] = bytes.fromhex(written + extra)
    p.scan(seconds + 1)
    assert p["Q0.0"] == 1
    assert _bytes(p, 0, 6).hex() == reads


def test_autumn_hour_runs_twice():
    """At the end of daylight saving the hour before it is read twice."""
    p = plcrt.load(ob1_text("LD SM0.1\nTODWX VB40", "LD SM0.0\nTODR VB0"), scan_ms=60_000)
    p.mem.areas["V"][40:59] = bytes.fromhex("2610250230000001" + "02" + NO_RULE)
    hours = []
    p.scan()
    for _ in range(12):
        hours.append(_bytes(p, 3, 2).hex())
        p.scan(10)
    assert hours == ["0230", "0240", "0250", "0200", "0210", "0220", "0230", "0240", "0250",
                     "0300", "0310", "0320"]


@pytest.mark.parametrize("extra", ["04" + "00" * 10, "FF" + "24" + "00" * 9,
                                   "FF0100" + "13290200" + "10250300"])
def test_todwx_refuses_unknown_modes_and_bad_rules(extra):
    """A reserved mode, or a user rule (16#FF) with a field out of range, is
    error 0007: nothing changes."""
    p = plcrt.load(ob1_text("LD SM0.1\nTODWX VB40\nAENO\nS Q0.0, 1", "LD SM0.0\nTODRX VB0"))
    p.mem.areas["V"][40:59] = bytes.fromhex("2603290159000001" + extra)
    p.scan(2)
    assert p["Q0.0"] == 0 and p["SM4.3"] == 1
    assert _bytes(p, 0, 19) == bytes.fromhex("2401010000000002") + bytes(11)


def test_fork_copies_the_clock():
    """A fork reads the same time and date, including what TODW set, and
    running one does not move the other's clock."""
    p = plcrt.load(ob1_text(WRITE, READ), scan_ms=1000)
    p.mem.areas["V"][20:28] = bytes.fromhex("3001010000000002")
    p.scan(2)
    twin = p.fork()
    twin.scan(10)
    p.scan()
    assert _bytes(p, 0).hex() == "3001010000020002"
    assert _bytes(twin, 0).hex() == "3001010000110002"


def test_plant_file_clock(tmp_path):
    """The plant file's [cpu] clock sets the start; load(clock=) wins over it."""
    plant = '[cpu]\nclock = "2026-12-02T08:00:00"\n'
    p = _load(plant=plant)
    p.scan()
    assert _bytes(p, 0).hex() == "2612020800000004"
    q = _load(plant=plant, clock="2027-01-01T00:00:00")
    q.scan()
    assert _bytes(q, 0).hex() == "2701010000000006"
    r = _load(plant="[cpu]\nclock = 2026-12-02T08:00:00\n")   # a TOML date-time
    r.scan()
    assert _bytes(r, 0).hex() == "2612020800000004"


@pytest.mark.parametrize("bad,match", [("[cpu]\nclock = \"yesterday\"\n", "cpu.clock"),
                                       ("[cpu]\nclock = \"1999-12-31T00:00:00\"\n",
                                        "2000..2099"),
                                       ("[cpu]\nclock = 5\n", "cpu.clock")])
def test_plant_file_clock_is_checked(bad, match):
    """A plant clock that is no date-time, or outside 2000..2099, is a config error."""
    with pytest.raises(PlcConfigError, match=match):
        _load(plant=bad)


@pytest.mark.parametrize("clock", ["tomorrow", 12, "2100-01-01T00:00:00"])
def test_load_clock_is_checked(clock):
    """load(clock=) refuses what is not a date-time in 2000..2099."""
    with pytest.raises(PlcConfigError):
        _load(clock=clock)


def test_clock_now_is_the_host_clock_only_when_asked():
    """clock="now" starts at the host's local time (to the second)."""
    before = dt.datetime.now().replace(microsecond=0)
    p = _load(clock="now")
    after = dt.datetime.now()
    assert before <= p.clock.now() <= after


def test_cli_clock_option(tmp_path, capsys):
    """plcrt run --clock sets the start; the JSON reports the clock's reading."""
    prog = tmp_path / "p.awl"
    prog.write_text(ob1_text(READ))
    code = main(["run", str(prog), "--scans", "100", "--clock", "2026-12-02T08:00:00",
                 "--watch", "VB5", "--watch", "VB7", "--json"])
    obj = json.loads(capsys.readouterr().out)
    assert code == 0
    assert obj["clock"] == "2026-12-02T08:00:01"
    assert obj["values"] == {"VB5": 0, "VB7": 4}


def test_cli_bad_clock_is_an_error(tmp_path, capsys):
    """A --clock that is no date-time is an input error (status 1), named."""
    prog = tmp_path / "p.awl"
    prog.write_text(ob1_text(READ))
    code = main(["run", str(prog), "--scans", "1", "--clock", "someday"])
    assert code == 1
    assert "clock" in capsys.readouterr().err


def test_buffer_past_area_end_is_refused():
    """TODRX's 19 bytes must fit the area (compile error with the location)."""
    with pytest.raises(plcrt.PlcCompileError, match="runs past the end"):
        _load("LD SM0.0\nTODRX VB10230")


def test_harness_clock():
    """Harness.load(clock=) starts the clock as load() does."""
    from plcrt.testing import Harness
    h = Harness.load(ob1_text(READ), clock="2026-12-02T08:00:00")
    h.scan()
    assert h.plc.clock.now().isoformat() == "2026-12-02T08:00:00"
    assert h.read("VB7") == 4


pytest_plugins = ["pytester"]


def test_plugin_marker_clock(pytester):
    """The plc marker and plc_factory take clock=; a bad one is a usage error."""
    (pytester.path / "p.awl").write_text(ob1_text(READ))
    pytester.makepyfile(test_clk="""\
import pytest

@pytest.mark.plc("p.awl", clock="2026-12-02T08:00:00")
def test_marker(plc):
    plc.scan()
    assert plc.read("VB7") == 4 and plc.read("VB3") == 8

def test_factory(plc_factory):
    h = plc_factory("p.awl", clock="2030-06-01 12:00")
    h.scan()
    assert h.read("VB0") == 0x30 and h.read("VB3") == 0x12

@pytest.mark.plc("p.awl", clock="soon")
def test_bad(plc):
    pass
""")
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    result.assert_outcomes(passed=2, errors=1)
    result.stdout.fnmatch_lines(["*clock=*2026-12-02T08:00:00*"])
