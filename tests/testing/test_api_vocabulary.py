"""One vocabulary: the harness (the ``plc`` fixture) is a superset of
:class:`plcrt.Plc`, so a test written from the README's "Python API"
section runs unchanged inside a pytest test.

Pinned here: every public method and property of ``Plc`` exists on the
harness with a compatible signature; the documented attributes read the
same on both; ``run`` takes the same arguments on both; ``axis()`` returns
the same type on both; the README snippet prints what its comments say on
a ``Plc`` and on the fixture.
"""

from __future__ import annotations

import contextlib
import inspect
import io
import json
import re
from pathlib import Path
from typing import Any

import pytest

import plcrt
from plcrt.devices import AxisState
from plcrt.testing import Harness

ROOT = Path(__file__).resolve().parents[2]
TIMERS = str(ROOT / "programs" / "timers.awl")
EM253 = ROOT / "programs" / "em253"

#: instance attributes of Plc the README and docstrings document for users
DOCUMENTED_ATTRIBUTES = ("mode", "fault", "scans", "time", "now_us", "diagnostics", "source",
                         "program", "symbols", "forces", "coverage")


def _public_members(cls: type) -> dict[str, Any]:
    """Public methods and properties defined on ``cls`` (and the item
    access dunders), by name."""
    out = {}
    for name, member in inspect.getmembers(cls):
        if name.startswith("_") and name not in ("__getitem__", "__setitem__"):
            continue
        if inspect.isfunction(member) or isinstance(member, property):
            out[name] = member
    return out


def _compatible(plc_fn: Any, h_fn: Any) -> list[str]:
    """Why a call that works on ``plc_fn`` might not work on ``h_fn`` (an
    empty list when every call of the first binds on the second the same way)."""
    problems = []
    p_params = list(inspect.signature(plc_fn).parameters.values())
    h_params = list(inspect.signature(h_fn).parameters.values())
    h_by_name = {p.name: p for p in h_params}
    for i, p in enumerate(p_params):
        h = h_by_name.get(p.name)
        if h is None:
            problems.append(f"parameter {p.name!r} missing")
            continue
        if h.kind != p.kind:
            problems.append(f"parameter {p.name!r} is {h.kind.description}, "
                            f"not {p.kind.description}")
        if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) and h_params.index(h) != i:
            problems.append(f"parameter {p.name!r} at position {h_params.index(h)}, not {i}")
        if p.default is not p.empty and h.default != p.default:
            problems.append(f"parameter {p.name!r} defaults to {h.default!r}, "
                            f"not {p.default!r}")
    for h in h_params:
        if h.name not in {p.name for p in p_params} and h.default is h.empty \
                and h.kind not in (h.VAR_POSITIONAL, h.VAR_KEYWORD):
            problems.append(f"extra parameter {h.name!r} without a default")
    return problems


PLC_MEMBERS = _public_members(plcrt.Plc)


def test_plc_has_the_public_interface_this_test_walks() -> None:
    """The walk below sees Plc's interface (a rename would empty it)."""
    assert {"scan", "run", "read", "write", "force", "unforce", "axis", "axes", "fork",
            "snapshot", "restore", "locate", "reader", "time", "__getitem__"} <= set(PLC_MEMBERS)


@pytest.mark.parametrize("name", sorted(PLC_MEMBERS))
def test_every_public_plc_member_is_on_the_harness_with_a_compatible_signature(
        name: str) -> None:
    member = PLC_MEMBERS[name]
    h_member = inspect.getattr_static(Harness, name, None)
    assert h_member is not None, f"Harness has no {name}"
    if isinstance(member, property):
        assert isinstance(h_member, property), f"Harness.{name} is not a property"
        return
    assert inspect.isfunction(h_member), f"Harness.{name} is not a method"
    assert _compatible(member, h_member) == [], f"Harness.{name}"


def test_the_signature_check_itself_finds_incompatible_signatures() -> None:
    def plc_run(self: Any, seconds: Any = None, scans: Any = None) -> None: ...
    def old_harness_run(self: Any, duration: Any = None, *, scans: Any = None) -> None: ...
    def extra_required(self: Any, seconds: Any = None, scans: Any = None, *, x: int) -> None: ...
    assert _compatible(plc_run, plc_run) == []
    # the harness's run() before it took seconds=: run(seconds=1.0) was a TypeError
    assert _compatible(plc_run, old_harness_run) == [
        "parameter 'seconds' missing",
        "parameter 'scans' is keyword-only, not positional or keyword"]
    assert _compatible(plc_run, extra_required) == ["extra parameter 'x' without a default"]


@pytest.mark.plc(TIMERS)
def test_documented_attributes_read_the_same_on_the_fixture(plc: Harness) -> None:
    twin = plcrt.load(TIMERS)
    for h, p in ((plc, twin),):
        h["I0.0"] = p["I0.0"] = 1
        h.run("1.5s")
        p.run("1.5s")
    for name in DOCUMENTED_ATTRIBUTES:
        got, want = getattr(plc, name), getattr(twin, name)
        if name == "program":
            assert got.file == want.file
        elif name == "diagnostics":
            assert [str(d) for d in got] == [str(d) for d in want]
        else:
            assert got == want, name


