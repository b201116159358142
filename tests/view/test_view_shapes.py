"""Table tests of the ladder view's elements: every contact, modifier, coil
and box shape is drawn with Micro/WIN's picture, and the LAD rows of the
shape table (:mod:`plcrt.isa.shape`) agree with the instruction registry."""

from __future__ import annotations

import re

import pytest
from stl_helpers import ob1_text

from plcrt.engine.runtime import parse_sources
from plcrt.isa.registry import REGISTRY, load_families
from plcrt.isa.shape import shape
from plcrt.view.ladder import Box, Coil, Contact, to_ladder
from plcrt.view.render import ladder_text


def _draw(stl: str) -> str:
    prog = parse_sources(ob1_text(stl))
    pou = prog.pous[0]
    return ladder_text(pou, pou.networks[0], program=prog)


@pytest.mark.parametrize("stl, picture, labels", [
    ("LD I0.0", "─┤ ├─", ["I0.0"]),
    ("LDN I0.0", "─┤/├─", ["I0.0"]),
    ("LDI I0.0", "─┤I├─", ["I0.0"]),
    ("LDNI I0.0", "─┤/I├─", ["I0.0"]),
    ("LD I0.1\nA M0.0", "─┤ ├─", ["M0.0"]),
    ("LD I0.1\nAN M0.0", "─┤/├─", ["M0.0"]),
    ("LD I0.1\nAI I0.0", "─┤I├─", ["I0.0"]),
    ("LD I0.1\nO M0.0", "─┤ ├─", ["M0.0"]),
    ("LD I0.1\nONI I0.0", "─┤/I├─", ["I0.0"]),
    ("LDB= VB0, 5", "─┤==B├─", ["VB0", "5"]),
    ("LDW<> VW0, +5", "─┤<>I├─", ["VW0", "+5"]),
    ("LDD>= VD0, +5", "─┤>=D├─", ["VD0", "+5"]),
    ("LDR< VD0, 1.5", "─┤<R├─", ["VD0", "1.5"]),
    ("LD I0.1\nAW<= VW0, VW2", "─┤<=I├─", ["VW0", "VW2"]),
    ("LD I0.1\nOB> VB0, 16#10", "─┤>B├─", ["VB0", "16#10"]),
    ("LD I0.1\nEU", "─┤P├─", []),
    ("LD I0.1\nED", "─┤N├─", []),
    ("LD I0.1\nNOT", "─┤NOT├─", []),
])
def test_contacts(stl: str, picture: str, labels: list[str]) -> None:
    text = _draw(stl + "\n= Q0.0")
    assert picture in text
    for label in labels:
        assert label in text


@pytest.mark.parametrize("stl, picture, above, below", [
    ("= Q0.0", "─( )", "Q0.0", ""),
    ("=I Q0.0", "─(I)", "Q0.0", ""),
    ("S Q0.0, 3", "─(S)", "Q0.0", "3"),
    ("R M0.0, 8", "─(R)", "M0.0", "8"),
    ("SI Q0.0, 1", "─(SI)", "Q0.0", "1"),
    ("RI Q0.0, 2", "─(RI)", "Q0.0", "2"),
    ("JMP 4", "─(JMP)", "4", ""),
    ("SCRT S0.1", "─(SCRT)", "S0.1", ""),
    ("CRET", "─(RET)", "", ""),
    ("CSCRE", "─(SCRE)", "", ""),
    ("STOP", "─(STOP)", "", ""),
    ("WDR", "─(WDR)", "", ""),
    ("END", "─(END)", "", ""),
])
def test_coils(stl: str, picture: str, above: str, below: str) -> None:
    lines = _draw("LD I0.0\n" + stl).splitlines()
    wire = next(i for i, ln in enumerate(lines) if picture in ln)
    col = lines[wire].index(picture)
    if above:
        assert above in lines[wire - 1][col - 2:]
    if below:
        assert lines[wire + 1].strip("┃ ") == below


