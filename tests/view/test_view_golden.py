"""Golden drawings of the ladder view (``plcrt.view``), without and with
live status.

Each case is a small STL network; its plain-text drawing must equal
``tests/view/golden/<name>.txt``.  After a deliberate change of the
drawing, regenerate the files with ``PLCRT_UPDATE_GOLDEN=1 pytest
tests/view`` and review every changed file before committing it.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from stl_helpers import load_ob1, ob1_text

import plcrt
from plcrt.engine.runtime import parse_sources
from plcrt.view.ladder import to_ladder
from plcrt.view.render import ladder_text
from plcrt.view.status import PlcStatus

GOLDEN = Path(__file__).resolve().parent / "golden"
PROGRAMS = Path(__file__).resolve().parents[2] / "programs"
UPDATE = os.environ.get("PLCRT_UPDATE_GOLDEN") == "1"

SEAL_IN = "LD I0.0\nO Q0.0\nAN I0.1\n= Q0.0"

#: name -> one network of STL
CASES = {
    "seal_in": SEAL_IN,
    # (I0.0 + I0.1) * ((I0.2 * (I0.3 + I0.4)) + I0.5): parallel in series in parallel
    "nested_parallel": """LD I0.0
        O I0.1
        LD I0.2
        LD I0.3
        O I0.4
        ALD
        O I0.5
        ALD
        = Q0.0""",
    # the System Manual's logic stack example (LPS/LRD/LPP, three outputs)
    "lps_three_outputs": """LD I0.0
        LPS
        LD I0.5
        O I0.6
        ALD
        = Q7.0
        LRD
        LD I2.1
        O I1.3
        ALD
        = Q6.0
        LPP
        A I1.0
        = Q3.0""",
    "ton_with_contact": "LD I0.0\nAN I0.1\nTON T37, +20",
    "ctu_count_reset": "LD I0.2\nLD I0.3\nCTU C0, +5",
    "ctud_three_inputs": "LD I0.4\nLD I0.5\nA I0.7\nLD I0.6\nCTUD C1, +3",
    "compare_contacts": """LDW>= VW0, +10
        AR< VD4, 2.5
        OB= VB8, 16#FF
        AD<> VD10, VD14
        = Q0.1""",
    # without AENO the coil hangs off the same point as the box (a branch)
    "movw_then_coil": "LD I0.0\nMOVW +25, VW100\n= Q0.0",
    # with AENO the path goes on from the box's ENO
    "boxes_in_series_aeno": "LD I0.0\nMOVW +25, VW100\nAENO\n+I VW2, VW100\nAENO\n= Q0.1",
    "output_then_contacts": "LD I0.0\n= Q0.0\nA I0.1\nS Q0.1, 2",
    "edges_and_not": "LD I0.0\nEU\nNOT\nR M0.0, 1",
    "immediate": "LDI I0.0\nANI I0.1\n=I Q0.0",
    "jump_label": "LD I0.0\nJMP 3",
    "rail_label": "LBL 3",
    "not_lad_lds": "LD I0.0\nLD I0.1\nLDS 1\nALD\nOLD\n= Q0.0",
    "not_lad_two_rungs": "LD I0.0\n= Q0.0\nLD I0.1\n= Q0.1",
}


def check_golden(name: str, text: str) -> None:
    path = GOLDEN / f"{name}.txt"
    if UPDATE:
        path.write_text(text + "\n", encoding="utf-8")
        return
    assert path.is_file(), f"no golden file {path}; create it with PLCRT_UPDATE_GOLDEN=1"
    assert text + "\n" == path.read_text(encoding="utf-8"), (
        f"drawing differs from {path.name}:\n{text}")


def _one(stl: str) -> tuple[plcrt.Plc | None, object, object]:
    prog = parse_sources(ob1_text(stl))
    pou = prog.pous[0]
    return prog, pou, pou.networks[0]


@pytest.mark.parametrize("name", sorted(CASES))
def test_golden_drawing(name: str) -> None:
    prog, pou, net = _one(CASES[name])
    check_golden(name, ladder_text(pou, net, program=prog))


def test_not_lad_networks_fall_back_to_stl_with_a_reason() -> None:
    for name in ("not_lad_lds", "not_lad_two_rungs"):
        _, pou, net = _one(CASES[name])
        text = ladder_text(pou, net)
        assert "not LAD-representable" in text
        assert "┃" not in text  # no rail: the STL is shown instead
        assert "LD     I0.0" in text


def test_sample_subroutine_call_names_its_pins() -> None:
    prog = parse_sources(PROGRAMS / "subroutine.awl")
    pou = prog.pous[0]
    check_golden("call_subroutine", ladder_text(pou, pou.networks[0], program=prog))
    text = ladder_text(pou, pou.networks[0])  # without the program: unnamed pins
    assert "Raw" not in text and "AIW0" in text


def test_library_call_names_its_pins() -> None:
    prog = parse_sources(PROGRAMS / "em253" / "pos_goto_r.awl")
    pou = prog.pous[0]
    check_golden("call_library", ladder_text(pou, pou.networks[2], program=prog))


# ---------------------------------------------------------------------------
# Live status
# ---------------------------------------------------------------------------

def _status_text(plc: plcrt.Plc, index: int = 0) -> str:
    pou = plc.program.pous[0]
    return ladder_text(pou, pou.networks[index], PlcStatus(plc), program=plc.program)


def test_status_seal_in_latched() -> None:
    plc = load_ob1(SEAL_IN)
    plc.write("I0.0", 1)
    plc.scan(2)
    plc.write("I0.0", 0)   # start released: the seal holds Q0.0
    plc.scan(1)
    text = _status_text(plc)
    check_golden("status_seal_in_latched", text)
    rung, seal = text.splitlines()[2], text.splitlines()[4]
    assert "┤ ├" in rung            # I0.0 open, drawn light on its right
    assert "┫/┣" in rung            # I0.1 (NC, not pressed) closed
    assert rung.endswith("(█)")     # Q0.0 energized
    assert "┫█┣" in seal and seal.rstrip().endswith("┛")  # the seal carries the power


def test_status_seal_in_stop_pressed() -> None:
    plc = load_ob1(SEAL_IN)
    plc.write("I0.0", 1)
    plc.scan(2)
    plc.write("I0.1", 1)
    plc.scan(1)
    text = _status_text(plc)
    check_golden("status_seal_in_stop", text)
    rung = text.splitlines()[2]
    assert "┤/├" in rung and rung.endswith("─( )")  # stop open: no power after it
    assert rung.startswith("┣━━┳━━┫█┣━━┳")          # power up to the stop contact


def test_status_lps_branches() -> None:
    plc = load_ob1(CASES["lps_three_outputs"])
    for addr in ("I0.0", "I0.6", "I1.0"):
        plc.write(addr, 1)
    plc.scan(1)
    text = _status_text(plc)
    check_golden("status_lps_branches", text)
    lines = text.splitlines()
    assert lines[2].endswith("(█)")   # Q7.0 through I0.6
    assert lines[6].endswith("( )")   # Q6.0: neither I2.1 nor I1.3
    assert lines[-1].endswith("(█)")  # Q3.0 through I1.0


def test_status_timer_and_values() -> None:
    plc = load_ob1(CASES["ton_with_contact"], "LD T37\n= Q0.0")
    plc.write("I0.0", 1)
    plc.run(seconds=1.0)
    text = _status_text(plc)
    check_golden("status_ton", text)
    assert "T37=+9" in text and "┫/┣" in text


def test_status_counter() -> None:
    plc = load_ob1(CASES["ctu_count_reset"])
    for _ in range(3):
        plc.write("I0.2", 1)
        plc.scan(1)
        plc.write("I0.2", 0)
        plc.scan(1)
    plc.write("I0.2", 1)
    plc.scan(1)
    text = _status_text(plc)
    check_golden("status_ctu", text)
    assert "C0=+4" in text


def test_status_compare_and_move_values() -> None:
    plc = load_ob1(CASES["compare_contacts"], CASES["boxes_in_series_aeno"])
    plc.write("VW0", 12)
    plc.write("VD4", 1.5)
    plc.write("VW2", -5)
    plc.write("I0.0", 1)
    plc.scan(1)
    text = _status_text(plc) + "\n" + _status_text(plc, 1)
    check_golden("status_compare_move", text)
    assert "VW0=+12" in text and "VD4=+1.5" in text and "VB8=0" in text
    assert "VW100=+20" in text and "VW2=-5" in text
    assert "┫>=I┣" in text and "┤==B├" in text


def test_status_stl_fallback_shows_values() -> None:
    plc = load_ob1(CASES["not_lad_lds"])
    plc.write("I0.0", 1)
    plc.scan(1)
    text = _status_text(plc)
    check_golden("status_stl_fallback", text)
    assert "I0.0=1" in text and "Q0.0=1" in text


def test_status_locals_are_unknown() -> None:
    """A subroutine's #locals cannot be read after the scan: their contacts
    are drawn as without status, and so is the power behind them."""
    plc = plcrt.load(PROGRAMS / "subroutine.awl")
    plc.write("AIW0", 32000)
    plc.scan(1)
    sbr = plc.program.pous[1]
    text = ladder_text(sbr, sbr.networks[2], PlcStatus(plc), program=plc.program)
    check_golden("status_subroutine_locals", text)
    assert "#Value" in text and "#Value=" not in text and "#Limit=" not in text
    assert "━" in text and "┤>=I├" in text and "┄( )" in text  # ┄: power unknown


def test_shapes_of_the_model() -> None:
    lad = to_ladder(_one(CASES["lps_three_outputs"])[2])
    assert lad.ok and lad.rung is not None and len(lad.rung.outs) == 3


def test_plc_status_values() -> None:
    plc = load_ob1("LD I0.0\nTON T37, +20", "LD SM0.0\nMOVR 2.5, VD100\nMOVW -3, VW10")
    plc.write("I0.0", 1)
    plc.run(seconds=3.0)
    st = PlcStatus(plc)
    assert st.value("OB1", "T37") == 29             # word context: current value
    assert st.value("OB1", "T37", "BIT") == 1       # contact: the timer bit
    assert st.value("OB1", "I0.0", "BIT") == 1
    assert st.value("OB1", "VD100", "REAL") == 2.5
    assert st.value("OB1", "VW10") == -3
    assert st.value("OB1", "Always_On", "BIT") == 1  # a system symbol
    for text in ("+20", "16#FF", "#Start", "L0.0", "LW4", "*VD100", "&VB0", "X9.9", ""):
        assert st.value("SBR0", text) is None, text
