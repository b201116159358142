"""The per-scan recorder (:class:`plcrt.trace.Trace`): what is sampled and
when, the array types, ``every``/``limit``, accessors and the CSV format.

The program's values are exactly known: T33 is a 10 ms TON, so with 10 ms
scans it counts one per scan from the scan after IN turned on (it advances
at the start of a scan by the ticks since the previous scan start); T37 is
a 100 ms timer; VW100 counts scans; VD200 adds 0.5 per scan as a REAL.
"""

from __future__ import annotations

import io

import numpy as np
import pytest

import plcrt
from plcrt.errors import PlcAddressError, PlcConfigError
from plcrt.lang import parse_symbols
from plcrt.trace import Trace
from stl_helpers import ob1_text

PROGRAM = ob1_text(
    "LD I0.0\nTON T33, +5",          # 10 ms on-delay, 50 ms
    "LD T33\n= Q0.0",
    "LD SM0.0\nINCW VW100",          # scan counter
    "LD SM0.0\n+R 0.5, VD200",       # REAL ramp
    "LD I0.0\nTON T37, +2",          # 100 ms on-delay
    "LD SM0.0\nMOVW -3, VW110\nMOVB 200, VB112\nMOVD -70000, VD114",
)
SIGNALS = ["I0.0", "T33", "T33:BIT", "Q0.0", "VW100", "VD200:REAL", "T37"]


def make_plc() -> plcrt.Plc:
    return plcrt.load(PROGRAM, scan_ms=10)


def run_toggle(signals: list[str] = SIGNALS, **kw: object) -> Trace:
    """I0.0 on for 8 scans, then off for 4."""
    plc = make_plc()
    trace = Trace(plc, signals, **kw)
    plc["I0.0"] = 1
    plc.scan(8)
    plc["I0.0"] = 0
    plc.scan(4)
    return trace


def test_per_scan_values_exact() -> None:
    tr = run_toggle()
    assert len(tr) == 12
    # a sample is taken at the end of a scan, stamped with plc.time then
    assert tr.time.dtype == np.float64
    assert tr.time.tolist() == [k / 100 for k in range(1, 13)]
    assert tr["I0.0"].tolist() == [1] * 8 + [0] * 4
    assert tr["T33"].tolist() == [0, 1, 2, 3, 4, 5, 6, 7, 0, 0, 0, 0]
    assert tr["T33:BIT"].tolist() == [0, 0, 0, 0, 0, 1, 1, 1, 0, 0, 0, 0]
    assert tr["Q0.0"].tolist() == [0, 0, 0, 0, 0, 1, 1, 1, 0, 0, 0, 0]
    assert tr["VW100"].tolist() == list(range(1, 13))
    assert tr["VD200:REAL"].tolist() == [0.5 * k for k in range(1, 13)]
    assert tr["T37"].tolist() == [0] * 12   # 100 ms not reached while I0.0 was on


def test_dtypes_and_signed_unsigned() -> None:
    plc = make_plc()
    tr = Trace(plc, ["VW110", "VB112", "VD114", "VD200:REAL", "Q0.0", "T33"])
    plc.scan(2)
    assert tr["VW110"].tolist() == [-3, -3]
    assert tr["VB112"].tolist() == [200, 200]
    assert tr["VD114"].tolist() == [-70000, -70000]
    for name in ("VW110", "VB112", "VD114", "Q0.0", "T33"):
        assert tr[name].dtype == np.int64
    assert tr["VD200:REAL"].dtype == np.float64
    assert tr.kind("Q0.0") == "bit" and tr.kind("T33") == "int"
    assert tr.kind("VD200:REAL") == "real"


def test_timer_value_over_longer_run() -> None:
    """T37 (100 ms) reaches 2 after 20 scans of 10 ms, its bit with it."""
    plc = make_plc()
    plc["I0.0"] = 1
    tr = Trace(plc, ["T37", "T37:BIT"])
    plc.scan(25)
    assert tr["T37"].tolist() == [0] * 10 + [1] * 10 + [2] * 5
    assert tr["T37:BIT"].tolist() == [0] * 20 + [1] * 5
    assert tr.changes("T37").tolist() == [0.11, 0.21]
    assert tr.changes("T37:BIT").tolist() == [0.21]