@pytest.mark.parametrize("stl, title, pins", [
    ("MOVB VB0, VB1", "MOV_B", ["VB0─┤IN", "OUT├─VB1"]),
    ("MOVW +25, VW100", "MOV_W", ["+25─┤IN", "OUT├─VW100"]),
    ("MOVD &VB0, VD4", "MOV_DW", ["&VB0─┤IN", "OUT├─VD4"]),
    ("MOVR 1.5, VD4", "MOV_R", ["1.5─┤IN", "OUT├─VD4"]),
    ("BMW VW0, VW10, 4", "BLKMOV_W", ["VW0─┤IN", "4─┤N", "OUT├─VW10"]),
    ("FILL +0, VW0, 8", "FILL_N", ["+0─┤IN", "8─┤N", "OUT├─VW0"]),
    # STL OUT := OUT op IN1 is LAD IN1 op IN2 with IN1 = OUT
    ("+I VW2, VW100", "ADD_I", ["VW100─┤IN1", "VW2─┤IN2", "OUT├─VW100"]),
    ("-D VD0, VD4", "SUB_DI", ["VD4─┤IN1", "VD0─┤IN2", "OUT├─VD4"]),
    ("/R VD0, VD4", "DIV_R", ["VD4─┤IN1", "VD0─┤IN2", "OUT├─VD4"]),
    ("INCW VW0", "INC_W", ["VW0─┤IN", "OUT├─VW0"]),
    ("INVB VB0", "INV_B", ["VB0─┤IN", "OUT├─VB0"]),
    ("ANDW VW0, VW2", "WAND_W", ["VW2─┤IN1", "VW0─┤IN2", "OUT├─VW2"]),
    ("SLW VW0, 3", "SHL_W", ["VW0─┤IN", "3─┤N", "OUT├─VW0"]),
    ("RRD VD0, 1", "ROR_DW", ["VD0─┤IN", "1─┤N", "OUT├─VD0"]),
    ("SHRB I0.1, V10.0, +8", "SHRB", ["I0.1─┤DATA", "V10.0─┤S_BIT", "+8─┤N"]),
    ("ITD VW0, VD2", "I_DI", ["VW0─┤IN", "OUT├─VD2"]),
    ("ROUND VD0, VD4", "ROUND", ["VD0─┤IN", "OUT├─VD4"]),
    ("SQRT VD0, VD4", "SQRT", ["VD0─┤IN", "OUT├─VD4"]),
    ("FOR VW0, +1, +8", "FOR", ["VW0─┤INDX", "+1─┤INIT", "+8─┤FINAL"]),
    ("TON T37, +20", "TON", ["┤IN", "+20─┤PT", "100 ms", "T37"]),
    ("TONR T1, +20", "TONR", ["┤IN", "+20─┤PT", "10 ms", "T1"]),
    ("TOF T32, +5", "TOF", ["┤IN", "+5─┤PT", "1 ms", "T32"]),
    ("PID VB300, 0", "PID", ["VB300─┤", "0─┤"]),   # not run by plcrt: unnamed pins
    # communications: the manual's pin names
    ("XMT VB100, 0", "XMT", ["VB100─┤TBL", "0─┤PORT"]),
    ("RCV VB200, 1", "RCV", ["VB200─┤TBL", "1─┤PORT"]),
    ("NETR VB300, 0", "NETR", ["VB300─┤TABLE", "0─┤PORT"]),
    ("NETW VB300, 0", "NETW", ["VB300─┤TABLE", "0─┤PORT"]),
    ("GET VB400", "GET", ["VB400─┤TABLE"]),
    ("PUT VB400", "PUT", ["VB400─┤TABLE"]),
])
def test_boxes(stl: str, title: str, pins: list[str]) -> None:
    text = _draw("LD I0.0\n" + stl)
    assert re.search(rf"│ *{re.escape(title)} *│", text), text
    for pin in pins:
        assert pin in text, (pin, text)
    has_eno = stl.split()[0] not in ("TON", "TONR", "TOF")
    assert ("ENO│" in text) == has_eno


@pytest.mark.parametrize("stl, names", [
    ("LD I0.0\nLD I0.1\nCTU C0, +5", ["CU", "R", "+5─┤PV"]),
    ("LD I0.0\nLD I0.1\nCTD C0, +5", ["CD", "LD", "+5─┤PV"]),
    ("LD I0.0\nLD I0.1\nLD I0.2\nCTUD C0, +5", ["CU", "CD", "R", "+5─┤PV"]),
])
def test_counter_inputs_are_rungs_from_the_rail(stl: str, names: list[str]) -> None:
    text = _draw(stl)
    rail_rungs = [ln for ln in text.splitlines() if ln.startswith("┠")]
    assert len(rail_rungs) == len(names) - 1
    for rung, name in zip(rail_rungs, names):
        assert f"┤{name}" in rung


