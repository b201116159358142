"""plcrt network benchmark: requests per second of the protocol servers
and the scan-time jitter their clients cause.

Run ``python bench/net.py`` (``--json`` for one JSON object,
``--seconds`` per measurement).  For the S7 server it

1. loads ``bench/programs/mixed.awl`` (about 1000 instructions: moves,
   INT/DINT math, compares, timers) with a 10 ms scan and serves it with
   ``plcrt.serve(plc, s7=0, speed="realtime")``;
2. measures the runner alone (no client), then with 1 and with 16
   python-snap7 clients in other processes (spawned, so the clients do not
   share this process's interpreter lock), each reading 64 bytes of V
   (``db_read(1, 0, 64)``) in a loop for ``--seconds``;
3. reports requests per second (all clients) and the scan timing: every
   chunk of scans the runner starts is recorded (wall time and simulated
   time), and the *lag* of a chunk is how far the simulated clock is behind
   the wall clock at its start, relative to the first chunk; the figures
   are the 50th, 99th percentile and largest lag and the largest wall time
   between two chunk starts.

A measuring tool: it asserts nothing.  The machine's load average is
printed; on a shared machine the figures vary from run to run.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import platform
import statistics
import sys
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing

import plcrt                                             # noqa: E402

PROGRAM = ROOT / "bench" / "programs" / "mixed.awl"


# -- S7 ----------------------------------------------------------------------
def _s7_client(port: int, threads: int, seconds: float, start: Any, out: Any) -> None:
    """A process of ``threads`` python-snap7 clients reading for ``seconds``."""
    import snap7
    counts = [0] * threads

    def loop(k: int) -> None:
        c = snap7.Client()
        c.set_connection_type(2 if k % 2 else 3)        # HMI/OP and basic connections
        c.connect("127.0.0.1", 0, 1, port)
        start.wait()
        end = time.monotonic() + seconds
        n = 0
        while time.monotonic() < end:
            c.db_read(1, 0, 64)
            n += 1
        counts[k] = n
        c.disconnect()

    ts = [threading.Thread(target=loop, args=(k,)) for k in range(threads)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    out.put(sum(counts))


def _record_chunks(plc: Any) -> list[tuple[float, int]]:
    """Wrap ``plc.scan`` (called by the runner once a chunk) to record each
    chunk's wall start and simulated time."""
    marks: list[tuple[float, int]] = []
    scan = plc.scan

    def recorded(n: int = 1) -> None:
        marks.append((time.perf_counter(), plc.now_us))
        scan(n)
    plc.scan = recorded
    return marks


def _lag_figures(marks: list[tuple[float, int]]) -> dict[str, float]:
    if len(marks) < 3:
        return {}
    w0, s0 = marks[0]
    lags = [((w - w0) - (s - s0) / 1e6) * 1000 for w, s in marks]
    base = min(lags)
    lags = sorted(x - base for x in lags)
    gaps = [(b[0] - a[0]) * 1000 for a, b in zip(marks, marks[1:])]
    return {"chunks": len(marks), "lag_p50_ms": round(statistics.median(lags), 3),
            "lag_p99_ms": round(lags[int(0.99 * (len(lags) - 1))], 3),
            "lag_max_ms": round(lags[-1], 3), "gap_max_ms": round(max(gaps), 3)}


def s7_run(clients: int, seconds: float) -> dict[str, Any]:
    """Serve the program and measure with ``clients`` S7 clients (0: the
    runner alone)."""
    from plcrt.net.s7 import S7Identity, S7Options
    plc = plcrt.load(PROGRAM, scan_ms=10)
    marks = _record_chunks(plc)
    ident = S7Identity(connections={"PG": 1, "OP": 16, "basic": 16})
    opts = S7Options(identity=ident, max_connections=33)
    ctx = mp.get_context("spawn")
    with plcrt.serve(plc, s7=opts, speed="realtime") as srv:
        procs, start, out = [], ctx.Event(), ctx.Queue()
        per = [clients // min(clients, 4) + (i < clients % min(clients, 4))
               for i in range(min(clients, 4))] if clients else []
        for threads in per:
            p = ctx.Process(target=_s7_client,
                            args=(srv.port("s7"), threads, seconds, start, out))
            p.start()
            procs.append(p)
        time.sleep(2.0 if clients else 0.2)             # the clients connect and import
        marks.clear()
        t0 = time.perf_counter()
        start.set()
        if clients:
            total = sum(out.get(timeout=seconds + 60) for _ in procs)
        else:
            time.sleep(seconds)
            total = 0
        wall = time.perf_counter() - t0
        chunks = list(marks)
        for p in procs:
            p.join(10)
        stats = dict(srv.services["s7"].stats)
    result = {"clients": clients, "requests": total,
              "requests_per_s": round(total / wall, 1) if clients else 0.0,
              "server_errors": stats.get("server_errors", 0)}
    result.update(_lag_figures(chunks))
    return result


def s7_bench(seconds: float) -> list[dict[str, Any]]:
    return [s7_run(n, seconds) for n in (0, 1, 16)]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seconds", type=float, default=5.0, help="per measurement")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    report = {"date": time.strftime("%Y-%m-%d"), "python": platform.python_version(),
              "cpus": os.cpu_count(), "load": [round(x, 2) for x in os.getloadavg()],
              "s7": s7_bench(args.seconds)}
    if args.json:
        print(json.dumps(report))
        return 0
    print(f"plcrt network bench {report['date']}  Python {report['python']}  "
          f"{report['cpus']} CPUs  load {report['load']}")
    print("S7, mixed.awl (~1000 instructions), 10 ms scans, real time:")
    print(f"{'clients':>8} {'req/s':>9} {'lag p50':>9} {'lag p99':>9} {'lag max':>9} "
          f"{'gap max':>9}  (ms)")
    for r in report["s7"]:
        print(f"{r['clients']:>8} {r['requests_per_s']:>9} {r.get('lag_p50_ms', '-'):>9} "
              f"{r.get('lag_p99_ms', '-'):>9} {r.get('lag_max_ms', '-'):>9} "
              f"{r.get('gap_max_ms', '-'):>9}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
