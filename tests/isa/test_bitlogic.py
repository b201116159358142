"""Table tests for plcrt.isa.bitlogic: contacts, the 9-level logic stack,
edges, outputs and set/reset ranges (S7-200 System Manual, "Bit logic
instructions" and "Logic stack instructions"; digest section 3.3)."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

import plcrt
from stl_helpers import load_ob1 as _load
from plcrt.errors import PlcCompileError


def _scan_with(p: plcrt.Plc, inputs: dict[str, int]) -> plcrt.Plc:
    for addr, value in inputs.items():
        p[addr] = value
    p.scan()
    return p


class _PqProbe:
    """A simulated device: records the physical outputs PQ after OB1 ran,
    before the end-of-scan copy of the image Q (so only immediate writes
    are visible)."""

    def __init__(self) -> None:
        self.seen: list[bytes] = []

    def step(self, plc: plcrt.Plc, t_from: int, t_to: int) -> None:
        self.seen.append(bytes(plc.mem.areas["PQ"][:2]))


# -- contacts: (mnemonic, bit, top before) -> top after --------------------
def _contact(mn: str, bit: int, top: int) -> int:
    neg = "N" in mn
    b = bit ^ 1 if neg else bit
    if mn.startswith("LD"):
        return b
    return top & b if mn.startswith("A") else top | b


CONTACTS = [(mn, bit, top) for mn in ("LD", "LDN", "A", "AN", "O", "ON")
            for bit in (0, 1) for top in (0, 1)]


@pytest.mark.parametrize("mn,bit,top", CONTACTS)
def test_standard_contacts(mn: str, bit: int, top: int) -> None:
    """LD/LDN push the (inverted) bit; A/AN/O/ON combine it into the top."""
    body = f"LD I0.1\n{mn} I0.0\n= Q0.0" if not mn.startswith("LD") else f"{mn} I0.0\n= Q0.0"
    p = _scan_with(_load(body), {"I0.0": bit, "I0.1": top})
    assert p["Q0.0"] == _contact(mn, bit, top)


IMMEDIATE = [(mn, bit, top) for mn in ("LDI", "LDNI", "AI", "ANI", "OI", "ONI")
             for bit in (0, 1) for top in (0, 1)]


@pytest.mark.parametrize("mn,bit,top", IMMEDIATE)
def test_immediate_contacts_read_the_physical_input(mn: str, bit: int, top: int) -> None:
    """LDI/LDNI/AI/ANI/OI/ONI read PI; the image I (forced to the opposite here) is ignored."""
    # Network 1 overwrites the image of I0.0 with the opposite of the
    # terminal, so an image read and a terminal read differ.
    image_fix = "S I0.0, 1" if bit == 0 else "R I0.0, 1"
    body = f"{mn} I0.0\n= Q0.0" if mn.startswith("LD") else f"LD M0.1\n{mn} I0.0\n= Q0.0"
    p = _load(f"LD SM0.0\n{image_fix}", body, "LD I0.0\n= Q0.1")
    p.mem.areas["PI"][0] = bit
    p["M0.1"] = top
    p.scan()
    assert p["Q0.1"] == bit ^ 1          # the image really holds the opposite
    assert p["Q0.0"] == _contact(mn.replace("I", ""), bit, top)


def test_immediate_read_does_not_update_the_image() -> None:
    """LDI leaves the image alone: after the program overwrote I0.0 the image keeps that value."""
    p = _load("LD SM0.0\nR I0.0, 1", "LDI I0.0\n= Q0.0", "LD I0.0\n= Q0.1")
    p.mem.areas["PI"][0] = 1
    p.scan()
    assert (p["Q0.0"], p["Q0.1"], p.mem.areas["I"][0] & 1) == (1, 0, 0)


@pytest.mark.parametrize("area_addr,setter", [
    ("I0.3", "I0.3"), ("Q1.7", "Q1.7"), ("M31.0", "M31.0"), ("V100.5", "V100.5"),
    ("S2.2", "S2.2"), ("SM0.0", None), ("L0.4", "L0.4"),
])
def test_contacts_read_every_bit_area(area_addr: str, setter: str | None) -> None:
    """Contacts accept I, Q, M, V, S, SM and L bits."""
    p = _load(f"LD {area_addr}\n= Q0.0\nLDN {area_addr}\n= Q0.1")
    if setter is not None:
        p[setter] = 1
    p.scan()
    assert (p["Q0.0"], p["Q0.1"]) == (1, 0)


@pytest.mark.parametrize("operand,area,n", [("T37", "TB", 37), ("C5", "CB", 5)])
def test_contacts_read_timer_and_counter_bits(operand: str, area: str, n: int) -> None:
    """LD Tn / LD Cn read the timer/counter bit, not the current value."""
    p = _load(f"LD {operand}\n= Q0.0")
    p[operand] = 1234                  # current value only
    p.scan()
    assert p["Q0.0"] == 0
    p.mem.areas[area][n >> 3] |= 1 << (n & 7)
    p.scan()
    assert p["Q0.0"] == 1


@pytest.mark.parametrize("value", [0, 1])
def test_not_inverts_the_top(value: int) -> None:
    """NOT inverts the top of the stack."""
    p = _scan_with(_load("LD I0.0\nNOT\n= Q0.0\nNOT\n= Q0.1"), {"I0.0": value})
    assert (p["Q0.0"], p["Q0.1"]) == (value ^ 1, value)


# -- edges ----------------------------------------------------------------
EDGES = [
    # (inputs of I0.0 per scan, EU output per scan, ED output per scan)
    ([1, 1, 0, 0, 1, 0], [0, 0, 0, 0, 1, 0], [0, 0, 1, 0, 0, 1]),   # on at first scan: no edge
    ([0, 1, 1, 0, 1, 1], [0, 1, 0, 0, 1, 0], [0, 0, 0, 1, 0, 0]),   # off at first scan: no edge
    ([0, 0, 0], [0, 0, 0], [0, 0, 0]),
]


@pytest.mark.parametrize("seq,eu,ed", EDGES)
def test_eu_ed_detect_edges_of_the_top(seq: list[int], eu: list[int], ed: list[int]) -> None:
    """EU/ED give 1 for one scan on a 0->1 / 1->0 change, never at their first execution."""
    p = _load("LD I0.0\nEU\n= Q0.0", "LD I0.0\nED\n= Q0.1")
    got_u, got_d = [], []
    for v in seq:
        _scan_with(p, {"I0.0": v})
        got_u.append(p["Q0.0"])
        got_d.append(p["Q0.1"])
    assert (got_u, got_d) == (eu, ed)


def test_each_edge_instruction_has_its_own_memory() -> None:
    """Two EU on the same input: one skipped by JMP keeps its old state and fires later."""
    p = _load("LD I0.0\nEU\n= Q0.0", "LD I0.1\nJMP 1", "LD I0.0\nEU\n= Q0.1", "LBL 1")
    _scan_with(p, {"I0.0": 0})
    _scan_with(p, {"I0.1": 1, "I0.0": 1})        # second EU jumped over
    assert (p["Q0.0"], p["Q0.1"]) == (1, 0)
    _scan_with(p, {"I0.1": 0})                  # second EU runs: remembers 0
    assert (p["Q0.0"], p["Q0.1"]) == (0, 1)
    _scan_with(p, {})
    assert (p["Q0.0"], p["Q0.1"]) == (0, 0)


def test_edge_first_executed_late_gives_no_edge() -> None:
    """An EU whose first execution happens in a later scan with the input on does not fire."""
    p = _load("LD I0.1\nJMP 1", "LD I0.0\nEU\n= Q0.0", "LBL 1")
    _scan_with(p, {"I0.1": 1, "I0.0": 1})
    _scan_with(p, {"I0.1": 0})
    assert p["Q0.0"] == 0


# -- stack instructions -----------------------------------------------------
def _truth(p: plcrt.Plc, names: list[str], out: str, fn) -> None:
    for bits in itertools.product((0, 1), repeat=len(names)):
        _scan_with(p, dict(zip(names, bits)))
        assert p[out] == int(bool(fn(*bits))), bits


STACK_PROGRAMS = [
    ("ALD", "LD I0.0\nO I0.1\nLD I0.2\nO I0.3\nALD\n= Q0.0",
     lambda a, b, c, d: (a or b) and (c or d)),
    ("OLD", "LD I0.0\nA I0.1\nLD I0.2\nA I0.3\nOLD\n= Q0.0",
     lambda a, b, c, d: (a and b) or (c and d)),
    ("LPS/LRD/LPP", "LD I0.0\nLPS\nA I0.1\n= Q0.1\nLRD\nA I0.2\n= Q0.2\nLPP\nAN I0.3\n= Q0.0",
     lambda a, b, c, d: a and not d),
    ("LRD copies level 1", "LD I0.0\nLPS\nA I0.1\nLRD\n= Q0.0", lambda a, b, c, d: a),
    ("LDS 1", "LD I0.0\nLD I0.1\nLDS 1\n= Q0.0", lambda a, b, c, d: a),
    ("LDS 2", "LD I0.0\nLD I0.1\nLD I0.2\nLDS 2\nA I0.3\n= Q0.0", lambda a, b, c, d: a and d),
    ("LDS pushes", "LD I0.0\nLD I0.1\nLDS 1\nOLD\nALD\n= Q0.0",
     lambda a, b, c, d: a and (b or a)),
    ("nested ALD/OLD", "LD I0.0\nLD I0.1\nLD I0.2\nA I0.3\nOLD\nALD\n= Q0.0",
     lambda a, b, c, d: a and (b or (c and d))),
]


@pytest.mark.parametrize("label,body,fn", STACK_PROGRAMS, ids=[s[0] for s in STACK_PROGRAMS])
def test_stack_instructions_truth_tables(label: str, body: str, fn) -> None:
    """ALD/OLD/LPS/LRD/LPP/LDS give the manual's logic over all inputs."""
    _truth(_load(body), ["I0.0", "I0.1", "I0.2", "I0.3"], "Q0.0", fn)


