"""plcrt benchmark: execution speed of compiled programs and compile time.

Run ``python bench/run.py`` (or ``make bench``).  It

1. generates two STL programs in Micro/WIN export form (deterministic,
   seeded): a boolean-heavy one (contacts, ALD/OLD, LPS/LRD/LPP, outputs)
   and a mixed one (moves, INT/DINT math, compares, 100 ms timers), each of
   at least 1000 instructions;
2. loads each with :func:`plcrt.load`, warms it up, then times many scans
   in CPU time (``time.process_time``: on a shared machine wall time moves
   several-fold with the load) and keeps the best of several repeats;
3. reports instructions per second = instructions in the program x scans /
   seconds.  Every instruction of the program is counted once per scan, as a
   PLC's instruction timing does, whether or not a box's enable was 1;
4. times parse, load (compile and bind) and a scan of the corpus file
   ``roundtrip.awl`` with its symbol table (if the shared corpus is
   present): a real export that uses every instruction family.  Its first
   loads on the default and the Python backend take turns (half of
   ``--repeats`` each) and are reported as medians of CPU and wall time
   and as the ratio of the CPU times; ``--corpus-only`` runs only this.

Every program runs on each backend of ``--backends`` (default: Python and,
where llvmlite works, native; docs/native.md) in three builds: plain,
instrumented (``+probes``: network, output and contact coverage probes, as
``pytest --plc-coverage`` loads it) and instrumented with a breakpoint
armed (``+break``: a breakpoint on the program's last network whose handler
resumes at once, as a debugger's breakpoint whose condition is false; what
``plcrt debug`` and the panel run while a breakpoint is set).  Rows of the
native backend are named ``+native``.  ``--seeds 5,6`` adds a boolean and
a mixed program per seed.

Load figures: every ``load`` printed is a *first* load -- the program cache
of the process emptied and the native backend's disk cache a fresh empty
folder (``$PLCRT_CACHE_DIR`` for this run) -- unless it says ``cached``
(the same load again: a cache hit, the best of several).

This is a measuring tool, not a test: it asserts nothing and never fails on
slow results (``--check`` makes it exit 1 below the targets).  ``--save DIR``
writes the generated programs so they can be read or dumped with
``plcrt dump``; ``bench/programs/`` holds such a copy (``--save bench/programs``).
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import json
import os
import platform
import random
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing

import plcrt

CORPUS = ROOT.parent / "shared" / "corpus"
if not CORPUS.is_dir():
    CORPUS = Path("/work/shared/corpus")
CORPUS_FILE = "bulaofen0036-coder__Smart200-MicroWIN-MCP__roundtrip.awl"
CORPUS_SYMBOLS = ROOT / "tests" / "data" / "roundtrip_symbols.sdf"

#: Targets from the project brief, in instructions per second.
TARGETS = {"bool": 10_000_000, "mixed": 3_000_000}

MIN_INSNS = 1000


# ---------------------------------------------------------------------------
# Program generators
# ---------------------------------------------------------------------------

def _insn(mnemonic: str, operands: str = "") -> str:
    # Micro/WIN pads the mnemonic to seven columns.
    return f"{mnemonic:<7}{operands}".rstrip()


def _export(title: str, networks: list[tuple[str, list[str]]]) -> str:
    lines = ["ORGANIZATION_BLOCK MAIN:OB1", f"TITLE={title}", "BEGIN"]
    for number, (net_title, body) in enumerate(networks, 1):
        lines.append(f"Network {number} // {net_title}" if net_title else f"Network {number}")
        lines.extend(body)
    lines.append("END_ORGANIZATION_BLOCK")
    return "\n".join(lines) + "\n"


def _count(networks: list[tuple[str, list[str]]]) -> int:
    return sum(len(body) for _, body in networks)


def bool_program(min_insns: int = MIN_INSNS, seed: int = 1) -> str:
    """Boolean-heavy OB1: rungs of contacts, blocks and branched outputs."""
    rnd = random.Random(seed)

    def contact() -> str:
        area = rnd.choice(("I", "I", "M", "V", "Q"))
        byte = rnd.randrange(4 if area != "V" else 16)
        return f"{area}{byte}.{rnd.randrange(8)}"

    def out_bit(k: int) -> str:
        # Outputs go to M and V so that later rungs read earlier results.
        return f"M{4 + k // 8 % 28}.{k % 8}" if k % 3 else f"V{100 + k // 8}.{k % 8}"

    networks: list[tuple[str, list[str]]] = []
    k = 0
    while _count(networks) < min_insns:
        shape = len(networks) % 4
        body: list[str] = []
        if shape == 0:  # series and parallel contacts
            body += [_insn("LD", contact()), _insn("A", contact()), _insn("AN", contact()),
                     _insn("O", contact()), _insn("ON", contact()), _insn("A", contact()),
                     _insn("=", out_bit(k))]
            k += 1
        elif shape == 1:  # (a AND b OR c AND NOT d) AND (e OR f)
            body += [_insn("LD", contact()), _insn("A", contact()),
                     _insn("LD", contact()), _insn("AN", contact()), _insn("OLD"),
                     _insn("LD", contact()), _insn("O", contact()), _insn("ALD"),
                     _insn("AN", contact()), _insn("=", out_bit(k))]
            k += 1
        elif shape == 2:  # one condition, three branched outputs
            body += [_insn("LD", contact()), _insn("O", contact()), _insn("LPS"),
                     _insn("A", contact()), _insn("=", out_bit(k)), _insn("LRD"),
                     _insn("AN", contact()), _insn("=", out_bit(k + 1)), _insn("LPP"),
                     _insn("A", contact()), _insn("=", out_bit(k + 2))]
            k += 3
        else:  # seal-in with interlocks
            out = out_bit(k)
            body += [_insn("LD", contact()), _insn("O", out), _insn("AN", contact()),
                     _insn("A", contact()), _insn("LDN", contact()), _insn("ON", contact()),
                     _insn("ALD"), _insn("=", out)]
            k += 1
        networks.append(("", body))
    return _export("plcrt benchmark: boolean logic", networks)


def mixed_program(min_insns: int = MIN_INSNS, seed: int = 2) -> str:
    """Mixed OB1: moves, INT/DINT math, compares and 100 ms timers."""
    rnd = random.Random(seed)
    networks: list[tuple[str, list[str]]] = []
    # TON numbers with 100 ms resolution: T37-T63 and T101-T255.
    timers = [*range(37, 64), *range(101, 256)]
    k = 0
    while _count(networks) < min_insns:
        shape = len(networks) % 5
        a, b = 2 * rnd.randrange(0, 40), 2 * rnd.randrange(0, 40)  # inputs VW0..VW78
        w = 200 + 2 * (k % 200)                                  # results VW200..
        d = 1000 + 4 * (k % 100)                                 # results VD1000..
        if shape == 0:  # moves
            body = [_insn("LD", "SM0.0"), _insn("MOVW", f"VW{a}, VW{w}"),
                    _insn("MOVB", f"VB{a + 1}, VB{w + 1}"), _insn("MOVD", f"VD{a}, VD{d}"),
                    _insn("MOVW", f"+{rnd.randrange(1, 500)}, VW{w + 400}")]
        elif shape == 1:  # INT math on a scratch word (no accumulation: no overflow)
            body = [_insn("LD", "SM0.0"), _insn("MOVW", f"VW{a}, VW{w}"),
                    _insn("+I", f"VW{b}, VW{w}"), _insn("-I", f"+{rnd.randrange(1, 9)}, VW{w}"),
                    _insn("*I", f"+3, VW{w}")]
        elif shape == 2:  # DINT math and a compare-driven move
            body = [_insn("LD", "SM0.0"), _insn("MOVD", f"VD{a}, VD{d}"),
                    _insn("+D", f"VD{b}, VD{d}"),
                    _insn("LDW>", f"VW{a}, VW{b}"), _insn("AW<", f"VW{a}, +500"),
                    _insn("MOVW", f"VW{a}, VW{w}")]
        elif shape == 3:  # compares into bits
            body = [_insn("LDW>=", f"VW{a}, +{rnd.randrange(0, 300)}"),
                    _insn("OW=", f"VW{b}, +7"), _insn("LDD<", f"VD{a}, VD{b}"),
                    _insn("AB<>", f"VB{a}, VB{b}"), _insn("OLD"),
                    _insn("=", f"M{k % 32}.{k % 8}"), _insn("INCW", f"VW{w}")]
        else:  # a 100 ms timer and its bit
            t = f"T{timers[k // 5 % len(timers)]}"
            body = [_insn("LD", f"I{k % 2}.{k % 8}"), _insn("AN", f"M{k % 32}.{(k + 1) % 8}"),
                    _insn("TON", f"{t}, +{rnd.randrange(5, 50)}"),
                    _insn("LD", t), _insn("=", f"Q{k % 4}.{k % 8}")]
        networks.append(("", body))
        k += 1
    return _export("plcrt benchmark: mixed word logic", networks)


# ---------------------------------------------------------------------------
# Measuring
# ---------------------------------------------------------------------------

@dataclasses.dataclass
class ScanResult:
    name: str
    instructions: int
    networks: int
    scans_per_repeat: int
    repeats: int
    best_s: float
    #: the first load of the program (no cache: see :func:`first_load`)
    load_s: float
    #: the same load again, a cache hit (best of three)
    load_cached_s: float

    @property
    def scans_per_s(self) -> float:
        return self.scans_per_repeat / self.best_s

    @property
    def insns_per_s(self) -> float:
        return self.instructions * self.scans_per_s

    def as_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d.update(scans_per_s=round(self.scans_per_s, 1),
                 insns_per_s=round(self.insns_per_s),
                 us_per_scan=round(1e6 / self.scans_per_s, 2),
                 target_insns_per_s=TARGETS.get(self.name),
                 meets_target=self.insns_per_s >= TARGETS.get(self.name, 0))
        return d


def _prepare_inputs(plc: plcrt.Plc) -> None:
    """Non-trivial data so both branches of the logic run."""
    rnd = random.Random(7)
    for byte in range(4):
        plc[f"IB{byte}"] = rnd.randrange(256)
    for word in range(0, 80, 2):
        plc[f"VW{word}"] = rnd.randrange(0, 1000)


def first_load(fn: Callable[[], Any]) -> tuple[float, Any]:
    """Time ``fn()`` (a load) as a first load: the process's program cache
    emptied first; the native disk cache is the run's own empty folder
    (:func:`main` points ``PLCRT_CACHE_DIR`` at it) and is emptied too."""
    from plcrt.compiler import cache
    cache.programs.clear()
    disk = os.environ.get("PLCRT_CACHE_DIR")
    if disk and Path(disk, "native").is_dir():
        for f in Path(disk, "native").iterdir():
            f.unlink()
    t0 = time.perf_counter()
    result = fn()
    return time.perf_counter() - t0, result


def measure_scans(name: str, text: str, *, repeats: int, target_s: float,
                  instrument: bool = False, backend: str = "python",
                  armed: bool = False) -> ScanResult:
    load_s, plc = first_load(lambda: plcrt.load(text, instrument=instrument, backend=backend))
    load_cached_s, _ = _best_of(3, lambda: plcrt.load(text, instrument=instrument,
                                                      backend=backend))
    if armed:
        # a breakpoint on the last network whose handler resumes at once
        cov = plc.coverage
        hits = [0]

        def resume(_net: Any) -> None:
            hits[0] += 1
        cov.on_break = resume
        cov.breakpoints[len(cov.networks) - 1] = 1
    _prepare_inputs(plc)
    plc.scan(200)  # warm-up: timers started, caches filled
    # calibrate: scans per repeat so one repeat takes about target_s.  CPU
    # time of the process (time.process_time), not wall time: on a shared
    # machine the wall time of a repeat moves several-fold with the load
    t0 = time.process_time()
    plc.scan(100)
    per_scan = (time.process_time() - t0) / 100
    n = max(100, int(target_s / max(per_scan, 1e-9)))
    best = float("inf")
    gc_was = gc.isenabled()
    gc.disable()  # generated code allocates little; keep collector pauses out
    try:
        for _ in range(repeats):
            t0 = time.process_time()
            plc.scan(n)
            best = min(best, time.process_time() - t0)
    finally:
        if gc_was:
            gc.enable()
    if plc.mode != "RUN":
        raise RuntimeError(f"benchmark program {name} left RUN mode: {plc.fault}")
    if armed and not hits[0]:
        raise RuntimeError(f"benchmark program {name}: the armed breakpoint never ran")
    return ScanResult(name, plc.program.instruction_count(), plc.program.network_count(),
                      n, repeats, best, load_s, load_cached_s)


def _best_of(repeats: int, fn: Callable[[], Any]) -> tuple[float, Any]:
    best, result = float("inf"), None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
    return best, result


def measure_corpus(repeats: int) -> dict[str, Any] | None:
    """Parse + compile time of the roundtrip corpus file, honestly labelled."""
    from plcrt.lang import parse_program, parse_symbols, read_source

    path = CORPUS / CORPUS_FILE
    if not path.is_file():
        return None
    symbols = None
    if CORPUS_SYMBOLS.is_file():
        symbols = parse_symbols(read_source(CORPUS_SYMBOLS), str(CORPUS_SYMBOLS))

    t0 = time.perf_counter()
    text = read_source(path)
    read_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    program = parse_program(text, str(path))  # first parse: builds or loads the grammar
    first_parse_s = time.perf_counter() - t0
    parse_s, program = _best_of(repeats, lambda: parse_program(text, str(path)))

    # the first load (no cache) on the default backend (auto: the Python
    # build at once, the native one in the background) and on Python,
    # `repeats` of each taking turns (neither backend always goes first),
    # the median of each in CPU time (the ratio of the two is the figure:
    # the wall time moves with the machine's load); then the cached load,
    # a cache hit of the process's program cache
    firsts: dict[str, list[tuple[float, float]]] = {"auto": [], "python": []}
    plc = None
    for i in range(repeats):
        for backend in ("auto", "python") if i % 2 == 0 else ("python", "auto"):
            c0 = time.process_time()
            wall, loaded = first_load(lambda: plcrt.Plc(program, symbols=symbols,
                                                        backend=backend))
            firsts[backend].append((wall, time.process_time() - c0))
            if backend == "auto":
                plc = loaded
    load_s, load_cpu_s = (statistics.median(x) for x in zip(*firsts["auto"]))
    load_python_s, load_python_cpu_s = (statistics.median(x) for x in zip(*firsts["python"]))
    load_cached_s, _ = _best_of(repeats, lambda: plcrt.Plc(program, symbols=symbols))
    plc.scan(100)
    t0 = time.perf_counter()
    plc.scan(1000)
    scan_s = (time.perf_counter() - t0) / 1000
    return {
        "file": CORPUS_FILE,
        "symbols": CORPUS_SYMBOLS.name if symbols is not None else None,
        "instructions": program.instruction_count(),
        "networks": program.network_count(),
        "blocks": len(program.pous),
        "read_s": read_s,
        "first_parse_s": first_parse_s,
        "parse_s": parse_s,
        "load_s": load_s,
        "load_python_s": load_python_s,
        "load_cpu_s": load_cpu_s,
        "load_python_cpu_s": load_python_cpu_s,
        "load_ratio_cpu": load_cpu_s / load_python_cpu_s,
        "load_cached_s": load_cached_s,
        "parse_plus_load_s": parse_s + load_s,
        "us_per_scan": scan_s * 1e6,
        "mode_after_run": plc.mode,
    }


# ---------------------------------------------------------------------------
# Main
# ---------------------------------------------------------------------------

def machine() -> dict[str, Any]:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"cores": os.cpu_count(), "cpu": cpu,
            "python": platform.python_version(),
            "implementation": platform.python_implementation(),
            "plcrt": plcrt.__version__}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--repeats", type=int, default=15, help="timed repeats (best is kept)")
    ap.add_argument("--repeat-seconds", type=float, default=0.2,
                    help="approximate duration of one repeat")
    ap.add_argument("--insns", type=int, default=MIN_INSNS,
                    help="minimum instructions per generated program")
    ap.add_argument("--save", metavar="DIR", help="write the generated programs to DIR")
    ap.add_argument("--check", action="store_true", help="exit 1 when below a target")
    ap.add_argument("--backends", default=None, metavar="LIST",
                    help="backends to time, of python,native (default: both, native where "
                         "llvmlite works)")
    ap.add_argument("--native", action="store_true",
                    help="time the native backend too (the default where llvmlite works)")
    ap.add_argument("--corpus-only", action="store_true",
                    help="only the corpus file's parse and loads (half of --repeats first "
                         "loads per backend)")
    ap.add_argument("--seeds", default="",
                    help="more generator seeds (comma-separated): each adds a boolean and a "
                         "mixed program of its own, so no figure rests on one program")
    args = ap.parse_args(argv)
    if args.backends:
        backends = [b.strip() for b in args.backends.split(",") if b.strip()]
        bad = [b for b in backends if b not in ("python", "native")]
        if bad:
            ap.error(f"unknown backend(s): {', '.join(bad)}; known: python, native")
    else:
        from plcrt.compiler.native.jit import usable
        why = usable()
        backends = ["python"] + (["native"] if why is None or args.native else [])
        if why is not None:
            print(f"native backend skipped: {why}", file=sys.stderr)

    programs = {"bool": bool_program(args.insns), "mixed": mixed_program(args.insns)}
    for seed in (int(x) for x in args.seeds.split(",") if x.strip()):
        programs[f"bool/s{seed}"] = bool_program(args.insns, seed=seed)
        programs[f"mixed/s{seed}"] = mixed_program(args.insns, seed=seed)
    if args.save:
        out = Path(args.save)
        out.mkdir(parents=True, exist_ok=True)
        for name, text in programs.items():
            (out / f"{name}.awl").write_text(text, encoding="utf-8")

    # the native backend's disk cache: this run's own folder, emptied before
    # every first load (first_load), so no figure is a hit of an earlier run
    saved = os.environ.get("PLCRT_CACHE_DIR")
    with tempfile.TemporaryDirectory(prefix="plcrt-bench-cache-") as disk:
        os.environ["PLCRT_CACHE_DIR"] = disk
        scans: dict[str, ScanResult] = {}
        for backend in [] if args.corpus_only else backends:
            tag = "" if backend == "python" else f"+{backend}"
            # plain, then with coverage probes (pytest --plc-coverage), then
            # with probes and an armed breakpoint (plcrt debug, the panel)
            for build, instrument, armed in (("", False, False), ("+probes", True, False),
                                             ("+break", True, True)):
                for name, text in programs.items():
                    r = measure_scans(name, text, repeats=args.repeats,
                                      target_s=args.repeat_seconds, backend=backend,
                                      instrument=instrument, armed=armed)
                    scans[name + tag + build] = dataclasses.replace(r, name=name + tag + build)
        corpus = measure_corpus(max(3, args.repeats // 2))
    if saved is None:
        os.environ.pop("PLCRT_CACHE_DIR", None)
    else:
        os.environ["PLCRT_CACHE_DIR"] = saved

    if args.json:
        print(json.dumps({"machine": machine(),
                          "programs": {k: v.as_dict() for k, v in scans.items()},
                          "corpus": corpus}, indent=2))
    else:
        m = machine()
        print(f"machine: {m['cores']} cores, {m['cpu']}, "
              f"{m['implementation']} {m['python']}, plcrt {m['plcrt']}")
        for r in scans.values():
            target = TARGETS.get(r.name)
            verdict = "" if target is None else \
                f" - {'meets' if r.insns_per_s >= target else 'BELOW'} target {target / 1e6:g} M/s"
            print(f"{r.name:<24} {r.instructions:>5} instructions, {r.networks:>4} networks: "
                  f"{r.insns_per_s / 1e6:7.2f} M instructions/s "
                  f"({1e6 / r.scans_per_s:7.1f} us/scan, best of {r.repeats} x "
                  f"{r.scans_per_repeat} scans; first load {r.load_s * 1e3:.0f} ms, "
                  f"cached {r.load_cached_s * 1e3:.1f} ms){verdict}")
        for name in programs:
            for tag in [t for t in ("", "+native") if name + t in scans]:
                plain = scans[name + tag]
                print(f"{name + tag:<19} with probes / plain: "
                      f"{scans[name + tag + '+probes'].insns_per_s / plain.insns_per_s:.2f}x, "
                      f"breakpoint armed / plain: "
                      f"{scans[name + tag + '+break'].insns_per_s / plain.insns_per_s:.2f}x")
            nat = scans.get(f"{name}+native")
            if nat is not None:
                print(f"{name:<19} native / python: plain "
                      f"{nat.insns_per_s / scans[name].insns_per_s:.1f}x, with probes "
                      f"{scans[name + '+native+probes'].insns_per_s / scans[name + '+probes'].insns_per_s:.1f}x, "
                      f"breakpoint armed "
                      f"{scans[name + '+native+break'].insns_per_s / scans[name + '+break'].insns_per_s:.1f}x")
        if corpus is None:
            print(f"corpus: {CORPUS_FILE} not found, skipped")
        else:
            c = corpus
            print(f"corpus {c['file']}: {c['instructions']} instructions, "
                  f"{c['networks']} networks, {c['blocks']} blocks"
                  + (f" (symbols {c['symbols']})" if c["symbols"] else ""))
            print(f"  parse {c['parse_s'] * 1e3:.1f} ms (first parse in process "
                  f"{c['first_parse_s'] * 1e3:.1f} ms); first load (compile+bind, no cache, "
                  f"median) {c['load_cpu_s'] * 1e3:.1f} ms CPU ({c['load_s'] * 1e3:.1f} ms wall) "
                  f"on the default backend, {c['load_python_cpu_s'] * 1e3:.1f} ms CPU "
                  f"({c['load_python_s'] * 1e3:.1f} ms wall) on Python, ratio "
                  f"{c['load_ratio_cpu']:.2f}; cached load "
                  f"{c['load_cached_s'] * 1e3:.1f} ms; parse+first load "
                  f"{c['parse_plus_load_s'] * 1e3:.1f} ms; {c['us_per_scan']:.1f} us/scan "
                  f"(mode {c['mode_after_run']} after 1100 scans)")
    if args.check and any(r.insns_per_s < TARGETS.get(r.name, 0) for r in scans.values()):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