@pytest.mark.plc(TIMERS)
@pytest.mark.parametrize("call", [
    lambda x: x.run("1.5s"), lambda x: x.run(1.5), lambda x: x.run(seconds=1.5),
    lambda x: x.run(seconds="1500ms"), lambda x: x.run(scans=150), lambda x: x.run(None, 150),
    lambda x: x.scan(150),
])
def test_run_takes_the_same_arguments_on_plc_and_fixture(plc: Harness, call: Any) -> None:
    """run("1.5s"), run(seconds=1.5), run(scans=N): the same 150 scans on both."""
    direct = plcrt.load(TIMERS)
    call(direct)
    call(plc)
    assert direct.scans == plc.scans == 150
    assert direct.time == plc.time == 1.5


@pytest.mark.plc(TIMERS)
@pytest.mark.parametrize("bad, message", [
    (dict(), "give exactly one of seconds"),
    (dict(seconds=1, scans=1), "give exactly one of seconds"),
    (dict(seconds=-1), "must be a non-negative"),
    (dict(seconds=float("nan")), "must be a non-negative"),
    (dict(seconds="soon"), "not a duration: 'soon'"),
    (dict(scans=-1), "scans must not be negative"),
    (dict(scans=1.5), "scans must be a whole number"),
])
def test_run_refuses_the_same_arguments_on_plc_and_fixture(plc: Harness, bad: dict[str, Any],
                                                           message: str) -> None:
    direct = plcrt.load(TIMERS)
    for target in (direct, plc):
        with pytest.raises(plcrt.PlcConfigError, match=message):
            target.run(**bad)


# ---------------------------------------------------------------------------
# axis(): one type with attribute and key access
# ---------------------------------------------------------------------------

@pytest.mark.plc(str(EM253 / "pos_goto_r.awl"), plant=str(EM253 / "plant.toml"))
def test_axis_is_one_type_with_attribute_and_key_access(plc: Harness) -> None:
    direct = plcrt.load(EM253 / "pos_goto_r.awl", plant=EM253 / "plant.toml")
    for target in (direct, plc):
        target["M2.0"] = 1
        target.run("2s")
        a = target.axis(0, 0)
        assert type(a) is AxisState
        assert a.position == a["position"] > 0
        assert a.moving and a["status"] == "moving"
        assert dict(a) == a.to_dict() == {k: getattr(a, k) for k in a}
        assert list(a) == ["slot", "axis", "position", "mechanical", "speed", "status",
                           "masked", "stf"]
        assert json.loads(json.dumps(a.to_dict())) == dict(a)
        assert a == dict(a)                       # equal to a mapping with the same items
        assert target.axes() == [target.axis(0, 0), target.axis(0, 1)]
        with pytest.raises(KeyError):
            a["moving"]                           # a property, not an item
        with pytest.raises(AttributeError):
            a.position = 0                        # type: ignore[misc]  # a snapshot
    assert plc.axis(0, 0) == direct.axis(0, 0)
    assert plc.axis() == direct.axis()            # the same defaults: slot 0, axis 0


def test_run_json_writes_the_axes_as_their_mappings(capsys: pytest.CaptureFixture[str]) -> None:
    from plcrt.cli import main
    code = main(["run", str(EM253 / "pos_goto_r.awl"), "--plant", str(EM253 / "plant.toml"),
                 "--seconds", "2", "--set", "M2.0=1", "--json"])
    assert code == 0
    axes = json.loads(capsys.readouterr().out)["axes"]
    plc = plcrt.load(EM253 / "pos_goto_r.awl", plant=EM253 / "plant.toml")
    plc["M2.0"] = 1
    plc.run(seconds=2)
    assert axes == [a.to_dict() for a in plc.axes()]


# ---------------------------------------------------------------------------
# The README's Python API section, on a Plc and on the fixture
# ---------------------------------------------------------------------------

def _readme_api_snippet() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Python API", 1)[1]
    m = re.search(r"```python\n(.*?)```", section, re.S)
    assert m is not None, "README: no python block under 'Python API'"
    return m.group(1)


def _expected_output(snippet: str) -> list[str]:
    """What the snippet's ``print(...)  # expected  (note)`` comments say."""
    out = []
    for line in snippet.splitlines():
        if line.lstrip().startswith("print(") and "#" in line:
            out.append(line.split("#", 1)[1].strip().split("   ")[0].strip())
    return out


def _run_snippet(snippet: str, plc: Any) -> list[str]:
    """Run the snippet with ``plc`` in place of its ``plcrt.load`` line."""
    lines = snippet.splitlines()
    load_lines = [i for i, ln in enumerate(lines) if re.match(r"plc\s*=\s*plcrt\.load\(", ln)]
    assert len(load_lines) == 1, "README snippet: expected one 'plc = plcrt.load(...)' line"
    del lines[load_lines[0]]
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        exec(compile("\n".join(lines), "README.md", "exec"), {"plcrt": plcrt, "plc": plc})
    return buf.getvalue().splitlines()


def test_the_readme_snippet_prints_what_its_comments_say() -> None:
    snippet = _readme_api_snippet()
    expected = _expected_output(snippet)
    assert len(expected) >= 3
    program = re.search(r'plcrt\.load\("([^"]+)"', snippet)
    assert program is not None
    assert _run_snippet(snippet, plcrt.load(ROOT / program.group(1))) == expected


@pytest.mark.plc(TIMERS)
def test_the_readme_snippet_runs_unchanged_on_the_fixture(plc: Harness) -> None:
    snippet = _readme_api_snippet()
    assert 'plcrt.load("programs/timers.awl"' in snippet   # the marker's program
    assert _run_snippet(snippet, plc) == _expected_output(snippet)
