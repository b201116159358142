"""Every network of the sample programs and of the shared real-file corpus
is drawn, as LAD or as the STL fallback, without an exception; and the
samples run with status drawn for every network."""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt
from plcrt.engine.runtime import parse_sources
from plcrt.view.ladder import to_ladder
from plcrt.view.render import ladder_text, render_program
from plcrt.view.status import PlcStatus

from stl_helpers import corpus_awl_params

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = (sorted((ROOT / "programs").glob("*.awl"))
           + sorted((ROOT / "programs" / "em253").glob("*.awl")))


def _draw_all(path: Path) -> tuple[int, int]:
    prog = parse_sources(path)
    lad = stl = 0
    for pou in prog.pous:
        for net in pou.networks:
            text = ladder_text(pou, net, program=prog)
            assert text.startswith(f"Network {net.number}")
            if to_ladder(net, program=prog).ok:
                lad += 1
                assert text.splitlines()[1][0] in "┃┠┣"  # the power rail
            else:
                stl += 1
                assert "not LAD-representable" in text
    assert len(render_program(prog, styled=False)) == len(prog.pous) + prog.network_count()
    return lad, stl


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.name)
def test_samples_draw_as_lad(path: Path) -> None:
    lad, stl = _draw_all(path)
    assert stl == 0 and lad > 0  # the samples are written the way Micro/WIN exports LAD


@pytest.mark.parametrize("path", corpus_awl_params())
def test_corpus_draws_without_exceptions(path: Path) -> None:
    lad, stl = _draw_all(path)
    assert lad + stl > 0


@pytest.mark.parametrize("path", [p for p in SAMPLES if p.parent.name == "programs"],
                         ids=lambda p: p.name)
def test_samples_draw_with_status(path: Path) -> None:
    plc = plcrt.load(path)
    plc.write("I0.0", 1)
    plc.scan(5)
    texts = render_program(plc.program, status=PlcStatus(plc), styled=False)
    assert any("━" in t.plain for t in texts)


def test_em253_sample_draws_with_status() -> None:
    em = ROOT / "programs" / "em253"
    plc = plcrt.load(em / "pos_goto_r.awl", plant=em / "plant.toml")
    plc.write("M2.0", 1)
    plc.run(seconds=1.0)
    text = "\n".join(t.plain for t in render_program(plc.program, status=PlcStatus(plc),
                                                   styled=False))
    assert "VW106=+1" in text          # C_Status: running
    assert "M2.0=1" in text            # a BOOL input pin shows its bit
    assert "Always" not in text


def test_network_selection() -> None:
    prog = parse_sources(ROOT / "programs" / "timers.awl")
    texts = render_program(prog, networks=[("OB1", 3)], styled=False)
    assert texts[1].plain.startswith("Network 3  Off-delay")
    assert len(texts) == 2
