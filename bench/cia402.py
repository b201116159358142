"""plcrt CiA 402 drive benchmark: simulated drive-seconds per wall-clock second.

Run ``python bench/cia402.py`` (``--json`` for one JSON object).  It

1. runs one and then eight HCFA drives in CSP (6060h = 8) through
   process-data images at a 1 ms bus cycle (``Drive.cycle`` with the default
   RxPDO 1600h image carrying 6040h and 607Ah, returning the TxPDO 1A00h
   image), the master sending a sine-like target each cycle, and reports
   simulated drive-seconds per wall second (drives x simulated seconds /
   wall seconds) as "x real time";
2. runs the same through ``Drive.exchange`` (object-level process data
   ``{(index, sub): value}``, the path of a PLC's master module), one and
   eight drives;
3. runs the same PP move (one set-point, the positive limit switch crossed
   half-way through the window) at 10 kP/s and at 1 MP/s with 1 ms cycles and reports the ratio of their costs: the drive solves
   positions and crossings in closed form (plcrt.devices.motion), so the
   ratio stays near 1 although the speed differs a hundredfold;
4. measures SDO round trips per second over python-can's ``virtual`` bus:
   a canopen master uploads 6064h from a drive put on the bus with
   ``plcrt.cia402.attach`` (manual clock, so only the SDO path is timed);
5. runs eight drives in CSP over python-can's ``virtual`` bus in one run,
   two ways, and gives the ratio: the process-data path (each drive
   attached with ``clock="sync"``, its CAN-view PDOs remapped by a canopen
   master to RPDO 6040h + 607Ah and TPDO 6041h + 6064h, transmission type 1;
   per 1 ms cycle the master sends eight RPDOs and a SYNC and waits for the
   eight TPDOs) and the SDO-only loop (per cycle the master downloads 607Ah
   and uploads 6064h of each drive by SDO, then every drive advances 1 ms on
   its manual clock);
6. runs the same two loops with the same canopen master over plcrt's
   in-process bus (``plcrt.cia402.bus``: each frame delivered in the
   sender's thread, no copy, no Notifier thread), in the same run as 5, so
   the ratios of the in-process PDO path to the virtual bus's PDO path and
   to its SDO-only loop are printed.

Each figure is the best of ``--repeat`` runs (fresh drives, set-up not
timed).  The CSP figures come twice: per wall second, and per CPU second
of this process (on a shared machine other processes take the CPU for part
of the wall time; the load average is printed).  A measuring tool: it
asserts nothing.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing

from plcrt.devices.cia402.drive import Drive            # noqa: E402
from plcrt.devices.cia402.esm import EsmState           # noqa: E402
from plcrt.devices.cia402.plant import DrivePlant       # noqa: E402

CYCLE_US = 1000


def rx(cw: int, target: int) -> bytes:
    return cw.to_bytes(2, "little") + target.to_bytes(4, "little", signed=True) + b"\0\0"


def csp_drives(n: int) -> list[Drive]:
    drives = []
    for _ in range(n):
        d = Drive()
        for s in (EsmState.PREOP, EsmState.SAFEOP, EsmState.OP):
            d.request_esm(s)
        t = 0
        for cw in (0x06, 0x07, 0x0F, 0x0F):
            t += CYCLE_US
            d.cycle(t, rx(cw, 0))
        drives.append(d)
    return drives


def time_csp(n: int, seconds: float) -> tuple[float, float]:
    drives = csp_drives(n)
    cycles = int(seconds * 1e6) // CYCLE_US
    t0 = drives[0].now
    # a triangle wave of +-20 000 counts, 400 counts per cycle at most
    targets = [rx(0x0F, 400 * (k % 100) if (k // 100) % 2 == 0 else 400 * (100 - k % 100))
               for k in range(cycles)]
    gc.collect()
    start, cpu = time.perf_counter(), time.process_time()
    for k in range(cycles):
        t = t0 + (k + 1) * CYCLE_US
        image = targets[k]
        for d in drives:
            d.cycle(t, image)
    return ratios(n * cycles * CYCLE_US / 1e6, start, cpu)


def ratios(simulated: float, start: float, cpu: float) -> tuple[float, float]:
    """Simulated seconds per wall second and per CPU second of this process
    (the second does not count the time other processes took the CPU)."""
    wall, used = time.perf_counter() - start, time.process_time() - cpu
    return simulated / wall, simulated / max(used, 1e-9)


def time_csp_exchange(n: int, seconds: float) -> tuple[float, float]:
    """As :func:`time_csp`, the process data given by object (``Drive.exchange``)."""
    drives = csp_drives(n)
    cycles = int(seconds * 1e6) // CYCLE_US
    t0 = drives[0].now
    targets = [{(0x6040, 0): 0x0F,
                (0x607A, 0): 400 * (k % 100) if (k // 100) % 2 == 0 else 400 * (100 - k % 100)}
               for k in range(cycles)]
    gc.collect()
    start, cpu = time.perf_counter(), time.process_time()
    for k in range(cycles):
        t = t0 + (k + 1) * CYCLE_US
        values = targets[k]
        for d in drives:
            d.exchange(t, values)
    return ratios(n * cycles * CYCLE_US / 1e6, start, cpu)


def time_pp(speed: int, seconds: float) -> float:
    # the same move in time: a limit switch crossed half-way through the window
    d = Drive(plant=DrivePlant(pos_limit=int(speed * seconds / 2)))
    d.write(0x6060, 0, 1)
    for index, value in ((0x6080, 10**7), (0x6081, speed), (0x6083, speed * 10),
                         (0x6084, speed * 10), (0x6085, speed * 10)):
        d.write(index, 0, value)
    for cw in (0x06, 0x07, 0x0F):
        d.write(0x6040, 0, cw)
    d.cycle(CYCLE_US)
    d.write(0x607A, 0, int(speed * seconds * 2))
    d.write(0x6040, 0, 0x1F)
    d.write(0x6040, 0, 0x0F)
    cycles = int(seconds * 1e6) // CYCLE_US
    gc.collect()
    start = time.perf_counter()
    for k in range(2, cycles + 2):
        d.cycle(k * CYCLE_US)
    return time.perf_counter() - start


def calibration() -> float:
    """Wall seconds of 10^6 integer additions in a Python loop (best of 3):
    how fast this machine runs plain Python, to compare figures across machines."""
    best = float("inf")
    for _ in range(3):
        start, x = time.perf_counter(), 0
        for k in range(10**6):
            x += k
        best = min(best, time.perf_counter() - start)
    return best


def sdo_round_trips(n: int = 2000) -> float:
    """SDO uploads of 6064h per wall second, canopen master <-> attached drive."""
    import canopen

    from plcrt import cia402

    channel = f"plcrt-bench-{time.monotonic_ns()}"
    dev, mst = canopen.Network(), canopen.Network()
    dev.NOTIFIER_CYCLE = mst.NOTIFIER_CYCLE = 0.02
    dev.connect(interface="virtual", channel=channel)
    mst.connect(interface="virtual", channel=channel)
    sim = cia402.attach(dev, 5, clock="manual")
    node = mst.add_node(5, cia402.object_dictionary())
    try:
        node.sdo.upload(0x6064, 0)
        start = time.perf_counter()
        for _ in range(n):
            node.sdo.upload(0x6064, 0)
        return n / (time.perf_counter() - start)
    finally:
        sim.close()
        mst.disconnect()
        dev.disconnect()


class _Tpdos:
    """Counts the TPDOs the master receives (its Notifier thread)."""

    def __init__(self) -> None:
        import threading
        self.count = 0
        self.cond = threading.Condition()

    def __call__(self, can_id: int, data: bytes, timestamp: float) -> None:
        with self.cond:
            self.count += 1
            self.cond.notify_all()

    def wait(self, count: int) -> None:
        with self.cond:
            if not self.cond.wait_for(lambda: self.count >= count, 5.0):
                raise RuntimeError(f"{count - self.count} TPDOs missing")


class _TpdosHere:
    """Counts the TPDOs the master receives on the in-process bus, where
    they have all arrived when the SYNC's send returns: no thread to wait for."""

    def __init__(self) -> None:
        self.count = 0

    def __call__(self, can_id: int, data: bytes, timestamp: float) -> None:
        self.count += 1

    def wait(self, count: int) -> None:
        if self.count < count:
            raise RuntimeError(f"{count - self.count} TPDOs missing")