def test_lps_branches_write_several_outputs() -> None:
    """LPS/LRD/LPP outputs: each branch sees the saved top."""
    p = _load("LD I0.0\nLPS\nA I0.1\n= Q0.1\nLRD\nA I0.2\n= Q0.2\nLPP\nA I0.3\n= Q0.3")
    for bits in itertools.product((0, 1), repeat=4):
        _scan_with(p, dict(zip(["I0.0", "I0.1", "I0.2", "I0.3"], bits)))
        a, b, c, d = bits
        assert (p["Q0.1"], p["Q0.2"], p["Q0.3"]) == (a & b, a & c, a & d)


def test_outputs_leave_the_stack_unchanged() -> None:
    """=, S and R read the top without popping, so several can follow one another."""
    p = _scan_with(_load("LD I0.0\n= Q0.0\n= M0.0\nS V0.0, 1\n= Q0.1"), {"I0.0": 1})
    assert (p["Q0.0"], p["M0.0"], p["V0.0"], p["Q0.1"]) == (1, 1, 1, 1)


@pytest.mark.parametrize("target", ["Q0.0", "M1.2", "V10.7", "S3.3", "L2.0", "I1.0"])
def test_assign_writes_bits_of_every_writable_area(target: str) -> None:
    """= writes the top to Q, M, V, S, L and even I (the image)."""
    p = _load(f"LD M0.0\n= {target}")
    _scan_with(p, {"M0.0": 1})
    assert p[target] == 1
    _scan_with(p, {"M0.0": 0})
    assert p[target] == 0


