"""Edit operations on the ladder model: each operation's result, the
refusals (with the model unchanged), undo/redo, the bounds on untrusted
JSON, and a property: random edit sequences on random networks only ever
give STL that ``plcrt check`` accepts and that reads back as the same
ladder."""

from __future__ import annotations

import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.errors import PlcConfigError
from plcrt.lang.stl import parse_program
from plcrt.view.ladder_edit import History, apply_edit, edit_json, get, model_json
from plcrt.view.ladder_model import Box, Coil, Model, Node, Parallel, Series, model_to_json
from plcrt.view.ladder_stl import model_to_stl, network_text, network_to_model

SEAL = "LD     I0.0\nO      Q0.0\nAN     I0.1\n=      Q0.0\n"


def _net(stl: str, n: int = 1):
    text = f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork {n}\n{stl}END_ORGANIZATION_BLOCK\n"
    return parse_program(text).pous[0].networks[0]


def _read_back(model: Model):
    """The model of the network that the model's STL text is, as parsed."""
    text = f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n{network_text(model, 1)}END_ORGANIZATION_BLOCK\n"
    return network_to_model(parse_program(text).pous[0].networks[0])


def _model(stl: str) -> Model:
    m = network_to_model(_net(stl))
    assert isinstance(m, Model)
    return m


def _stl(model: Model) -> list[str]:
    return [line.split()[0] + (" " + "".join(line.split()[1:]) if len(line.split()) > 1 else "")
            for line in model_to_stl(model).splitlines()]


NO = {"el": "NO", "ops": ["I0.2"]}


def test_insert_in_series_before_and_after() -> None:
    m = _model(SEAL)
    after = apply_edit(m, {"op": "insert", "at": ["rung", "logic", 1], "side": "after",
                           "element": NO})
    assert _stl(after) == ["LD I0.0", "O Q0.0", "AN I0.1", "A I0.2", "= Q0.0"]
    before = apply_edit(m, {"op": "insert", "at": ["rung", "logic", 0], "side": "before",
                            "element": {"el": "NC", "ops": ["I0.3"]}})
    assert _stl(before) == ["LDN I0.3", "LD I0.0", "O Q0.0", "ALD", "AN I0.1", "= Q0.0"]


def test_parallel_branch_around_a_range() -> None:
    m = _model("LD     I0.0\nA      I0.1\nA      I0.2\n=      Q0.0\n")
    got = apply_edit(m, {"op": "parallel", "at": ["rung", "logic", 1], "count": 2,
                         "branch": {"el": "NO", "ops": ["M0.0"]}})
    assert _stl(got) == ["LD I0.0", "LD I0.1", "A I0.2", "O M0.0", "ALD", "= Q0.0"]
    whole = apply_edit(m, {"op": "parallel", "at": ["rung", "logic"],
                           "branch": {"el": "series", "items": [NO, {"el": "P"}]}})
    assert _stl(whole) == ["LD I0.0", "A I0.1", "A I0.2", "LD I0.2", "EU", "OLD", "= Q0.0"]


def test_outputs_branches_and_eno() -> None:
    m = _model("LD     I0.0\n=      Q0.0\n")
    m = apply_edit(m, {"op": "output", "at": ["rung"], "element": {
        "el": "node", "logic": {"el": "NC", "ops": ["I0.1"]},
        "outs": [{"el": "coil", "insn": "S", "ops": ["Q0.1", "1"]}]}})
    m = apply_edit(m, {"op": "output", "at": ["rung"], "index": 0,
                       "element": {"el": "box", "insn": "MOVW", "ops": ["+5", "VW0"]}})
    m = apply_edit(m, {"op": "output", "at": ["rung", "outs", 0],
                       "element": {"el": "coil", "insn": "=", "ops": ["Q0.3"]}})
    assert _stl(m) == ["LD I0.0", "LPS", "MOVW +5,VW0", "AENO", "= Q0.3", "LPP", "= Q0.0",
                       "AN I0.1", "S Q0.1,1"]
    assert get(m, ("rung", "outs", 0, "next", "outs", 0)) == Coil("=", ("Q0.3",))


