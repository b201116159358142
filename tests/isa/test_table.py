"""Table tests for plcrt.isa.table: ATT, FIFO, LIFO, FND=/<>/</> (S7-200
System Manual, "Table instructions": TL, EC, then the entries; SM1.4 table
full, SM1.5 table empty; FND from INDX, INDX = EC when nothing matches)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

import plcrt
from plcrt.errors import PlcCompileError
from stl_helpers import load_ob1


def _run(body: str, preset: dict | None = None, table: tuple | None = None) -> plcrt.Plc:
    """``LD SM0.0`` + body + ``AENO / = Q0.0`` (Q0.0 = ENO), one scan; ``table``
    = (TL, EC, entries...) written from VW200."""
    p = load_ob1("LD SM0.0\n" + body + "\nAENO\n= Q0.0")
    for i, w in enumerate(table or ()):
        p[f"VW{200 + 2 * i}"] = w
    for addr, value in (preset or {}).items():
        p[addr] = value
    p.scan()
    return p


def _table(p: plcrt.Plc, n: int) -> list[int]:
    return [p[f"VW{200 + 2 * i}"] for i in range(n)]


# (id, body, table from VW200, preset, expected reads; "ENO" = Q0.0)
CASES = [
    # ATT: the manual's example: TL 6, EC 2 -> 3, the new entry at d2
    ("ATT appends", "ATT VW100, VW200", (6, 2, 1234, 4321), {"VW100": 1111},
     {"VW202": 3, "VW208": 1111, "VW204": 1234, "SM1.4": 0, "ENO": 1}),
    ("ATT into empty", "ATT +7, VW200", (3, 0), {}, {"VW202": 1, "VW204": 7, "ENO": 1}),
    ("ATT fills to TL", "ATT -5, VW200", (3, 2, 1, 2, 99), {},
     {"VW202": 3, "VW208": -5, "SM1.4": 0, "ENO": 1}),
    ("ATT full sets SM1.4", "ATT +9, VW200", (2, 2, 1, 2, 77), {},
     {"VW202": 2, "VW208": 77, "SM1.4": 1, "ENO": 0}),
    ("ATT success clears SM1.4", "ATT +9, VW200", (2, 0), {"SMB1": 0x10},
     {"SMB1": 0, "ENO": 1}),
    ("ATT full keeps other flags", "ATT +9, VW200", (1, 1, 5), {"SMB1": 0x23},
     {"SMB1": 0x33}),
    ("ATT TL above 100 holds 100", "ATT +1, VW200", (200, 100), {},
     {"VW202": 100, "SM1.4": 1, "ENO": 0}),
    ("ATT EC above 100 is error 0091", "ATT +1, VW200", (200, 101), {},
     {"VW202": 101, "SM4.3": 1, "SM1.4": 0, "ENO": 0}),
    ("ATT negative EC is error 0091", "ATT +1, VW200", (5, -1), {},
     {"VW202": -1, "SM4.3": 1, "ENO": 0}),
    ("ATT TL 0 is full", "ATT +1, VW200", (0, 0), {}, {"SM1.4": 1, "VW202": 0}),
    # FIFO: the oldest entry, the others move up; the last word keeps its value
    ("FIFO oldest", "FIFO VW200, VW100", (6, 3, 5431, 8942, 1234), {},
     {"VW100": 5431, "VW202": 2, "VW204": 8942, "VW206": 1234, "VW208": 1234,
      "SM1.5": 0, "ENO": 1}),
    ("FIFO last entry", "FIFO VW200, VW100", (6, 1, -3), {},
     {"VW100": -3, "VW202": 0, "ENO": 1}),
    ("FIFO empty sets SM1.5", "FIFO VW200, VW100", (6, 0, 42), {"VW100": 9},
     {"VW100": 9, "VW202": 0, "SM1.5": 1, "ENO": 0}),
    ("FIFO success clears SM1.5", "FIFO VW200, VW100", (6, 1, 1), {"SMB1": 0x20},
     {"SMB1": 0}),
    # LIFO: the newest entry; the manual's example TL 6, EC 3 -> 2
    ("LIFO newest", "LIFO VW200, VW100", (6, 3, 5431, 8942, 1234), {},
     {"VW100": 1234, "VW202": 2, "VW204": 5431, "VW206": 8942, "ENO": 1}),
    ("LIFO empty sets SM1.5", "LIFO VW200, VW100", (6, 0), {"VW100": 9},
     {"VW100": 9, "SM1.5": 1, "ENO": 0}),
    ("LIFO EC above 100", "LIFO VW200, VW100", (6, 101), {"VW100": 9},
     {"VW100": 9, "VW202": 101, "SM4.3": 1, "ENO": 0}),
    ("LIFO into AC", "LIFO VW200, AC0\nMOVW AC0, VW100", (6, 2, 7, -8), {}, {"VW100": -8}),
    # FND: TBL is the entry count word (VW202 for the table at VW200)
    ("FND= from 0", "MOVW 0, AC1\nFND= VW202, 16#3130, AC1", (6, 6, 1, 2, 0x3130, 4, 0x3130, 6),
     {}, {"AC1": 2, "ENO": 1}),
    ("FND= from the next entry", "MOVW 3, AC1\nFND= VW202, 16#3130, AC1",
     (6, 6, 1, 2, 0x3130, 4, 0x3130, 6), {}, {"AC1": 4}),
    ("FND= none left gives EC", "MOVW 5, AC1\nFND= VW202, 16#3130, AC1",
     (6, 6, 1, 2, 0x3130, 4, 0x3130, 6), {}, {"AC1": 6, "ENO": 1}),
    ("FND= INDX past EC gives EC", "FND= VW202, 4, VW100", (6, 6, 1, 2, 3, 4, 5, 6),
     {"VW100": 40}, {"VW100": 6}),
    ("FND<> first different", "FND<> VW202, 0, VW100", (9, 3, 0, 0, 5), {}, {"VW100": 2}),
    ("FND< compares INT", "FND< VW202, 0, VW100", (9, 3, 5, -1, 7), {}, {"VW100": 1}),
    ("FND> compares INT", "FND> VW202, -2, VW100", (9, 3, -5, -3, -1), {}, {"VW100": 2}),
    ("FND> none", "FND> VW202, 100, VW100", (9, 3, -5, -3, -1), {}, {"VW100": 3}),
    ("FND empty table", "FND= VW202, 0, VW100", (9, 0, 0), {}, {"VW100": 0, "ENO": 1}),
    ("FND keeps SMB1", "FND= VW202, 0, VW100", (9, 1, 0), {"SMB1": 0x35}, {"SMB1": 0x35}),
    ("FND EC above 100", "FND= VW202, 0, VW100", (9, 101), {"VW100": 3},
     {"VW100": 3, "SM4.3": 1, "ENO": 0}),
    ("FND through a pointer", "MOVD &VB202, AC2\nFND= *AC2, 8, VW100", (9, 2, 7, 8), {},
     {"VW100": 1}),
]


@pytest.mark.parametrize("body,table,preset,expect", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_table(body, table, preset, expect):
    """ATT/FIFO/LIFO/FND give the manual's table contents, INDX, SM1.4/SM1.5 and ENO."""
    p = _run(body, preset, table)
    got = {a: p["Q0.0" if a == "ENO" else a] for a in expect}
    assert got == expect


