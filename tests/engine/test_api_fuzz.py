"""The API fuzz: hostile values at every parameter of every public entry point.

The public surface is enumerated from the public modules (``plcrt``,
``plcrt.testing``, ``plcrt.trace``, ``plcrt.cia402``): every function, and
every public method, constructor, item access and property setter of every
class they export (and of the objects they hand out: the CANopen
simulator, axis and drive states).  :func:`test_every_public_parameter_is_fuzzed`
fails when a parameter has no entry in :data:`FUZZ`, so a new public method
is fuzzed or the test says which one is missing.

Each entry calls its callable with sane values for the other parameters and
a hypothesis value for its own: huge ints (``10**400``), NUL characters in
text and paths, encodings that are not text encodings or always fail,
NaN, infinities, negative numbers, containers, arbitrary objects.  Nothing
but a :class:`~plcrt.PlcError` may come out (the harness may also fail a
test with an ``AssertionError``, its way of reporting a timeout).  Durations
and scan counts get values that are either short or refused, so an example
never asks for a long run.

``PLCRT_FUZZ_EXAMPLES`` sets the examples per entry (default 8, as in CI);
``PLCRT_FUZZ_EXAMPLES=2000 pytest tests/engine/test_api_fuzz.py -n 4`` is
the large run (docs/testing.md).
"""

from __future__ import annotations

import inspect
import io
import math
import os
import tempfile
from decimal import Decimal
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import plcrt
import plcrt.cia402
import plcrt.testing
import plcrt.trace
from plcrt import PlcError
from plcrt.devices import DriveState
from plcrt.devices.cia402.canopen_node import CanopenDrive
from plcrt.devices.machines import Machine
from plcrt.engine.runtime import parse_sources
from plcrt.engine.values import LOAD_OPTIONS, MAX_STEPS
from plcrt.testing import Harness

ROOT = Path(__file__).resolve().parents[2]
TIMERS = ROOT / "programs" / "timers.awl"
EM253 = ROOT / "programs" / "em253"
BUS = ROOT / "examples" / "bus_drive"

#: examples per entry: small in CI, thousands for a local hunt
EXAMPLES = int(os.environ.get("PLCRT_FUZZ_EXAMPLES", "8"))

# ---------------------------------------------------------------------------
# Hostile values
# ---------------------------------------------------------------------------

_HUGE = st.sampled_from([2**63, 2**64 + 1, 2**70, -(2**70), 10**400, -(10**400), 10**5000])
_TEXT = st.sampled_from([
    "a\x00b", "\x00", "VW0\x00", "Q0.0\x00", "\ud800", "x\udcff", "", " ", "\n", "x" * 5000,
    "punycode", "undefined", "idna", "utf-7", "hex", "rot13", "base64", "1e400", "-1",
    "nan", "inf", "-inf", "1e300s", "1e999", "99999999999999999999h", "CPU226\x00",
    "VD0:REAL", "T37:BIT", "VW0:FLOAT", ":REAL", "I0.0", "SM0.0", "AC0", "axis0.0.position",
    "drive1.statusword", "16#FF", "hcfa-am0520b\x00", "../../etc/passwd", "/dev/zero", "/"])
_NUMBERS = st.sampled_from([
    math.nan, math.inf, -math.inf, -0.0, 1e300, -1e300, 1.8e302, 5e-324, -1, 0, 1,
    Fraction(1, 3), Fraction(10**400, 3), Decimal("NaN"), Decimal("1e400"), Decimal("-1"),
    np.int64(-1), np.float64("nan"), np.uint64(2**64 - 1), np.float32(1.5), np.bool_(True)])
_OBJECTS = st.sampled_from([
    object(), Path("a\x00b"), Path("."), Path("/dev/zero"), Path("no/such.awl"), b"a\x00b",
    bytearray(b"x"), [10**5000], (1, 2, 3), {"VW0": 10**400}, {1: 2}, set(), frozenset(),
    lambda: None, Ellipsis, NotImplemented, range(10**12), np.array([1, 2]), np.array(5)])
ANY = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-(10**40), max_value=10**40),
    st.floats(), st.text(max_size=12), st.binary(max_size=8),
    st.lists(st.integers(), max_size=3),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
    st.tuples(st.integers(), st.text(max_size=3)), _HUGE, _TEXT, _NUMBERS, _OBJECTS)

#: a duration that is short, or refused: never a long run
DURATION = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-5, max_value=1),
    st.floats(max_value=0.05), st.floats(min_value=1e8), _HUGE,
    st.text(alphabet="-.0e sm uxh", max_size=5), _TEXT, _NUMBERS.filter(
        lambda v: not (isinstance(v, (int, float, np.integer, np.floating))
                       and 1 < v < 1e8)), _OBJECTS)
