"""Table tests for the counter family (CTU, CTD, CTUD) and plcrt.engine.counters.

S7-200 System Manual, "Counter instructions" (digest section 3.5).  The
boxes take their inputs from the logic stack: CTU: CU second, R top; CTD:
CD second, LD top; CTUD: CU third, CD second, R top.  Each row lists the
inputs per scan and the (current value, counter bit) seen after the scan.
"""

from __future__ import annotations

import pytest

import plcrt
from stl_helpers import load_ob1 as _load


def _cbit(p: plcrt.Plc, n: int) -> int:
    """The counter bit of Cn (``plc["Cn"]`` reads the current value)."""
    return p.mem.areas["CB"][n >> 3] >> (n & 7) & 1


def _set_cv(p: plcrt.Plc, n: int, value: int) -> None:
    p[f"C{n}"] = value


def _trace(p: plcrt.Plc, n: int, inputs: list[str], steps: list[tuple[int, ...]]
           ) -> list[tuple[int, int]]:
    out = []
    for values in steps:
        for addr, v in zip(inputs, values):
            p[addr] = v
        p.scan()
        out.append((p[f"C{n}"], _cbit(p, n)))
    return out


CTU_TABLE = [
    ("counts rising edges", [(0, 0), (1, 0), (0, 0), (1, 0), (1, 0), (0, 0), (1, 0)],
     [(0, 0), (1, 0), (1, 0), (2, 0), (2, 0), (2, 0), (3, 1)]),
    ("keeps counting past PV", [(1, 0), (0, 0), (1, 0), (0, 0), (1, 0), (0, 0), (1, 0)],
     [(1, 0), (1, 0), (2, 0), (2, 0), (3, 1), (3, 1), (4, 1)]),
    ("R clears and wins", [(1, 0), (0, 0), (1, 1), (0, 0), (1, 0)],
     [(1, 0), (1, 0), (0, 0), (0, 0), (1, 0)]),
    ("held CU counts once", [(1, 0)] * 5, [(1, 0)] * 5),
]


@pytest.mark.parametrize("label,steps,expected", CTU_TABLE, ids=[r[0] for r in CTU_TABLE])
def test_ctu(label: str, steps: list, expected: list) -> None:
    """CTU counts CU rising edges (second level); R (top) clears; bit on at CV >= PV."""
    p = _load("LD I0.0\nLD I0.1\nCTU C0, +3")
    assert _trace(p, 0, ["I0.0", "I0.1"], steps) == expected


CTD_TABLE = [
    ("load then count down", [(0, 1), (0, 0), (1, 0), (0, 0), (1, 0), (0, 0), (1, 0)],
     [(2, 0), (2, 0), (1, 0), (1, 0), (0, 1), (0, 1), (0, 1)]),
    ("LD reloads and clears the bit", [(0, 1), (1, 0), (0, 0), (1, 0), (1, 1)],
     [(2, 0), (1, 0), (1, 0), (0, 1), (2, 0)]),
    ("never loaded: CV 0, bit on", [(0, 0), (1, 0), (0, 0)], [(0, 1), (0, 1), (0, 1)]),
]


@pytest.mark.parametrize("label,steps,expected", CTD_TABLE, ids=[r[0] for r in CTD_TABLE])
def test_ctd(label: str, steps: list, expected: list) -> None:
    """CTD counts CD rising edges down to 0; LD (top) loads PV and clears the bit; bit on at 0."""
    p = _load("LD I0.0\nLD I0.1\nCTD C1, +2")
    assert _trace(p, 1, ["I0.0", "I0.1"], steps) == expected


CTUD_TABLE = [
    ("up and down", [(1, 0, 0), (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 0), (0, 1, 0),
                     (0, 0, 0), (0, 1, 0)],
     [(1, 0), (1, 0), (2, 1), (1, 0), (1, 0), (0, 0), (0, 0), (-1, 0)]),
    ("both edges in one scan cancel", [(0, 0, 0), (1, 1, 0)], [(0, 0), (0, 0)]),
    ("R clears", [(1, 0, 0), (0, 0, 0), (1, 0, 0), (0, 0, 1)], [(1, 0), (1, 0), (2, 1), (0, 0)]),
]


@pytest.mark.parametrize("label,steps,expected", CTUD_TABLE, ids=[r[0] for r in CTUD_TABLE])
def test_ctud(label: str, steps: list, expected: list) -> None:
    """CTUD: CU third level, CD second, R top; bit on at CV >= PV."""
    p = _load("LD I0.0\nLD I0.1\nLD I0.2\nCTUD C2, +2")
    assert _trace(p, 2, ["I0.0", "I0.1", "I0.2"], steps) == expected


