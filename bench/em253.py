"""plcrt EM253 benchmark: simulated seconds per wall-clock second.

Run ``python bench/em253.py`` (``--json`` for one JSON object).  It

1. loads every seed example ``programs/em253/*.awl`` with its plant
   (``<name>_plant.toml`` beside it, else ``plant.toml``) and data block
   (``<name>.db`` if present), sets the Run input of every motion CALL so
   the axes move from the first scan, and times a fixed window of simulated
   time at 1 ms scans.  ``pos_goto_r.awl`` (the manual's 3.2.5 example) is
   always measured: if the file is missing, a copy held in this script is
   used;
2. runs one POS_GOTO_R move with differential output (MOTION_EN3
   P_DorCCW = 1) at 5 kHz and at 500 kHz over the same window.  The pulse
   count differs a hundredfold, the cost should not: the module solves
   pulse counts and switch crossings in closed form (plcrt.devices.motion)
   instead of stepping through pulses;
3. prints the best of several repeats as simulated seconds per wall second
   ("x real time") and microseconds per scan, with the machine it ran on.

Each repeat loads a fresh PLC (not timed) and runs the window from
power-up, so every repeat does the same work.

``--against DIR`` measures side by side instead: DIR is another checkout
(``git worktree add DIR <commit>``) whose ``bench/em253.py`` has
``--json``; the two alternate in fresh processes for ``--rounds``
rounds, and the script prints each example's median speed on both sides
and the median of the per-round ratios.  On a shared machine whose speed
moves from minute to minute, that ratio is the figure that holds.  This is a measuring tool:
it asserts nothing and never fails on slow results unless ``--check`` is
given (exit 1 below the target of 300 x real time).
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing

import plcrt
from plcrt.blocks.interface import interfaces
from plcrt.engine.runtime import parse_sources

try:  # the machine description of the main benchmark, when it is beside us
    from run import machine  # type: ignore[import-not-found]
except ImportError:  # pragma: no cover - bench/run.py missing
    import os
    import platform

    def machine() -> dict[str, Any]:
        return {"cores": os.cpu_count(), "cpu": platform.processor() or platform.machine(),
                "python": platform.python_version(),
                "implementation": platform.python_implementation(),
                "plcrt": plcrt.__version__}

EXAMPLES = ROOT / "programs" / "em253"
TARGET_X = 300.0  #: simulated seconds per wall second at 1 ms scans


def _goto_program(title: str, comment: str, speeds: str) -> str:
    """OB1: MOTION_EN3, one POS_GOTO_R on axis 0 (Run M2.0), GET_AbsPos.

    ``speeds`` is AccTime, DecTime, SpdSs, SpdSet, PosSet as STL operands.
    """
    goto = ("CALL   POS_GOTO_R, 0, 0, " + speeds
            + ", VD100, VB104, M2.1, M2.0, VW106, VD108, VD112")
    return "\n".join([
        "ORGANIZATION_BLOCK MAIN:OB1", f"TITLE={title}", "BEGIN",
        "Network 1 // module enable, every scan first; M0.0 = P_DorCCW",
        "LD     SM0.0", "CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0",
        f"Network 2 // {comment}", "LD     SM0.0", goto,
        "Network 3 // position counter of axis 0",
        "LD     SM0.0", "CALL   GET_AbsPos, 0, 0, VD120, VW124",
        "END_ORGANIZATION_BLOCK", ""])


#: The manual's point-to-point example (3.2.5), used when
#: programs/em253/pos_goto_r.awl does not exist.
POS_GOTO_R_TEXT = _goto_program(
    "EM253 point-to-point move (manual 3.2.5), bench copy",
    "axis 0: 4800 ms ramps, 5 kHz -> 80 kHz, 1 000 000 pulses, M2.0 runs",
    "+4800, +4800, +5000, +80000, +1000000")

#: Both axes of slot 0 with limits the examples never reach.
DEFAULT_PLANT = {"module": {"0": {"axis": {
    "0": {"limit_neg": -2_000_000, "limit_pos": 3_000_000},
    "1": {"limit_neg": -2_000_000, "limit_pos": 3_000_000}}}}}

#: One move, two frequencies: M0.0 is P_DorCCW (set to 1: differential),
#: VD300/VD304/VD308 SpdSs/SpdSet/PosSet, M2.0 Run.
FREQ_TEXT = _goto_program(
    "EM253 bench: one relative move at a given frequency",
    "axis 0: 100 ms ramps from SpdSs VD300 to SpdSet VD304, PosSet VD308",
    "+100, +100, VD300, VD304, VD308")

#: Far limits, a reference switch and Z marks: thresholds exist but are
#: never reached, as on a real machine between two switches.
FREQ_PLANT = {"module": {"0": {"axis": {"0": {
    "limit_neg": -1_000_000_000, "limit_pos": 1_000_000_000,
    "rps": [-500_000_000, -499_000_000], "z_period": 10_000}}}}}

FREQUENCIES = (5_000, 500_000)


# ---------------------------------------------------------------------------
# Cases
# ---------------------------------------------------------------------------

@dataclasses.dataclass
class Case:
    """One program to time: its text, plant, data block and inputs to set."""

    name: str
    text: str
    plant: Any
    data: str | None = None
    inputs: dict[str, int] = dataclasses.field(default_factory=dict)
    source: str = "file"   #: "file" or "bench copy"


def run_inputs(text: str) -> dict[str, int]:
    """The Run argument of every library CALL that has one, set to 1.

    Only plain bit addresses outside SM are set (a Run tied to SM0.0 runs
    anyway; a symbol or an indirect operand is left alone).
    """
    program = parse_sources(text)
    itf = interfaces()
    found: dict[str, int] = {}
    for pou in program.pous:
        for net in pou.networks:
            for insn in net.insns:
                if insn.mnemonic != "CALL" or not insn.operands:
                    continue
                block = itf.get(insn.operands[0].text.split(":")[0].strip().upper())
                if block is None:
                    continue
                names = [p.name for p in block.params]
                if "Run" not in names or len(insn.operands) != len(names) + 1:
                    continue
                arg = insn.operands[1 + names.index("Run")].text
                if arg[:1] in "IQMV" and "." in arg and not arg.startswith("SM"):
                    found[arg] = 1
    return found


def example_cases() -> list[Case]:
    """The seed examples present now (pos_goto_r.awl always)."""
    cases = []
    files = sorted(EXAMPLES.glob("*.awl")) if EXAMPLES.is_dir() else []
    if not any(f.name == "pos_goto_r.awl" for f in files):
        cases.append(Case("pos_goto_r.awl", POS_GOTO_R_TEXT, DEFAULT_PLANT,
                          inputs=run_inputs(POS_GOTO_R_TEXT), source="bench copy"))
    for f in files:
        text = f.read_text(encoding="utf-8")
        own_plant = f.with_name(f"{f.stem}_plant.toml")
        shared = f.with_name("plant.toml")
        plant: Any = own_plant if own_plant.is_file() else shared if shared.is_file() \
            else DEFAULT_PLANT
        db = f.with_suffix(".db")
        cases.append(Case(f.name, text, plant, str(db) if db.is_file() else None,
                          run_inputs(text)))
    return sorted(cases, key=lambda c: c.name)


def frequency_case(hz: int) -> Case:
    return Case(f"POS_GOTO_R {hz // 1000} kHz", FREQ_TEXT, FREQ_PLANT,
                inputs={"M0.0": 1, "VD300": 1_000, "VD304": hz, "VD308": 2_000_000_000,
                        "M2.0": 1},
                source="bench")


# ---------------------------------------------------------------------------
# Measuring
# ---------------------------------------------------------------------------

@dataclasses.dataclass
class Result:
    name: str
    source: str
    scan_ms: float
    sim_s: float
    scans: int
    repeats: int
    best_s: float
    load_s: float
    pulses: int           #: pulses generated on all axes during the window
    axes: list[dict[str, Any]]
    warnings: list[str]

    @property
    def x_real_time(self) -> float:
        return self.sim_s / self.best_s

    @property
    def us_per_scan(self) -> float:
        return self.best_s / self.scans * 1e6

    def as_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d.update(x_real_time=round(self.x_real_time, 1), us_per_scan=round(self.us_per_scan, 2),
                 target_x=TARGET_X, meets_target=self.x_real_time >= TARGET_X)
        return d


def _load(case: Case, scan_ms: float) -> plcrt.Plc:
    plc = plcrt.load(case.text, plant=case.plant, data=case.data, scan_ms=scan_ms)
    for addr, value in case.inputs.items():
        plc[addr] = value
    return plc


def _pulses(plc: plcrt.Plc) -> int:
    """Pulses generated so far on every axis (module counters, not PLC data)."""
    t = plc.now_us
    return sum(ax.pulses_total + ax.travel(t) for mod in plc.modules.values()
               for ax in mod.axes)


def measure(case: Case, *, seconds: float, scan_ms: float, repeats: int) -> Result:
    """Best wall time of ``repeats`` runs of ``seconds`` simulated time."""
    t0 = time.perf_counter()
    plc = _load(case, scan_ms)
    load_s = time.perf_counter() - t0
    plc.scan(1)  # compile caches, first-scan work: outside the timing
    best = float("inf")
    gc_was = gc.isenabled()
    for _ in range(repeats):
        plc = _load(case, scan_ms)
        gc.collect()
        gc.disable()  # the kinematics allocate Fractions only per event
        try:
            t0 = time.perf_counter()
            plc.run(seconds=seconds)
            best = min(best, time.perf_counter() - t0)
        finally:
            if gc_was:
                gc.enable()
    if plc.mode != "RUN":
        raise RuntimeError(f"{case.name} left RUN mode: {plc.fault}")
    return Result(case.name, case.source, scan_ms, plc.time, plc.scans, repeats, best, load_s,
                  _pulses(plc), plc.axes(),
                  [d.message for d in plc.diagnostics if d.severity == "warning"])


# ---------------------------------------------------------------------------
# Main
# ---------------------------------------------------------------------------

def _line(r: Result) -> str:
    verdict = "meets" if r.x_real_time >= TARGET_X else "BELOW"
    moving = sum(1 for a in r.axes if a["status"] == "moving")
    return (f"  {r.name:<22} {r.x_real_time:8.1f} x real time {r.us_per_scan:7.2f} us/scan  "
            f"{r.pulses:>11,} pulses  {moving}/{len(r.axes)} axes moving at the end  "
            f"- {verdict} {TARGET_X:g} x" + (f"  [{r.source}]" if r.source != "file" else ""))


def _bench_json(root: Path, args: argparse.Namespace) -> dict[str, float]:
    """x real time per example of the bench in checkout ``root``, run in a
    fresh process with this run's options."""
    cmd = [sys.executable, str(root / "bench" / "em253.py"), "--json",
           "--repeats", str(args.repeats), "--seconds", str(args.seconds),
           "--scan-ms", str(args.scan_ms)]
    done = subprocess.run(cmd, cwd=root, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"error: the bench in {root} failed (exit {done.returncode}):\n"
                         f"{done.stderr.strip()}")
    return {e["name"]: e["x_real_time"] for e in json.loads(done.stdout)["examples"]}