def test_stack_overflow_loses_the_bottom_level_with_a_warning() -> None:
    """A tenth push drops the bottom level (iv8 lost) and a warning is reported."""
    body = "LD I0.0\n" + "LD I0.1\n" * 9 + "OLD\n" * 8 + "= Q0.0"
    p = _load(body)
    warnings = [d for d in p.diagnostics if d.severity == "warning" and d.code == "stack-overflow"]
    assert len(warnings) == 1 and warnings[0].loc is not None and warnings[0].loc.line == 13
    _scan_with(p, {"I0.0": 1, "I0.1": 0})
    assert p["Q0.0"] == 0                   # the 1 at the bottom was lost
    _scan_with(p, {"I0.0": 0, "I0.1": 1})
    assert p["Q0.0"] == 1


def test_nine_levels_fit_without_warning() -> None:
    """Nine pushes fit the S7-200 stack exactly."""
    body = "LD I0.0\n" + "LD I0.1\n" * 8 + "OLD\n" * 8 + "= Q0.0"
    p = _load(body)
    assert not [d for d in p.diagnostics if d.code == "stack-overflow"]
    _scan_with(p, {"I0.0": 1, "I0.1": 0})
    assert p["Q0.0"] == 1


def test_network_starting_with_a_is_a_compile_error_with_location(tmp_path: Path) -> None:
    """A network that starts with A has no value to AND with: compile error at file:line:col."""
    src = tmp_path / "bad_start.awl"
    src.write_text("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\n    A I0.0\n= Q0.0\n"
                   "END_ORGANIZATION_BLOCK\n", encoding="utf-8")
    with pytest.raises(PlcCompileError) as exc:
        plcrt.load(src)
    assert f"{src}:4:5" in str(exc.value)
    assert "logic stack is empty" in str(exc.value)