def test_fnd_loop_finds_every_match():
    """The manual's search loop: FND from INDX, use the match, INDX + 1, again,
    until INDX = EC; every matching entry is found once, in order."""
    p = load_ob1("""LD SM0.0
MOVW 0, VW100
MOVW 0, VW102
FOR VW104, 1, 10
LDW< VW100, VW202
FND= VW202, 16#3130, VW100
LDW< VW100, VW202
INCW VW100
INCW VW102
NEXT""")
    for i, w in enumerate((6, 6, 1, 0x3130, 0x3130, 4, 5, 0x3130)):
        p[f"VW{200 + 2 * i}"] = w
    p.scan()
    assert p["VW102"] == 3 and p["VW100"] == 6


def test_box_needs_power_flow():
    """Without power flow no table instruction changes anything."""
    p = load_ob1("LD I0.0\nATT +1, VW200\nFIFO VW200, VW100\nFND= VW202, 1, VW102")
    p["VW200"], p["VW202"], p["VW102"] = 5, 1, 7
    p.scan()
    assert (_table(p, 3), p["VW100"], p["VW102"]) == ([5, 1, 0], 0, 7)


def test_table_past_area_end_is_error_0091():
    """A table whose entries run past the end of V is run-time error 0091:
    SM4.3, ENO 0, a warning with the location, no fault."""
    p = load_ob1("LD SM0.0\nATT +1, VW10236\nAENO\n= Q0.0")
    p["VW10236"], p["VW10238"] = 10, 1
    p.scan()
    assert (p["VW10238"], p["SM4.3"], p["Q0.0"], p.mode) == (1, 1, 0, "RUN")
    assert any("0091" in d.message and d.loc and d.loc.line for d in p.diagnostics)


def test_table_in_accumulator_is_refused():
    """A table is memory: an accumulator cannot hold one (compile error)."""
    with pytest.raises(PlcCompileError, match="in memory .an address or .pointer.*not memory"):
        load_ob1("LD SM0.0\nATT +1, AC0")


WORDS = st.integers(-32768, 32767)


@settings(max_examples=60, deadline=None)
@given(values=st.lists(WORDS, min_size=0, max_size=12), tl=st.integers(0, 12))
def test_att_then_fifo_and_lifo_keep_order(values, tl):
    """ATT up to TL entries, then FIFO returns them in order and LIFO in
    reverse; SM1.4 exactly when an ATT found the table full, SM1.5 when the
    last take found it empty."""
    n = len(values)
    body = [f"ATT {v}, VW200\nLD SM1.4\n= V{300 + i // 8}.{i % 8}\nLD SM0.0"
            for i, v in enumerate(values)]
    takes = "LD SM0.0\n" + "\n".join(f"FIFO VW200, VW{400 + 2 * i}" for i in range(n + 1))
    p = load_ob1("LD SM0.0\nMOVW %d, VW200\nMOVW 0, VW202\n" % tl + "\n".join(body), takes)
    p.scan()
    kept = values[:tl]
    assert [p[f"VW{400 + 2 * i}"] for i in range(len(kept))] == kept
    assert [p[f"V{300 + i // 8}.{i % 8}"] for i in range(n)] == [int(i >= tl) for i in range(n)]
    assert p["VW202"] == 0 and p["SM1.5"] == 1
    q = load_ob1("LD SM0.0\nMOVW %d, VW200\nMOVW 0, VW202\n" % tl
                 + "\n".join(f"ATT {v}, VW200" for v in values),
                 "LD SM0.0\n" + "\n".join(f"LIFO VW200, VW{400 + 2 * i}" for i in range(len(kept))))
    q.scan()
    assert [q[f"VW{400 + 2 * i}"] for i in range(len(kept))] == kept[::-1]
