"""A drawn network saved into its program: the network's lines are
replaced, the rest of the file is kept byte for byte, and the program is
checked as ``plcrt check`` checks it (what only the whole program can tell,
such as a call of a missing subroutine, is refused there)."""

from __future__ import annotations

from pathlib import Path

import pytest

from plcrt.errors import PlcError
from plcrt.lang.stl import parse_program
from plcrt.view.ladder_check import check_in_program, replace_network
from plcrt.view.ladder_edit import apply_edit
from plcrt.view.ladder_stl import network_to_model

ROOT = Path(__file__).resolve().parents[2]
SEAL = (ROOT / "programs" / "seal_in.awl").read_text(encoding="utf-8")


def _model(text: str, index: int):
    m = network_to_model(parse_program(text).pous[0].networks[index])
    assert not hasattr(m, "reason")
    return m


@pytest.mark.parametrize("index", [0, 1])
def test_saving_a_network_keeps_the_rest_of_the_file(index: int) -> None:
    model = apply_edit(_model(SEAL, index), {"op": "insert", "at": ["rung", "logic"],
                                            "side": "after",
                                            "element": {"el": "NC", "ops": ["I0.7"]}})
    new = check_in_program(SEAL, "OB1", index + 1, model)
    old_nets = parse_program(SEAL).pous[0].networks
    new_nets = parse_program(new).pous[0].networks
    assert [n.insns[-2].mnemonic + n.insns[-2].operands[0].text
            for n in new_nets][index] == "ANI0.7"
    other = 1 - index
    assert ([(i.mnemonic, [o.text for o in i.operands]) for i in new_nets[other].insns]
            == [(i.mnemonic, [o.text for o in i.operands]) for i in old_nets[other].insns])
    assert new.startswith(SEAL.split("Network 1")[0])          # the header, byte for byte
    assert new.endswith("END_ORGANIZATION_BLOCK\n")
    assert network_to_model(new_nets[index]) == model


def test_unchanged_model_saves_the_same_instructions() -> None:
    # the same instructions, titles and comments (the comment lines are
    # written as "//text": the parser keeps them without the blank)
    for k in range(2):
        again = replace_network(SEAL, "MAIN", k + 1, _model(SEAL, k))
        assert ([(n.title, n.comment, [(i.mnemonic, [o.text for o in i.operands])
                                       for i in n.insns])
                 for n in parse_program(again).pous[0].networks]
                == [(n.title, n.comment, [(i.mnemonic, [o.text for o in i.operands])
                                          for i in n.insns])
                    for n in parse_program(SEAL).pous[0].networks])


def test_what_only_the_program_can_tell_is_refused_there() -> None:
    model = apply_edit(_model(SEAL, 1), {"op": "output", "at": ["rung"], "element": {
        "el": "box", "insn": "CALL", "ops": ["NO_SUCH_BLOCK"]}})    # fits the element checks
    with pytest.raises(PlcError, match="NO_SUCH_BLOCK"):
        check_in_program(SEAL, "OB1", 2, model)


def test_unknown_block_or_network_is_named() -> None:
    m = _model(SEAL, 0)
    with pytest.raises(PlcError, match="no block"):
        replace_network(SEAL, "SBR7", 1, m)
    with pytest.raises(PlcError, match="no network 9"):
        replace_network(SEAL, "OB1", 9, m)


def test_timer_numbers_of_the_other_kind_are_refused_by_the_element_check() -> None:
    for box, number in (("TON", "T0"), ("TONR", "T37"), ("TOF", "T95")):
        with pytest.raises(PlcError, match=f"not a {box} timer number"):
            apply_edit(_model(SEAL, 1), {"op": "output", "at": ["rung"], "element": {
                "el": "box", "insn": box, "ops": [number, "+10"]}})


def test_an_edit_checked_in_its_program() -> None:
    from plcrt.view.ladder_edit import History

    h = History(_model(SEAL, 1), check=lambda m: check_in_program(SEAL, "OB1", 2, m))
    h.apply({"op": "output", "at": ["rung"], "element": {"el": "coil", "insn": "=",
                                                         "ops": ["Q0.2"]}})
    with pytest.raises(PlcError, match="NO_SUCH_BLOCK"):
        h.apply({"op": "output", "at": ["rung"], "element": {
            "el": "box", "insn": "CALL", "ops": ["NO_SUCH_BLOCK"]}})
    assert [o.ops for o in h.model.rung.outs] == [("Q0.1",), ("Q0.2",)]


def test_call_pins_are_named_after_the_block() -> None:
    from plcrt.engine.runtime import parse_sources
    from plcrt.view.ladder_edit import call_parameters, model_json

    prog = parse_sources(ROOT / "programs" / "subroutine.awl")
    sbr = next(p for p in prog.pous if p.kind == "SBR")
    interface = [(v.name, "out" if v.section == "OUT" else "in")
                 for v in sbr.variables if v.section != "TEMP"]
    assert [(p["name"], p["side"]) for p in call_parameters(sbr.name, prog)] == interface
    calls = [n for n in prog.pous[0].networks if any(i.mnemonic == "CALL" for i in n.insns)]
    box = model_json(calls[0], program=prog)["ladder"]["rung"]["outs"][0]
    assert [(p["name"], p["op"]) for p in box["pins"]] == [
        (name, k + 1) for k, (name, _) in enumerate(interface)]
    unnamed = model_json(calls[0])["ladder"]["rung"]["outs"][0]     # without the program
    assert unnamed["pins"] == [{"op": k + 1} for k in range(len(interface))]
    # a library block is named from library/*.toml
    assert call_parameters("POS_GOTO_R")[0] == {"name": "EmNo", "side": "in"}
    assert call_parameters("NO_SUCH_BLOCK") == []
