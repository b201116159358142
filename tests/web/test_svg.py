"""Rungs as SVG: the shapes drawn from the view model, the numbering that
frames use, and escaping of program text."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import pytest

import plcrt
from plcrt.view.status import PlcStatus
from plcrt.web.svg import esc, network_state, network_svg

from .conftest import PROGRAM

NS = "{http://www.w3.org/2000/svg}"


def nets(text: str = PROGRAM, symbols: str | None = None):
    plc = plcrt.load(text, symbols=symbols)
    pou = plc.program.pous[0]
    return plc, pou


def test_seal_in_rung_has_three_contacts_a_parallel_branch_and_a_coil() -> None:
    plc, pou = nets()
    svg = network_svg(pou, pou.networks[0], program=plc.program)
    root = ET.fromstring(svg)
    assert root.tag == NS + "svg"
    paths = root.findall(f".//{NS}path")
    assert len([p for p in paths if p.get("class") == "ct"]) == 3      # I0.0, Q0.0, I0.1
    assert len([p for p in paths if p.get("class") == "co"]) == 1      # the coil
    assert len([p for p in paths if p.get("class") == "nc"]) == 1      # AN I0.1 is NC
    ops = [t.get("data-op") for t in root.iter(NS + "text") if t.get("data-op")]
    assert ops == ["I0.0", "Q0.0", "I0.1", "Q0.0"]


def test_box_shows_title_pins_and_value_slots() -> None:
    plc, pou = nets()
    root = ET.fromstring(network_svg(pou, pou.networks[1], program=plc.program))
    texts = ["".join(t.itertext()) for t in root.iter(NS + "text")]
    assert "TON" in texts and "IN" in texts and "PT" in texts and "100 ms" in texts
    assert len(root.findall(f".//*[@data-v]")) == 2      # T37 above, PT beside


def test_state_numbers_match_the_drawing() -> None:
    plc, pou = nets()
    plc.write("I0.0", 1)
    plc.scan()
    for n in pou.networks:
        svg = network_svg(pou, n, program=plc.program)
        st = network_state(pou, n, PlcStatus(plc), program=plc.program)
        ks = {int(k) for k in re.findall(r'data-k="(\d+)"', svg)}
        vs = {int(k) for k in re.findall(r'data-v="(\d+)"', svg)}
        assert ks == set(range(len(st.power))) or ks <= set(range(len(st.power)))
        assert max(ks) == len(st.power) - 1
        assert all(v < len(st.values) for v in vs)
    first = network_state(pou, pou.networks[0], PlcStatus(plc), program=plc.program)
    assert first.power[0] == "1" and first.power[-1] == "1"    # rail and coil powered
    timer = network_state(pou, pou.networks[1], PlcStatus(plc), program=plc.program)
    assert timer.values == ["", "+0", ""]    # T37 counts; a contact and a constant have none


def test_without_status_everything_is_unknown() -> None:
    plc, pou = nets()
    st = network_state(pou, pou.networks[0], None, program=plc.program)
    assert set(st.power) == {"?"}


def test_a_network_without_lad_has_no_svg_but_a_state_per_operand() -> None:
    text = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\nLPS\nA I0.1\n"
            "= Q0.0\nEND_ORGANIZATION_BLOCK\n")
    plc, pou = nets(text)
    assert network_svg(pou, pou.networks[0], program=plc.program) is None
    st = network_state(pou, pou.networks[0], PlcStatus(plc), program=plc.program)
    assert st.values == ["0", "0", "0"]


@pytest.mark.parametrize("text", ['<script>alert(1)</script>', '"><img src=x onerror=alert(1)>',
                                  "a'b&c", "\x1b[2J\u202e"])
def test_esc_leaves_no_markup_and_no_control_characters(text: str) -> None:
    out = esc(text)
    assert "<" not in out and ">" not in out and '"' not in out and "'" not in out
    assert "\x1b" not in out and "\u202e" not in out
    ET.fromstring(f'<t a="{out}">{out}</t>')      # well-formed as attribute and text


def test_hostile_symbols_and_comments_stay_text_in_the_svg() -> None:
    from plcrt.web.present import symbol_names
    symbols = 'Evil\tI0.0\t"><svg onload=alert(1)><script>x()</script>\n'
    text = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD Evil\n"
            "= Q0.0\nEND_ORGANIZATION_BLOCK\n")
    plc, pou = nets(text, symbols)
    svg = network_svg(pou, pou.networks[0], program=plc.program,
                      names=symbol_names(plc.symbols))
    root = ET.fromstring(svg)
    tags = {e.tag.removeprefix(NS) for e in root.iter()}
    assert tags <= {"svg", "g", "line", "path", "rect", "text", "title"}
    assert all(not a.startswith("on") for e in root.iter() for a in e.attrib)
    tips = ["".join(t.itertext()) for t in root.iter(NS + "title")]
    assert any("<script>x()</script>" in t for t in tips)      # shown as text


def _texts(root: ET.Element) -> dict[str, ET.Element]:
    return {"".join(t.itertext()): t for t in root.iter(NS + "text")}


def test_a_compare_contact_writes_its_operator_between_its_bars() -> None:
    """``>=I`` sits between the two bars on the wire, the operands and their
    values above and below, one text line apart (it was drawn on the second
    operand)."""
    text = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLDW>= VW0, VW2\n"
            "= Q0.0\nEND_ORGANIZATION_BLOCK\n")
    plc, pou = nets(text)
    root = ET.fromstring(network_svg(pou, pou.networks[0], program=plc.program))
    group = next(g for g in root.iter(NS + "g")
                 if any("".join(t.itertext()) == ">=I" for t in g.findall(NS + "text")))
    bars = [float(v) for v in re.findall(r"M([\d.]+),", group.find(NS + "path").get("d"))]
    top = float(re.search(r",([\d.]+)v22", group.find(NS + "path").get("d")).group(1))
    texts = _texts(group)
    op = texts[">=I"]
    assert bars[0] < float(op.get("x")) < bars[1]
    assert top < float(op.get("y")) < top + 22          # on the wire, inside the bars
    assert (bars[1] - bars[0]) > 3 * 6.0                 # wide enough for 3 characters
    ys = sorted([float(t.get("y")) for t in group.findall(NS + "text")])
    assert all(b - a >= 12 for a, b in zip(ys, ys[1:])), ys   # VW0, value, >=I, VW2, value


def test_letters_of_coils_and_compares_are_coloured_with_their_fill() -> None:
    """The letters of R, S and SCRE coils and a compare's operator carry the
    number of the fill they sit on, so the page can turn them white when it
    is filled."""
    text = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLDB= VB0, VB1\nS Q0.0, 1\n"
            "Network 2\nLD I0.0\nR Q0.1, 1\nNetwork 3\nLSCR S0.0\nNetwork 4\nSCRE\n"
            "END_ORGANIZATION_BLOCK\n")
    plc, pou = nets(text)
    seen = set()
    for n in pou.networks:
        root = ET.fromstring(network_svg(pou, n, program=plc.program))
        for g in root.iter(NS + "g"):
            fills = {r.get("data-k") for r in g.findall(NS + "rect") if r.get("class") == "cf"}
            for t in g.findall(NS + "text"):
                if t.get("class") == "in":
                    seen.add("".join(t.itertext()))
                    assert t.get("data-k") in fills, "".join(t.itertext())
    assert {"==B", "S", "R", "SCRE"} <= seen