@pytest.mark.parametrize("stl, picture", [
    ("LBL 3", "┤ LBL"), ("LSCR S0.0", "┤ SCR"), ("SCRE", "─(SCRE)"),
    ("NEXT", "─(NEXT)"), ("RET", "─(RET)"), ("MEND", "─(END)"),
])
def test_rail_elements(stl: str, picture: str) -> None:
    text = _draw(stl)
    assert picture in text and "┠" in text and "not LAD" not in text


@pytest.mark.parametrize("stl, reason", [
    ("LD I0.0\nLD I0.1\nLDS 1\nALD\nOLD\n= Q0.0", "LDS has no LAD form"),
    ("LD I0.0\n= Q0.0\nLD I0.1\n= Q0.1", "several rungs"),
    ("LD I0.0\n= Q0.0\nO I0.1\n= Q0.1", "after an output"),
    ("LD I0.0\nLPS\nA I0.1\n= Q0.0\nLPP\nLD I0.2\nOLD\n= Q0.1", "after an output"),
    ("LD I0.0\nLD I0.1\n= Q0.0", "without an output"),
    ("LD I0.0\nLPS\n= Q0.0", "not back to one level"),
    ("LD I0.0\nLPS\nA I0.1\nLPP\n= Q0.0", "branch without an output"),
    ("LD I0.0\nAENO\n= Q0.0", "AENO"),
    ("LD I0.0\nJMP 1\nLBL 1", "LBL together with rung logic"),
    ("LD I0.0\nLD I0.1\nCTU C0, 5\n= Q0.0", "after a counter"),
    ("ALD", "without a value"),
])
def test_not_lad_reasons(stl: str, reason: str) -> None:
    prog = parse_sources(ob1_text(stl))
    lad = to_ladder(prog.pous[0].networks[0])
    assert not lad.ok and reason in lad.reason


def test_model_of_a_branch_after_an_output() -> None:
    prog = parse_sources(ob1_text("LD I0.0\n= Q0.0\nA I0.1\nMOVW +1, VW0\nAENO\n= Q0.1"))
    lad = to_ladder(prog.pous[0].networks[0])
    assert lad.ok
    root = lad.rung
    assert isinstance(root.logic, Contact) and isinstance(root.outs[0], Coil)
    branch = root.outs[1]
    box = branch.outs[0]
    assert isinstance(branch.logic, Contact) and branch.logic.above == "I0.1"
    assert isinstance(box, Box) and box.title == "MOV_W"
    assert isinstance(box.next.outs[0], Coil) and box.next.outs[0].above == "Q0.1"


# ---------------------------------------------------------------------------
# The shape table against the registry
# ---------------------------------------------------------------------------

def _registry() -> dict:
    load_families()
    return REGISTRY


def test_shape_kinds_unchanged_for_existing_users() -> None:
    """The LAD fields were added to the table without changing what the
    coverage probes rely on: kind and the number of power inputs."""
    expect = {"LD": ("contact", 0), "AN": ("contact", 0), "OW>=": ("contact", 0),
              "NOT": ("modifier", 1), "ALD": ("stack", 0), "AENO": ("stack", 0),
              "=": ("coil", 1), "JMP": ("coil", 1), "LBL": ("rail", 0),
              "MOVW": ("box", 1), "CTU": ("box", 2), "CTUD": ("box", 3), "XYZ": ("box", 1)}
    for m, (kind, inputs) in expect.items():
        assert (shape(m).kind, shape(m).inputs) == (kind, inputs), m


@pytest.mark.parametrize("mnemonic", sorted(m for m, s in _registry().items()
                                            if not s.variadic))
def test_pins_cover_every_operand(mnemonic: str) -> None:
    """Each operand of an instruction appears exactly in the LAD picture."""
    spec = _registry()[mnemonic]
    shp = shape(mnemonic)
    if shp.kind == "stack":
        return
    assert shp.lad, mnemonic
    used = {int(re.search(r"(\d+)r?$", item).group(1))
            for item in shp.pins.split() if not item.startswith("~")}
    assert used == set(range(len(spec.roles))), (mnemonic, shp.pins, spec.roles)
    real = {int(re.search(r"(\d+)r$", item).group(1))
            for item in shp.pins.split() if item.endswith("r")}
    for i in real:  # a REAL marker only on operands that can hold a real
        assert spec.roles[i].name in ("R_R", "R_W", "D_R", "D_W"), (mnemonic, i)
