"""Each kind of ladder element read from STL, written back, and kept by the
JSON form: one row per element kind (contacts, compares, modifiers, coils,
boxes, branches), each checked to be a program ``plcrt check`` accepts."""

from __future__ import annotations

import pytest

import plcrt
from plcrt.lang.stl import parse_program
from plcrt.view.ladder_edit import check_model
from plcrt.view.ladder_model import (Box, Coil, Contact, Model, Node, Parallel, Series,
                                     model_from_json, model_to_json)
from plcrt.view.ladder_stl import NoLadder, model_to_stl, network_to_model

SBR = """SUBROUTINE_BLOCK SCALE:SBR0
TITLE=scale
VAR_INPUT
IN:INT;
END_VAR
VAR_OUTPUT
OUT:INT;
END_VAR
BEGIN
Network 1
LD     SM0.0
MOVW   #IN, #OUT
END_SUBROUTINE_BLOCK
"""


def _network(stl: str):
    text = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\n" + stl + "END_ORGANIZATION_BLOCK\n"
    return parse_program(text).pous[0].networks[0], text


def _first(model: Model):
    """The first element of the rung: its first contact and its first output."""
    rung = model.rung
    if isinstance(rung, Box):
        return rung.inputs[0], rung
    logic = rung.logic
    while isinstance(logic, (Series, Parallel)):
        logic = logic.items[-1] if isinstance(logic, Series) else logic.items[0]
    return logic, rung.outs[0]


CASES = [
    # STL, what the last contact is, what the first output is
    ("LD     I0.0\n=      Q0.0\n", Contact("NO", ("I0.0",)), Coil("=", ("Q0.0",))),
    ("LDN    I0.0\nS      Q0.0, 1\n", Contact("NC", ("I0.0",)), Coil("S", ("Q0.0", "1"))),
    ("LDI    I0.0\n=I     Q0.0\n", Contact("NOI", ("I0.0",)), Coil("=I", ("Q0.0",))),
    ("LDNI   I0.0\nR      Q0.0, 2\n", Contact("NCI", ("I0.0",)), Coil("R", ("Q0.0", "2"))),
    ("LD     I0.0\nEU\nSI     Q0.0, 1\n", Contact("P"), Coil("SI", ("Q0.0", "1"))),
    ("LD     I0.0\nED\nRI     Q0.0, 1\n", Contact("N"), Coil("RI", ("Q0.0", "1"))),
    ("LD     I0.0\nNOT\n=      M0.0\n", Contact("NOT"), Coil("=", ("M0.0",))),
    ("LDW>=  VW0, +10\n=      Q0.0\n", Contact("CMP", ("VW0", "+10"), "W>="), None),
    ("LDB=   VB0, 5\n=      Q0.0\n", Contact("CMP", ("VB0", "5"), "B="), None),
    ("LD     I0.0\nAD<    VD0, +100000\n=      Q0.0\n",
     Contact("CMP", ("VD0", "+100000"), "D<"), None),
    ("LD     I0.0\nAR>    VD4, 1.5\n=      Q0.0\n", Contact("CMP", ("VD4", "1.5"), "R>"), None),
    ("LDW<>  VW0, VW2\nOW=    VW0, +3\n=      Q0.0\n",
     Contact("CMP", ("VW0", "VW2"), "W<>"), None),
    ("LD     I0.0\nTON    T37, +100\n", None, Box("TON", ("T37", "+100"))),
    ("LD     I0.0\nTOF    T33, +5\n", None, Box("TOF", ("T33", "+5"))),
    ("LD     I0.0\nTONR   T1, VW10\n", None, Box("TONR", ("T1", "VW10"))),
    ("LD     I0.0\nLD     I0.1\nCTU    C0, +10\n", Contact("NO", ("I0.0",)), None),
    ("LD     I0.0\nLD     I0.1\nCTD    C1, +10\n", Contact("NO", ("I0.0",)), None),
    ("LD     I0.0\nLD     I0.1\nLD     I0.2\nCTUD   C2, +10\n", Contact("NO", ("I0.0",)), None),
    ("LD     I0.0\nMOVB   16#FF, VB0\n", None, Box("MOVB", ("16#FF", "VB0"))),
    ("LD     I0.0\nMOVW   +5, VW0\n", None, Box("MOVW", ("+5", "VW0"))),
    ("LD     I0.0\nMOVD   &VB100, VD0\n", None, Box("MOVD", ("&VB100", "VD0"))),
    ("LD     I0.0\nMOVR   1.0, VD0\n", None, Box("MOVR", ("1.0", "VD0"))),
    ("LD     I0.0\n+I     +1, VW0\n", None, Box("+I", ("+1", "VW0"))),
    ("LD     I0.0\n-D     VD4, VD0\n", None, Box("-D", ("VD4", "VD0"))),
    ("LD     I0.0\n*R     VD4, VD0\n", None, Box("*R", ("VD4", "VD0"))),
    ("LD     I0.0\n/I     +2, VW0\n", None, Box("/I", ("+2", "VW0"))),
    ("LD     I0.0\nMUL    VW4, VD8\n", None, Box("MUL", ("VW4", "VD8"))),
    ("LD     I0.0\nINCW   VW0\n", None, Box("INCW", ("VW0",))),
    ("LD     I0.0\nDECD   VD0\n", None, Box("DECD", ("VD0",))),
    ("LD     I0.0\nCALL   SBR0, VW0, VW2\n", None, Box("CALL", ("SBR0", "VW0", "VW2"))),
    ("LD     I0.0\nMOVW   +5, VW0\nAENO\n=      Q0.0\n", None,
     Box("MOVW", ("+5", "VW0"), Node(None, (Coil("=", ("Q0.0",)),)))),
]


