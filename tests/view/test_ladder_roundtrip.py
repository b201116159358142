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
docs/ladder-view.md lists them."""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import pytest

from plcrt.engine.runtime import parse_sources
from plcrt.lang import ir
from plcrt.lang.stl import parse_program
from plcrt.view.ladder import to_ladder
from plcrt.view.ladder_model import model_from_json, model_to_json
from plcrt.view.ladder_stl import NoLadder, model_to_stl, network_text, network_to_model

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = sorted(p for d in ("programs", "examples", "library") for p in (ROOT / d).rglob("*.awl"))
CORPUS = ROOT.parent / "shared" / "corpus"


def _corpus_files() -> list:
    files = sorted(CORPUS.glob("*.awl")) if CORPUS.is_dir() else []
    if not files:
        return [pytest.param(None, marks=pytest.mark.skip(reason=f"corpus not found at {CORPUS}"))]
    return [pytest.param(f, id=f.name) for f in files]


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


@pytest.mark.parametrize("path", _corpus_files())
def test_corpus_round_trip(path: Path) -> None:
    ok, reasons = _round_trip(path)
    assert ok + sum(reasons.values()) > 0