def test_delete_replace_operands_move() -> None:
    m = _model(SEAL)
    gone = apply_edit(m, {"op": "delete", "at": ["rung", "logic", 0, 1]})
    assert _stl(gone) == ["LD I0.0", "AN I0.1", "= Q0.0"]
    nc = apply_edit(m, {"op": "replace", "at": ["rung", "logic", 0, 0],
                        "element": {"el": "NC", "ops": ["I0.0"]}})
    assert _stl(nc)[0] == "LDN I0.0"
    ops = apply_edit(m, {"op": "operands", "at": ["rung", "outs", 0], "ops": ["Q0.5"]})
    assert _stl(ops)[-1] == "= Q0.5"
    moved = apply_edit(m, {"op": "move", "from": ["rung", "logic", 1],
                           "to": ["rung", "logic"], "side": "before"})
    assert _stl(moved) == ["LDN I0.1", "LD I0.0", "O Q0.0", "ALD", "= Q0.0"]
    titled = apply_edit(m, {"op": "title", "title": " Motor ", "comment": "one\n two"})
    assert (titled.title, titled.comment) == ("Motor", "one\ntwo")


REFUSED = [
    ({"op": "operands", "at": ["rung", "logic", 0, 0], "ops": ["VW0"]}, "not a valid bit"),
    ({"op": "operands", "at": ["rung", "logic", 0, 0], "ops": ["I0.0\nLD I0.1"]}, "reads back"),
    ({"op": "operands", "at": ["rung", "logic", 0, 0], "ops": ["I0.0, I0.1"]}, "reads back"),
    ({"op": "operands", "at": ["rung", "logic", 0, 0], "ops": ["I0.0 // x"]}, "reads back"),
    ({"op": "operands", "at": ["rung", "outs", 0], "ops": ["I9.9"]}, "operand 1"),
    ({"op": "insert", "at": ["rung", "logic", 0], "side": "before", "element": {"el": "P"}},
     "cannot start with P"),
    ({"op": "delete", "at": ["rung", "outs", 0]}, "without an output"),
    ({"op": "delete", "at": ["rung", "logic"]}, "starts with a contact"),
    ({"op": "title", "title": "a\nLD I0.0"}, "one line"),
    ({"op": "output", "at": ["rung"], "element": {"el": "box", "insn": "TON",
                                                  "ops": ["VW0", "+1"]}}, "timer"),
    ({"op": "output", "at": ["rung"], "element": {"el": "box", "insn": "XYZ", "ops": []}},
     "unknown instruction"),
    ({"op": "output", "at": ["rung"], "element": {"el": "box", "insn": "CTU",
                                                  "ops": ["C0", "+1"]}}, "one power input"),
    ({"op": "insert", "at": ["rung", "logic", 7], "element": NO}, "no element"),
    ({"op": "insert", "at": ["rung", "nope"], "element": NO}, "bad step"),
    ({"op": "explode"}, "unknown operation"),
    ({"op": "insert", "at": ["rung", "logic"], "element": NO, "x": 1}, "unknown field"),
    ({"op": "insert", "at": ["rung", "logic"], "element": {"el": "NO", "ops": [7]}},
     "expected a text"),
    ({"op": "insert", "at": ["rung", "logic"], "element": {"el": "NO", "ops": ["x" * 300]}},
     "longer than"),
    ({"op": "insert", "at": ["rung", "logic"],
      "element": {"el": "CMP", "cmp": "W=>", "ops": ["VW0", "1"]}}, "unknown compare"),
    ("insert", "JSON object"),
    ({"op": "replace", "at": ["rung"], "element": {"el": "coil", "insn": "=", "ops": ["Q0.0"]}},
     "a rung is a node"),
    ({"op": "replace", "at": [], "element": {"el": "coil", "insn": "=", "ops": ["Q0.0"]}},
     "path is empty"),
    ({"op": "move", "from": [], "to": ["rung"]}, "path is empty"),
    ({"op": ["insert"]}, "unknown operation"),
    ({"op": "insert", "at": ["rung", "logic"], "element": {"el": ["NO"], "ops": ["I0.0"]}},
     "expected a text"),
]


