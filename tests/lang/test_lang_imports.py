"""The import graph of plcrt.lang: one way only, and no module over 500 lines.

plcrt.lang is the front end, below the compiler: its modules import each
other and the ground below them (plcrt.errors, plcrt.safetext and
plcrt.paths, the checks of file names), and nothing else of plcrt.  Among
themselves they form no cycle (the two parsers share their tables through
plcrt.lang.stltext, below both).  Every import counts, also one inside a
function or under TYPE_CHECKING: the graph is read from the source with ast.
"""

from __future__ import annotations

from import_graph import PLCRT, cycles, graph, long_modules

LANG = PLCRT / "lang"
BELOW = {"plcrt.errors", "plcrt.safetext", "plcrt.paths"}


def _graph() -> dict[str, frozenset[str]]:
    """The imports of the modules of plcrt.lang."""
    return {m: ts for m, ts in graph().items()
            if m == "plcrt.lang" or m.startswith("plcrt.lang.")}


def test_lang_imports_only_itself_and_the_ground() -> None:
    g = _graph()
    up = sorted(f"{m} -> {t}" for m, ts in g.items() for t in ts
                if t not in BELOW and not t.startswith("plcrt.lang"))
    assert up == []


def test_no_import_cycle_in_lang() -> None:
    assert [c for c in cycles(graph()) if any(m.startswith("plcrt.lang") for m in c)] == []


def test_the_parsers_share_their_tables_from_below() -> None:
    g = _graph()
    assert "plcrt.lang.stl" not in g["plcrt.lang.fastparse"]
    assert "plcrt.lang.stltext" in g["plcrt.lang.fastparse"]
    assert "plcrt.lang.stltext" in g["plcrt.lang.stl"]


def test_the_cycle_finder_finds_a_cycle() -> None:
    # the helper the test above relies on, on a graph with one cycle and a tail
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set()}
    assert cycles(edges) == [{"a", "b", "c"}]


def test_lang_modules_stay_under_500_lines() -> None:
    assert long_modules(LANG) == {}
