"""The message schema: what a client may send, checked in one place."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from plcrt.errors import PlcError
from plcrt.web.protocol import (CLIENT, MAX_DEPTH, MAX_MESSAGE, SERVER, ProtocolError, dumps,
                                nesting, parse, validate)

GOOD = [
    ({"type": "run"}, {"type": "run"}),
    ({"type": "step"}, {"type": "step"}),
    ({"type": "step", "scans": 5, "id": 7}, {"type": "step", "scans": 5, "id": 7}),
    ({"type": "until", "cond": " VW100 >= 5 "}, {"type": "until", "cond": "VW100 >= 5"}),
    ({"type": "speed", "mode": "factor", "factor": 2.5},
     {"type": "speed", "mode": "factor", "factor": 2.5}),
    ({"type": "set", "addr": "I0.0", "value": "1"}, {"type": "set", "addr": "I0.0", "value": "1"}),
    ({"type": "unforce"}, {"type": "unforce"}),
    ({"type": "unforce", "addr": None}, {"type": "unforce"}),
    ({"type": "watch", "spec": "VD4", "format": "real"},
     {"type": "watch", "spec": "VD4", "format": "real"}),
    ({"type": "trend", "signals": ["I0.0", "T37"]}, {"type": "trend", "signals": ["I0.0", "T37"]}),
    ({"type": "trend", "signals": []}, {"type": "trend", "signals": []}),
]

BAD = [
    ([], "a JSON object"),
    ({"type": "launch"}, "unknown message type 'launch'"),
    ({"type": 3}, "unknown message type 'int'"),
    ({"type": "step", "scans": 0}, "step.scans must be between 1"),
    ({"type": "step", "scans": 1.5}, "step.scans must be a whole number"),
    ({"type": "step", "scans": True}, "step.scans must be a whole number"),
    ({"type": "until"}, "until: missing field 'cond'"),
    ({"type": "speed", "mode": "warp"}, "speed.mode must be one of realtime, factor, max"),
    ({"type": "speed", "mode": "factor", "factor": 1e9}, "speed.factor must be between"),
    ({"type": "set", "addr": "", "value": "1"}, "set.addr must not be empty"),
    ({"type": "set", "addr": "I0.0", "value": 1}, "set.value must be a text"),
    ({"type": "set", "addr": "x" * 201, "value": "1"}, "too long"),
    ({"type": "run", "extra": 1}, "run: unknown field 'extra'"),
    ({"type": "run", "id": {"a": 1}}, "id must be a number or a short text"),
    ({"type": "trend", "signals": "I0.0"}, "a list of texts"),
    ({"type": "trend", "signals": ["I0.0"] * 9}, "at most 8 items"),
    ({"type": "watch", "spec": "VW0", "format": "octal"}, "watch.format must be one of"),
]


@pytest.mark.parametrize("msg, expected", GOOD)
def test_valid_messages_come_back_checked_and_trimmed(msg, expected) -> None:
    assert validate(msg) == expected


@pytest.mark.parametrize("msg, message", BAD)
def test_invalid_messages_are_refused_with_a_message(msg, message) -> None:
    with pytest.raises(ProtocolError, match=None) as e:
        validate(msg)
    assert message in e.value.message
    assert isinstance(e.value, PlcError)


def test_parse_refuses_non_json_and_oversized_text() -> None:
    with pytest.raises(ProtocolError, match="JSON object"):
        parse("{not json")
    with pytest.raises(ProtocolError, match="too long"):
        parse(json.dumps({"type": "run", "pad": "x" * 20000}))
    assert parse('{"type":"stop"}') == {"type": "stop"}


def test_a_hostile_type_is_quoted_escaped_and_short() -> None:
    with pytest.raises(ProtocolError) as e:
        validate({"type": "\x1b[2J" + "a" * 100})
    assert "\x1b" not in e.value.message and "\\x1b" in e.value.message
    assert len(e.value.message) < 100


def test_dumps_carries_nan_as_text_never_bare() -> None:
    assert dumps({"v": [1, 2]}) == '{"v":[1,2]}'
    with pytest.raises(ValueError):
        dumps({"v": float("nan")})


def test_docs_name_every_message_type_of_both_directions() -> None:
    doc = (Path(__file__).resolve().parents[2] / "docs" / "panel.md").read_text()
    for kind in list(CLIENT) + list(SERVER):
        assert f"`{kind}`" in doc, kind


@pytest.mark.parametrize("text", ["[" * 1000 + "]" * 1000, "[" * 5000,
                                  '{"type": "step", "x": ' + "{\"a\": " * 900 + "1" + "}" * 901])
def test_deep_nesting_is_refused_before_the_parser_recurses(text: str) -> None:
    """Python's JSON decoder recurses once per level and raises
    RecursionError near 1000: the depth is bounded before parsing."""
    with pytest.raises(ProtocolError, match=f"{MAX_DEPTH} deep at most"):
        parse(text)


def test_brackets_inside_texts_do_not_count_as_nesting() -> None:
    msg = parse(json.dumps({"type": "trend", "signals": ["[" * 50 + '\\"{']}))
    assert msg["signals"] == ["[" * 50 + '\\"{']
    assert nesting('{"a": "[[[[", "b": [[1]]}') == 3


def test_the_size_limit_counts_bytes_not_characters() -> None:
    text = json.dumps({"type": "unwatch", "spec": "é" * 9000}, ensure_ascii=False)
    assert len(text) < MAX_MESSAGE < len(text.encode())
    with pytest.raises(ProtocolError, match="message too long"):
        parse(text)