@pytest.mark.parametrize("op,why", REFUSED, ids=[str(i) for i in range(len(REFUSED))])
def test_refused_operations_leave_the_history_unchanged(op, why: str) -> None:
    h = History(_model(SEAL))
    before = h.model
    with pytest.raises(PlcConfigError, match=why):
        h.apply(op)
    assert h.model == before and not h.can_undo


def test_stack_depth_is_refused() -> None:
    # each parallel block in series loads a level; the tenth has no room
    m = _model("LD     I0.0\n=      Q0.0\n")
    pair = {"el": "parallel", "items": [NO, {"el": "NO", "ops": ["I0.3"]}]}
    for _ in range(8):
        m = apply_edit(m, {"op": "insert", "at": ["rung", "logic"], "side": "before",
                           "element": {"el": "series", "items": [NO, pair]}})
        m = apply_edit(m, {"op": "parallel", "at": ["rung", "logic"], "branch": NO})
    with pytest.raises(PlcConfigError, match="levels of the logic stack"):
        for _ in range(3):
            m = apply_edit(m, {"op": "insert", "at": ["rung", "logic"], "side": "before",
                               "element": {"el": "series", "items": [NO, pair]}})
            m = apply_edit(m, {"op": "parallel", "at": ["rung", "logic"], "branch": NO})


def test_undo_redo() -> None:
    h = History(_model(SEAL))
    first = h.model
    second = h.apply({"op": "insert", "at": ["rung", "logic", 1], "element": NO})
    third = h.apply({"op": "operands", "at": ["rung", "outs", 0], "ops": ["Q0.7"]})
    assert h.undo() == second and h.undo() == first and not h.can_undo
    assert h.redo() == second and h.redo() == third and not h.can_redo
    h.undo()
    h.apply({"op": "delete", "at": ["rung", "logic", 2]})
    assert not h.can_redo
    with pytest.raises(PlcConfigError, match="nothing to redo"):
        h.redo()


def test_json_api_round_trip() -> None:
    got = model_json(_net(SEAL))
    assert got["stl"] == SEAL and got["ladder"]["rung"]["outs"][0]["lad"] == "( )"
    doc = json.loads(json.dumps(got["ladder"]))        # what the page sends back
    out = edit_json(doc, {"op": "operands", "at": ["rung", "outs", 0], "ops": ["Q0.1"]})
    assert out["stl"].endswith("=      Q0.1\n")
    stays = model_json(_net("LD     I0.0\nLDS    1\n=      Q0.0\n"))
    assert stays["ladder"] is None and "LDS" in stays["reason"] and "LDS" in stays["stl"]


def test_untrusted_json_is_bounded() -> None:
    doc = model_to_json(_model(SEAL))
    many = dict(doc, rung={"el": "node", "logic": {"el": "series", "items": [NO] * 300},
                           "outs": [{"el": "coil", "insn": "=", "ops": ["Q0.0"]}]})
    with pytest.raises(PlcConfigError, match="more than"):
        apply_edit(many, {"op": "title", "title": "x"})
    deep: dict = NO
    for _ in range(60):
        deep = {"el": "series", "items": [deep, NO]}
    with pytest.raises(PlcConfigError, match="nested deeper"):
        apply_edit(dict(doc, rung={"el": "node", "logic": deep, "outs": []}),
                   {"op": "title", "title": "x"})
    for bad in (None, [], {"format": "x"}, dict(doc, extra=1), dict(doc, rung=7),
                dict(doc, rung={"el": "coil", "insn": "=", "ops": ["Q0.0"]})):
        with pytest.raises(PlcConfigError):
            apply_edit(bad, {"op": "title", "title": "x"})
    with pytest.raises(PlcConfigError, match="at most"):
        apply_edit(doc, {"op": "delete", "at": ["rung"] + [0] * 100})


