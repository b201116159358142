"""backend="auto" runs the Python build at once and switches to the native
build at a scan boundary (plcrt/engine/tiering.py).

The switch must be invisible except for speed: a PLC that switches at any
scan has, after every scan, the memory image of the all-Python and of the
all-native run of the same program and inputs.  Forks, snapshots taken on
one build and restored on the other, pickling and the background job are
pinned here too.
"""

from __future__ import annotations

import os
import pickle
import shutil
import subprocess
import sys
import threading
import time

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.compiler.cache import programs
from plcrt.engine import tiering

from test_backends import AREAS, scan_each, structured_programs
from test_differential import INITIAL_MEMORY, M_BYTES, SEGMENTS, V_BYTES

pytest.importorskip("llvmlite")

TIMERS = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\nTON T37, +10\n" \
         "Network 2\nLD T37\nEU\n= Q0.0\nINCW VW0\nNetwork 3\nLD SM0.0\nCALL SBR_0\n" \
         "END_ORGANIZATION_BLOCK\nSUBROUTINE_BLOCK SBR_0:SBR0\nBEGIN\nNetwork 1\n" \
         "LD I0.1\nED\nINCB MB3\nEND_SUBROUTINE_BLOCK\n"


@pytest.fixture(autouse=True)
def _no_native_build_cached(tmp_path, monkeypatch):
    """A native build in the program cache, or a mark of one on disk, is
    used at once, without tiers: each test starts with neither."""
    programs.clear()
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path / "cache"))


def _fresh_disk_cache() -> None:
    """An empty disk cache for one hypothesis example (the machine code and
    the marks of the previous example gone)."""
    shutil.rmtree(os.environ["PLCRT_CACHE_DIR"], ignore_errors=True)


def _image(plc: plcrt.Plc) -> tuple:
    return (tuple(bytes(plc.mem.areas[a]) for a in AREAS), bytes(plc.timers.running),
            list(plc.timers.preset), plc.mode)


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(program=structured_programs(), inputs=SEGMENTS, initial=INITIAL_MEMORY,
       scan_ms=st.sampled_from((1, 10, 130)), switch=st.integers(0, 40))
def test_the_switch_at_any_scan_gives_the_images_of_both_backends(
        program, inputs, initial, scan_ms, switch) -> None:
    programs.clear()    # else the native build of an earlier example is used at once
    _fresh_disk_cache()
    plcs = [plcrt.load(program, scan_ms=scan_ms, backend=b)
            for b in ("auto", "python", "native")]
    for plc in plcs:
        plc.mem.areas["V"][:V_BYTES] = initial[:V_BYTES]
        plc.mem.areas["M"][:M_BYTES] = initial[V_BYTES:]
    auto, py, nat = plcs
    assert auto.backend["name"] == "python" and auto.backend["tiered"]
    scan = 0
    for ib0, ib1, repeat in inputs:
        for _ in range(repeat):
            if scan == switch:
                auto._tier_up()
                assert auto.backend["name"] == "native"
                assert auto.backend["python_scans"] == switch
            faults = scan_each(plcs, ib0, ib1)
            scan += 1
            assert faults[0] == faults[1] == faults[2], f"scan {scan}\n{program}"
            assert _image(auto) == _image(py) == _image(nat), f"scan {scan}\n{program}"
            if faults[0] is not None:
                return      # all three stopped on the same fault at the same scan
    assert auto.backend["name"] == ("native" if scan > switch else "python")


@pytest.mark.parametrize("switch", [0, 1, 7, 33, 64, 65, 200])
def test_a_switch_inside_one_long_run_changes_nothing(switch, monkeypatch) -> None:
    """scan(n) runs in chunks and looks at the job between them: the image
    after n scans is the same wherever in them the switch falls."""
    auto = plcrt.load(TIMERS, backend="auto")
    ref = plcrt.load(TIMERS, backend="python")
    for plc in (ref, auto):
        plc["I0.0"] = 1
        plc.scan(switch)
    auto._tier_up()
    for plc in (ref, auto):
        plc["I0.1"] = 1
        plc.scan(150)
        plc["I0.1"] = 0
        plc.scan(150)
    assert auto.backend["name"] == "native"
    assert _image(auto) == _image(ref)
    assert auto["VW0"] == 1 and auto["MB3"] == 1


def test_the_background_job_switches_a_running_plc(monkeypatch) -> None:
    """With no wait before the job, a running PLC switches by itself at a
    scan boundary, and its image still equals the Python run's."""
    monkeypatch.setattr(tiering, "START_AFTER_S", 0.0)
    monkeypatch.setattr(tiering, "LOAD_FACTOR", 0.0)
    monkeypatch.setattr(tiering, "LLVM_START_S", 0.0)
    ref = plcrt.load(TIMERS, backend="python", scan_ms=1)
    auto = plcrt.load(TIMERS, backend="auto", scan_ms=1)
    for plc in (ref, auto):
        plc["I0.0"] = 1
    deadline = time.monotonic() + 60
    while auto.backend["name"] != "native" and time.monotonic() < deadline:
        for plc in (ref, auto):
            plc.scan(100)
    assert auto.backend["name"] == "native"
    assert 0 < auto.backend["python_scans"] <= auto.scans
    assert _image(auto) == _image(ref)
    assert not [t for t in threading.enumerate()
                if t.name == "plcrt-native-compile" and not t.daemon]


