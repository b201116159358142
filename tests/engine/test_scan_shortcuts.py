"""The scan start's shortcuts against the exact computation.

plcrt.engine.runtime keeps SM0.4/SM0.5 for the half second they hold and
skips TimerBank.start_scan inside a window where no 100 ms tick passes and
no 1 ms / 10 ms timer runs; inside both (Plc._calm_start) a scan start
sets only SMB0's parity byte and the bank's millisecond (perf).  These properties run programs at scan
times that do and do not divide the clocks' periods, with restores back in
time, and compare each scan with the closed form (SMB0) or with the same
PLC made to take the exact path at every scan start (timers).
"""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

import plcrt

SMB0 = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD SM0.0\nMOVB SMB0, VB0\n"
        "END_ORGANIZATION_BLOCK\n")

TIMERS = ("ORGANIZATION_BLOCK OB1\nBEGIN\n"
          "Network 1\nLD I0.0\nTON T32, +700\n"      # 1 ms
          "Network 2\nLD I0.1\nTON T33, +90\n"       # 10 ms
          "Network 3\nLD I0.2\nTON T37, +12\n"       # 100 ms
          "Network 4\nLD I0.3\nTONR T1, +40\n"       # 10 ms retentive
          "Network 5\nLD I0.4\nR T1, 1\n"
          "END_ORGANIZATION_BLOCK\n")

SCAN_MS = st.sampled_from((1, 3, 7, 10, 33, 99.999, 100, 250, 333.333, 499.999, 500, 1000, 7001))


def _expected_smb0(t_us: int, scan: int) -> int:
    b0 = 0x81 | (0x0A if scan == 0 else 0)
    if scan % 2 == 0:
        b0 |= 0x40
    if t_us % 60_000_000 >= 30_000_000:
        b0 |= 0x10
    if t_us % 1_000_000 >= 500_000:
        b0 |= 0x20
    return b0


@settings(max_examples=40, deadline=None)
@given(SCAN_MS, st.integers(1, 400), st.integers(0, 399))
def test_smb0_is_the_closed_form_at_every_scan_start(scan_ms: float, n: int, back: int) -> None:
    p = plcrt.load(SMB0, scan_ms=scan_ms)
    snap, snap_at = p.snapshot(), 0
    scan = 0
    while scan < n:
        if scan == back % n and snap_at == 0:
            snap, snap_at = p.snapshot(), scan
        t = p.now_us
        p.scan()
        assert p["VB0"] == _expected_smb0(t, scan), (scan, t)
        scan += 1
    # back in time: the clock bits follow the restored time
    p.restore(snap)
    for scan in range(snap_at, min(n, snap_at + 50)):
        t = p.now_us
        p.scan()
        assert p["VB0"] == _expected_smb0(t, scan), (scan, t)


def _run_pair(scan_ms: float, steps: list) -> int:
    """Run TIMERS on a PLC and on a twin whose timer bank takes the exact
    path (TimerBank.start_scan) at every scan start; after every scan the
    timer words and bits must agree.  Returns the scans whose start took
    the shortcut."""
    fast, exact = plcrt.load(TIMERS, scan_ms=scan_ms), plcrt.load(TIMERS, scan_ms=scan_ms)
    shortcuts = 0
    for inputs, scans in steps:
        for plc in (fast, exact):
            plc["IB0"] = inputs
        for _ in range(scans):
            shortcuts += fast.timers.quiet(fast.now_us)
            fast.scan()
            exact.timers.quiet_hi = exact._calm_hi = 0   # never inside a window
            exact.scan()
            assert bytes(fast.timers.tv) == bytes(exact.timers.tv), fast.now_us
            assert bytes(fast.timers.tb) == bytes(exact.timers.tb), fast.now_us
    return shortcuts


@settings(max_examples=40, deadline=None)
@given(SCAN_MS, st.lists(st.tuples(st.integers(0, 31), st.integers(1, 60)), min_size=1,
                         max_size=12))
def test_timers_are_those_of_the_exact_scan_start(scan_ms: float, steps: list) -> None:
    """Inputs switch the timers on and off at random scans."""
    _run_pair(scan_ms, steps)


def test_a_fast_timer_started_after_quiet_scans_counts_from_its_scan() -> None:
    """Quiet scans (only a 100 ms timer) then the 1 ms and 10 ms timers
    start: they count from the scan that started them, not from the last
    exact scan start."""
    assert _run_pair(1, [(0b100, 57), (0b111, 30), (0b100, 40), (0b1011, 90)]) > 50


def test_restoring_a_state_ahead_keeps_its_timer_ticks() -> None:
    """A PLC restored to a snapshot taken ahead of it, inside its own quiet
    window, counts the 100 ms ticks of the snapshot's history, not its
    own window's."""
    p = plcrt.load(TIMERS, scan_ms=10)
    p["IB0"] = 0b100                         # T37, 100 ms
    p.run(scans=5)                           # t = 50 ms
    ahead = p.fork()
    ahead.run(scans=6)                       # its last scan started at 100 ms: a tick
    snap = ahead.snapshot()
    p.run(scans=10)                          # t = 150 ms, quiet since 110 ms
    p.restore(snap)
    for plc in (p, ahead):
        plc.run(scans=25)
    assert p["T37"] == ahead["T37"] and p.now_us == ahead.now_us
