"""The import graph of the library blocks and the devices: one way only.

plcrt.blocks sits below plcrt.devices: the registry reads a table the
device libraries fill and never imports them; no module of plcrt.blocks,
plcrt.devices or the plcrt.cia402 facade is on an import cycle; nothing in
plcrt imports the facade; no module of either package is longer than 500
non-blank lines.  Every import counts, also one inside a function or under
TYPE_CHECKING (the graph is read from the source with ast).
"""

from __future__ import annotations

from import_graph import PLCRT, cycles, graph, long_modules


def _ours(mod: str) -> bool:
    return mod == "plcrt.cia402" or mod.split(".")[:2] in (["plcrt", "blocks"],
                                                           ["plcrt", "devices"])


def test_blocks_import_nothing_from_devices() -> None:
    g = graph()
    up = sorted(f"{m} -> {t}" for m, ts in g.items() if m.startswith("plcrt.blocks")
                for t in ts if t.startswith("plcrt.devices") or t == "plcrt.cia402")
    assert up == []


def test_no_import_cycle_through_blocks_devices_or_the_cia402_facade() -> None:
    found = [sorted(c) for c in cycles(graph()) if any(_ours(m) for m in c)]
    assert found == []


def test_nothing_in_plcrt_imports_the_cia402_facade() -> None:
    g = graph()
    assert sorted(m for m, ts in g.items() if "plcrt.cia402" in ts) == []


def test_the_cycle_finder_finds_a_cycle() -> None:
    # the helper the tests above rely on, on a graph with one cycle and a tail
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set()}
    assert cycles(edges) == [{"a", "b", "c"}]


def test_modules_of_blocks_and_devices_stay_under_500_lines() -> None:
    long = {**long_modules(PLCRT / "blocks"), **long_modules(PLCRT / "devices")}
    assert long == {}