@pytest.mark.parametrize("stl,contact,out", CASES, ids=[c[0].split("\n")[-2] for c in CASES])
def test_element_kind(stl: str, contact, out) -> None:
    net, text = _network(stl)
    model = network_to_model(net)
    assert isinstance(model, Model), model
    first, first_out = _first(model)
    if contact is not None:
        assert first == contact
    if out is not None:
        assert first_out == out
    assert model_to_stl(model) == stl                        # the export's own layout
    assert model_from_json(model_to_json(model)) == model
    assert check_model(model) == model                       # operands and round trip
    plcrt.load(text + SBR, library=True, backend="python")   # plcrt check accepts it


BRANCHES = [
    # parallel contacts, a parallel block in series, a branch of a series
    "LD     I0.0\nO      I0.1\nA      I0.2\n=      Q0.0\n",
    "LD     I0.0\nLD     I0.1\nO      I0.2\nALD\n=      Q0.0\n",
    "LD     I0.0\nA      I0.1\nLD     I0.2\nA      I0.3\nOLD\n=      Q0.0\n",
    # a split: coils on the point, branches with LPS / LRD / LPP
    "LD     I0.0\n=      Q0.0\nA      I0.1\n=      Q0.1\n",
    "LD     I0.0\nLPS\nA      I0.1\n=      Q0.1\nLRD\nA      I0.2\n=      Q0.2\n"
    "LPP\nA      I0.3\n=      Q0.3\n",
    "LD     I0.0\nLPS\nA      I0.1\n=      Q0.1\nLPP\n=      Q0.2\n",
    "LD     I0.0\nLPS\nMOVW   +1, VW0\nAENO\n=      Q0.0\nLPP\n=      Q0.1\n",
]


@pytest.mark.parametrize("stl", BRANCHES)
def test_branches(stl: str) -> None:
    net, text = _network(stl)
    model = network_to_model(net)
    assert isinstance(model, Model), model
    assert model_to_stl(model) == stl
    plcrt.load(text, library=True, backend="python")


NO_LADDER = [
    ("LD     I0.0\nLDS    1\n=      Q0.0\n", "LDS"),
    ("LD     I0.0\n=      Q0.0\nLD     I0.1\n=      Q0.1\n", "several rungs"),
    ("LD     I0.0\nJMP    1\nLBL    1\n", "together with rung logic"),
    ("LD     I0.0\nA      I0.1\n", "without an output"),
    ("LD     I0.0\nLD     I0.1\nALD\n=      Q0.0\n", "instruction 2"),   # Micro/WIN writes A
    ("LD     I0.0\n=      Q0.0  // lamp\n", "comment"),
]


@pytest.mark.parametrize("stl,why", NO_LADDER)
def test_networks_without_ladder_form_say_why(stl: str, why: str) -> None:
    net, _ = _network(stl)
    got = network_to_model(net)
    assert isinstance(got, NoLadder)
    assert why in got.reason


def test_rail_elements_and_empty_network() -> None:
    net, _ = _network("LBL    3\n")
    model = network_to_model(net)
    assert isinstance(model, Model) and model.rail == (Coil("LBL", ("3",)),)
    assert model_to_stl(model) == "LBL    3\n"
    empty, _ = _network("")
    assert network_to_model(empty) == Model()


def test_pins_place_every_operand_of_every_coil_and_box() -> None:
    from plcrt.isa.registry import REGISTRY, load_families
    from plcrt.isa.shape import shape
    from plcrt.view.ladder_model import pins
    load_families()
    described = 0
    for mnemonic, spec in REGISTRY.items():
        if (shape(mnemonic).kind not in ("coil", "box") or not shape(mnemonic).pins
                or spec.variadic):   # variadic ones (ATCH, CALL ...) check their own count
            continue
        described += 1
        shown = [p["op"] for p in pins(mnemonic) if "op" in p]
        # each operand once, except the in-out operand of STL's two-operand
        # arithmetic, which is both IN1 and OUT of the LAD box
        assert set(shown) == set(range(len(spec.roles))), mnemonic
    assert described > 100
    ton = model_to_json(network_to_model(_network("LD     I0.0\nTON    T37, +10\n")[0]))
    assert ton["rung"]["outs"][0]["pins"][1] == {"power": "IN"}


def test_a_coil_line_between_branches_is_written_with_the_fewest_stack_instructions() -> None:
    # the manual and the corpus do not show this form (docs/decisions.md)
    head = "LD     I0.0\nLPS\nA      I0.1\n=      Q0.1\n"
    fewest = head + "LPP\n=      Q0.2\nA      I0.3\n=      Q0.3\n"
    other = head + "LRD\n=      Q0.2\nLPP\nA      I0.3\n=      Q0.3\n"
    model = network_to_model(_network(fewest)[0])
    assert isinstance(model, Model) and model_to_stl(model) == fewest
    got = network_to_model(_network(other)[0])
    assert isinstance(got, NoLadder) and got.reason.startswith("instruction 5 (LRD)")
