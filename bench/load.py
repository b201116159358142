"""plcrt load benchmark: load time, load memory and the pytest fixture's cost.

Run ``python bench/load.py`` (``--json`` for one JSON document).  It

1. generates programs with the benchmark's own generators (``bench/run.py``:
   the boolean and the mixed shape, one seed each by default, ``--seeds``
   for more) of 1 000, 10 000 and 100 000 statements (``--sizes``);
2. loads each in a fresh interpreter (one subprocess per program and
   measurement, so that one load's memory never counts in another's) and
   reports parse time and compile time (``Plc()``: check, generate,
   compile, bind) separately, the growth of the resident set (VmRSS) from
   before the load to after it, the resident peak (VmHWM), and in another
   subprocess tracemalloc's peak during the load and what stays allocated;
3. measures the same load with the garbage collector left on during it
   (``gc on``), so its effect is visible (this needs a plcrt with
   ``plcrt.compiler.cache``);
4. measures the pytest fixture ``plc`` on a 1 000-statement program: the
   plugin's work per test timed in one process (``in_process``), and whole
   pytest runs of N and 2N tests with and without the fixture, whose
   difference per added test is the fixture's overhead with pytest's own.

``--plcrt DIR`` measures the plcrt package found in DIR instead (another
checkout: the figures before a change, side by side in the same run with
``--compare DIR``).  This is a measuring tool, not a test: it asserts
nothing.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent


def _generators() -> dict[str, Any]:
    """The benchmark's program generators (bench/run.py).  Imported only in
    the parent process: run.py puts this checkout first on sys.path, and a
    child measuring another checkout (``--plcrt``) must not import it."""
    sys.path.insert(0, str(HERE))
    from run import bool_program, mixed_program
    return {"bool": bool_program, "mixed": mixed_program}

TINY = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD     I0.0\n=      Q0.0\nEND_ORGANIZATION_BLOCK\n"


def _status() -> dict[str, int]:
    """VmRSS and VmHWM of this process in KiB."""
    out = {}
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(("VmRSS:", "VmHWM:")):
            out[line.split(":")[0]] = int(line.split()[1])
    return out


# ---------------------------------------------------------------------------
# Child: one load in a fresh interpreter
# ---------------------------------------------------------------------------

def child(path: str, mode: str) -> dict[str, Any]:
    import contextlib
    import gc
    import tracemalloc

    import plcrt
    from plcrt.engine import runtime
    from plcrt.engine.runtime import Plc, parse_sources
    plcrt.load(TINY).scan(1)          # imports and first-use costs out of the way
    out: dict[str, Any] = {"mode": mode, "plcrt": str(Path(plcrt.__file__).parent)}
    if mode == "gc-on":
        if not hasattr(runtime, "gc_paused"):
            return {"mode": mode, "skipped": "this plcrt does not pause the collector"}
        runtime.gc_paused = contextlib.nullcontext   # type: ignore[attr-defined]
    text = Path(path).read_text()
    gc.collect()
    if mode == "trace":
        tracemalloc.start()
        base = tracemalloc.get_traced_memory()[0]
    before = _status()
    pause = getattr(runtime, "gc_paused", contextlib.nullcontext)
    t0 = time.perf_counter()
    with (contextlib.nullcontext() if mode == "gc-on" else pause()):
        program = parse_sources(text)
    t1 = time.perf_counter()
    plc = Plc(program, scan_ms=1)
    t2 = time.perf_counter()
    if mode == "trace":
        now, peak = tracemalloc.get_traced_memory()
        out.update(traced_live_mib=(now - base) / 2**20, traced_peak_mib=(peak - base) / 2**20)
        tracemalloc.stop()
    gc.collect()
    after = _status()
    t3 = time.perf_counter()
    plc.fork()
    t4 = time.perf_counter()
    out.update(insns=program.instruction_count(), parse_s=t1 - t0, compile_s=t2 - t1,
               load_s=t2 - t0, fork_s=t4 - t3,
               rss_growth_mib=(after["VmRSS"] - before["VmRSS"]) / 1024,
               rss_peak_mib=after["VmHWM"] / 1024)
    return out


def child_fixture(path: str, tests: int = 200) -> dict[str, Any]:
    """The ``plc`` fixture's own work per test, in this process: what the
    plugin does for a test's marker (then one scan), after a first test has
    loaded the program."""
    from plcrt.testing import plugin
    root = Path(path).parent
    sess = plugin._Session(rootpath=root, scan_ms=10.0, history=20, max_time=None,
                           coverage=False, coverage_report=None)

    def one_test() -> None:
        spec = plugin._make_spec((Path(path).name,), {}, [root], root)
        plugin._build(sess, spec).run(scans=1)

    t0 = time.perf_counter()
    one_test()
    t1 = time.perf_counter()
    for _ in range(tests):
        one_test()
    t2 = time.perf_counter()
    return {"mode": "fixture", "first_test_s": t1 - t0,
            "per_test_ms": (t2 - t1) / tests * 1000}


def _run_child(path: Path, mode: str, plcrt_dir: str | None) -> dict[str, Any]:
    env = dict(os.environ)
    if plcrt_dir:
        env["PYTHONPATH"] = plcrt_dir + os.pathsep + env.get("PYTHONPATH", "")
    r = subprocess.run([sys.executable, __file__, "--child", str(path), mode],
                       capture_output=True, text=True, env=env, check=False,
                       cwd=tempfile.gettempdir())
    if r.returncode != 0:
        return {"mode": mode, "error": r.stderr.strip().splitlines()[-1:]}
    return json.loads(r.stdout.strip().splitlines()[-1])


# ---------------------------------------------------------------------------
# The fixture
# ---------------------------------------------------------------------------

FIXTURE_TEST = '''
import pytest
pytestmark = pytest.mark.plc("prog.awl")
@pytest.mark.parametrize("i", range({n}))
def test_fixture(plc, i):
    plc.run(scans=1)
'''
PLAIN_TEST = '''
import pytest
@pytest.mark.parametrize("i", range({n}))
def test_plain(i):
    pass
'''


def fixture_overhead(text: str, tests: int, plcrt_dir: str | None) -> dict[str, Any]:
    """Milliseconds per test that the ``plc`` fixture adds (one scan of the
    program included): pytest runs of ``tests`` and ``2 * tests`` tests with
    and without the fixture, so the one-off costs (start-up, the first load)
    cancel out; best of two runs each."""
    env = dict(os.environ)
    if plcrt_dir:
        env["PYTHONPATH"] = plcrt_dir + os.pathsep + env.get("PYTHONPATH", "")
    times: dict[tuple[str, int], float] = {}
    with tempfile.TemporaryDirectory() as d:
        Path(d, "prog.awl").write_text(text)
        Path(d, "pytest.ini").write_text("[pytest]\n")
        for n in (tests, 2 * tests):
            Path(d, f"test_fx{n}.py").write_text(FIXTURE_TEST.format(n=n))
            Path(d, f"test_plain{n}.py").write_text(PLAIN_TEST.format(n=n))
            for kind in ("plain", "fx"):
                best = float("inf")
                for _ in range(2):
                    t0 = time.perf_counter()
                    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p",
                                        "no:cacheprovider", "-p", "no:xdist", "-p",
                                        "no:hypothesispytest", f"test_{kind}{n}.py"],
                                       cwd=d, env=env, capture_output=True, text=True,
                                       check=False)
                    best = min(best, time.perf_counter() - t0)
                    if r.returncode != 0:
                        return {"error": r.stdout.strip().splitlines()[-3:]}
                times[kind, n] = best
    marginal = ((times["fx", 2 * tests] - times["fx", tests])
                - (times["plain", 2 * tests] - times["plain", tests])) / tests
    first = (times["fx", tests] - times["plain", tests]) - marginal * tests
    return {"tests": [tests, 2 * tests],
            "seconds": {f"{k}{n}": round(v, 3) for (k, n), v in times.items()},
            "overhead_ms_per_test": marginal * 1000, "first_load_s": first}


# ---------------------------------------------------------------------------
# Driver
# ---------------------------------------------------------------------------

def measure(plcrt_dir: str | None, sizes: list[int], seeds: list[int], shapes: list[str],
            fixture_tests: int, workdir: Path) -> dict[str, Any]:
    rows = []
    for size in sizes:
        for shape in shapes:
            for seed in seeds:
                path = workdir / f"{shape}_{size}_{seed}.awl"
                if not path.exists():
                    path.write_text(_generators()[shape](size, seed))
                row: dict[str, Any] = {"size": size, "shape": shape, "seed": seed}
                for mode in ("plain", "gc-on", "trace"):
                    row[mode] = _run_child(path, mode, plcrt_dir)
                rows.append(row)
                print(_line(row), file=sys.stderr)
    text = _generators()["bool"](1000, 1)
    fixture = fixture_overhead(text, fixture_tests, plcrt_dir)
    (workdir / "fixture_1000.awl").write_text(text)
    fixture["in_process"] = _run_child(workdir / "fixture_1000.awl", "fixture", plcrt_dir)
    print(f"fixture: {fixture}", file=sys.stderr)
    return {"plcrt": plcrt_dir or "this checkout", "loads": rows, "fixture": fixture}


def _line(row: dict[str, Any]) -> str:
    p, g, t = row["plain"], row["gc-on"], row["trace"]
    if "error" in p:
        return f"{row['shape']:5} {row['size']:>6}: error {p['error']}"
    gc_on = f"{g['load_s']:.2f} s" if "load_s" in g else "-"
    return (f"{row['shape']:5} {row['size']:>6} seed {row['seed']}: parse {p['parse_s']:.3f} s, "
            f"compile {p['compile_s']:.3f} s (load with gc on {gc_on}), "
            f"RSS +{p['rss_growth_mib']:.0f} MiB (peak {p['rss_peak_mib']:.0f}), "
            f"traced peak {t.get('traced_peak_mib', 0):.0f} MiB, "
            f"live {t.get('traced_live_mib', 0):.1f} MiB, fork {p['fork_s'] * 1000:.1f} ms")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", default="1000,10000,100000")
    ap.add_argument("--seeds", default="1")
    ap.add_argument("--shapes", default="bool,mixed")
    ap.add_argument("--fixture-tests", type=int, default=300)
    ap.add_argument("--plcrt", default=None, help="measure the plcrt package in this directory")
    ap.add_argument("--compare", default=None,
                    help="also measure the plcrt in this directory (before/after)")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        path, mode = args.child
        print(json.dumps(child_fixture(path) if mode == "fixture" else child(path, mode)))
        return 0
    sizes = [int(x) for x in args.sizes.split(",")]
    seeds = [int(x) for x in args.seeds.split(",")]
    shapes = args.shapes.split(",")
    result: dict[str, Any] = {
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "host": f"{platform.node()}, {platform.processor() or platform.machine()}, "
                f"{os.cpu_count()} CPUs, Python {platform.python_version()}"}
    with tempfile.TemporaryDirectory() as d:
        runs = [("after", args.plcrt)]
        if args.compare:
            runs.insert(0, ("before", args.compare))
        for label, where in runs:
            print(f"== {label}: {where or 'this checkout'}", file=sys.stderr)
            result[label] = measure(where, sizes, seeds, shapes, args.fixture_tests, Path(d))
    if args.json:
        print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
