"""What a loaded program keeps, kept small: the location tables that
replace a list of SourceLoc and a dict keyed by generated line, the module
text without comment lines, and the parentheses of combined contacts."""

from __future__ import annotations

import ast
import random
import types
from typing import Any

import pytest

import plcrt
from plcrt.compiler.locs import LineLocs, LocTable
from plcrt.dump import render_dump
from plcrt.errors import SourceLoc
from plcrt.gen.emit import Gen
from plcrt.gen.exprs import is_atom as _is_atom

LOOP = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     I0.0
A      I0.1
AN     M0.0
O      M0.1
=      Q0.0
Network 2
LD     SM0.0
FOR    VW0, +1, +3
Network 3
LD     SM0.0
+I     +1, VW2
Network 4
NEXT
Network 5
LD     I0.2
LPS
A      I0.3
=      Q0.1
LPP
AN     I0.4
=      Q0.2
END_ORGANIZATION_BLOCK
"""


def _locs() -> list[SourceLoc]:
    return [SourceLoc("a.awl", 3, 1), SourceLoc("a.awl", 4, 8, "OB1", 1),
            SourceLoc("b.awl", 70000, 2, "SBR2", 12), SourceLoc("a.awl", 5, 1, "OB1", 1),
            SourceLoc("b.awl", 9, 3, None, 4)]


def test_loc_table_gives_back_equal_locations() -> None:
    table = LocTable()
    locs = _locs()
    for loc in locs:
        table.append(loc)
    assert len(table) == len(locs)
    assert list(table) == locs and table[-1] == locs[-1] and table[1:3] == locs[1:3]
    assert table.index(locs[3]) == 3 and locs[2] in table
    with pytest.raises(IndexError):
        table[len(locs)]


def test_line_locs_map_each_start_line_to_the_last_instruction_there() -> None:
    table = LocTable()
    for loc in _locs():
        table.append(loc)
    lines = LineLocs(table)
    for line in (2, 5, 5, 5, 9):      # three instructions share line 5
        lines.add(line, 1)
    assert dict(lines) == {2: table[0], 5: table[3], 9: table[4]}
    assert 5 in lines and 4 not in lines and "5" not in lines and 10 not in lines
    assert lines.get(4) is None and len(lines) == 3
    with pytest.raises(KeyError):
        lines[1]
    with pytest.raises(ValueError):
        lines.add(8, 1)                 # instructions follow the text


def test_the_module_has_no_comments_and_every_marker_is_in_the_dump() -> None:
    plc = plcrt.load(LOOP)
    assert "#" not in plc.source
    lines = plc.source.splitlines()
    starts = list(plc.line_locs.starts)
    assert len(starts) == len(plc.unit.locs) == plc.program.instruction_count()
    assert all(1 <= line <= len(lines) for line in starts) and starts == sorted(starts)
    dump = render_dump(plc)
    markers = [ln.strip() for ln in dump.splitlines() if ln.lstrip().startswith("# [")]
    assert [m.split(":")[0] for m in markers] == [
        f"# [{i}] line {plc.unit.locs[i].line}" for i in range(len(starts))]
    assert "# [0] line 4: LD     I0.0" in markers[0]
    compile(dump, "dump", "exec")


def test_a_fault_is_located_at_the_instruction_whose_code_failed() -> None:
    plc = plcrt.load(LOOP)
    fn = plc._ns["n_OB1_3_2"]          # network 3: LD SM0.0 / +I +1, VW2
    broken = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__,
                                tuple(None for _ in fn.__defaults__ or ()))
    with pytest.raises(TypeError) as err:
        broken(bytearray(64))
    loc = plc._loc_from_tb(err.value)
    # LD's value is stored by the +I that reads it: the line is +I's
    assert loc is not None and (loc.line, loc.block, loc.network) == (14, "OB1", 3)


class _Unit:
    """The part of a compilation unit a Gen needs for contacts."""

    def __init__(self) -> None:
        self.n = 0

    def fresh(self, hint: str) -> str:
        self.n += 1
        return f"_{hint}{self.n}"


OPERANDS = ["(I[0] >> 3 & 1)", "((M[1] & 1) ^ 1)", "s1", "1 if (V[2] > V[4]) else 0",
            "V[7] >> 2 & 1", "(a) | (b)", "Q[0] & 1 | M[3] & 1"]


@pytest.mark.parametrize("seed", range(40))
def test_combined_contacts_parse_as_fully_parenthesized_ones(seed: int) -> None:
    """combine() leaves out parentheses; the expression must have the syntax
    tree of the one with every operand parenthesized (the former form)."""
    rnd = random.Random(seed)
    gen = Gen(_Unit())
    first = rnd.choice(OPERANDS)
    gen.push(first)
    full = first
    for _ in range(rnd.randrange(1, 12)):
        op, expr = rnd.choice("&|"), rnd.choice(OPERANDS)
        gen.combine(op, expr)
        full = f"({full}) {op} ({expr})"
    assert gen.pending is not None
    assert ast.dump(ast.parse(gen.pending, mode="eval")) == \
        ast.dump(ast.parse(full, mode="eval"))


def test_atoms() -> None:
    assert all(_is_atom(e) for e in ("s1", "V[3]", "7", "(V[3] >> 2 & 1)", "((M[0] & 1) ^ 1)"))
    assert not any(_is_atom(e) for e in ("(a) & (b)", "a & b", "-1", "1 if (a) else 0",
                                         "f('(')", "('x)')"))


def _scan_all(plc: Any) -> list[bytes]:
    seen = []
    for i in range(6):
        plc["I0.0"], plc["I0.1"], plc["I0.2"], plc["I0.3"] = i & 1, i >> 1 & 1, i >> 2 & 1, 1
        plc.scan()
        seen.append(bytes(plc.mem.areas["Q"][:1]) + bytes(plc.mem.areas["V"][:4]))
    return seen


def test_the_program_runs_the_same_in_small_chunks(monkeypatch: pytest.MonkeyPatch) -> None:
    from plcrt.compiler import cache
    whole = _scan_all(plcrt.load(LOOP))
    cache.programs.clear()
    monkeypatch.setattr(cache, "CHUNK_LINES", 3)
    plc = plcrt.load(LOOP)
    assert len(plc.unit.chunks) > 3
    assert _scan_all(plc) == whole
    cache.programs.clear()


def test_a_large_compile_hands_free_heap_pages_back(monkeypatch: pytest.MonkeyPatch) -> None:
    from plcrt.compiler import cache
    calls: list[int] = []
    monkeypatch.setattr(cache, "release_free_memory", lambda: calls.append(1) or True)
    cache.compile_chunks("x = 1\n", [(1, 0)], "<t>")
    assert calls == []                          # a small module: not worth it
    monkeypatch.setattr(cache, "TRIM_SOURCE_CHARS", 4)
    codes = cache.compile_chunks("x = 1\ny = 2\n", [(1, 0), (2, 6)], "<t>")
    assert calls == [1] and [c.co_firstlineno for c in codes] == [1, 2]


def test_releasing_free_memory_is_harmless() -> None:
    from plcrt.compiler import cache
    plc = plcrt.load(LOOP)
    assert cache.release_free_memory() in (True, False)
    assert len(_scan_all(plc)) == 6


def test_pieces_are_slices_of_their_networks_instructions() -> None:
    """A network without cuts is one piece holding the network's own tuple;
    LBL cuts before itself, FOR and NEXT after themselves, and a network's
    empty tail after a cut is no piece."""
    text = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     I0.0
=      Q0.0
Network 2
LD     SM0.0
FOR    VW0, +1, +3
+I     +1, VW2
NEXT
Network 3
LBL    4
LD     I0.1
=      Q0.1
Network 4
END_ORGANIZATION_BLOCK
"""
    plc = plcrt.load(text)
    info = plc.unit.pous["OB1"]
    nets = info.pou.networks
    got = [(p.network.number, [i.mnemonic for i in p.insns], p.index, p.suffix)
           for p in info.pieces]
    assert got == [(1, ["LD", "="], 0, ""), (2, ["LD", "FOR"], 1, ""),
                   (2, ["+I", "NEXT"], 2, "_a"), (3, ["LBL", "LD", "="], 3, ""),
                   (4, [], 4, "")]
    assert info.pieces[0].insns is nets[0].insns and info.pieces[3].insns is nets[2].insns
    assert all(isinstance(p.insns, tuple) for p in info.pieces)
    assert info.cost == [2, 2, 2, 3, 0] and list(info.depth_after) == [1]
