"""plcrt events benchmark: interrupts, a pulse output and a high-speed counter.

Run ``python bench/events.py`` (``--json`` for one JSON object).  One
program (held in this script) attaches a 1 ms timed interrupt (its routine
counts and reads HC0), runs endless PTO trains on Q0.0 (the PTO-complete
interrupt starts the next) wired to I0.0 in the plant, and counts them with
HSC0 (a CV=PV interrupt that moves PV on).  It is timed over a window of
simulated time at 10 ms and at 1 ms scans, at pulse rates of 1 kHz, 10 kHz
and 100 kHz.

The events per simulated second are the same at every rate: 1000 timed
interrupts, 100 CV=PV interrupts (PV moves on by rate / 100 pulses) and 10
PTO-complete interrupts (trains of rate / 10 pulses); only the pulses grow,
100-fold.  So the cost ratio 100 kHz / 1 kHz that it reports is what the
pulse rate costs (flat when pulses are never simulated one by one).

It reports simulated seconds per second of the process's CPU time
("x real time"; the simulation runs in one thread, so on an idle machine
that is its wall time, and on a shared one it leaves out the time other
processes took) and per wall second.  Each case loads a fresh PLC (not
timed), checks the counts it must reach (so a broken run is never reported
as fast), runs its first 0.1 s untimed (the first scan's set-up, warm
caches), and keeps the best of ``--repeats``.  A measuring tool: it
asserts nothing else.
"""

from __future__ import annotations

import argparse
import gc
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing

import plcrt  # noqa: E402

#: simulated seconds run before the timed window of each case
WARM_UP = 0.1
PLANT = '[cpu]\nwire = { "I0.0" = "Q0.0" }\n'


def program(cycle_us: int) -> str:
    """The benchmark program at a pulse cycle of *cycle_us* µs."""
    rate = 1_000_000 // cycle_us
    step, train = rate // 100, rate // 10
    return f"""ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1 // 1 ms timed interrupt, HSC0 on I0.0 (wired to Q0.0), endless PTO trains
LD     SM0.1
MOVB   1, SMB34
ATCH   INT_0, 10
MOVB   16#F8, SMB37
MOVD   +0, SMD38
MOVD   +{step}, SMD42
HDEF   0, 0
HSC    0
ATCH   INT_1, 12
ATCH   INT_2, 19
MOVB   16#85, SMB67
MOVW   +{cycle_us}, SMW68
MOVD   +{train}, SMD72
ENI
PLS    0
Network 2 // some main-program work
LD     SM0.0
MOVD   HC0, VD100
+D     +1, VD104
END_ORGANIZATION_BLOCK
INTERRUPT_BLOCK INT_0:INT0
BEGIN
Network 1 // every ms: count, read the counter
LD     SM0.0
INCD   VD0
MOVD   HC0, VD4
END_INTERRUPT_BLOCK
INTERRUPT_BLOCK INT_1:INT1
BEGIN
Network 1 // CV=PV: PV moves on
LD     SM0.0
INCD   VD8
+D     +{step}, SMD42
MOVB   16#A0, SMB37
HSC    0
END_INTERRUPT_BLOCK
INTERRUPT_BLOCK INT_2:INT2
BEGIN
Network 1 // a train ended: the next one
LD     SM0.0
INCD   VD12
PLS    0
END_INTERRUPT_BLOCK
"""


def run_case(cycle_us: int, scan_ms: float, seconds: float, repeats: int) -> dict:
    best = best_wall = float("inf")
    step = 1_000_000 // cycle_us // 100
    for _ in range(repeats):
        # the CPU 224XP's Q0.0 makes 100 kHz (the others 20 kHz)
        plc = plcrt.load(program(cycle_us), plant=PLANT, scan_ms=scan_ms, cpu="CPU224XP")
        plc.run(WARM_UP)        # the first scan's set-up, warm caches: not timed
        gc.collect()
        wall, cpu = time.perf_counter(), time.process_time()
        plc.run(seconds)
        best = min(best, time.process_time() - cpu)
        best_wall = min(best_wall, time.perf_counter() - wall)
        pulses = plc.pulse[0].pulses_until(plc.now_us)
        # the checks that make a fast result a real one (a train the last
        # routine started at the window's end is counted at the next scan start)
        plc.hsc[0].sync(plc.now_us)
        assert plc["VD0"] == round((WARM_UP + seconds) * 1000), plc["VD0"]
        assert plc["HC0"] == pulses and plc["VD8"] == pulses // step, (plc["HC0"], pulses)
    return {"pulse_hz": 1_000_000 // cycle_us, "scan_ms": scan_ms, "seconds": seconds,
            "cpu_s": best, "wall_s": best_wall, "x_real_time": seconds / best,
            "x_real_time_wall": seconds / best_wall, "pulses": pulses,
            "interrupts": plc["VD0"] + plc["VD8"] + plc["VD12"]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=2.0, help="simulated seconds per case")
    ap.add_argument("--repeats", type=int, default=3, help="timed repeats (best is kept)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    cases = [run_case(c, s, args.seconds, args.repeats)
             for s in (10, 1) for c in (1000, 100, 10)]
    out = {"cases": cases}
    for s in (10, 1):
        row = {c["pulse_hz"]: c["cpu_s"] for c in cases if c["scan_ms"] == s}
        out[f"ratio_100k_over_1k_at_{s}ms"] = row[100_000] / row[1000]
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"{'pulse rate':>10}  {'scan':>6}  {'x real time':>11}  {'(wall)':>6}  "
          f"{'pulses':>8}  interrupts")
    for c in cases:
        print(f"{c['pulse_hz']:>8} Hz  {c['scan_ms']:>4g} ms  {c['x_real_time']:>11.0f}  "
              f"{c['x_real_time_wall']:>6.0f}  {c['pulses']:>8}  {c['interrupts']}")
    for s in (10, 1):
        print(f"cost 100 kHz / 1 kHz at {s} ms scans: {out[f'ratio_100k_over_1k_at_{s}ms']:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
