"""Every error from the public API is a PlcError that says what was expected.

A table of hostile arguments for every public entry point -- ``plcrt.load``,
the methods of :class:`plcrt.Plc` and of the test harness -- each with the
PlcError subclass it must raise and words its message must hold; then
hypothesis throws arbitrary Python values at the same entry points and
checks that nothing but a PlcError ever comes out (no TypeError,
AttributeError, ValueError or OverflowError from inside plcrt).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Callable

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import plcrt
from plcrt import PlcAddressError, PlcConfigError, PlcError, PlcSyntaxError
from plcrt.engine.values import MAX_STEPS
from plcrt.testing import Harness

ROOT = Path(__file__).resolve().parents[2]
TIMERS = ROOT / "programs" / "timers.awl"
EM253 = ROOT / "programs" / "em253"

Call = Callable[[], Any]


def _plc() -> plcrt.Plc:
    return plcrt.load(TIMERS)


def _h() -> Harness:
    return Harness.load(TIMERS)


def _forced_block(h: Harness, values: Any) -> None:
    with h.forced(values):
        pass


# (id, call, error class, words of the message)
LOAD_CASES: list[tuple[str, Call, type[PlcError], str]] = [
    ("None", lambda: plcrt.load(None), PlcConfigError,
     "the program must be a file path (str or pathlib.Path), STL text (a str with a newline), "
     "or a list of them; got NoneType None"),
    ("int", lambda: plcrt.load(123), PlcConfigError, "got int 123"),
    ("dict", lambda: plcrt.load({"x": 1}), PlcConfigError, "got dict"),
    ("empty list", lambda: plcrt.load([]), PlcConfigError, "no program given"),
    ("0-d array", lambda: plcrt.load(__import__("numpy").array(5)), PlcConfigError,
     "got ndarray"),
    ("endless iterable", lambda: plcrt.load(iter(int, 1)), PlcConfigError,
     "a program is at most 1000 files"),
    ("huge range", lambda: plcrt.load(range(10**12)), PlcConfigError,
     "a program is at most 1000 files"),
    ("None in list", lambda: plcrt.load([TIMERS, None]), PlcConfigError, "got NoneType"),
    ("bytes", lambda: plcrt.load(b"ORGANIZATION_BLOCK OB1\n"), PlcConfigError,
     "the program is bytes; give a file path"),
    ("bytearray", lambda: plcrt.load(bytearray(b"x")), PlcConfigError, "is bytearray"),
    ("empty string", lambda: plcrt.load(""), PlcConfigError, "the program is an empty string"),
    ("blank string", lambda: plcrt.load("   "), PlcConfigError, "empty string"),
    ("missing file", lambda: plcrt.load(Path("no/such.awl")), PlcSyntaxError, "no such file"),
    ("cpu int", lambda: plcrt.load(TIMERS, cpu=226), PlcConfigError,
     "the CPU model is a name such as 'CPU226' (known: CPU221"),
    ("cpu unknown", lambda: plcrt.load(TIMERS, cpu="CPU999"), PlcConfigError,
     "unknown CPU model 'CPU999'"),
    ("plant list", lambda: plcrt.load(TIMERS, plant=[1, 2]), PlcConfigError,
     "plant must be a plant file's path or TOML text, a dict, or a plcrt.devices.plant.Plant; "
     "got list [1, 2]"),
    ("plant int", lambda: plcrt.load(TIMERS, plant=5), PlcConfigError, "plant must be"),
    ("plant empty", lambda: plcrt.load(TIMERS, plant=""), PlcConfigError,
     "plant is an empty string"),
    ("data int", lambda: plcrt.load(TIMERS, data=123), PlcConfigError,
     "data must be a data block's path or text, or a plcrt.lang.DataBlock; got int 123"),
    ("data bytes", lambda: plcrt.load(TIMERS, data=b"VB0 1"), PlcConfigError, "data is bytes"),
    ("symbols int", lambda: plcrt.load(TIMERS, symbols=123), PlcConfigError,
     "symbols must be a symbol table's path or text, or a plcrt.lang.SymbolTable; got int 123"),
    ("symbols empty", lambda: plcrt.load(TIMERS, symbols=""), PlcConfigError,
     "symbols is an empty string"),
    ("scan_ms text", lambda: plcrt.load(TIMERS, scan_ms="10"), PlcConfigError, "scan time"),
    ("scan_ms nan", lambda: plcrt.load(TIMERS, scan_ms=math.nan), PlcConfigError, "scan time"),
    ("scan_ms bool", lambda: plcrt.load(TIMERS, scan_ms=True), PlcConfigError, "scan time"),
    ("pace", lambda: plcrt.load(TIMERS, pace="fast"), PlcConfigError,
     "pace must be 'simulated' or 'realtime'"),
    ("watchdog", lambda: plcrt.load(TIMERS, watchdog_ms=-1), PlcConfigError,
     "watchdog_ms must be a positive number"),
    ("system_symbols", lambda: plcrt.load(TIMERS, system_symbols=5), PlcConfigError,
     "system_symbols must be a dict"),
    ("unknown option", lambda: plcrt.load(TIMERS, scan=5), PlcConfigError,
     "load() got unknown option(s) 'scan'; the options are symbols, data, scan_ms, cpu"),
    ("Plc of text", lambda: plcrt.Plc("OB1"), PlcConfigError, "Plc() needs a parsed program"),
]

PLC_CASES: list[tuple[str, Callable[[plcrt.Plc], Any], type[PlcError], str]] = [
    ("plc[123]", lambda p: p[123], PlcAddressError,
     "an address is a string such as 'VW100', 'Q0.0' or a symbol name, got int 123"),
    ("plc[None]", lambda p: p[None], PlcAddressError, "got NoneType None"),
    ("plc['']", lambda p: p[""], PlcAddressError, "got an empty string"),
    ("plc[123]=", lambda p: p.__setitem__(123, 1), PlcAddressError, "got int 123"),
    ("read FLOAT", lambda p: p.read("VD0", "FLOAT"), PlcAddressError,
     "VD0: unknown format 'FLOAT' (:REAL reads a double word as a float (REAL); :BIT reads "
     "the bit of a timer or counter (T37:BIT))"),
    ("read :FLOAT", lambda p: p.read("VD0:FLOAT"), PlcAddressError, "unknown suffix ':FLOAT'"),
    ("read kind int", lambda p: p.read("VD0", 5), PlcAddressError, "a format is a string"),
    ("read twice", lambda p: p.read("VD0:REAL", "BIT"), PlcAddressError,
     "the format is given twice"),
    ("read REAL of word", lambda p: p.read("VW0", "REAL"), PlcAddressError,
     "a REAL needs a double word"),
    ("read BIT of V", lambda p: p.read("VW0", "BIT"), PlcAddressError,
     "':BIT' is for timers and counters"),
    ("write str", lambda p: p.write("VW0", "12"), PlcAddressError,
     "VW0: '12' is not a number (expected an int, a float or a bool, got str)"),
    ("write list", lambda p: p.write("VW0", [1]), PlcAddressError, "is not a number"),
    ("write VB0=-1", lambda p: p.write("VB0", -1), PlcAddressError,
     "VB0: -1 does not fit in a byte (BYTE), which takes 0 to 255; an S7-200 byte is unsigned"),
    ("write VB0=256", lambda p: p.write("VB0", 256), PlcAddressError, "takes 0 to 255"),
    ("write VW0=70000", lambda p: p.write("VW0", 70000), PlcAddressError,
     "VW0: 70000 does not fit in a word (INT or WORD), which takes -32768 to 65535"),
    ("write VD0 big", lambda p: p.write("VD0", 2**32), PlcAddressError,
     "takes -2147483648 to 4294967295"),
    ("write huge int", lambda p: p.write("VW0", 10**5000), PlcAddressError,
     "VW0: a 16610-bit integer does not fit in a word"),
    ("write huge float", lambda p: p.write("VW0", 1e300), PlcAddressError,
     "VW0: 1e+300 does not fit in a word"),
    ("write REAL range", lambda p: p.write("VD0", 3.5e38), PlcAddressError,
     "VD0: 3.5e+38 is out of the range of a REAL (about -3.4e38 to 3.4e38)"),
    ("write real to word", lambda p: p.write("VW0", 1.5), PlcAddressError,
     "VW0: a real value needs a double word (VD, MD, ...), got 1.5"),
    ("write nan to word", lambda p: p.write("VW0", math.nan), PlcAddressError,
     "a real value needs a double word"),
    ("write bit 2", lambda p: p.write("Q0.0", 2), PlcAddressError, "a bit takes 0 or 1, got 2"),
    ("write SM0.0", lambda p: p.write("SM0.0", 0), PlcAddressError,
     "SM0.0: SMB0 (SM0.0 always on, SM0.1 first scan, SM0.4/SM0.5 clocks, SM0.6 scan clock, "
     "SM0.7 RUN switch) is set by the CPU at the start of every scan and cannot be written "
     "or forced"),
    ("write SMW0", lambda p: p.write("SMW0", 0), PlcAddressError, "SMB0"),
    ("force SM0.1", lambda p: p.force("SM0.1", 1), PlcAddressError, "cannot be written or forced"),
    ("force str", lambda p: p.force("VW0", "x"), PlcAddressError, "is not a number"),
    ("force addr int", lambda p: p.force(7, 1), PlcAddressError, "got int 7"),
    ("unforce int", lambda p: p.unforce(7), PlcAddressError, "got int 7"),
    ("unforce not forced", lambda p: p.unforce("VW0"), PlcAddressError, "VW0 is not forced"),
    ("scan 1.5", lambda p: p.scan(1.5), PlcConfigError,
     "the number of scans must be a whole number (an int), got float 1.5"),
    ("scan 2.0", lambda p: p.scan(2.0), PlcConfigError, "must be an int, got the float 2.0; "
                                                         "write 2"),
    ("scan -1", lambda p: p.scan(-1), PlcConfigError, "the number of scans must not be negative"),
    ("scan str", lambda p: p.scan("3"), PlcConfigError, "got str '3'"),
    ("scan None", lambda p: p.scan(None), PlcConfigError, "got NoneType None"),
    ("scan True", lambda p: p.scan(True), PlcConfigError, "got bool True"),
    ("run nothing", lambda p: p.run(), PlcConfigError, "give exactly one of seconds"),
    ("run both", lambda p: p.run(1, 1), PlcConfigError, "give exactly one of seconds"),
    ("run nan", lambda p: p.run(seconds=math.nan), PlcConfigError,
     "seconds: a duration must be a non-negative, finite time, got nan"),
    ("run inf", lambda p: p.run(seconds=math.inf), PlcConfigError, "finite"),
    ("run -1", lambda p: p.run(seconds=-1), PlcConfigError, "non-negative"),
    ("run list", lambda p: p.run(seconds=[1]), PlcConfigError,
     "seconds: not a duration: list [1]"),
    ("run soon", lambda p: p.run("soon"), PlcConfigError,
     "seconds: not a duration: 'soon' (write e.g. 2, '1.5s', '200ms', '2min')"),
    ("run scans -1", lambda p: p.run(scans=-1), PlcConfigError, "scans must not be negative"),
    ("run scans 1.5", lambda p: p.run(scans=1.5), PlcConfigError, "scans must be a whole"),
    ("axis no plant", lambda p: p.axis(0, 0), PlcAddressError, "no module in slot 0"),
    ("axis str", lambda p: p.axis("0", 0), PlcAddressError,
     "an axis is named by two ints, slot and axis"),
    ("locate int", lambda p: p.locate(5), PlcAddressError, "got int 5"),
    ("reader None", lambda p: p.reader(None), PlcAddressError, "got NoneType"),
    ("reader bad", lambda p: p.reader("VW0:WORD"), PlcAddressError, "unknown suffix ':WORD'"),
    ("restore int", lambda p: p.restore(5), PlcConfigError,
     "restore() needs a snapshot made by snapshot(), got int"),
]

HARNESS_CASES: list[tuple[str, Callable[[Harness], Any], type[PlcError], str]] = [
    ("Harness(5)", lambda h: Harness(5), PlcConfigError, "Harness() wraps a plcrt.Plc"),
    ("watch str", lambda h: Harness(h.plc, watch="Q0.0"), PlcConfigError,
     "watch is a list of addresses such as ['Q0.0', 'VW10'], got str 'Q0.0'"),
    ("history str", lambda h: Harness(h.plc, history="x"), PlcConfigError,
     "history (a number of scans) must be a whole number"),
    ("load None", lambda h: Harness.load(None), PlcConfigError, "the program must be"),
    ("load empty", lambda h: Harness.load(""), PlcConfigError, "empty string"),
    ("load cpu", lambda h: Harness.load(TIMERS, cpu=226), PlcConfigError, "the CPU model"),
    ("load symbols", lambda h: Harness.load(TIMERS, symbols=123), PlcConfigError,
     "symbols must be"),
    ("load plant", lambda h: Harness.load(TIMERS, plant=[1]), PlcConfigError, "plant must be"),
    ("h[123]", lambda h: h[123], PlcAddressError, "got int 123"),
    ("read FLOAT", lambda h: h.read("VD0", "FLOAT"), PlcAddressError, "unknown format 'FLOAT'"),
    ("write VB0=-1", lambda h: h.write("VB0", -1), PlcAddressError, "unsigned"),
    ("scan 1.5", lambda h: h.scan(1.5), PlcConfigError, "whole number"),
    ("scan -1", lambda h: h.scan(-1), PlcConfigError, "must not be negative"),
    ("run nan", lambda h: h.run(seconds=math.nan), PlcConfigError, "finite"),
    ("run soon", lambda h: h.run("soon"), PlcConfigError, "not a duration: 'soon'"),
    ("run_until int", lambda h: h.run_until(123), PlcConfigError,
     "a condition is a string such as 'Q0.0' or 'VW100 >= 25', or a function; got int 123"),
    ("run_until bad addr", lambda h: h.run_until("XX9"), PlcAddressError, "not an address"),
    ("run_until timeout", lambda h: h.run_until("Q0.0", timeout=math.nan), PlcConfigError,
     "a duration must be a non-negative, finite time"),
    ("run_while", lambda h: h.run_while(None), PlcConfigError, "a condition is a string"),
    ("stays", lambda h: h.stays("Q0.0", -1), PlcConfigError, "non-negative"),
    ("watch int", lambda h: h.watch(5), PlcAddressError, "got int 5"),
    ("values", lambda h: h.values(None), PlcAddressError, "got NoneType"),
    ("set list", lambda h: h.set([1, 2]), PlcConfigError,
     "set() takes a dict of address -> value, got list"),
    ("patch str", lambda h: h.patch("I0.0"), PlcConfigError, "patch() takes a dict"),
    ("patch bad value", lambda h: h.patch({"I0.0": 1, "VB0": -1}), PlcAddressError, "unsigned"),
    ("pulse scans", lambda h: h.pulse("I0.0", scans=-1), PlcConfigError,
     "scans must not be negative"),
    ("pulse 1.5", lambda h: h.pulse("I0.0", scans=1.5), PlcConfigError, "whole number"),
    ("pulse value", lambda h: h.pulse("I0.0", value=2), PlcAddressError, "a bit takes 0 or 1"),
    ("force SM", lambda h: h.force("SM0.0", 0), PlcAddressError, "SMB0"),
    ("forced list", lambda h: _forced_block(h, [1]), PlcConfigError, "forced() takes a dict"),
    ("forced value", lambda h: _forced_block(h, {"Q0.0": 0, "VW0": "x"}), PlcAddressError,
     "is not a number"),
    ("unforce", lambda h: h.unforce(3), PlcAddressError, "got int 3"),
    ("stimulus int", lambda h: h.stimulus(5), PlcConfigError,
     "a stimulus is a list of (time, address, value) rows, got int"),
    ("stimulus row", lambda h: h.stimulus([(0, "VB0", -1)]), PlcAddressError,
     "stimulus row 1 (0, 'VB0', -1): VB0: -1 does not fit in a byte"),
    ("stimulus time", lambda h: h.stimulus([("soon", "I0.0", 1)]), PlcConfigError,
     "stimulus row 1"),
    ("stimulus addr", lambda h: h.stimulus([(0, 5, 1)]), PlcAddressError, "got int 5"),
    ("history_rows -1", lambda h: h.history_rows(-1), PlcConfigError,
     "the number of rows must not be negative"),
    ("history_table str", lambda h: h.history_table("2"), PlcConfigError,
     "the number of rows must be a whole number"),
    ("warnings", lambda h: h.warnings(5), PlcConfigError, "warnings(contains=...) takes a str"),
    ("limit_time", lambda h: h.limit_time("soon"), PlcConfigError, "not a duration"),
    ("trace bad", lambda h: h.trace("VD0:FLOAT"), PlcAddressError, "unknown suffix ':FLOAT'"),
    ("trace every", lambda h: h.trace("Q0.0", every=0), PlcConfigError, "every must be"),
    ("axis no plant", lambda h: h.axis(), PlcAddressError, "no module in slot 0"),
    ("axes/axis str", lambda h: h.axis(None, 0), PlcAddressError, "two ints"),
    ("axis_done_within", lambda h: h.axis_done_within("x"), PlcConfigError, "not a duration"),
    ("wait_axis_moving", lambda h: h.wait_axis_moving(timeout=math.inf), PlcConfigError,
     "finite"),
    ("restore", lambda h: h.restore("snap"), PlcConfigError, "needs a snapshot"),
    ("locate", lambda h: h.locate(1.5), PlcAddressError, "got float 1.5"),
]


def _check(call: Call, cls: type[PlcError], words: str) -> None:
    with pytest.raises(PlcError) as info:
        call()
    assert isinstance(info.value, cls), f"{type(info.value).__name__}: {info.value}"
    assert words in info.value.message


@pytest.mark.parametrize("call, cls, words", [c[1:] for c in LOAD_CASES],
                         ids=[c[0] for c in LOAD_CASES])
def test_load_refuses_hostile_arguments_with_a_plc_error(call: Call, cls: type[PlcError],
                                                         words: str) -> None:
    _check(call, cls, words)


@pytest.mark.parametrize("call, cls, words", [c[1:] for c in PLC_CASES],
                         ids=[c[0] for c in PLC_CASES])
def test_plc_methods_refuse_hostile_arguments_with_a_plc_error(
        call: Callable[[plcrt.Plc], Any], cls: type[PlcError], words: str) -> None:
    plc = _plc()
    _check(lambda: call(plc), cls, words)
    assert plc.scans == 0 and plc.mode == "RUN"          # nothing ran
    assert plc["VW0"] == plc["VB0"] == plc["Q0.0"] == 0  # nothing was written


@pytest.mark.parametrize("call, cls, words", [c[1:] for c in HARNESS_CASES],
                         ids=[c[0] for c in HARNESS_CASES])
def test_harness_methods_refuse_hostile_arguments_with_a_plc_error(
        call: Callable[[Harness], Any], cls: type[PlcError], words: str) -> None:
    h = _h()
    _check(lambda: call(h), cls, words)
    assert h.scans == 0                                   # nothing ran
    assert h["VW0"] == h["VB0"] == h["I0.0"] == 0         # nothing was written
    assert h.forces == {}


def test_checked_values_are_stored_as_documented() -> None:
    """The other side of the table: what is accepted, and how it is stored."""
    plc = _plc()
    plc["VW0"] = -1
    assert plc["VW0"] == -1 and plc["VB0"] == 255        # INT -1 is WORD 16#FFFF
    plc["VW0"] = 65535
    assert plc["VW0"] == -1
    plc["VW2"] = 2.0                                      # a whole float is its int
    assert plc["VW2"] == 2
    plc["VD4"] = math.inf                                 # the REAL format holds it
    assert plc.read("VD4", "REAL") == math.inf
    plc["VD4"] = math.nan
    assert math.isnan(plc.read("VD4:REAL"))
    plc["VB8"] = True
    assert plc["VB8"] == 1
    plc.run("20ms")
    plc.run(scans=0)
    plc.scan(0)
    assert plc.scans == 2


# ---------------------------------------------------------------------------
# Arbitrary values: nothing but a PlcError comes out
# ---------------------------------------------------------------------------

_ANY = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-(10**40), max_value=10**40),
    st.floats(), st.text(max_size=12), st.binary(max_size=8),
    st.lists(st.integers(), max_size=3), st.dictionaries(st.text(max_size=3), st.integers(),
                                                         max_size=2),
    st.tuples(st.integers(), st.text(max_size=3)), st.just(object()), st.just(Path(".")),
    st.sampled_from(["VW0", "Q0.0", "VD0:REAL", "T37:BIT", "VB0", "SM0.0", "I0.0", ":REAL",
                     "VD0:", "16#FF", "nan", "1.5s", "T37", "C5", "AC0", "VW0:FLOAT"]),
)
#: arguments that never ask for a long run: counts and durations stay small
_SMALL = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-5, max_value=5),
    st.floats(max_value=0.05), st.floats(min_value=-1e300, max_value=-1e-300),
    st.just(math.inf), st.just(math.nan), st.text(alphabet="-.0sm ux", max_size=5),
    st.binary(max_size=4), st.lists(st.integers(), max_size=2), st.just(object()),
)

_FUZZ_PLC = None
_FUZZ_H = None


def _fuzz_plc() -> plcrt.Plc:
    global _FUZZ_PLC
    if _FUZZ_PLC is None or _FUZZ_PLC.mode != "RUN":
        _FUZZ_PLC = _plc()
    return _FUZZ_PLC


def _fuzz_h() -> Harness:
    global _FUZZ_H
    if _FUZZ_H is None or _FUZZ_H.mode != "RUN":
        _FUZZ_H = _h()
    return _FUZZ_H


ENTRY_POINTS: dict[str, tuple[Callable[[Any, Any], Any], st.SearchStrategy[Any]]] = {
    "load(x)": (lambda x, _: plcrt.load(x) if not isinstance(x, str) or "\n" in x
                or not x.strip() else None, _ANY),
    "load(symbols=x)": (lambda x, _: plcrt.load(TIMERS, symbols=x)
                        if not isinstance(x, str) else None, _ANY),
    "load(data=x)": (lambda x, _: plcrt.load(TIMERS, data=x)
                     if not isinstance(x, str) else None, _ANY),
    "load(plant=x)": (lambda x, _: plcrt.load(TIMERS, plant=x)
                      if not isinstance(x, (str, dict)) else None, _ANY),
    "load(cpu=x)": (lambda x, _: plcrt.load(TIMERS, cpu=x), _ANY),
    "load(scan_ms=x)": (lambda x, _: plcrt.load(TIMERS, scan_ms=x), _ANY),
    "load(watchdog_ms=x)": (lambda x, _: plcrt.load(TIMERS, watchdog_ms=x), _ANY),
    "plc[x]": (lambda x, _: _fuzz_plc()[x], _ANY),
    "plc.read(x, y)": (lambda x, y: _fuzz_plc().read(x, y), _ANY),
    "plc.read('VD0', y)": (lambda x, y: _fuzz_plc().read("VD0", y), _ANY),
    "plc.write(x, y)": (lambda x, y: _fuzz_plc().write(x, y), _ANY),
    "plc.write('VB0', y)": (lambda x, y: _fuzz_plc().write("VB0", y), _ANY),
    "plc.write('VD0', y)": (lambda x, y: _fuzz_plc().write("VD0", y), _ANY),
    "plc.write('Q0.0', y)": (lambda x, y: _fuzz_plc().write("Q0.0", y), _ANY),
    "plc.force(x, y)": (lambda x, y: _fuzz_plc().force(x, y), _ANY),
    "plc.unforce(x)": (lambda x, _: _fuzz_plc().unforce(x), _ANY),
    "plc.locate(x)": (lambda x, _: _fuzz_plc().locate(x), _ANY),
    "plc.axis(x, y)": (lambda x, y: _fuzz_plc().axis(x, y), _ANY),
    "plc.restore(x)": (lambda x, _: _fuzz_plc().restore(x), _ANY),
    "plc.scan(x)": (lambda x, _: _fuzz_plc().scan(x), _SMALL),
    "plc.run(x)": (lambda x, _: _fuzz_plc().run(x), _SMALL),
    "plc.run(scans=x)": (lambda x, _: _fuzz_plc().run(scans=x), _SMALL),
    "h.run(x, y)": (lambda x, y: _fuzz_h().run(x, y), _SMALL),
    "h.run_until(x)": (lambda x, _: _fuzz_h().run_until(x, timeout="20ms")
                       if not callable(x) else None, _ANY),
    "h.run_until('Q0.0', timeout=x)": (lambda x, _: _fuzz_h().run_until("Q0.0", timeout=x),
                                       _SMALL),
    "h.stays(x, y)": (lambda x, y: _fuzz_h().stays(x, y) if not callable(x) else None, _SMALL),
    "h.pulse(x, y)": (lambda x, y: _fuzz_h().pulse(x, y), _SMALL),
    "h.patch(x, y)": (lambda x, y: _fuzz_h().patch(x, y), _SMALL),
    "h.set(x)": (lambda x, _: _fuzz_h().set(x), _ANY),
    "h.watch(x)": (lambda x, _: _fuzz_h().watch(x), _ANY),
    "h.history_rows(x)": (lambda x, _: _fuzz_h().history_rows(x), _ANY),
    "h.warnings(x)": (lambda x, _: _fuzz_h().warnings(x), _ANY),
    "h.limit_time(x)": (lambda x, _: Harness(_plc()).limit_time(x), _ANY),
    "h.trace(x)": (lambda x, _: _fuzz_h().trace(x).detach(), _ANY),
    "h.stimulus([(0, x, y)])": (lambda x, y: _fuzz_h().stimulus([(0, x, y)]), _ANY),
    "h.stimulus(x)": (lambda x, _: _fuzz_h().stimulus(x), _ANY),
}


@pytest.mark.parametrize("name", sorted(ENTRY_POINTS))
def test_arbitrary_arguments_raise_nothing_but_plc_errors(name: str) -> None:
    call, values = ENTRY_POINTS[name]

    @settings(max_examples=60, deadline=None, database=None,
              suppress_health_check=[HealthCheck.too_slow])
    @given(values, values)
    def check(x: Any, y: Any) -> None:
        try:
            call(x, y)
        except PlcError as e:
            assert e.message.strip(), "an error needs a message"
            assert "internal error" not in e.message
        except AssertionError as e:
            # the harness's way of failing a test (PlcTimeout, stays()), with a message
            assert name.startswith("h.") and str(e).strip()

    check()


def test_load_takes_any_iterable_of_sources() -> None:
    """A list, a tuple or a generator (``Path.glob``) of files: the blocks are merged."""
    for sources in ([TIMERS], (TIMERS,), (p for p in [TIMERS])):
        assert plcrt.load(sources).program.file == str(TIMERS)


@pytest.mark.parametrize("call", ["read", "getitem", "write", "force"])
@pytest.mark.parametrize("length", [300, 200_000])
def test_a_huge_address_is_not_echoed_in_full(call: str, length: int) -> None:
    """An address of hundreds of thousands of characters ends in a
    PlcAddressError that quotes at most 40 characters of it."""
    plc = plcrt.load(TIMERS)
    spec = "V" * length
    actions = {"read": lambda: plc.read(spec), "getitem": lambda: plc[spec],
               "write": lambda: plc.write(spec, 1), "force": lambda: plc.force(spec, 1)}
    with pytest.raises(plcrt.PlcAddressError) as err:
        actions[call]()
    assert len(str(err.value)) < 200 and "V" * 41 not in str(err.value)


# ---------------------------------------------------------------------------
# Huge ints, file names, encodings, scan counts and scan times
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("call", [
    lambda p, h: p.run(10**400), lambda p, h: p.run(seconds=10**400),
    lambda p, h: h.limit_time(10**400), lambda p, h: h.stimulus([(10**400, "I0.0", 1)]),
    lambda p, h: h.run_until("Q0.0", timeout=10**400),
    lambda p, h: h.stays("not Q0.0", 10**5000)],
    ids=["run", "run seconds", "limit_time", "stimulus", "run_until", "stays"])
def test_a_huge_int_duration_is_a_config_error(call: Callable[..., Any]) -> None:
    """An int too large for a float is a duration too long to count, said
    with its order of magnitude, before anything runs."""
    plc = _plc()
    h = Harness(_plc())
    with pytest.raises(PlcConfigError, match=r"about 1e\d+ s is too long to count in "
                                             r"microseconds"):
        call(plc, h)
    assert plc.scans == h.scans == 0


@pytest.mark.parametrize("kwargs", [{"source": "a\x00b"}, {"source": Path("a\x00b")},
                                    {"symbols": "sym\x00.txt"}, {"data": Path("d\x00.db")},
                                    {"plant": "p\x00.toml"}, {"source": "a\ud800.awl"}],
                         ids=["program", "program Path", "symbols", "data", "plant",
                              "surrogate"])
def test_a_file_name_no_file_can_have_is_a_config_error(kwargs: dict[str, Any]) -> None:
    """A NUL character (or an unencodable one) in any path argument names
    the argument and the character."""
    args = {"source": TIMERS, **kwargs}
    with pytest.raises(PlcConfigError) as info:
        plcrt.load(args.pop("source"), **args)
    what = next(iter(kwargs)).replace("source", "the program")
    assert info.value.message.startswith(f"{what}: the file name")
    assert "NUL character" in info.value.message or "U+D800" in info.value.message


def test_trace_and_plot_paths_are_checked(tmp_path: Path) -> None:
    from plcrt.trace import Trace, plot
    plc = _plc()
    tr = Trace(plc, ["Q0.0"])
    plc.scan(2)
    for write in (lambda p: tr.to_csv(p), lambda p: plot(tr, p)):
        with pytest.raises(PlcConfigError, match="NUL character"):
            write(str(tmp_path / "t\x00.svg"))
        with pytest.raises(PlcConfigError, match="cannot write the (trace|plot) to"):
            write(tmp_path / "no" / "such" / "t.svg")


@pytest.mark.parametrize("encoding", ["punycode", "undefined", "idna", "hex", "a\x00b"])
def test_an_encoding_stl_cannot_be_in_is_a_config_error(encoding: str) -> None:
    """Codecs that are not text encodings, always fail or mangle text are
    refused by name, for load and the harness alike."""
    for load in (plcrt.load, Harness.load):
        with pytest.raises(PlcConfigError, match="encoding"):
            load(TIMERS, encoding=encoding)


@pytest.mark.parametrize("call, words", [
    (lambda p: p.run(scans=2**70), "scans must be at most 1_000_000_000"),
    (lambda p: p.scan(MAX_STEPS + 1), "the number of scans must be at most 1_000_000_000"),
    (lambda p: p.run(1e300), "1e+300 s at 10 ms a scan is more than 1_000_000_000 scans"),
    (lambda p: p.run("99999999s"), "more than 1_000_000_000 scans"),
    (lambda p: Harness(p).run_until("Q0.0", timeout=1e12), "timeout: 1000000000000.0 s at 10 ms"),
    (lambda p: Harness(p).stimulus([(0, "I0.0", 1)], until=1e12), "until: 1000000000000.0 s"),
    (lambda p: Harness(p).pulse("I0.0", scans=2**70), "scans must be at most"),
    (lambda p: plcrt.link(p, 0, _plc(), 0).run(1e12), "synchronisation"),
], ids=["scans", "scan", "seconds", "text", "run_until", "until", "pulse", "link"])
def test_a_run_that_cannot_end_is_refused_before_it_starts(call: Callable[..., Any],
                                                           words: str) -> None:
    plc = _plc()
    with pytest.raises(PlcConfigError) as info:
        call(plc)
    assert words in info.value.message and "split a longer run" in info.value.message
    assert plc.scans == 0 and plc["I0.0"] == 0


def test_the_longest_run_is_allowed() -> None:
    """The bound is exactly MAX_STEPS scans (checked, not run: a Harness
    wait computes its count the same way)."""
    from plcrt.engine.values import scan_total
    assert scan_total(10_000, seconds=MAX_STEPS * 0.01) == MAX_STEPS
    assert scan_total(10_000, scans=MAX_STEPS) == MAX_STEPS
    with pytest.raises(PlcConfigError):
        scan_total(10_000, seconds=MAX_STEPS * 0.01 + 0.001)


def _progress_with_huge_wall() -> None:
    from plcrt.trace import run_with_progress
    run_with_progress(_plc(), scans=1, max_wall=10**400)


def _marker_with_a_name_too_long() -> None:
    from plcrt.testing.markers import PlcUsageError, _resolve
    try:
        _resolve("x" * 5000, "data", [ROOT])
    except PlcUsageError as e:
        raise PlcConfigError(str(e)) from None


@pytest.mark.parametrize("call, words", [
    (lambda: plcrt.load(TIMERS, entry=10**5000), "entry must name a block"),
    (lambda: Harness.load(EM253 / "pos_goto_r.awl", plant=EM253 / "plant.toml")
     .axis_done_within(1.0, axis=10**5000), "-bit integer"),
    (_progress_with_huge_wall, "--max-wall must be a positive number of seconds"),
    (_marker_with_a_name_too_long, "File name too long"),
], ids=["entry huge int", "axis huge int", "max_wall huge int", "marker file name too long"])
def test_values_no_message_or_file_system_can_take_are_plc_errors(call: Call, words: str) -> None:
    """Found by the API fuzz: a huge int quoted in a message, an int too
    large for a float added to a clock, a file name the file system cannot
    look up."""
    with pytest.raises(PlcError) as info:
        call()
    assert words in str(info.value)
