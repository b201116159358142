"""Round trip of every network of the samples and of the corpus: parsed,
read as the editable ladder model, written as STL, parsed again.

The comparison is the IR of the network: the same instructions (mnemonic
and operand texts, in order) with the same title and comment; only the
source locations differ.  The text is compared too: each instruction line
as written in the file and as the model writes it are the same up to
blanks, and the count of networks whose lines are identical character for
character (Micro/WIN's export layout, ``LD     I0.0``; indentation aside)
is printed.  A network without a ladder form must say why,
and the counts per source are printed (``pytest -s`` or ``-rP``) as
docs/ladder-view.md lists them.  Random networks (hypothesis) are a ladder
that writes them back exactly, or stay STL with a reason."""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plcrt.engine.runtime import parse_sources
from plcrt.lang import ir
from plcrt.lang.stl import parse_program
from plcrt.view.ladder import to_ladder
from plcrt.view.ladder_edit import check_model
from plcrt.view.ladder_model import model_from_json, model_to_json
from plcrt.view.ladder_stl import NoLadder, model_to_stl, network_text, network_to_model

from stl_helpers import corpus_awl_params

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = sorted(p for d in ("programs", "examples", "library") for p in (ROOT / d).rglob("*.awl"))


def _ir(net: ir.Network) -> tuple:
    return (net.title, net.comment,
            tuple((i.mnemonic, tuple(o.text for o in i.operands)) for i in net.insns))


def _blanks(line: str) -> str:
    return re.sub(r"\s*,\s*", ", ", " ".join(line.split()))


def _round_trip(path: Path) -> tuple[int, Counter]:
    prog = parse_sources(path)
    source = prog.source.splitlines()
    ok, same, reasons = 0, 0, Counter()
    for pou in prog.pous:
        for net in pou.networks:
            model = network_to_model(net)
            if isinstance(model, NoLadder):
                assert model.reason, f"{pou.ident}/{net.number}: a refusal without a reason"
                if to_ladder(net).ok:
                    # drawn by the viewer, but written otherwise by the LAD editor
                    assert "instruction" in model.reason
                reasons[model.reason] += 1
                continue
            ok += 1
            text = network_text(model, net.number)
            wrap = f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n{text}END_ORGANIZATION_BLOCK\n"
            back = parse_program(wrap).pous[0].networks
            assert len(back) == 1 and _ir(back[0]) == _ir(net), f"{pou.ident}/{net.number}"
            assert network_to_model(back[0]) == model
            assert model_from_json(model_to_json(model)) == model
            written = [line.strip() for line in model_to_stl(model).splitlines()]
            original = [source[i.loc.line - 1].strip() for i in net.insns]
            assert [_blanks(x) for x in written] == [_blanks(x) for x in original]
            same += written == original
    print(f"\n{path.name}: {ok} network(s) as ladder ({same} with the same text), "
          f"{sum(reasons.values())} stay STL")
    for why, n in reasons.most_common():
        print(f"  {n} x {why}")
    return ok, reasons


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: str(p.relative_to(ROOT)))
def test_samples_round_trip(path: Path) -> None:
    ok, _ = _round_trip(path)
    assert ok > 0


@pytest.mark.parametrize("path", corpus_awl_params())
def test_corpus_round_trip(path: Path) -> None:
    ok, reasons = _round_trip(path)
    assert ok + sum(reasons.values()) > 0


LOADS = ["LD     I0.0", "LDN    M0.0", "LDW>=  VW0, +10", "LDI    I0.4"]
ANDS = ["A      I0.1", "AN     M0.1", "AW<>   VW2, VW4", "EU", "ED", "NOT"]
ORS = ["O      I0.2", "ON     Q0.3", "OB=    VB6, 3"]
OUTS = ["=      Q0.0", "S      Q0.1, 1", "R      M1.0, 2", "MOVW   +5, VW10",
        "TON    T37, +100", "INCW   VW20", "CALL   SBR0, VW0", "=I     Q0.5"]


@st.composite
def _stl_network(draw) -> list[str]:
    """A network the logic stack can run (loads before uses, LPS before
    LRD/LPP), not necessarily one with a ladder form: LDS, a second rung,
    an OR after an output, a JMP/LBL mix, a counter box ... may come."""
    lines, depth, kept = [draw(st.sampled_from(LOADS))], 1, 0
    for _ in range(draw(st.integers(0, 12))):
        choices = ["load", "and", "or", "out", "out"]
        choices += ["ald", "old", "ctu"] * (depth >= 2) + ["lps"] * (depth < 8)
        choices += ["lrd", "lpp"] * (kept > 0)
        choices += ["aeno", "lds", "rail"] * (draw(st.integers(0, 5)) == 0)   # now and then
        kind = draw(st.sampled_from(choices))
        if kind == "load":
            lines.append(draw(st.sampled_from(LOADS)))
            depth += 1
        elif kind in ("and", "or", "out"):
            lines.append(draw(st.sampled_from({"and": ANDS, "or": ORS, "out": OUTS}[kind])))
        elif kind in ("ald", "old"):
            lines.append(kind.upper())
            depth -= 1
        elif kind == "ctu":
            lines.append("CTU    C0, +5")
            depth -= 1
        elif kind == "lps":
            lines.append("LPS")
            depth, kept = depth + 1, kept + 1
        elif kind == "lrd":
            lines.append("LRD")
        elif kind == "lpp":
            lines.append("LPP")
            depth, kept = depth - 1, kept - 1
        elif kind == "aeno":
            lines.append("AENO")
        elif kind == "lds":
            lines.append("LDS    1")
            depth += 1
        else:
            lines.append(draw(st.sampled_from(["LBL    1", "JMP    1", "NEXT"])))
    while kept:
        lines += ["LPP", "=      Q0.7"]
        kept -= 1
    return lines + ["=      Q1.0"]


@settings(max_examples=300, deadline=None)
@given(_stl_network())
def test_any_network_is_a_ladder_that_writes_it_back_or_stays_stl(lines: list[str]) -> None:
    stl = "".join(line + "\n" for line in lines)
    text = f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\n{stl}END_ORGANIZATION_BLOCK\n"
    net = parse_program(text).pous[0].networks[0]
    got = network_to_model(net)
    if isinstance(got, NoLadder):
        assert got.reason
    else:
        assert model_to_stl(got) == stl
        assert check_model(got) == got      # and an editable model: checks and round trip
