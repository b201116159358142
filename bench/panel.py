"""plcrt panel benchmark: simulated seconds per wall second with clients.

Run ``python bench/panel.py`` (``--json`` for one JSON object).  It loads
the generated boolean program of ``bench/run.py`` (about 1000
instructions) at 1 ms scans as ``plcrt serve`` loads it (no network
probes until a breakpoint is set; the default backend, native where
llvmlite works), serves it with ``plcrt serve``'s application on a free
loopback port, connects 5 websocket clients that each read every frame
they are sent (each viewing networks 1-10 of OB1, a screenful, as a page
does), , puts the PLC in "as fast as possible" mode and measures
simulated seconds per wall second over a fixed wall-clock window.  The
frames each client received are reported too (the display rate, not the
scan rate), and the same PLC's speed without a panel, measured in the same
run, so the ratio of the two is the panel's cost.

A measuring tool: it asserts nothing and never fails on slow results
unless ``--check`` is given (exit 1 below the target of 50 x real time).
``--probes`` runs in the build with probes (as while a breakpoint is set
in a network the scan does not reach) and ``--backend`` chooses the code
generator.
All traffic stays on 127.0.0.1 and the run stops by itself.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import aiohttp  # noqa: E402
from aiohttp import web  # noqa: E402

import plcrt  # noqa: E402
from run import bool_program, machine  # type: ignore[import-not-found]  # noqa: E402
from plcrt.web.server import Panel, make_app  # noqa: E402
from plcrt.web.session import PanelSession  # noqa: E402

TARGET_X = 50.0   #: simulated seconds per wall second at 1 ms scans
CLIENTS = 5


async def _client(url: str, counts: list[int], i: int, stop: asyncio.Event) -> None:
    async with aiohttp.ClientSession() as http:
        async with http.ws_connect(url, max_msg_size=0) as ws:
            # a page shows a screenful of networks: it names them in its view
            await ws.send_json({"type": "view", "block": "OB1",
                                "networks": [f"OB1/{n}" for n in range(1, 11)]})
            while not stop.is_set():
                try:
                    m = await asyncio.wait_for(ws.receive(), 0.5)
                except asyncio.TimeoutError:
                    continue
                if m.type != aiohttp.WSMsgType.TEXT:
                    break
                if json.loads(m.data)["type"] == "frame":
                    counts[i] += 1


def default_backend() -> str:
    """The backend ``plcrt serve`` chooses: the default, ``auto``."""
    return "auto"


def alone(plc: plcrt.Plc, seconds: float) -> float:
    """Simulated seconds per wall second of ``plc`` on its own (a fork)."""
    twin = plc.fork()
    n, t0 = 1, time.perf_counter()
    while True:
        twin.scan(n)
        wall = time.perf_counter() - t0
        if wall >= seconds:
            return twin.time / wall
        n *= 2


async def measure(seconds: float, clients: int, scan_ms: float, *, probes: bool = False,
                  backend: str | None = None) -> dict[str, Any]:
    text = bool_program()
    plc = plcrt.load(text, scan_ms=scan_ms, instrument=probes,
                     backend=backend or default_backend())
    x_alone = alone(plc, min(seconds, 2.0))
    session = PanelSession(plc)
    panel = Panel(session)
    runner = web.AppRunner(make_app(panel))
    await runner.setup()
    site = web.TCPSite(runner, "127.0.0.1", 0)
    await site.start()
    port = site._server.sockets[0].getsockname()[1]  # type: ignore[union-attr]
    url = f"http://127.0.0.1:{port}/ws"
    session.start()
    counts = [0] * clients
    stop = asyncio.Event()
    tasks = [asyncio.create_task(_client(url, counts, i, stop)) for i in range(clients)]
    try:
        await asyncio.sleep(0.5)   # every client connected and sent its view
        session.submit(None, {"type": "speed", "mode": "max"})
        session.submit(None, {"type": "run"})
        await asyncio.sleep(0.5)   # the chunk size settles
        t0, s0, c0 = time.perf_counter(), session.plc.now_us, list(counts)
        await asyncio.sleep(seconds)
        t1, s1 = time.perf_counter(), session.plc.now_us
        frames = [c - b for c, b in zip(counts, c0)]
    finally:
        stop.set()
        session.submit(None, {"type": "stop"})
        await asyncio.gather(*tasks, return_exceptions=True)
        session.close()
        await runner.cleanup()
    wall = t1 - t0
    sim = (s1 - s0) / 1e6
    return {"program_insns": plc.program.instruction_count(), "scan_ms": scan_ms,
            "probes": probes, "backend": plc.backend["name"],
            "clients": clients, "wall_s": round(wall, 3), "simulated_s": round(sim, 3),
            "x_real_time": round(sim / wall, 1), "x_alone": round(x_alone, 1),
            "us_per_scan": round(wall / sim * scan_ms * 1e3, 2)
            if sim else None, "frames_per_client_per_s": [round(f / wall, 1) for f in frames],
            "target_x": TARGET_X, "machine": machine()}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=5.0, help="wall seconds measured")
    ap.add_argument("--clients", type=int, default=CLIENTS)
    ap.add_argument("--scan-ms", type=float, default=1.0)
    ap.add_argument("--probes", action="store_true",
                    help="run in the build with network probes (as while a breakpoint is set)")
    ap.add_argument("--backend", choices=("auto", "python", "native"), default=None)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--check", action="store_true", help=f"exit 1 below {TARGET_X:g} x")
    args = ap.parse_args(argv)
    r = asyncio.run(measure(args.seconds, args.clients, args.scan_ms,
                            probes=args.probes, backend=args.backend))
    if args.json:
        print(json.dumps(r))
    else:
        print(f"panel: {r['program_insns']} instructions, {r['scan_ms']:g} ms scans, "
              f"{r['clients']} websocket clients, as fast as possible, backend "
              f"{r['backend']}, {'with' if r['probes'] else 'without'} breakpoint probes")
        print(f"  {r['x_real_time']:g} x real time ({r['simulated_s']:g} simulated s in "
              f"{r['wall_s']:g} wall s, {r['us_per_scan']} us per scan); target "
              f"{TARGET_X:g} x")
        print(f"  the same PLC without a panel: {r['x_alone']:g} x real time")
        print(f"  frames per client per second: {r['frames_per_client_per_s']}")
    return 1 if args.check and r["x_real_time"] < TARGET_X else 0


if __name__ == "__main__":
    sys.exit(main())