#: a number of scans that is small, or refused
COUNT = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-5, max_value=5),
    st.integers(min_value=MAX_STEPS + 1), _HUGE, st.floats(), _TEXT, _OBJECTS)

# ---------------------------------------------------------------------------
# Receivers: fresh for every example, so no example depends on another
# ---------------------------------------------------------------------------


def _plc() -> plcrt.Plc:
    return plcrt.load(TIMERS)


def _h() -> Harness:
    return Harness(_plc())


def _axis_plc() -> plcrt.Plc:
    return plcrt.load(EM253 / "abs_pos.awl", plant=EM253 / "plant.toml")


def _bus_plc() -> plcrt.Plc:
    return plcrt.load(BUS / "bus_drive.awl", data=BUS / "bus_drive.db",
                      symbols=BUS / "bus_drive_symbols.txt", plant=BUS / "plant.toml")


def _trace() -> plcrt.trace.Trace:
    plc = _plc()
    tr = plcrt.trace.Trace(plc, ["Q0.0", "VW0", "VD4:REAL"])
    plc.run(scans=3)
    return tr


class _Bus:
    """A virtual CAN bus with one simulated drive (clock="manual")."""

    def __init__(self) -> None:
        import canopen
        self.net = canopen.Network()
        self.net.connect(interface="virtual", channel=f"fuzz{id(self)}")

    def __enter__(self) -> Any:
        return self

    def __exit__(self, *exc: Any) -> None:
        for node in list(self.net.values()):
            if hasattr(node, "nmt"):
                node.nmt.stop_heartbeat()
        self.net.disconnect()


def _with_drive(fn: Callable[[Any], Any]) -> Any:
    with _Bus() as bus:
        sim = plcrt.cia402.attach(bus.net, 5, clock="manual")
        try:
            return fn(sim)
        finally:
            sim.close()


def _with_network(fn: Callable[[Any], Any]) -> Any:
    with _Bus() as bus:
        return fn(bus.net)


def _forced(h: Harness, values: Any) -> None:
    with h.forced(values):
        pass


def _marker(**kw: Any) -> Any:
    """The pytest marker's (and plc_factory's) argument check."""
    from plcrt.testing.plugin import PlcUsageError, _make_spec
    args = kw.pop("program", TIMERS)
    try:
        return _make_spec((args,), kw, [ROOT], ROOT)
    except PlcUsageError:
        return None   # the plugin turns it into a usage error or a PlcConfigError


# ---------------------------------------------------------------------------
# The entries: callable -> (call with keyword arguments, sane arguments)
# ---------------------------------------------------------------------------

Call = Callable[..., Any]
def _machine_plc() -> plcrt.Plc:
    return plcrt.load(ROOT / "examples" / "machines" / "conveyor.awl",
                      plant={"machine": {"conveyor": {}}})


def _machine() -> Machine:
    return _machine_plc().machine("conveyor")


_OUT = Path(tempfile.mkdtemp(prefix="plcrt-fuzz-"))


class Fresh:
    """A sane argument made anew for every example (a PLC, a trace)."""

    def __init__(self, make: Callable[[], Any]) -> None:
        self.make = make


PLC, TRACE = Fresh(_plc), Fresh(_trace)


def _sane(kwargs: dict[str, Any]) -> dict[str, Any]:
    return {k: v.make() if isinstance(v, Fresh) else v for k, v in kwargs.items()}


def _call(fn: Callable[..., Any], k: dict[str, Any]) -> Any:
    """``fn(**k)``, a ``*args`` parameter given as one positional value."""
    star = [p.name for p in inspect.signature(fn).parameters.values()
            if p.kind is p.VAR_POSITIONAL]
    args = [k.pop(star[0])] if star and star[0] in k else []
    return fn(*args, **k)


