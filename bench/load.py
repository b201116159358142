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
   difference per added test is the fixture's overhead with pytest's own;
5. with ``--awlsim``, times parse + compile of the same logic in plcrt and
   in awlsim side by side (``--peer-size`` statements, 20 000 by default):
   the peer benchmark's generator (``../shared/peers/gen.py``, ``--peers``)
   writes it as S7-200 STL and as S7-300 AWL, each engine loads it in
   fresh processes taking turns (``--peer-rounds``), and each reports its
   first load in the process and the best of ``--peer-repeats`` more
   (plcrt with its program cache off, so every load compiles; awlsim
   parses, loads, builds and starts up).  awlsim runs from its virtual
   environments (``--cache``, as for ``bench/peers.py``); without them
   this part is skipped with a message.

``--backends python,native,auto`` measures instead, per backend, the first
load (a fresh process and an empty disk cache) and the cached load (a
fresh process, the machine code on disk) with the RSS growth of each (all
of it, and the private part: without the pages of the llvmlite library's
code, which every process maps from one file), the scan cost in CPU
nanoseconds per statement, the machine code's size, and for ``auto`` the
growth once the background native build has been switched in; and the
same load again in the first process ("cached (in process)": a hit of
the program cache, what a test session's later loads cost).

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
import statistics
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
    """VmRSS, VmHWM, RssAnon (private) and RssFile (mapped files: the
    llvmlite library's code) of this process in KiB."""
    out = {}
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(("VmRSS:", "VmHWM:", "RssAnon:", "RssFile:")):
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
    # "plain@native": a backend named (the backend rows); without one the
    # plcrt's default, and a tiny load first takes imports and first-use
    # costs out of the way.  With one, the tiny load is Python's, so the
    # native row's first load includes loading llvmlite and LLVM: what a
    # user's first load of a session costs
    mode, _, backend = mode.partition("@")
    kw: dict[str, Any] = {"backend": backend} if backend else {}
    plcrt.load(TINY, backend="python" if backend else None).scan(1)
    out: dict[str, Any] = {"mode": mode, "plcrt": str(Path(plcrt.__file__).parent)}
    if mode == "gc-on":
        if not hasattr(runtime, "gc_paused"):
            return {"mode": mode, "skipped": "this plcrt does not pause the collector"}
        # where the engine pauses it: building a PLC and compiling its template
        for name in ("plcrt.engine.runtime", "plcrt.engine.binding"):
            module = sys.modules.get(name)
            if module is not None and hasattr(module, "gc_paused"):
                module.gc_paused = contextlib.nullcontext   # type: ignore[attr-defined]
    text = Path(path).read_text()
    gc.collect()
    if mode == "trace":
        tracemalloc.start()
        base = tracemalloc.get_traced_memory()[0]
    before = _status()
    pause = getattr(runtime, "gc_paused", contextlib.nullcontext)
    c0 = time.process_time()
    t0 = time.perf_counter()
    with (contextlib.nullcontext() if mode == "gc-on" else pause()):
        program = parse_sources(text)
    t1 = time.perf_counter()
    c1 = time.process_time()
    plc = Plc(program, scan_ms=1, **kw)
    t2 = time.perf_counter()
    c2 = time.process_time()
    # CPU time too: on a loaded machine the wall time says little
    out["load_cpu_s"] = time.process_time() - c0
    if mode == "trace":
        now, peak = tracemalloc.get_traced_memory()
        out.update(traced_live_mib=(now - base) / 2**20, traced_peak_mib=(peak - base) / 2**20)
        tracemalloc.stop()
    gc.collect()
    after = _status()
    t3 = time.perf_counter()
    plc.fork()
    t4 = time.perf_counter()
    # the same load again in this process: a hit of the program cache
    # (plcrt.compiler.cache.programs), the cached load of a test session
    t5 = time.perf_counter()
    Plc(program, scan_ms=1, **kw)
    out["load_again_s"] = time.perf_counter() - t5
    out.update(insns=program.instruction_count(), parse_s=t1 - t0, compile_s=t2 - t1,
               load_s=t2 - t0, compile_cpu_s=c2 - c1, fork_s=t4 - t3,
               rss_growth_mib=(after["VmRSS"] - before["VmRSS"]) / 1024,
               anon_growth_mib=(after.get("RssAnon", 0) - before.get("RssAnon", 0)) / 1024,
               rss_peak_mib=after["VmHWM"] / 1024)
    if backend:
        out.update(_backend_figures(plc, before, out["insns"]))
    return out


def _backend_figures(plc: Any, before: dict[str, int], insns: int) -> dict[str, Any]:
    """A named backend's row: for ``auto``, the native build compiled and
    switched in (``_tier_up``, what a long run reaches after its first
    scans) and the RSS growth then; the scan cost in nanoseconds per
    statement (CPU time: the machine may be loaded), best of 5 runs."""
    import gc
    out: dict[str, Any] = {}
    if plc.backend.get("tiered"):
        t0, c0 = time.perf_counter(), time.process_time()
        plc._tier_up()
        out["native_build_s"] = time.perf_counter() - t0
        out["native_build_cpu_s"] = time.process_time() - c0
        plc.scan(2)
        gc.collect()
        now = _status()
        out.update(switched_rss_growth_mib=(now["VmRSS"] - before["VmRSS"]) / 1024,
                   switched_anon_growth_mib=(now.get("RssAnon", 0)
                                             - before.get("RssAnon", 0)) / 1024)
    out["backend"] = plc.backend["name"]
    out["native_cached"] = bool(plc.backend.get("cached"))
    code = getattr(plc.compiled.native, "code_bytes", None) if out["backend"] == "native" \
        else None
    if code is not None:
        out["code_mib"] = code / 2**20
    scans = max(10, int(2e7 // max(insns, 1)) if out["backend"] == "native"
                else int(2e6 // max(insns, 1)))
    plc.scan(3)
    best = float("inf")
    for _ in range(5):
        c0 = time.process_time()
        plc.scan(scans)
        best = min(best, (time.process_time() - c0) / scans)
    out["ns_per_statement"] = best / max(insns, 1) * 1e9
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


def child_peer_load(path: str, repeats: int = 3) -> dict[str, Any]:
    """Parse + compile of ``path`` with ``plcrt.load``: the first load in
    this process (after a tiny one: imports out of the way), then the best
    of ``repeats``, every one compiled (program cache off)."""
    import gc

    import plcrt
    from plcrt.compiler import cache
    plcrt.load(TINY).scan(1)
    cache.programs.max_entries = 0
    text = Path(path).read_text()
    times = []
    statements = 0
    for _ in range(1 + repeats):
        gc.collect()
        t0 = time.perf_counter()
        plc = plcrt.load(text, scan_ms=1)
        times.append(time.perf_counter() - t0)
        statements = plc.program.instruction_count()
        del plc
    return {"mode": "peer", "statements": statements, "first_s": times[0],
            "best_s": min(times[1:]), "all_s": times}


def _run_child(path: Path, mode: str, plcrt_dir: str | None,
               cache_dir: Path | None = None) -> dict[str, Any]:
    env = dict(os.environ)
    if cache_dir is not None:          # the native backend's disk cache
        env["PLCRT_CACHE_DIR"] = str(cache_dir)
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
# Side by side with awlsim
# ---------------------------------------------------------------------------

AWLSIM_ENVS = (("awlsim-cy", "venv-awlsim-cy", "2"), ("awlsim-py", "venv-awlsim", None))


def _peer_cache(arg: str | None) -> Path:
    """Where awlsim's environments are (as ``bench/peers.py`` looks)."""
    if arg:
        return Path(arg)
    env = os.environ.get("PLCRT_PEERS_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "plcrt" / "peers"


def _awlsim_load(py: Path, cython: str | None, peers: Path, path: Path,
                 repeats: int) -> dict[str, Any]:
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    env.pop("AWLSIM_CYTHON", None)
    if cython:
        env["AWLSIM_CYTHON"] = cython           # the Cython core, or abort
    r = subprocess.run([str(py), str(peers / "bench_awlsim.py"), "load", str(path),
                        "--repeats", str(repeats)], env=env, capture_output=True, text=True,
                       check=False, cwd=tempfile.gettempdir())
    if r.returncode != 0:
        return {"error": (r.stderr.strip().splitlines() or ["failed"])[-1][:200]}
    out = json.loads(r.stdout)
    return {"statements": out["statements"], "first_s": out["first"]["total_s"],
            "best_s": out["best"]["total_s"], "parse_best_s": out["best"]["parse_s"]}


def versus_awlsim(peers: Path, cache: Path, size: int, rounds: int, repeats: int,
                  plcrt_dir: str | None, workdir: Path) -> dict[str, Any]:
    """Parse + compile time of the same boolean logic in plcrt and awlsim,
    in turns; the median over the rounds of each engine's figures."""
    if not (peers / "gen.py").exists():
        return {"skipped": f"no peer benchmark at {peers} (--peers DIR)"}
    engines = {name: (cache / venv / "bin" / "python", cy) for name, venv, cy in AWLSIM_ENVS
               if (cache / venv / "bin" / "python").exists()}
    if not engines:
        return {"skipped": f"awlsim's environments are not in {cache} (--cache DIR; "
                           f"python bench/peers.py --setup creates them)"}
    progdir = workdir / f"peer_{size}"
    subprocess.run([sys.executable, str(peers / "gen.py"), str(progdir), "--bool", str(size),
                    "--mixed", "10", "--seed", "1"], check=True, capture_output=True)
    runs: dict[str, list[dict[str, Any]]] = {"plcrt": [], **{e: [] for e in engines}}
    errors: dict[str, Any] = {}
    for _ in range(rounds):
        res = _run_child(progdir / "bool_s7200.awl", f"peer:{repeats}", plcrt_dir)
        if "error" in res:
            errors["plcrt"] = res["error"]
        else:
            runs["plcrt"].append(res)
        for name, (py, cy) in engines.items():
            res = _awlsim_load(py, cy, peers, progdir / "bool_s7300.awl", repeats)
            if "error" in res:
                errors[name] = res["error"]
            else:
                runs[name].append(res)
    out: dict[str, Any] = {"rounds": rounds, "repeats": repeats, "errors": errors}
    for name, rs in runs.items():
        if rs:
            out[name] = {"statements": rs[0]["statements"],
                         "first_s": statistics.median(r["first_s"] for r in rs),
                         "best_s": statistics.median(r["best_s"] for r in rs),
                         "best_each_round_s": [round(r["best_s"], 3) for r in rs]}
    if "plcrt" in out:
        for name in engines:
            if name in out:
                out[f"{name}/plcrt"] = round(out[name]["best_s"] / out["plcrt"]["best_s"], 2)
    return out


def _peer_line(res: dict[str, Any]) -> str:
    if "skipped" in res:
        return f"versus awlsim: skipped: {res['skipped']}"
    parts = []
    for name in ("plcrt", *(e for e, _, _ in AWLSIM_ENVS)):
        if name in res:
            r = res[name]
            parts.append(f"{name} {r['statements']} statements: first {r['first_s']:.3f} s, "
                         f"best {r['best_s']:.3f} s")
    ratios = ", ".join(f"{k} {v}" for k, v in res.items() if k.endswith("/plcrt"))
    return "versus awlsim (parse + compile, median of rounds): " + "; ".join(parts) + \
        (f" ({ratios}; above 1: plcrt faster)" if ratios else "") + \
        (f"; errors {res['errors']}" if res["errors"] else "")


# ---------------------------------------------------------------------------
# Driver
# ---------------------------------------------------------------------------

def backend_loads(path: Path, backends: list[str], plcrt_dir: str | None,
                  workdir: Path) -> dict[str, Any]:
    """Per backend: the first load (a fresh process, an empty disk cache)
    and the cached load (a fresh process whose disk cache holds the
    machine code the first one made: a second ``plcrt run`` or pytest
    session; the Python backend keeps nothing on disk, so it is a first
    load again)."""
    out: dict[str, Any] = {}
    for backend in backends:
        cache = Path(tempfile.mkdtemp(prefix=f"cache-{backend}-", dir=workdir))
        out[backend] = {"first": _run_child(path, f"plain@{backend}", plcrt_dir, cache),
                        "cached": _run_child(path, f"plain@{backend}", plcrt_dir, cache)}
    return out


def _backend_line(row: dict[str, Any]) -> str:
    parts = []
    for backend, r in row["backends"].items():
        f, c = r["first"], r["cached"]
        if "error" in f or "error" in c:
            parts.append(f"{backend}: error {f.get('error') or c.get('error')}")
            continue
        switched = (f", native after {f['native_build_s']:.1f} s: RSS "
                    f"+{f['switched_rss_growth_mib']:.0f} MiB "
                    f"(private +{f['switched_anon_growth_mib']:.0f})"
                    if "native_build_s" in f else "")
        parts.append(f"{backend}: first {f['load_s']:.2f} s ({f.get('load_cpu_s', 0):.2f} s CPU, "
                     f"compile {f['compile_cpu_s']:.2f} s) RSS +{f['rss_growth_mib']:.0f} MiB "
                     f"(private +{f['anon_growth_mib']:.0f}){switched}, "
                     f"cached (disk) {c['load_s']:.2f} s ({c.get('load_cpu_s', 0):.2f} s CPU) "
                     f"RSS +{c['rss_growth_mib']:.0f} MiB, "
                     f"cached (in process) {f['load_again_s'] * 1e3:.1f} ms, "
                     f"{c['ns_per_statement']:.2f} ns/statement")
    return f"{row['shape']:5} {row['size']:>6} seed {row['seed']}: " + "; ".join(parts)


def measure(plcrt_dir: str | None, sizes: list[int], seeds: list[int], shapes: list[str],
            fixture_tests: int, workdir: Path, backends: list[str] | None = None
            ) -> dict[str, Any]:
    rows = []
    for size in sizes:
        for shape in shapes:
            for seed in seeds:
                path = workdir / f"{shape}_{size}_{seed}.awl"
                if not path.exists():
                    path.write_text(_generators()[shape](size, seed))
                row: dict[str, Any] = {"size": size, "shape": shape, "seed": seed}
                if backends:
                    row["backends"] = backend_loads(path, backends, plcrt_dir, workdir)
                    rows.append(row)
                    print(_backend_line(row), file=sys.stderr)
                    continue
                for mode in ("plain", "gc-on", "trace"):
                    row[mode] = _run_child(path, mode, plcrt_dir)
                rows.append(row)
                print(_line(row), file=sys.stderr)
    fixture: dict[str, Any] = {}
    if fixture_tests > 0:                      # --fixture-tests 0: loads only
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
    ap.add_argument("--fixture-tests", type=int, default=300,
                    help="pytest runs of N and 2N tests for the fixture's cost (0: none)")
    ap.add_argument("--plcrt", default=None, help="measure the plcrt package in this directory")
    ap.add_argument("--compare", default=None,
                    help="also measure the plcrt in this directory (before/after)")
    ap.add_argument("--awlsim", action="store_true",
                    help="also time parse + compile side by side with awlsim")
    ap.add_argument("--awlsim-only", action="store_true",
                    help="only the side-by-side time with awlsim")
    ap.add_argument("--peers", default=str(HERE.parents[1] / "shared" / "peers"),
                    help="the peer benchmark's folder (gen.py, bench_awlsim.py)")
    ap.add_argument("--cache", default=None, help="where awlsim's environments are")
    ap.add_argument("--peer-size", type=int, default=20000)
    ap.add_argument("--peer-rounds", type=int, default=3)
    ap.add_argument("--peer-repeats", type=int, default=3)
    ap.add_argument("--backends", default=None, metavar="LIST",
                    help="instead of the load breakdown: the first and the cached load "
                         "(RSS growth too) on each of these backends, e.g. python,native")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        path, mode = args.child
        if mode == "fixture":
            res = child_fixture(path)
        elif mode.startswith("peer:"):
            res = child_peer_load(path, int(mode.split(":")[1]))
        else:
            res = child(path, mode)
        print(json.dumps(res))
        return 0
    sizes = [int(x) for x in args.sizes.split(",")]
    seeds = [int(x) for x in args.seeds.split(",")]
    shapes = args.shapes.split(",")
    result: dict[str, Any] = {
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "host": f"{platform.node()}, {platform.processor() or platform.machine()}, "
                f"{os.cpu_count()} CPUs, Python {platform.python_version()}",
        "load_average_before": os.getloadavg()}
    with tempfile.TemporaryDirectory() as d:
        runs = [("after", args.plcrt)]
        if args.compare:
            runs.insert(0, ("before", args.compare))
        for label, where in runs:
            print(f"== {label}: {where or 'this checkout'}", file=sys.stderr)
            if not args.awlsim_only:
                result[label] = measure(where, sizes, seeds, shapes, args.fixture_tests,
                                        Path(d), args.backends.split(",") if args.backends
                                        else None)
            if args.awlsim or args.awlsim_only:
                peer = versus_awlsim(Path(args.peers), _peer_cache(args.cache),
                                     args.peer_size, args.peer_rounds, args.peer_repeats,
                                     where, Path(d))
                result.setdefault(label, {})["versus_awlsim"] = peer
                print(_peer_line(peer), file=sys.stderr)
    result["load_average_after"] = os.getloadavg()
    if args.json:
        print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