# ---------------------------------------------------------------------------
# Property: random edits
# ---------------------------------------------------------------------------

BITS = ["I0.0", "I0.1", "I1.7", "Q0.0", "M0.0", "V10.3", "SM0.1", "T37", "C0"]
COILS = ["Q0.0", "Q0.1", "M1.0", "V2.0"]
BIT_CONTACTS = st.builds(
    lambda k, b: {"el": k if k in ("NO", "NC") or b.startswith(("I", "Q")) else "NO", "ops": [b]},
    st.sampled_from(["NO", "NC", "NOI", "NCI"]), st.sampled_from(BITS))
COMPARES = st.builds(lambda c, b: {"el": "CMP", "cmp": c, "ops": {
    "W": ["VW0", b], "B": ["VB0", "5"], "D": ["VD0", "+70000"]}[c[0]]},
    st.sampled_from(["W=", "W>=", "W<>", "B<", "D>"]), st.sampled_from(["+10", "VW2"]))
LOADABLE = st.one_of(BIT_CONTACTS, COMPARES)
CONTACTS = st.one_of(LOADABLE, st.sampled_from([{"el": "P"}, {"el": "N"}, {"el": "NOT"}]))
OUTS = st.one_of(
    st.builds(lambda i, b: {"el": "coil", "insn": i, "ops": [b] + (["1"] if i in "SR" else [])},
              st.sampled_from(["=", "S", "R"]), st.sampled_from(COILS)),
    # a timer number of the other kind is refused (TONR: T0-T31, T64-T95)
    st.builds(lambda box, n: {"el": "box", "insn": box, "ops": [f"T{n}", "+100"]},
              st.sampled_from(["TON", "TONR"]), st.integers(0, 255)),
    st.sampled_from([{"el": "box", "insn": "MOVW", "ops": ["+5", "VW10"]},
                     {"el": "box", "insn": "INCW", "ops": ["VW20"]},
                     {"el": "box", "insn": "+I", "ops": ["VW2", "VW4"]},
                     {"el": "box", "insn": "MOVR", "ops": ["1.5", "VD30"]}]),
)
START = ["LD     I0.0\n=      Q0.0\n", SEAL,
         "LD     I0.0\nLPS\nA      I0.1\n=      Q0.1\nLPP\n=      Q0.2\n",
         "LD     I0.0\nMOVW   +1, VW0\nAENO\n=      Q0.0\n"]


def _paths(model: Model) -> tuple[list[tuple], list[tuple]]:
    """Paths of the logic elements and of the nodes and boxes."""
    logic: list[tuple] = []
    nodes: list[tuple] = []

    def walk_logic(x, p):
        logic.append(p)
        if isinstance(x, (Series, Parallel)):
            for k, i in enumerate(x.items):
                walk_logic(i, p + (k,))

    def walk(x, p):
        if isinstance(x, Node):
            nodes.append(p)
            if x.logic is not None:
                walk_logic(x.logic, p + ("logic",))
            for k, o in enumerate(x.outs):
                walk(o, p + ("outs", k))
        elif isinstance(x, Box) and x.next is not None:
            nodes.append(p)
            walk(x.next, p + ("next",))
        elif isinstance(x, Box):
            nodes.append(p)
    if model.rung is not None:
        walk(model.rung, ("rung",))
    return logic, nodes