#: "owner.name" -> (call(**kwargs), the sane kwargs); the parameter fuzzed
#: replaces its sane value or is added
CALLS: dict[str, tuple[Call, dict[str, Any]]] = {
    "plcrt.load": (plcrt.load, {"source": TIMERS}),
    "plcrt.link": (plcrt.link, {"plc_a": PLC, "port_a": 0, "plc_b": PLC, "port_b": 0}),
    # a served PLC is closed again at once (its servers and runner thread)
    "plcrt.serve": (lambda **k: plcrt.serve(**k).close(),
                    {"plc": PLC, "lockstep": 0, "speed": "lockstep"}),
    "Plc.__init__": (plcrt.Plc, {"program": Fresh(lambda: parse_sources(TIMERS))}),
    "Plc.from_program": (plcrt.Plc.from_program, {"compiled": Fresh(lambda: _plc().compiled)}),
    "Plc.__getitem__": (lambda **k: _plc()[k["address"]], {"address": "VW0"}),
    "Plc.__setitem__": (lambda **k: _plc().__setitem__(k["address"], k["value"]),
                        {"address": "VW0", "value": 1}),
    "Plc.stop_requested=": (lambda **k: setattr(_plc(), "stop_requested", k["value"]),
                            {"value": True}),
    "Network.__init__": (lambda **k: _call(plcrt.Network, k), {"plcs": PLC}),
    "Network.add": (lambda **k: plcrt.Network().add(**k), {"plc": PLC}),
    "Network.link": (lambda **k: plcrt.Network().link(**k),
                     {"a": PLC, "port_a": 0, "b": PLC, "port_b": 0}),
    "Network.ethernet_of": (lambda **k: plcrt.link(_plc(), 0, _plc(), 0).ethernet_of(**k),
                            {"ip": b"\x00\x00\x00\x00"}),
    "Network.run": (lambda **k: plcrt.link(_plc(), 0, _plc(), 0).run(**k), {"seconds": 0.01}),
    "plcrt.testing.seconds": (plcrt.testing.seconds, {"d": 1}),
    "Harness.__init__": (Harness, {"plc": PLC}),
    "Harness.load": (Harness.load, {"program": TIMERS}),
    "Harness.__getitem__": (lambda **k: _h()[k["address"]], {"address": "VW0"}),
    "Harness.__setitem__": (lambda **k: _h().__setitem__(k["address"], k["value"]),
                            {"address": "VW0", "value": 1}),
    "Harness.forced": (lambda **k: _forced(_h(), **k), {"values": {"Q0.0": 1}}),
    "Harness.trace": (lambda **k: _call(_h().trace, k).detach(), {"signals": "Q0.0"}),
    "AxisState.__init__": (plcrt.testing.AxisState,
                           {"slot": 0, "axis": 0, "position": 0, "mechanical": 0, "speed": 0,
                            "status": "stopped"}),
    "AxisState.__getitem__": (lambda **k: _axis_plc().axis()[k["key"]], {"key": "speed"}),
    "AxisState.__contains__": (lambda **k: k["key"] in _axis_plc().axis(), {"key": "speed"}),
    "DriveState.__init__": (DriveState,
                            {"slot": 0, "node": 1, "model": "m", "state": "s", "statusword": 0,
                             "controlword": 0, "mode": 0, "position": 0, "velocity": 0,
                             "following_error": 0, "error_code": 0, "online": True}),
    "DriveState.__getitem__": (lambda **k: _bus_plc().drive(1)[k["key"]], {"key": "state"}),
    "DriveState.__contains__": (lambda **k: k["key"] in _bus_plc().drive(1), {"key": "state"}),
    "Trace.__init__": (lambda **k: plcrt.trace.Trace(**k).detach(),
                       {"plc": PLC, "signals": ["Q0.0"]}),
    "Trace.__getitem__": (lambda **k: _trace()[k["name"]], {"name": "Q0.0"}),
    "Trace.__contains__": (lambda **k: k["name"] in _trace(), {"name": "Q0.0"}),
    "plcrt.trace.plot": (plcrt.trace.plot, {"trace": TRACE, "path": _OUT / "t.svg"}),
    "plcrt.trace.run_with_progress": (plcrt.trace.run_with_progress,
                                      {"plc": PLC, "scans": 2, "stream": io.StringIO()}),
    "plcrt.trace.sparkline": (plcrt.trace.sparkline, {"values": [0, 1, 0]}),
    "plcrt.trace.trend": (plcrt.trace.trend, {"trace": TRACE}),
    "plcrt.cia402.attach": (lambda **k: _with_network(
        lambda net: plcrt.cia402.attach(**{"network": net, **k}).close()),
        {"node_id": 5, "clock": "manual"}),
    "plcrt.cia402.bus": (lambda **k: plcrt.cia402.bus(**k).disconnect(), {"channel": "fuzz"}),
    "plcrt.cia402.eds_text": (plcrt.cia402.eds_text, {}),
    "plcrt.cia402.models": (plcrt.cia402.models, {}),
    "plcrt.cia402.object_dictionary": (plcrt.cia402.object_dictionary, {}),
    "CanopenDrive.__init__": (lambda **k: _with_network(
        lambda net: CanopenDrive(**{"network": net, **k}).close()),
        {"node_id": 5, "clock": "manual"}),
    "CanopenDrive.advance": (lambda **k: _with_drive(lambda sim: sim.advance(**k)),
                             {"seconds": 0.01}),
    "CanopenDrive.close": (lambda **k: _with_drive(lambda sim: sim.close()), {}),
    "plcrt.testing.plugin.marker": (_marker, {}),
}