def test_samples_match_plc_read_at_every_scan() -> None:
    plc = make_plc()
    plc["I0.0"] = 1
    tr = Trace(plc, SIGNALS)
    seen = []
    for _ in range(15):
        plc.scan()
        seen.append((plc.time, plc.read("T33"), plc.read("VD200", "REAL"), plc.read("T37")))
    assert [(r[0], r[2], r[6], r[7]) for r in tr.last(15)] == seen


def test_every_records_on_multiples_of_the_scan_count() -> None:
    tr = run_toggle(["VW100", "T33"], every=3)
    assert tr.time.tolist() == [0.03, 0.06, 0.09, 0.12]
    assert tr["VW100"].tolist() == [3, 6, 9, 12]
    assert tr["T33"].tolist() == [2, 5, 0, 0]


def test_limit_keeps_the_last_samples() -> None:
    tr = run_toggle(["VW100", "VD200:REAL"], limit=5)
    assert len(tr) == 5
    assert tr.time.tolist() == [0.08, 0.09, 0.1, 0.11, 0.12]
    assert tr["VW100"].tolist() == [8, 9, 10, 11, 12]
    assert tr["VD200:REAL"].tolist() == [4.0, 4.5, 5.0, 5.5, 6.0]


def test_every_and_limit_together() -> None:
    tr = run_toggle(["VW100"], every=2, limit=3)
    assert tr["VW100"].tolist() == [8, 10, 12]


def test_arrays_are_refreshed_after_more_scans() -> None:
    plc = make_plc()
    tr = Trace(plc, ["VW100"])
    plc.scan(2)
    first = tr["VW100"]
    assert first.tolist() == [1, 2]
    assert tr.array("VW100") is first          # cached until the next sample
    plc.scan(1)
    assert tr["VW100"].tolist() == [1, 2, 3]
    assert first.tolist() == [1, 2]            # an old array is not changed
    with pytest.raises(ValueError):
        first[0] = 5                            # and it is read-only


def test_detach_and_context_manager() -> None:
    plc = make_plc()
    with Trace(plc, ["VW100"]) as tr:
        assert plc.observers == [tr._record]
        plc.scan(3)
    assert plc.observers == []
    plc.scan(3)
    assert tr["VW100"].tolist() == [1, 2, 3]
    tr.detach()   # twice is harmless
    tr2 = Trace(plc, ["VW100"])
    tr2.detach()
    plc.scan(1)
    assert len(tr2) == 0
    assert "detached" in repr(tr2)


def test_two_traces_record_independently() -> None:
    plc = make_plc()
    a = Trace(plc, ["VW100"])
    plc.scan(2)
    b = Trace(plc, ["VW100", "Q0.0"])
    plc.scan(2)
    assert a["VW100"].tolist() == [1, 2, 3, 4]
    assert b["VW100"].tolist() == [3, 4]


def test_nothing_recorded_in_stop_mode() -> None:
    plc = plcrt.load(ob1_text("LD SM0.0\nINCW VW0", "LDW>= VW0, 3\nSTOP"))
    tr = Trace(plc, ["VW0"])
    plc.scan(10)
    assert plc.mode == "STOP"
    assert tr["VW0"].tolist() == [1, 2, 3]


def test_faulting_scan_is_not_recorded() -> None:
    plc = plcrt.load(ob1_text("LD SM0.0\nINCW VW0",
                              "LDW>= VW0, 3\nMOVD +0, AC1\nMOVW *AC1, VW10"))
    tr = Trace(plc, ["VW0"])
    with pytest.raises(plcrt.PlcRuntimeError):
        plc.scan(10)
    assert tr["VW0"].tolist() == [1, 2]


def test_symbols() -> None:
    symbols = parse_symbols('"Lamp","Q0.0",""\n"Count, scans","VW100",""\n', "s.sdf")
    plc = plcrt.load(PROGRAM, symbols=symbols)
    plc["I0.0"] = 1
    tr = Trace(plc, ["Lamp", "Count, scans"])
    plc.scan(7)
    assert tr.names == ["Lamp", "Count, scans"]
    assert tr["Lamp"].tolist() == [0, 0, 0, 0, 0, 1, 1]
    out = io.StringIO()
    tr.to_csv(out)
    assert out.getvalue().splitlines()[0] == 'time_s,Lamp,"Count, scans"'