def compare(against: Path, args: argparse.Namespace) -> int:
    """Alternate this checkout's bench with ``against``'s; print medians."""
    if not (against / "bench" / "em253.py").is_file():
        print(f"error: {against} has no bench/em253.py", file=sys.stderr)
        return 2
    sides: dict[str, list[dict[str, float]]] = {"this": [], "other": []}
    for k in range(args.rounds):
        # the order flips every round, so neither side always runs first
        order = [("this", ROOT), ("other", against)]
        for side, root in order if k % 2 == 0 else order[::-1]:
            sides[side].append(_bench_json(root, args))
        print(f"round {k + 1}: slowest example {min(sides['this'][-1].values()):.0f} x here, "
              f"{min(sides['other'][-1].values()):.0f} x there", flush=True)
    names = sorted(set(sides["this"][0]) & set(sides["other"][0]))
    print(f"{args.rounds} rounds, best of {args.repeats} each, x real time "
          f"(median over rounds; ratio: median of the per-round ratios):")
    print(f"  {'example':<22} {'here':>7} {'there':>7} {'ratio':>6}   here, every round")
    rows = [(n, [r[n] for r in sides["this"]], [r[n] for r in sides["other"]])
            for n in names]
    rows.append(("slowest example", [min(r.values()) for r in sides["this"]],
                 [min(r.values()) for r in sides["other"]]))
    for name, here, there in rows:
        ratio = statistics.median(a / b for a, b in zip(here, there))
        print(f"  {name:<22} {statistics.median(here):7.0f} {statistics.median(there):7.0f} "
              f"{ratio:6.2f}   " + " ".join(f"{x:.0f}" for x in here))
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--seconds", type=float, default=10.0,
                    help="simulated seconds per timed run (default 10)")
    ap.add_argument("--scan-ms", type=float, default=1.0, help="scan time (default 1 ms)")
    ap.add_argument("--repeats", type=int, default=5, help="timed repeats (best is kept)")
    ap.add_argument("--check", action="store_true",
                    help=f"exit 1 when a case is below {TARGET_X:g} x real time")
    ap.add_argument("--against", type=Path, metavar="DIR",
                    help="another checkout to measure side by side with this one")
    ap.add_argument("--rounds", type=int, default=6,
                    help="rounds of the side-by-side comparison (default 6)")
    args = ap.parse_args(argv)
    if args.against is not None:
        return compare(args.against.resolve(), args)

    opts = {"seconds": args.seconds, "scan_ms": args.scan_ms, "repeats": args.repeats}
    examples = [measure(c, **opts) for c in example_cases()]
    freq = [measure(frequency_case(hz), **opts) for hz in FREQUENCIES]
    ratio = freq[1].best_s / freq[0].best_s

    if args.json:
        print(json.dumps({"machine": machine(), "seconds": args.seconds,
                          "scan_ms": args.scan_ms, "target_x_real_time": TARGET_X,
                          "examples": [r.as_dict() for r in examples],
                          "frequency": [r.as_dict() for r in freq],
                          "cost_ratio_500k_to_5k": round(ratio, 3)}, indent=2))
    else:
        m = machine()
        print(f"machine: {m['cores']} cores, {m['cpu']}, "
              f"{m['implementation']} {m['python']}, plcrt {m['plcrt']}")
        print(f"EM253 seed examples, {args.seconds:g} s simulated at {args.scan_ms:g} ms scans "
              f"from power-up, best of {args.repeats}:")
        for r in examples:
            print(_line(r))
        print(f"one POS_GOTO_R move, differential output (P_DorCCW = 1), "
              f"{args.seconds:g} s simulated:")
        for r in freq:
            print(_line(r))
        print(f"  cost at 500 kHz / cost at 5 kHz: {ratio:.2f} "
              f"({freq[1].pulses / max(freq[0].pulses, 1):.0f} x the pulses)")
    if args.check and any(r.x_real_time < TARGET_X for r in examples + freq):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