def _methods(owner: str, make: Callable[[], Any], sane: dict[str, dict[str, Any]]) -> None:
    """Entries for methods called on ``make()``: name -> sane kwargs."""
    for name, kwargs in sane.items():
        CALLS[f"{owner}.{name}"] = (
            lambda _n=name, **k: _call(getattr(make(), _n), k), kwargs)


_PLC_SANE: dict[str, dict[str, Any]] = {
    "axes": {}, "axis": {}, "drive": {"node": 1}, "drives": {},
    "force": {"address": "VW0", "value": 1}, "fork": {}, "locate": {"spec": "VW0"},
    "module": {"slot": 0}, "read": {"address": "VW0"}, "reader": {"spec": "VW0"},
    "power_cycle": {}, "recompiled": {}, "request_stop": {}, "restore": {"snapshot": PLC},
    "run": {"scans": 1},
    "scan": {}, "set_mode": {"mode": "STOP"}, "snapshot": {}, "unforce": {},
    "warn": {"message": "m", "loc": None, "key": "k"},
    "write": {"address": "VW0", "value": 1},
}
_methods("Plc", _plc, _PLC_SANE)
_methods("Harness", _h, {
    **_PLC_SANE, "axis_done_within": {"limit": 0.01}, "history_rows": {},
    "history_table": {}, "limit_time": {"max_time": 1}, "patch": {"values": {"I0.0": 1}},
    "pulse": {"address": "I0.0"}, "run_until": {"cond": "Q0.0", "timeout": 0.02},
    "run_while": {"cond": "Q0.0", "timeout": 0.02}, "set": {"values": {"VW0": 1}},
    "stays": {"cond": "not Q0.0", "duration": 0.02},
    "stimulus": {"table": [(0, "I0.0", 1)]}, "values": {"addresses": "VW0"},
    "wait_axis_moving": {"timeout": 0.02}, "wait_axis_stopped": {"timeout": 0.02},
    "warnings": {}, "watch": {"addresses": "VW0"}})
_methods("Trace", _trace, {
    "array": {"name": "Q0.0"}, "attach": {}, "changes": {"name": "Q0.0"}, "detach": {},
    "kind": {"name": "Q0.0"}, "last": {}, "table": {}, "to_csv": {"path_or_file": _OUT / "t.csv"}})
# a PLC with a machine: plc.machine(), the harness's, the Machine handed out
CALLS["Plc.machine"] = (lambda **k: _machine_plc().machine(**k), {"name": "conveyor"})
CALLS["Harness.machine"] = (lambda **k: Harness(_machine_plc()).machine(**k),
                            {"name": "conveyor"})
CALLS["Plc.machines"] = (lambda **k: _machine_plc().machines(**k), {})
CALLS["Harness.machines"] = (lambda **k: Harness(_machine_plc()).machines(**k), {})
CALLS["Machine.__init__"] = (Machine, {"device": Fresh(lambda: _machine()._dev)})
_methods("Machine", _machine, {
    "state": {}, "wiring": {}, "faults": {}, "buttons": {},
    "fault": {"name": "jam", "on": True},
    "press": {"name": "start", "seconds": 0.1}, "hold": {"name": "start"},
    "release": {"name": "start"}, "edges": {"signal": "eye_entry"}, "notes": {}})
for _owner, _make in (("AxisState", lambda: _axis_plc().axis()),
                      ("DriveState", lambda: _bus_plc().drive(1))):
    _methods(_owner, _make, {"get": {"key": "speed"}, "items": {}, "keys": {}, "to_dict": {},
                             "values": {}})

#: parameters whose valid values may ask for a long run, by name ...
_KINDS: dict[str, st.SearchStrategy[Any]] = {
    "seconds": DURATION, "timeout": DURATION, "duration": DURATION, "until": DURATION,
    "max_wall": DURATION, "d": DURATION, "scans": COUNT}
#: ... and by entry, where the name alone says too little
_KIND_OF: dict[tuple[str, str], st.SearchStrategy[Any]] = {
    ("Plc.scan", "n"): COUNT, ("Harness.scan", "n"): COUNT,
    ("Harness.axis_done_within", "limit"): DURATION,
    ("Harness.stimulus", "table"): st.one_of(
        ANY, st.lists(st.tuples(DURATION, ANY, ANY), max_size=2),
        st.lists(st.tuples(st.just(0), ANY, ANY), max_size=2))}