@pytest.mark.parametrize("how", ["run", "in chunks"])
def test_a_long_planned_run_starts_the_compile_after_its_first_chunk(how, monkeypatch) -> None:
    """A run whose length is known starts the native compile as soon as its
    first chunk of scans says the rest would take PLAN_FACTOR times the
    wait in Python; a short one waits (here: never, the wait is 0.1 s).
    ``plcrt run`` with a progress line or --max-wall runs in chunks of its
    own and says the whole length first."""
    monkeypatch.setattr(tiering, "START_AFTER_S", 0.1)
    started: list[int] = []
    real = tiering._start
    plcs: list[plcrt.Plc] = []

    def start(key, make):
        started.append(plcs[-1].scans)
        return real(key, make)
    monkeypatch.setattr(tiering, "_start", start)
    plcs.append(plcrt.load(TIMERS, backend="auto"))
    plcs[-1].scan(500)           # 500 scans of a few µs: far from 0.1 s
    assert started == [] and plcs[-1].backend["name"] == "python"
    programs.clear()
    plcs.append(plcrt.load(TIMERS, backend="auto"))
    if how == "run":
        plcs[-1].run(seconds=2_000_000 * 0.01)   # two million scans: seconds in Python
        assert started == [tiering.CHUNK_SCANS]
    else:
        from plcrt.term.progress import run_with_progress
        run_with_progress(plcs[-1], scans=2_000_000, quiet=True, max_wall=3600.0)
        assert len(started) == 1 and started[0] <= 100     # in its first chunk
    assert plcs[-1].scans == 2_000_000
    assert plcs[-1].backend["name"] == "native"
    assert 0 < plcs[-1].backend["python_scans"] < plcs[-1].scans


def test_a_final_run_compiles_only_when_the_compile_pays_within_it(monkeypatch) -> None:
    """``plcrt run`` says its run is the PLC's last (final): there the
    compile starts only by the plan (a rest that pays for it, here never),
    not by the wait alone, as it does where the program may go on."""
    from plcrt.term.progress import run_with_progress
    monkeypatch.setattr(tiering, "START_AFTER_S", 0.001)   # 30 000 scans take longer
    monkeypatch.setattr(tiering, "LOAD_FACTOR", 0.0)
    monkeypatch.setattr(tiering, "LLVM_START_S", 0.0)
    monkeypatch.setattr(tiering, "PLAN_FACTOR", 1e9)       # no rest pays
    started: list[str] = []
    real = tiering._start

    def start(key, make):
        started.append(how)
        return real(key, make)
    monkeypatch.setattr(tiering, "_start", start)
    for how in ("final", "not final"):
        programs.clear()
        plc = plcrt.load(TIMERS, backend="auto")
        if how == "final":
            run_with_progress(plc, scans=30_000, quiet=True)
        else:
            plc.run(scans=30_000)
        assert plc.scans == 30_000
    assert started == ["not final"]


def test_snapshot_fork_and_pickle_across_the_switch() -> None:
    auto = plcrt.load(TIMERS, backend="auto")
    ref = plcrt.load(TIMERS, backend="python")
    for plc in (ref, auto):
        plc["I0.0"] = 1
        plc.scan(5)
    before = auto.snapshot()                  # on the Python build
    blob = pickle.dumps(auto.compiled)
    auto._tier_up()
    twin = auto.fork()                        # on the native build
    assert twin.backend["name"] == "native"
    for plc in (ref, auto, twin):
        plc.scan(20)
    assert _image(auto) == _image(ref) == _image(twin)
    auto.restore(before)                      # a Python-build state into the native build
    assert auto.backend["name"] == "native" and auto.scans == 5
    auto.scan(20)
    again = plcrt.load(TIMERS, backend="python")
    again["I0.0"] = 1
    again.scan(25)
    assert _image(auto) == _image(again)
    other = plcrt.Plc.from_program(pickle.loads(blob))
    other["I0.0"] = 1
    other.scan(25)
    assert _image(other) == _image(again)
    assert pickle.loads(pickle.dumps(auto.compiled)).native is not None


def test_the_python_build_leaves_the_cache_when_the_native_one_takes_over() -> None:
    """After the switch the program cache holds the native build only (the
    Python build's memory goes with the last PLC on it): a PLC still on
    it runs on, and the next auto load is native at once."""
    auto = plcrt.load(TIMERS, backend="auto")
    sibling = plcrt.load(TIMERS, backend="auto")       # the same Python build
    python = auto.compiled
    assert sibling.compiled is python and python in programs._entries.values()
    auto._tier_up()
    assert auto.backend["name"] == "native"
    assert python not in programs._entries.values()
    assert auto.compiled in programs._entries.values()
    assert plcrt.load(TIMERS, backend="auto").backend["name"] == "native"
    ref = plcrt.load(TIMERS, backend="python")
    for plc in (sibling, ref):
        plc["I0.0"] = 1
        plc.scan(30)
    assert _image(sibling) == _image(ref)


def test_python_and_native_keep_their_meaning() -> None:
    """python never switches, native is native from the first scan, and
    auto with the native build already made uses it at once."""
    assert plcrt.load(TIMERS, backend="python").backend == {"name": "python"}
    native = plcrt.load(TIMERS, backend="native").backend
    assert native["name"] == "native" and "tiered" not in native
    assert plcrt.load(TIMERS, backend="auto").backend["name"] == "native"


def test_a_process_with_a_job_under_way_exits(tmp_path) -> None:
    """The worker is a daemon; exit waits for a started job and ends."""
    code = ("import plcrt; from plcrt.engine import tiering\n"
            "tiering.START_AFTER_S = tiering.LOAD_FACTOR = tiering.LLVM_START_S = 0.0\n"
            f"plc = plcrt.load({TIMERS!r}, backend='auto')\n"
            "plc.scan(200)\nprint('ran', plc.scans)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, env={"PLCRT_CACHE_DIR": str(tmp_path),
                                           "PATH": "/usr/bin:/bin"})
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ran 200"