@pytest.mark.parametrize("box,preset_cv,inputs,expected_cv", [
    ("LD I0.0\nLD I0.1\nCTU C3, +5", 32767, (1, 0), 32767),        # CTU saturates
    ("LD I0.0\nLD I0.1\nCTD C3, +5", 0, (1, 0), 0),                # CTD stops at 0
    ("LD I0.0\nLD I0.1\nLD I0.2\nCTUD C3, +5", 32767, (1, 0, 0), -32768),   # wraps up
    ("LD I0.0\nLD I0.1\nLD I0.2\nCTUD C3, +5", -32768, (0, 1, 0), 32767),   # wraps down
])
def test_limits(box: str, preset_cv: int, inputs: tuple[int, ...], expected_cv: int) -> None:
    """CTU saturates at 32767, CTD stops at 0, CTUD wraps 32767 <-> -32768."""
    p = _load(box)
    p.scan()
    _set_cv(p, 3, preset_cv)
    for i, v in enumerate(inputs):
        p[f"I0.{i}"] = v
    p.scan()
    assert p["C3"] == expected_cv


def test_ctud_wrap_changes_the_bit() -> None:
    """After wrapping to -32768 a CTUD with PV 5 turns its bit off."""
    p = _load("LD I0.0\nLD I0.1\nLD I0.2\nCTUD C4, +5")
    p.scan()
    _set_cv(p, 4, 32766)
    p["I0.0"] = 1
    p.scan()
    assert (p["C4"], _cbit(p, 4)) == (32767, 1)
    p["I0.0"] = 0
    p.scan()
    p["I0.0"] = 1
    p.scan()
    assert (p["C4"], _cbit(p, 4)) == (-32768, 0)


def test_preset_from_a_word_operand_is_compared_at_each_execution() -> None:
    """PV may come from VW memory; the bit follows a changed PV at the next execution."""
    p = _load("LD I0.0\nLD I0.1\nCTU C5, VW0")
    p["VW0"] = 3
    for v in (1, 0, 1, 0):
        p["I0.0"] = v
        p.scan()
    assert (p["C5"], _cbit(p, 5)) == (2, 0)
    p["VW0"] = 2
    p.scan()
    assert (p["C5"], _cbit(p, 5)) == (2, 1)


def test_ctd_loads_a_preset_from_a_word_operand() -> None:
    """CTD's LD loads the current value from a word operand."""
    p = _load("LD I0.0\nLD I0.1\nCTD C6, VW10")
    p["VW10"] = 1234
    p["I0.1"] = 1
    p.scan()
    assert (p["C6"], _cbit(p, 6)) == (1234, 0)


def test_inputs_built_with_logic_on_the_stack() -> None:
    """Each counter input may be a whole logic expression: CU = I0.0 AND I0.3, R = I0.1 OR I0.2."""
    p = _load("LD I0.0\nA I0.3\nLD I0.1\nO I0.2\nCTU C7, +10")
    steps = [(1, 0, 0, 0), (0, 0, 0, 0), (1, 0, 0, 1), (0, 0, 0, 1), (1, 0, 0, 1),
             (1, 0, 1, 1)]
    assert _trace(p, 7, ["I0.0", "I0.1", "I0.2", "I0.3"], steps) == \
        [(0, 0), (0, 0), (1, 0), (1, 0), (2, 0), (0, 0)]


def test_r_instruction_resets_counters() -> None:
    """R Cn, k clears current value and bit of k counters."""
    p = _load("LD I0.0\nLD I0.1\nCTU C8, +1", "LD I0.0\nLD I0.1\nCTU C9, +1",
              "LD I0.2\nR C8, 2")
    p["I0.0"] = 1
    p.scan()
    assert [p["C8"], p["C9"], _cbit(p, 8), _cbit(p, 9)] == [1, 1, 1, 1]
    p["I0.2"] = 1
    p.scan()
    assert [p["C8"], p["C9"], _cbit(p, 8), _cbit(p, 9)] == [0, 0, 0, 0]


def test_cu_already_on_at_the_first_execution_counts_once() -> None:
    """Counter edge memory starts at 0 when entering RUN (docs/decisions.md)."""
    p = _load("LD SM0.0\nLD I0.1\nCTU C10, +1")
    p.scan(3)
    assert p["C10"] == 1


def test_counter_used_by_two_boxes_warns() -> None:
    """Two boxes on one counter number share state; plcrt warns about it."""
    p = _load("LD I0.0\nLD I0.1\nCTU C11, +1", "LD I0.0\nLD I0.1\nCTD C11, +1")
    assert any(d.code == "counter-twice" for d in p.diagnostics)


@pytest.mark.parametrize("body", ["LD I0.0\nCTU C0, +1", "LD I0.0\nLD I0.1\nCTUD C0, +1",
                                  "LD I0.0\nLD I0.1\nCTU T0, +1"])
def test_missing_stack_inputs_are_compile_errors(body: str) -> None:
    """A counter needs all its inputs on the stack and a C operand."""
    with pytest.raises(plcrt.PlcCompileError):
        _load(body)