# ---------------------------------------------------------------------------
# The public surface, enumerated
# ---------------------------------------------------------------------------

PUBLIC_MODULES = (plcrt, plcrt.testing, plcrt.trace, plcrt.cia402)
#: classes the public functions hand out, not exported by name
HANDED_OUT = (CanopenDrive, DriveState, Machine)
#: exported names that are not entry points: errors and plain records of a
#: location or a finding, with nothing to check
NOT_ENTRIES = {"Diagnostic", "SourceLoc", "PlcError", "PlcSyntaxError", "PlcCompileError",
               "PlcRuntimeError", "PlcAddressError", "PlcConfigError", "PlcTimeout",
               "__version__"}
#: dunder methods that take a user's value
_DUNDERS = ("__init__", "__getitem__", "__setitem__", "__contains__")


def _params(owner: str, fn: Callable[..., Any]) -> list[str]:
    """``owner(param)`` for each parameter of ``fn`` a user gives, or
    ``owner()`` when there is none."""
    names = []
    for p in inspect.signature(fn).parameters.values():
        if p.name in ("self", "cls") or p.name.startswith("_"):
            continue
        if p.kind is p.VAR_KEYWORD:
            # load(**kw) takes the options listed in LOAD_OPTIONS
            assert owner == "plcrt.load", f"{owner} takes **{p.name}: list its options"
            names += list(LOAD_OPTIONS)
        else:
            names.append(p.name)
    return [f"{owner}({n})" for n in names] or [f"{owner}()"]


def _class_params(cls: type) -> list[str]:
    keys = []
    for name in dir(cls):
        if name.startswith("_") and name not in _DUNDERS:
            continue
        member = inspect.getattr_static(cls, name)
        if getattr(object, name, None) is member or name == "__init__" and \
                cls.__init__ is object.__init__:
            continue
        if isinstance(member, property):
            if member.fset is not None:
                keys.append(f"{cls.__name__}.{name}=(value)")
            continue
        if callable(getattr(cls, name)) and not inspect.isclass(getattr(cls, name)):
            keys += _params(f"{cls.__name__}.{name}", getattr(cls, name))
    return keys


def public_parameters() -> list[str]:
    """Every parameter of every public entry point, as ``owner.name(param)``."""
    keys: list[str] = []
    for mod in PUBLIC_MODULES:
        for name in mod.__all__:
            if name in NOT_ENTRIES:
                continue
            obj = getattr(mod, name)
            if inspect.isclass(obj):
                keys += _class_params(obj)
            else:
                keys += _params(f"{mod.__name__}.{name}", obj)
    for cls in HANDED_OUT:
        keys += _class_params(cls)
    # the pytest marker's (and plc_factory's) options
    from plcrt.testing.plugin import OPTIONS
    keys += [f"plcrt.testing.plugin.marker({o})" for o in ("program", *OPTIONS)]
    return sorted(set(keys))


def _entry(key: str) -> tuple[str, str]:
    owner, _, param = key.partition("(")
    return owner, param.rstrip(")")


PARAMETERS = public_parameters()


def test_every_public_parameter_is_fuzzed() -> None:
    """A public method (or a new parameter) without an entry in CALLS fails
    here, naming it; an entry for something no longer public too."""
    missing = [k for k in PARAMETERS if _entry(k)[0] not in CALLS]
    assert not missing, f"public entry points without a fuzz entry in CALLS: {missing}"
    stale = sorted(set(CALLS) - {_entry(k)[0] for k in PARAMETERS})
    assert not stale, f"fuzz entries for no public entry point: {stale}"
    assert len(PARAMETERS) > 150   # the enumeration found the surface


@pytest.mark.parametrize("key", PARAMETERS)
def test_hostile_arguments_raise_nothing_but_plc_errors(key: str,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    # a path drawn as any text is a file written relative to the working
    # folder: that is a scratch folder, never the checkout
    monkeypatch.chdir(_OUT)
    owner, param = _entry(key)
    call, sane = CALLS[owner]
    values = _KIND_OF.get((owner, param), _KINDS.get(param, ANY)) if param else st.none()

    @settings(max_examples=EXAMPLES if param else 1, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(values)
    def check(x: Any) -> None:
        kwargs = _sane(sane)
        if param:
            kwargs[param] = x
        try:
            call(**kwargs)
        except PlcError as e:
            assert e.message.strip(), "an error needs a message"
            assert "internal error" not in e.message
            str(e)   # printable, whatever it quotes
        except AssertionError as e:
            # the harness's way of failing a test (PlcTimeout, stays()), with a message
            assert owner.startswith("Harness.") and str(e).strip()

    check()
