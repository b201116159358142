"""plcrt against awlsim, side by side: time per scan of the same logic.

Run ``python bench/peers.py`` (``--json`` for one JSON object).  It uses the
peer benchmark kept next to the project (``../shared/peers/``, or
``--peers DIR``): its generator writes the same logic as S7-200 STL for
plcrt and as S7-300 AWL for awlsim, and its two drivers check every engine
against a Python reference before timing it.  This script

1. keeps awlsim's virtual environments in a cache (``--cache DIR``, default
   ``$PLCRT_PEERS_CACHE`` or ``~/.cache/plcrt/peers``); ``--setup`` creates
   them there once with the peers' ``setup_venvs.sh`` (awlsim from PyPI,
   and its Cython core built from the sdist: about 30 minutes on 2 cores;
   ``--no-cython`` skips that build);
2. generates the programs for every seed of ``--seeds`` and every size of
   ``--sizes`` (boolean and mixed statements), so that no figure rests on
   one program;
3. times plcrt (this checkout, this interpreter; ``plcrt-auto`` is the
   default backend, ``auto``: the Python build at once, the native one
   compiled in the background and switched to between two scans, so its
   best time is the native build's; ``plcrt`` is the Python backend and
   ``plcrt-native`` the native one, chosen through ``PLCRT_BACKEND``) and
   each awlsim core alternately, ``--rounds`` times, and keeps each
   engine's best time per scan;
4. reports µs per scan and the ratio awlsim / plcrt per program (above 1:
   plcrt is faster), with the straight-line Python functions of the
   boolean program that the plcrt driver times in the same process.

A measuring tool: it asserts nothing, and a program that an engine
computes differently from the reference is reported, not timed as fast.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
ENGINES = ("plcrt", "plcrt-auto", "plcrt-native", "awlsim-cy", "awlsim-py")


def _cache_dir(arg: str | None) -> Path:
    if arg:
        return Path(arg)
    env = os.environ.get("PLCRT_PEERS_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "plcrt" / "peers"


def _pythons(cache: Path) -> dict[str, Path]:
    """The interpreters of each engine that exist in the cache."""
    found = {e: Path(sys.executable) for e in ENGINES if e.startswith("plcrt")}
    for engine, venv in (("awlsim-cy", "venv-awlsim-cy"), ("awlsim-py", "venv-awlsim")):
        py = cache / venv / "bin" / "python"
        if py.exists():
            found[engine] = py
    return found


def _setup(peers: Path, cache: Path, cython: bool) -> None:
    cache.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, VENVS=str(cache), PLCRT_SRC=str(ROOT),
               SKIP_CYTHON="0" if cython else "1")
    print(f"creating awlsim's environments in {cache} "
          f"({'with' if cython else 'without'} the Cython core)", file=sys.stderr)
    subprocess.run(["bash", str(peers / "setup_venvs.sh")], env=env, cwd=ROOT, check=True)


def _run(engine: str, py: Path, peers: Path, progdir: Path, repeats: int) -> dict[str, Any]:
    script = "bench_plcrt.py" if engine.startswith("plcrt") else "bench_awlsim.py"
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    env.pop("AWLSIM_CYTHON", None)
    if engine == "awlsim-cy":
        env["AWLSIM_CYTHON"] = "2"       # the Cython core, or abort
    if engine.startswith("plcrt"):
        env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
        # the driver loads programs without a backend option: the
        # environment chooses it (plcrt.load's default); plcrt-auto leaves
        # it unset, the default backend
        env.pop("PLCRT_BACKEND", None)
        if engine != "plcrt-auto":
            env["PLCRT_BACKEND"] = "native" if engine == "plcrt-native" else "python"
    out = subprocess.run([str(py), str(peers / script), "speed", str(progdir),
                          "--repeats", str(repeats)], env=env, capture_output=True, text=True)
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["failed"])[-1][:200]}
    return json.loads(out.stdout)


def measure(peers: Path, cache: Path, seeds: list[int], sizes: list[tuple[int, int]],
            rounds: int, repeats: int, engines: list[str]) -> dict[str, Any]:
    pythons = _pythons(cache)
    missing = [e for e in engines if e not in pythons]
    engines = [e for e in engines if e in pythons]
    cases = []
    with tempfile.TemporaryDirectory(prefix="plcrt-peers-") as tmp:
        for seed in seeds:
            for n_bool, n_mixed in sizes:
                progdir = Path(tmp) / f"s{seed}_{n_bool}_{n_mixed}"
                subprocess.run([sys.executable, str(peers / "gen.py"), str(progdir),
                                "--bool", str(n_bool), "--mixed", str(n_mixed),
                                "--seed", str(seed)], check=True, capture_output=True)
                best: dict[str, float] = {}     # engine:program -> best µs per scan
                checks: dict[str, dict[str, Any]] = {}
                errors: dict[str, str] = {}
                for _ in range(rounds):
                    for engine in engines:              # alternately: same machine state
                        res = _run(engine, pythons[engine], peers, progdir, repeats)
                        if "error" in res:
                            errors[engine] = res["error"]
                            continue
                        for prog, r in res["programs"].items():
                            label = f"{engine}:{prog}"
                            us = r["best_s"] * 1e6
                            best[label] = min(best.get(label, us), us)
                            if "check" in r:
                                checks[label] = r["check"]
                row: dict[str, Any] = {"seed": seed, "bool": n_bool, "mixed": n_mixed,
                                       "us_per_scan": {k: round(v, 2)
                                                       for k, v in sorted(best.items())},
                                       "checks": checks, "errors": errors, "ratios": {}}
                for prog in ("bool", "mixed"):
                    for me in ("plcrt", "plcrt-auto", "plcrt-native"):
                        mine = best.get(f"{me}:{prog}")
                        for peer in ("awlsim-cy", "awlsim-py"):
                            theirs = best.get(f"{peer}:{prog}")
                            if mine and theirs:
                                row["ratios"][f"{peer}/{me} {prog}"] = round(theirs / mine, 3)
                cases.append(row)
    return {"engines": engines, "missing": missing, "cache": str(cache),
            "rounds": rounds, "cases": cases}


def _sizes(text: str) -> list[tuple[int, int]]:
    out = []
    for part in text.split(","):
        b, _, m = part.partition("/")
        out.append((int(b), int(m or b)))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--peers", default=str(ROOT.parent / "shared" / "peers"),
                    help="the peer benchmark's folder")
    ap.add_argument("--cache", help="where awlsim's environments are kept")
    ap.add_argument("--setup", action="store_true", help="create the environments if missing")
    ap.add_argument("--no-cython", action="store_true", help="with --setup: no Cython build")
    ap.add_argument("--seeds", default="1,2,3", help="generator seeds, comma-separated")
    ap.add_argument("--sizes", default="2000/1000",
                    help="BOOL/MIXED statement counts, comma-separated (e.g. 2000/1000,500/4000)")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds per program")
    ap.add_argument("--repeats", type=int, default=5, help="timed repeats per run")
    ap.add_argument("--engines", default="plcrt,plcrt-auto,plcrt-native,awlsim-cy",
                    help=f"engines to time, of {', '.join(ENGINES)}")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    peers = Path(args.peers)
    if not (peers / "gen.py").exists():
        print(f"no peer benchmark at {peers} (--peers DIR)", file=sys.stderr)
        return 2
    cache = _cache_dir(args.cache)
    engines = [e.strip() for e in args.engines.split(",") if e.strip()]
    bad = [e for e in engines if e not in ENGINES]
    if bad:
        print(f"unknown engine(s): {', '.join(bad)}; known: {', '.join(ENGINES)}", file=sys.stderr)
        return 2
    if args.setup and not (cache / "venv-awlsim").exists():
        _setup(peers, cache, not args.no_cython)
    out = measure(peers, cache, [int(s) for s in args.seeds.split(",")], _sizes(args.sizes),
                  args.rounds, args.repeats, engines)
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    if out["missing"]:
        print(f"not in {cache}: {', '.join(out['missing'])} (python bench/peers.py --setup)")
    for c in out["cases"]:
        print(f"seed {c['seed']}, {c['bool']} boolean / {c['mixed']} mixed statements:")
        for label, us in c["us_per_scan"].items():
            print(f"  {label:28s} {us:9.1f} µs per scan")
        for label, r in c["ratios"].items():
            print(f"  {label:28s} {r:9.2f}  (above 1: plcrt faster)")
        for label, chk in c["checks"].items():
            if chk.get("mismatching_scans") or chk.get("agrees_with_image") is False:
                print(f"  {label}: DIFFERS from the reference: {chk}")
        for engine, err in c["errors"].items():
            print(f"  {engine}: failed: {err}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