@st.composite
def _edit(draw, model: Model):
    logic, nodes = _paths(model)
    kind = draw(st.sampled_from(["insert", "parallel", "output", "delete", "move", "operands"]))
    if kind == "insert" and logic:
        return {"op": "insert", "at": list(draw(st.sampled_from(logic))),
                "side": draw(st.sampled_from(["before", "after"])), "element": draw(CONTACTS)}
    if kind == "parallel" and logic:
        return {"op": "parallel", "at": list(draw(st.sampled_from(logic))),
                "count": draw(st.integers(1, 3)), "branch": draw(CONTACTS)}
    if kind == "output" and nodes:
        return {"op": "output", "at": list(draw(st.sampled_from(nodes))),
                "element": draw(st.one_of(OUTS, st.builds(
                    lambda c, o: {"el": "node", "logic": c, "outs": [o]}, CONTACTS, OUTS)))}
    if kind == "delete" and len(logic) + len(nodes) > 1:
        return {"op": "delete", "at": list(draw(st.sampled_from(logic + nodes[1:])))}
    if kind == "move" and len(logic) > 1:
        a, b = draw(st.sampled_from(logic)), draw(st.sampled_from(logic))
        return {"op": "move", "from": list(a), "to": list(b),
                "side": draw(st.sampled_from(["before", "after"]))}
    if logic:
        return {"op": "operands", "at": list(draw(st.sampled_from(logic))),
                "ops": [draw(st.sampled_from(BITS))]}
    return {"op": "title", "title": "t"}


LOGIC = st.recursive(LOADABLE, lambda inner: st.builds(
    lambda kind, first, rest: {"el": kind, "items": [first] + rest},
    st.sampled_from(["series", "parallel"]), inner, st.lists(st.one_of(inner, CONTACTS),
                                                            min_size=1, max_size=3)),
    max_leaves=8)
NODES = st.recursive(OUTS, lambda inner: st.builds(
    lambda logic, outs: {"el": "node", "logic": logic, "outs": outs},
    LOGIC, st.lists(inner, min_size=1, max_size=3)), max_leaves=6)


@st.composite
def _random_model(draw) -> Model:
    """A random drawing from the page; one the editor would refuse (a
    branch that starts with P, ...) is replaced by a sample network."""
    doc = {"format": "plcrt-ladder", "version": 1, "title": "", "comment": "", "rail": [],
           "rung": {"el": "node", "logic": draw(LOGIC),
                    "outs": draw(st.lists(NODES, min_size=1, max_size=3))}}
    try:
        return History(Model()).apply({"op": "replace", "at": ["rung"], "element": doc["rung"]})
    except PlcConfigError:
        return _model(draw(st.sampled_from(START)))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_random_edits_give_checked_round_tripping_stl(data) -> None:
    h = History(data.draw(_random_model()))
    accepted = [h.model]
    for _ in range(data.draw(st.integers(1, 8))):
        op = data.draw(_edit(h.model))
        try:
            accepted.append(h.apply(op))
        except PlcConfigError:
            continue  # refused: the model must be the last accepted one
        finally:
            assert h.model == accepted[-1]
    # every accepted model reads back from its STL as itself ...
    for m in accepted:
        assert _read_back(m) == m, model_to_stl(m)
    # ... and all of them, one network each, pass plcrt check
    body = "".join(network_text(m, k + 1) for k, m in enumerate(accepted))
    plcrt.load(f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n{body}END_ORGANIZATION_BLOCK\n",
               library=True, backend="python")


def test_a_network_drawn_from_nothing() -> None:
    empty = Model()
    assert model_to_stl(empty) == ""
    m = apply_edit(empty, {"op": "replace", "at": ["rung"], "element": {
        "el": "node", "logic": {"el": "NO", "ops": ["I0.0"]},
        "outs": [{"el": "coil", "insn": "=", "ops": ["Q0.0"]}]}})
    m = apply_edit(m, {"op": "parallel", "at": ["rung", "logic"],
                       "branch": {"el": "NO", "ops": ["Q0.0"]}})
    m = apply_edit(m, {"op": "insert", "at": ["rung", "logic"], "side": "after",
                       "element": {"el": "NC", "ops": ["I0.1"]}})
    assert model_to_stl(m) == SEAL                                   # the seal-in rung
    assert apply_edit(m, {"op": "delete", "at": ["rung"]}) == Model()


