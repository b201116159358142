"""plcrt Modbus TCP benchmark: requests per second and the scan-time
jitter they cause while the PLC runs in real time.

Run ``python bench/net_modbus.py`` (``--json`` for one JSON object,
``--seconds`` per phase).  It loads the generated boolean program of
``bench/run.py`` (about 1000 instructions) at 1 ms scans, serves it with
``plcrt.serve(plc, modbus=0)`` in real time on a free loopback port, and
runs three phases of the same length:

- no client (the PLC alone: the baseline of the jitter);
- 1 client, one request in flight;
- 16 clients at once, one request in flight each.

The clients run in a separate process (so that they do not share the
server's interpreter lock) and send raw MBAP frames on asyncio streams,
alternating a read of 10 holding registers (FC3) and a write of one
(FC6); every answer is checked.  The jitter is measured in the runner's
thread after every scan (``plc.observers``): how far the PLC's simulated
clock lags the wall clock at each scan end (from the phase's first scan),
and how far that lateness strays from its median — the jitter — as
median, 99th percentile and maximum, and the scans run against the scans
due.

A measuring tool: it asserts nothing but the answers' form.  All traffic
stays on 127.0.0.1 and the run stops by itself.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import statistics
import struct
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import plcrt  # noqa: E402
from run import bool_program, machine  # type: ignore[import-not-found]  # noqa: E402

SCAN_MS = 1.0
CLIENTS = (1, 16)
_READ = bytes((3, 0, 0, 0, 10))


# -- the clients' process ------------------------------------------------------
async def _client(port: int, until: float, counts: list[int], k: int) -> None:
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    tid = 0
    try:
        while time.monotonic() < until:
            tid = (tid + 1) & 0xFFFF
            pdu = _READ if tid & 1 else bytes((6, 0, 100)) + tid.to_bytes(2, "big")
            writer.write(struct.pack(">HHHB", tid, 0, len(pdu) + 1, 1) + pdu)
            head = await reader.readexactly(7)
            body = await reader.readexactly(struct.unpack(">H", head[4:6])[0] - 1)
            if struct.unpack(">H", head[:2])[0] != tid or body[0] & 0x80:
                raise SystemExit(f"bad answer {head.hex()} {body.hex()}")
            counts[k] += 1
    finally:
        writer.close()


async def _clients(port: int, n: int, seconds: float) -> list[int]:
    counts = [0] * n
    until = time.monotonic() + seconds
    await asyncio.gather(*(_client(port, until, counts, k) for k in range(n)))
    return counts


def client_main(port: int, n: int, seconds: float) -> None:
    print(json.dumps(asyncio.run(_clients(port, n, seconds))))


# -- the server's process ------------------------------------------------------
class ScanClock:
    """Wall time and simulated time at every scan end (an observer)."""

    def __init__(self) -> None:
        self.marks: list[tuple[float, int]] = []
        self.on = False

    def __call__(self, plc: Any) -> None:
        if self.on:
            self.marks.append((time.monotonic(), plc.now_us))

    def jitter(self) -> dict[str, float]:
        """Each scan end's lateness (wall time minus simulated time since
        the phase's first scan), taken from its median: the jitter."""
        m = self.marks
        if len(m) < 2:
            return {}
        w0, s0 = m[0]
        late = [((w - w0) - (s - s0) / 1e6) * 1e3 for w, s in m]
        mid = statistics.median(late)
        dev = sorted(abs(x - mid) for x in late)
        due = (m[-1][0] - w0) * 1e3 / SCAN_MS
        return {"scans": len(m), "scans_due": round(due),
                "jitter_ms_median": round(dev[len(dev) // 2], 3),
                "jitter_ms_p99": round(dev[int(0.99 * (len(dev) - 1))], 3),
                "jitter_ms_max": round(dev[-1], 3)}


def phase(serving: Any, clock: ScanClock, port: int, n: int, seconds: float
          ) -> dict[str, Any]:
    out: dict[str, Any] = {"clients": n}
    clock.marks = []
    serving.call(lambda p: setattr(clock, "on", True))
    if n:
        res = subprocess.run([sys.executable, __file__, "--client", str(port), str(n),
                              str(seconds)], capture_output=True, text=True, check=True,
                             timeout=seconds + 60)
        counts = json.loads(res.stdout)
        out.update(requests=sum(counts), requests_per_s=round(sum(counts) / seconds),
                   per_client_min=min(counts), per_client_max=max(counts))
    else:
        time.sleep(seconds)
    serving.call(lambda p: setattr(clock, "on", False))
    out.update(clock.jitter())
    return out


def main(argv: list[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=5.0)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--client", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.client:
        client_main(int(args.client[0]), int(args.client[1]), float(args.client[2]))
        return {}
    plc = plcrt.load(bool_program(), scan_ms=SCAN_MS)
    clock = ScanClock()
    plc.observers.append(clock)
    result: dict[str, Any] = {"date": time.strftime("%Y-%m-%d"), "machine": machine(),
                              "program_scan_ms": SCAN_MS, "phases": []}
    with plcrt.serve(plc, modbus=0, max_connections=32) as s:
        port = s.port("modbus")
        time.sleep(0.5)                               # settle the pacing
        for n in (0, *CLIENTS):
            result["phases"].append(phase(s, clock, port, n, args.seconds))
        result["door_served"] = s.door.served
    if args.json:
        print(json.dumps(result))
    else:
        print(f"plcrt Modbus TCP bench, {result['date']}, {result['machine']['cpu']}, "
              f"~1000-instruction program at {SCAN_MS:g} ms scans, real time")
        print(f"{'clients':>7} {'req/s':>8} {'scans':>7} {'due':>7} "
              f"{'jitter ms: median':>18} {'p99':>7} {'max':>7}")
        for p in result["phases"]:
            print(f"{p['clients']:>7} {p.get('requests_per_s', 0):>8} {p.get('scans', 0):>7} "
                  f"{p.get('scans_due', 0):>7} {p.get('jitter_ms_median', 0):>18} "
                  f"{p.get('jitter_ms_p99', 0):>7} {p.get('jitter_ms_max', 0):>7}")
    return result


if __name__ == "__main__":
    main()