def test_last_table_changes() -> None:
    tr = run_toggle()
    assert tr.last(2) == [(0.11, 0, 0, 0, 0, 11, 5.5, 0), (0.12, 0, 0, 0, 0, 12, 6.0, 0)]
    assert tr.last(0) == []
    assert len(tr.last(100)) == 12
    assert tr.table(2) == [
        ["time_s", *SIGNALS],
        ["0.11", "0", "0", "0", "0", "11", "5.5", "0"],
        ["0.12", "0", "0", "0", "0", "12", "6", "0"],
    ]
    assert tr.changes("Q0.0").tolist() == [0.06, 0.09]
    assert tr.changes("I0.0").tolist() == [0.09]
    assert tr.changes("VW100").tolist() == [k / 100 for k in range(2, 13)]


def test_csv_exact(tmp_path) -> None:
    tr = run_toggle(["I0.0", "T33", "Q0.0", "VD200:REAL"], every=2)
    path = tmp_path / "t.csv"
    tr.to_csv(path)
    assert path.read_text(encoding="utf-8") == (
        "time_s,I0.0,T33,Q0.0,VD200:REAL\n"
        "0.02,1,1,0,1.0\n"
        "0.04,1,3,0,2.0\n"
        "0.06,1,5,1,3.0\n"
        "0.08,1,7,1,4.0\n"
        "0.1,0,0,0,5.0\n"
        "0.12,0,0,0,6.0\n")
    buf = io.StringIO()
    tr.to_csv(buf)
    assert buf.getvalue() == path.read_text(encoding="utf-8")


def test_csv_floats_keep_repr_precision() -> None:
    plc = plcrt.load(ob1_text("LD SM0.0\n+R 0.1, VD0"))
    tr = Trace(plc, ["VD0:REAL"])
    plc.scan(2)
    out = io.StringIO()
    tr.to_csv(out)
    rows = out.getvalue().splitlines()
    # 0.1 as a REAL is 0.100000001490116...; the CSV gives the exact double
    assert rows[1] == f"0.01,{float(np.float32(0.1))!r}"
    assert float(rows[2].split(",")[1]) == tr["VD0:REAL"][1]


def test_empty_trace() -> None:
    tr = Trace(make_plc(), ["VW100"])
    assert len(tr) == 0
    assert tr.time.tolist() == [] and tr["VW100"].dtype == np.int64
    assert tr.changes("VW100").tolist() == []
    out = io.StringIO()
    tr.to_csv(out)
    assert out.getvalue() == "time_s,VW100\n"


@pytest.mark.parametrize(("signal", "error", "text"), [
    ("X9.9", PlcAddressError, "trace signal 'X9.9': 'X9.9' is not an address"),
    ("VW999999", PlcAddressError, "out of range"),
    ("VW100:REAL", PlcAddressError, "a REAL needs a double word"),
    ("T37:REAL", PlcAddressError, "a REAL needs a double word"),
    ("Q0.0:BIT", PlcAddressError, "':BIT' is for timers and counters"),
    ("VD0:FLOAT", PlcAddressError, "unknown suffix ':FLOAT'"),
    ("", PlcConfigError, "give an address"),
    ("axis0.0.speed", PlcAddressError, "no plant is loaded"),
    ("axis0.0.torque", PlcConfigError, "quantity position|mechanical|speed"),
    ("axis0.speed", PlcConfigError, "axis<slot>.<axis>.<quantity>"),
])
def test_bad_signals(signal: str, error: type, text: str) -> None:
    plc = make_plc()
    with pytest.raises(error) as info:
        Trace(plc, ["VW100", signal])
    assert text in info.value.message
    assert plc.observers == []   # nothing attached after a failure


@pytest.mark.parametrize(("kw", "text"), [
    (dict(every=0), "every must be"),
    (dict(every=1.5), "every must be"),
    (dict(limit=0), "limit must be"),
])
def test_bad_options(kw: dict, text: str) -> None:
    with pytest.raises(PlcConfigError, match=text):
        Trace(make_plc(), ["VW100"], **kw)


def test_no_or_duplicate_signals() -> None:
    with pytest.raises(PlcConfigError, match="at least one signal"):
        Trace(make_plc(), [])
    with pytest.raises(PlcConfigError, match="given twice"):
        Trace(make_plc(), ["VW100", " VW100 "])


def test_unknown_name_is_a_key_error() -> None:
    tr = Trace(make_plc(), ["VW100"])
    with pytest.raises(KeyError, match="no signal 'VW102'"):
        tr["VW102"]
    assert "VW100" in tr and "VW102" not in tr