@pytest.mark.parametrize("body,message", [
    ("LD I0.0\nALD\n= Q0.0", "needs 2 values"),
    ("LD I0.0\nLPP\n= Q0.0", "needs 2 values"),
    ("LD I0.0\nLRD\n= Q0.0", "needs 2 values"),
    ("LD I0.0\nLDS 9\n= Q0.0", "1..8"),
    ("NOT\n= Q0.0", "logic stack is empty"),
    ("= Q0.0", "logic stack is empty"),
    ("LD I0.0\n= SM0.0", "read-only"),
    ("LD I0.0\n= T37", "writable bit"),
    ("LD I0.0\nLDI M0.0\n= Q0.0", "input bit"),
    ("LD I0.0\n=I M0.0", "output bit"),
    ("LD I0.0\nS T37, 1", "S cannot set timers"),
])
def test_stack_and_operand_misuse_are_compile_errors(body: str, message: str) -> None:
    """Pops below the pushed values and wrong operand kinds are rejected at compile time."""
    with pytest.raises(PlcCompileError) as exc:
        _load(body)
    assert message in str(exc.value)


# -- AENO ---------------------------------------------------------------------
@pytest.mark.parametrize("body,preset,expected", [
    ("LD SM0.0\n+I VW0, VW2\nAENO\n= Q0.0", {"VW0": 1, "VW2": 5}, 1),
    ("LD SM0.0\n+I VW0, VW2\nAENO\n= Q0.0", {"VW0": 32767, "VW2": 5}, 0),   # overflow
    ("LD SM0.0\n/I VW0, VW2\nAENO\n= Q0.0", {"VW0": 0, "VW2": 5}, 0),       # divide by 0
    ("LD SM0.0\nMOVW VW0, VW2\nAENO\n= Q0.0", {"VW0": 1}, 1),               # cannot fail
    ("LD I0.0\n+I VW0, VW2\nAENO\n= Q0.0", {"VW0": 1}, 0),                  # box not enabled
])
def test_aeno_ands_the_previous_box_eno(body: str, preset: dict, expected: int) -> None:
    """AENO ANDs the ENO of the preceding box (0 after an overflow or divide by zero)."""
    p = _load(body)
    for a, v in preset.items():
        p[a] = v
    p.scan()
    assert p["Q0.0"] == expected


# -- outputs and ranges ---------------------------------------------------------
def test_immediate_assign_writes_image_and_terminal_at_once() -> None:
    """=I writes Q and the physical output PQ during the scan (seen before the end-of-scan copy)."""
    p = _load("LD I0.0\n=I Q0.3", "LD I0.0\n= Q0.4")
    probe = _PqProbe()
    p.devices.append(probe)
    _scan_with(p, {"I0.0": 1})
    assert probe.seen[-1][0] == 0b1000          # Q0.4 not yet on the terminal
    assert p.mem.areas["PQ"][0] == 0b11000      # both after the scan
    _scan_with(p, {"I0.0": 0})
    assert probe.seen[-1][0] == 0b10000


def _bits_after(op: str, start: str, n: int, preset: int) -> list[int]:
    """Run ``op start, n`` over V bytes 0..3 preset to ``preset``; return the bytes."""
    p = _load(f"LD I0.0\n{op} {start}, {n}")
    for i in range(4):
        p[f"VB{i}"] = preset
    _scan_with(p, {"I0.0": 1})
    return [p[f"VB{i}"] for i in range(4)]