def can_networks(local: bool) -> tuple:
    """A connected (drive, master) pair of ``canopen.Network``: plcrt's
    in-process bus (``cia402.bus``) or python-can's ``virtual`` bus."""
    import canopen

    from plcrt import cia402

    channel = f"plcrt-bench-can-{time.monotonic_ns()}"
    if local:
        return cia402.bus(channel), cia402.bus(channel)
    dev, mst = canopen.Network(), canopen.Network()
    dev.NOTIFIER_CYCLE = mst.NOTIFIER_CYCLE = 0.02
    dev.connect(interface="virtual", channel=channel)
    mst.connect(interface="virtual", channel=channel)
    return dev, mst


def target_of(k: int) -> int:
    """The triangle wave of the CAN runs: +-20 000 counts, 400 per cycle at most."""
    return 400 * (k % 100) if (k // 100) % 2 == 0 else 400 * (100 - k % 100)


def can_csp(n: int, cycles: int, local: bool = False, sdo: bool = True,
            profile: Any = None) -> tuple[tuple[float, float], tuple[float, float]]:
    """Eight (*n*) drives in CSP over a CAN bus (*local*: plcrt's in-process
    bus, else python-can's ``virtual`` bus): (PDO path, SDO-only loop), each
    as (drive-seconds per wall second, per CPU second of the process: its
    threads, the bus's included); the SDO-only figures are (0, 0) without
    *sdo*.  *profile*: a ``cProfile.Profile`` enabled around the PDO cycles."""
    import struct

    import canopen

    from plcrt import cia402

    dev, mst = can_networks(local)
    ids = range(1, n + 1)
    sims = [cia402.attach(dev, i, clock="sync") for i in ids]
    tpdos: Any = _TpdosHere() if local else _Tpdos()
    rx_ids = []
    try:
        nodes = []
        for i, sim in zip(ids, sims):
            node = canopen.RemoteNode(i, cia402.object_dictionary(node_id=i))
            mst.add_node(node)
            nodes.append(node)
            node.nmt.state = "PRE-OPERATIONAL"
            node.tpdo.read()
            node.rpdo.read()
            node.sdo[0x1006].raw = CYCLE_US
            tpdo, rpdo = node.tpdo[sim.tpdo_no], node.rpdo[sim.rpdo_no]
            for pdo, objects in ((tpdo, (0x6041, 0x6064)), (rpdo, (0x6040, 0x607A))):
                pdo.clear()
                for index in objects:
                    pdo.add_variable(index)
                pdo.trans_type = 1
                pdo.enabled = True
                pdo.save()
            rx_ids.append(rpdo.cob_id)
            mst.subscribe(tpdo.cob_id, tpdos)
            node.nmt.state = "OPERATIONAL"
        for sim in sims:
            while sim.drive.esm.state is not EsmState.OP:
                time.sleep(0.001)
        sent = 0

        def cycle(cw: int, target: int) -> None:
            nonlocal sent
            data = struct.pack("<Hi", cw, target)
            for can_id in rx_ids:
                mst.send_message(can_id, data)
            mst.sync.transmit()
            sent += n
            tpdos.wait(sent)

        for cw in (0x06, 0x07, 0x0F, 0x0F):
            cycle(cw, 0)
        gc.collect()
        if profile is not None:
            profile.enable()
        start, cpu = time.perf_counter(), time.process_time()
        for k in range(cycles):
            cycle(0x0F, target_of(k))
        pdo_x = ratios(n * cycles * CYCLE_US / 1e6, start, cpu)
        if profile is not None:
            profile.disable()
        assert all(s.drive.sm.state.name == "OPERATION_ENABLED" for s in sims)
        if not sdo:
            return pdo_x, (0.0, 0.0)
        for sim in sims:                      # today's loop: SDO only, manual time
            sim.clock = "manual"
        start, cpu = time.perf_counter(), time.process_time()
        for k in range(cycles):
            for node in nodes:
                node.sdo.download(0x607A, 0, struct.pack("<i", target_of(k)))
                node.sdo.upload(0x6064, 0)
            for sim in sims:
                sim.advance(CYCLE_US / 1e6)
        sdo_x = ratios(n * cycles * CYCLE_US / 1e6, start, cpu)
        return pdo_x, sdo_x
    finally:
        for sim in sims:
            sim.close()
        mst.disconnect()
        dev.disconnect()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=2.0, help="simulated seconds per run")
    ap.add_argument("--repeat", type=int, default=3, help="runs per figure (best is kept)")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    def best(runs: list[tuple[float, float]]) -> tuple[float, float]:
        return max(r[0] for r in runs), max(r[1] for r in runs)

    one, one_cpu = best([time_csp(1, args.seconds) for _ in range(args.repeat)])
    eight, eight_cpu = best([time_csp(8, args.seconds / 4) for _ in range(args.repeat)])
    x_one, x_one_cpu = best([time_csp_exchange(1, args.seconds) for _ in range(args.repeat)])
    x_eight, x_eight_cpu = best([time_csp_exchange(8, args.seconds / 4)
                                 for _ in range(args.repeat)])
    slow = min(time_pp(10_000, args.seconds) for _ in range(args.repeat))
    fast = min(time_pp(1_000_000, args.seconds) for _ in range(args.repeat))
    sdo = max(sdo_round_trips() for _ in range(args.repeat))
    can_runs = [can_csp(8, int(args.seconds * 250)) for _ in range(args.repeat)]
    can_pdo, can_pdo_cpu = best([r[0] for r in can_runs])
    can_sdo, can_sdo_cpu = best([r[1] for r in can_runs])
    local_runs = [can_csp(8, int(args.seconds * 500), local=True) for _ in range(args.repeat)]
    in_pdo, in_pdo_cpu = best([r[0] for r in local_runs])
    in_sdo, in_sdo_cpu = best([r[1] for r in local_runs])
    cal = calibration()
    out = {"machine": f"{platform.python_implementation()} {platform.python_version()} "
                      f"on {platform.machine()}",
           "calibration_1e6_adds_s": round(cal, 3),
           "csp_1_drive_x_real_time": round(one, 1),
           "csp_8_drives_x_real_time": round(eight, 1),
           "csp_exchange_1_drive_x_real_time": round(x_one, 1),
           "csp_exchange_8_drives_x_real_time": round(x_eight, 1),
           "per_cpu_second": {"csp_1": round(one_cpu, 1), "csp_8": round(eight_cpu, 1),
                              "exchange_1": round(x_one_cpu, 1),
                              "exchange_8": round(x_eight_cpu, 1)},
           "load_average_1min": round(os.getloadavg()[0], 2),
           "pp_10kHz_wall_s": round(slow, 4), "pp_1MHz_wall_s": round(fast, 4),
           "pp_cost_ratio_fast_over_slow": round(fast / slow, 2),
           "sdo_round_trips_per_s": round(sdo),
           "can_csp_8_drives_pdo_sync_x_real_time": round(can_pdo, 2),
           "can_csp_8_drives_sdo_only_x_real_time": round(can_sdo, 2),
           "can_pdo_over_sdo": round(can_pdo / can_sdo, 1),
           "can_per_cpu_second": {"pdo_sync": round(can_pdo_cpu, 2),
                                  "sdo_only": round(can_sdo_cpu, 2)},
           "inproc_csp_8_drives_pdo_sync_x_real_time": round(in_pdo, 2),
           "inproc_csp_8_drives_sdo_only_x_real_time": round(in_sdo, 2),
           "inproc_per_cpu_second": {"pdo_sync": round(in_pdo_cpu, 2),
                                     "sdo_only": round(in_sdo_cpu, 2)},
           "inproc_pdo_over_virtual_pdo_per_cpu_second": round(in_pdo_cpu / can_pdo_cpu, 2),
           "inproc_pdo_over_virtual_sdo_per_cpu_second": round(in_pdo_cpu / can_sdo_cpu, 1)}
    if args.json:
        print(json.dumps(out))
        return 0
    print(f"plcrt CiA 402 drive benchmark ({out['machine']}), 1 ms bus cycle, best of "
          f"{args.repeat}; 10^6 Python additions take {cal * 1e3:.0f} ms here")
    print(f"  load average {out['load_average_1min']} on {os.cpu_count()} CPUs; in brackets: "
          "drive-seconds per CPU second of this process")
    print(f"  CSP, 1 drive:  {one:8.1f} x real time ({one_cpu:.1f})")
    print(f"  CSP, 8 drives: {eight:8.1f} x real time ({eight_cpu:.1f}; drive-seconds per "
          "wall second)")
    print(f"  CSP through Drive.exchange (process data by object), 1 drive: {x_one:8.1f} x "
          f"({x_one_cpu:.1f}), 8 drives: {x_eight:8.1f} x real time ({x_eight_cpu:.1f})")
    print(f"  PP move at 10 kP/s: {slow * 1e3:.1f} ms wall, at 1 MP/s: {fast * 1e3:.1f} ms wall "
          f"(ratio {fast / slow:.2f}) for {args.seconds:g} s simulated")
    print(f"  SDO round trips over the virtual bus (canopen master, attach): {sdo:8.0f} /s")
    print(f"  CSP over the virtual bus, 8 drives at a 1 ms SYNC: PDOs {can_pdo:6.2f} x real time, "
          f"({can_pdo_cpu:.2f}), SDO-only loop {can_sdo:6.2f} x ({can_sdo_cpu:.2f}); ratio "
          f"{can_pdo / can_sdo:.1f}")
    print(f"  the same over the in-process bus (cia402.bus): PDOs {in_pdo:6.2f} x real time "
          f"({in_pdo_cpu:.2f}), SDO-only loop {in_sdo:6.2f} x ({in_sdo_cpu:.2f}); per CPU "
          f"second {in_pdo_cpu / can_pdo_cpu:.2f} times the virtual bus's PDO path, "
          f"{in_pdo_cpu / can_sdo_cpu:.1f} times its SDO-only loop")
    return 0


if __name__ == "__main__":
    sys.exit(main())