def test_counter_inputs_and_rail_elements() -> None:
    m = _model("LD     I0.0\nLD     I0.1\nCTU    C0, +10\n")
    m = apply_edit(m, {"op": "insert", "at": ["rung", "inputs", 0], "side": "after",
                       "element": {"el": "P"}})
    assert _stl(m) == ["LD I0.0", "EU", "LD I0.1", "CTU C0,+10"]
    with pytest.raises(PlcConfigError, match="counter box, which has no ENO"):
        apply_edit(m, {"op": "output", "at": ["rung"],
                       "element": {"el": "coil", "insn": "=", "ops": ["Q0.0"]}})
    with pytest.raises(PlcConfigError, match="counter"):
        apply_edit(m, {"op": "delete", "at": ["rung", "inputs", 1]})
    rail = _model("LBL    3\n")
    rail = apply_edit(rail, {"op": "output", "at": ["rail"],
                             "element": {"el": "coil", "insn": "LSCR", "ops": ["S0.1"]}})
    assert _stl(rail) == ["LBL 3", "LSCR S0.1"]
    with pytest.raises(PlcConfigError, match="not a rail element"):
        apply_edit(rail, {"op": "replace", "at": ["rail", 0],
                          "element": {"el": "coil", "insn": "=", "ops": ["Q0.0"]}})
    with pytest.raises(PlcConfigError, match="with a rung has no elements"):
        apply_edit(_model(SEAL), {"op": "output", "at": ["rail"],
                                  "element": {"el": "coil", "insn": "LBL", "ops": ["1"]}})


# ---------------------------------------------------------------------------
# Untrusted JSON: whatever the page sends is a model and an edit, or a
# PlcConfigError; never another exception
# ---------------------------------------------------------------------------

JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-5, 300) | st.floats(allow_nan=True)
    | st.sampled_from(["", "el", "NO", "node", "series", "rung", "logic", "outs", "I0.0", "=",
                       "MOVW", "CALL", "CMP", "W=", "\n", "//", ",", "\x1b[2J"]),
    lambda inner: st.lists(inner, max_size=4)
    | st.dictionaries(st.sampled_from(["el", "ops", "items", "logic", "outs", "insn", "next",
                                       "inputs", "cmp", "op", "at", "side", "element",
                                       "branch", "count", "index", "from", "to", "x"]),
                      inner, max_size=5),
    max_leaves=12)


def _mutate(doc, path, value):
    """``doc`` with the value at ``path`` (keys and indexes) replaced."""
    if not path:
        return value
    head, rest = path[0], path[1:]
    if isinstance(doc, dict) and head in doc:
        return {**doc, head: _mutate(doc[head], rest, value)}
    if isinstance(doc, list) and isinstance(head, int) and head < len(doc):
        return doc[:head] + [_mutate(doc[head], rest, value)] + doc[head + 1:]
    return doc


def _places(doc, path=()):
    yield path
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) \
        else ()
    for k, v in items:
        yield from _places(v, path + (k,))


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_untrusted_documents_and_operations_never_raise_anything_else(data) -> None:
    doc = model_to_json(_model(data.draw(st.sampled_from(START))))
    place = data.draw(st.sampled_from(list(_places(doc))))
    doc = _mutate(doc, place, data.draw(JSON))
    op = data.draw(st.one_of(JSON, st.builds(
        lambda kind, at, el: {"op": kind, "at": at, "element": el},
        st.sampled_from(["insert", "output", "replace", "delete"]),
        st.lists(st.sampled_from(["rung", "logic", "outs", 0, 1, 2]), max_size=5), JSON)))
    try:
        new = apply_edit(doc, op)
    except PlcConfigError:
        return
    assert _read_back(new) == new