RANGES = [
    ("S", "V0.0", 1, 0x00, [0x01, 0, 0, 0]),
    ("S", "V0.6", 4, 0x00, [0xC0, 0x03, 0, 0]),
    ("S", "V0.3", 13, 0x00, [0xF8, 0xFF, 0, 0]),
    ("S", "V0.7", 18, 0x00, [0x80, 0xFF, 0xFF, 0x01]),
    ("S", "V1.0", 8, 0x00, [0, 0xFF, 0, 0]),
    ("R", "V0.5", 5, 0xFF, [0x1F, 0xFC, 0xFF, 0xFF]),
    ("R", "V1.2", 3, 0xFF, [0xFF, 0xE3, 0xFF, 0xFF]),
    ("R", "V0.0", 32, 0xFF, [0, 0, 0, 0]),
]


@pytest.mark.parametrize("op,start,n,preset,expected", RANGES)
def test_set_reset_ranges_cross_byte_boundaries(op: str, start: str, n: int, preset: int,
                                                expected: list[int]) -> None:
    """S/R bit, n touch exactly n consecutive bits, across byte boundaries."""
    assert _bits_after(op, start, n, preset) == expected


def test_set_reset_do_nothing_when_the_top_is_0() -> None:
    """S/R only act when the top of the stack is 1."""
    p = _load("LD I0.0\nS V0.0, 8\nLD I0.1\nR V1.0, 8")
    p["VB1"] = 0xFF
    p.scan()
    assert (p["VB0"], p["VB1"]) == (0, 0xFF)


def test_si_ri_write_image_and_terminal_at_once() -> None:
    """SI/RI set and reset Q bits and their terminals immediately, across bytes."""
    p = _load("LD I0.0\nSI Q0.6, 4", "LD I0.1\nRI Q0.7, 2")
    probe = _PqProbe()
    p.devices.append(probe)
    _scan_with(p, {"I0.0": 1})
    assert probe.seen[-1] == bytes([0xC0, 0x03])
    assert (p["QB0"], p["QB1"]) == (0xC0, 0x03)
    _scan_with(p, {"I0.0": 0, "I0.1": 1})
    assert probe.seen[-1] == bytes([0x40, 0x02])


def test_range_past_the_area_end_is_a_compile_error() -> None:
    """S/R ranges may not run past the end of the memory area."""
    with pytest.raises(PlcCompileError, match="run past the end"):
        _load("LD I0.0\nS M31.4, 5")


def test_r_resets_a_range_of_timers_and_counters() -> None:
    """R T37, 2 resets T37 and T38 but not T39; R C1, 2 resets C1 and C2 but not C3."""
    p = _load("LD SM0.0\nTON T37, +1\nTON T38, +1\nTON T39, +1",
              "LD I0.0\nLD I0.2\nCTU C1, +1", "LD I0.0\nLD I0.2\nCTU C2, +1",
              "LD I0.0\nLD I0.2\nCTU C3, +1",
              "LD I0.1\nR T37, 2\nR C1, 2", scan_ms=100)
    _scan_with(p, {"I0.0": 1})
    p.scan(4)
    tb = p.mem.areas["TB"]
    assert [p["T37"], p["T38"], p["T39"]] == [4, 4, 4]
    assert [p["C1"], p["C2"], p["C3"]] == [1, 1, 1]
    _scan_with(p, {"I0.1": 1})
    assert [p["T37"], p["T38"], p["T39"]] == [0, 0, 5]
    assert (tb[4] >> 5 & 1, tb[4] >> 6 & 1, tb[4] >> 7 & 1) == (0, 0, 1)
    assert [p["C1"], p["C2"], p["C3"]] == [0, 0, 1]
    assert p.mem.areas["CB"][0] & 0b1110 == 0b1000


@pytest.mark.parametrize("n", [0, 1, 255])
def test_nop_accepts_0_to_255(n: int) -> None:
    """NOP N (N = 0..255) does nothing and leaves the stack alone."""
    p = _load(f"LD I0.0\nNOP {n}\n= Q0.0")
    _scan_with(p, {"I0.0": 1})
    assert p["Q0.0"] == 1
