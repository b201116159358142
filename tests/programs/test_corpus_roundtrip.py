"""The corpus's largest program, the Micro/WIN SMART roundtrip export (635
instructions in 18 blocks: bit logic, timers, counters, an SCR sequence,
analog scaling, math, tables, conversions, strings, the clock, freeport and
GET, HSC and PTO), runs 10 000 scans without a runtime error, and its
sequence steps through one whole machine cycle at the times its timers
give (read from ../shared/corpus; skipped where the corpus is absent)."""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt

ROOT = Path(__file__).resolve().parents[2]
ROUNDTRIP = ROOT.parent / "shared" / "corpus" / \
    "bulaofen0036-coder__Smart200-MicroWIN-MCP__roundtrip.awl"
SYMBOLS = ROOT / "tests" / "data" / "roundtrip_symbols.sdf"

pytestmark = pytest.mark.skipif(not ROUNDTRIP.is_file(), reason="shared/corpus not available")

#: emergency stop (NC) closed, safety door closed, automatic, a part at the
#: light barrier, and every position switch made
HELD = ("I0.0", "I0.6", "I0.4", "I0.5", "I0.7", "I1.2", "I1.0", "I1.3", "I1.1")


def machine() -> plcrt.Plc:
    plc = plcrt.load(ROUNDTRIP, symbols=SYMBOLS)
    for address in HELD:
        plc.write(address, 1)
    plc.write("启动按钮", 1)            # start (I0.1), pressed for one scan
    plc.scan()
    plc.write("启动按钮", 0)
    return plc


def test_ten_thousand_scans_run_without_a_runtime_error():
    plc = machine()
    plc.run(scans=9999)
    assert plc.mode == "RUN" and plc.fault is None and plc.scans == 10000
    # the program's freeport exchange starts RCV on the first scan and sends
    # every 5 s: the port is half duplex, so its XMT is refused and reported
    assert [d.message.split(" at ")[0] for d in plc.diagnostics] == ["XMT on port 0"]


def test_the_sequence_runs_one_machine_cycle_at_its_timers_times():
    """S0.1 loads and hands over at once (part in place), S0.2 clamps for
    T41 (3 s), S0.3 machines for T42 (20 s), S0.4 releases for T43 (3 s),
    S0.5 and S0.6 follow in the same scan (SCRT acts on later segments at
    once), S0.6 waits T45 (2 s) and returns to S0.0: scan numbers at 10 ms."""
    plc = machine()
    steps: list[tuple[int, int]] = []

    def step(p: plcrt.Plc) -> None:
        active = [k for k in range(7) if p.read(f"S0.{k}")]
        if len(active) == 1 and (not steps or steps[-1][1] != active[0]):
            steps.append((p.scans, active[0]))

    plc.observers.append(step)
    plc.run(scans=3000)
    assert steps == [(2, 2), (301, 3), (2301, 4), (2601, 6), (2801, 0)]
    assert plc.read("就绪指示") == 1                 # back in S0.0: ready
    assert plc.read("VW130") == 1                   # one part machined (T42's edge)
