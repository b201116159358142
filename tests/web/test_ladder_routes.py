"""The ladder drawing's endpoints (plcrt/web/ladderroutes.py): the networks
of the editor's text with their reasons, a drawing opened, edited, undone
and redone with the text written back around it, and the refusals (another
origin, bad JSON, bodies and operations out of bounds, a network typed
over, a closed drawing)."""

from __future__ import annotations

import pytest

from plcrt.errors import PlcConfigError
from plcrt.web import ladderroutes
from plcrt.web.editor import MAX_TEXT
from plcrt.web.editroutes import MAX_BODY

from .test_editor import _post, _run

TEXT = """\
ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1 // Motor
LD     Start
=      Motor
Network 2
LDS    1
=      Q0.1
Network 3
END_ORGANIZATION_BLOCK
"""

SEAL_IN = TEXT.replace("LD     Start\n=      Motor\n",
                       "LD     Start\nO      Motor\nAN     Stop\n=      Motor\n")


def test_networks_lists_each_network_and_why_one_stays_stl(tmp_path) -> None:
    async def body(client, panel, path):
        status, ans = await _post(client, "/ladder/networks", text=TEXT)
        assert status == 200
        rows = {n["number"]: n for n in ans["networks"]}
        assert [n["block"] for n in ans["networks"]] == ["OB1"] * 3
        assert rows[1]["drawable"] and rows[1]["title"] == "Motor"
        assert rows[3]["drawable"]   # empty: a rung is drawn into it
        assert not rows[2]["drawable"] and "LDS" in rows[2]["reason"]
        # a network without ladder form opens as STL with its reason
        status, ans = await _post(client, "/ladder/open", text=TEXT, block="OB1", number=2)
        assert status == 200 and ans["ladder"] is None and "id" not in ans
        assert "LDS" in ans["reason"] and ans["stl"].startswith("LDS")
    _run(tmp_path, body)


def test_edits_write_the_network_back_into_the_text_and_undo_redo(tmp_path) -> None:
    async def body(client, panel, path):
        _, ans = await _post(client, "/ladder/open", text=TEXT, block="OB1", number=1)
        key, text = ans["id"], TEXT
        assert ans["ladder"]["rung"]["logic"] == {"el": "NO", "ops": ["Start"]}
        ops = [{"op": "insert", "at": ["rung", "logic"], "side": "after",
                "element": {"el": "NC", "ops": ["Stop"]}},
               {"op": "parallel", "at": ["rung", "logic", 0],
                "branch": {"el": "NO", "ops": ["Motor"]}}]
        for op in ops:
            status, ans = await _post(client, "/ladder/edit", id=key, text=text, op=op)
            assert status == 200, ans
            text = ans["text"]
        assert text == SEAL_IN
        assert ans["stl"] == "LD     Start\nO      Motor\nAN     Stop\n=      Motor\n"
        assert ans["undo"] and not ans["redo"]
        status, ans = await _post(client, "/ladder/undo", id=key, text=text)
        assert status == 200 and ans["redo"]
        assert ans["text"] == TEXT.replace("=      Motor", "AN     Stop\n=      Motor", 1)
        status, ans = await _post(client, "/ladder/redo", id=key, text=ans["text"])
        assert ans["text"] == SEAL_IN and not ans["redo"]
        # a refused operation changes nothing and says why
        status, ans = await _post(client, "/ladder/edit", id=key, text=SEAL_IN, op={
            "op": "operands", "at": ["rung", "outs", 0], "ops": ["Q0.9"]})
        assert status == 400 and not ans["ok"] and "Q0.9" in ans["message"]
        _, ans = await _post(client, "/ladder/undo", id=key, text=SEAL_IN)
        assert "AN     Stop" in ans["text"] and "O      Motor" not in ans["text"]
    _run(tmp_path, body)


def test_an_empty_network_gets_a_rung(tmp_path) -> None:
    async def body(client, panel, path):
        _, ans = await _post(client, "/ladder/open", text=TEXT, block="OB1", number=3)
        assert ans["ladder"]["rung"] is None
        status, ans = await _post(client, "/ladder/edit", id=ans["id"], text=TEXT, op={
            "op": "replace", "at": ["rung"], "element": {
                "el": "node", "logic": {"el": "NO", "ops": ["I0.3"]},
                "outs": [{"el": "coil", "insn": "S", "ops": ["Q0.3", "1"]}]}})
        assert status == 200
        assert ans["text"].endswith("Network 3\nLD     I0.3\nS      Q0.3, 1\n"
                                    "END_ORGANIZATION_BLOCK\n")
    _run(tmp_path, body)


def test_a_network_typed_over_or_a_closed_drawing_is_refused(tmp_path) -> None:
    async def body(client, panel, path):
        _, ans = await _post(client, "/ladder/open", text=TEXT, block="OB1", number=1)
        op = {"op": "delete", "at": ["rung", "logic"]}
        typed = TEXT.replace("LD     Start", "LD     Other")
        status, ans2 = await _post(client, "/ladder/edit", id=ans["id"], text=typed, op=op)
        assert status == 400 and "changed in the text" in ans2["message"]
        status, ans2 = await _post(client, "/ladder/edit", id="nope", text=TEXT, op=op)
        assert status == 400 and "closed" in ans2["message"]
        status, ans2 = await _post(client, "/ladder/open", text=TEXT, block="SBR9", number=1)
        assert status == 400 and "SBR9" in ans2["message"]
        status, ans2 = await _post(client, "/ladder/open", text=TEXT, block="OB1", number=True)
        assert status == 400
    _run(tmp_path, body)


def test_bad_json_big_bodies_and_other_origins_are_refused(tmp_path) -> None:
    async def body(client, panel, path):
        _, ans = await _post(client, "/ladder/open", text=TEXT, block="OB1", number=1)
        key = ans["id"]
        r = await client.post("/ladder/edit", data=b"{not json",
                              headers={"Content-Type": "application/json"})
        assert r.status == 400 and "not JSON" in (await r.json())["message"]
        r = await client.post("/ladder/edit", data=b"[]",
                              headers={"Content-Type": "application/json"})
        assert r.status == 400
        r = await client.post("/ladder/edit", data=b'{"id": "x"}',
                              headers={"Content-Type": "text/plain"})
        assert r.status == 400
        r = await client.post("/ladder/open", data=b"x" * (MAX_BODY + 10),
                              headers={"Content-Type": "application/json"})
        assert r.status == 400 and "larger" in (await r.json())["message"]
        status, ans = await _post(client, "/ladder/open", text=TEXT, block="OB1", number=1,
                                  extra=1)
        assert status == 400 and "unknown field" in ans["message"]
        # operations are untrusted: nesting, sizes, unknown fields
        deep: dict = {"el": "NO", "ops": ["I0.0"]}
        for _ in range(60):
            deep = {"el": "series", "items": [deep, {"el": "NO", "ops": ["I0.1"]}]}
        for op in ({"op": "insert", "at": ["rung", "logic"], "side": "after", "element": deep},
                   {"op": "operands", "at": ["rung", "logic"], "ops": ["I" * 300]},
                   {"op": "insert", "at": ["rung"] * 50, "element": {}},
                   {"op": "explode"}, "delete", None):
            status, ans = await _post(client, "/ladder/edit", id=key, text=TEXT, op=op)
            assert status == 400 and not ans["ok"], op
        # a text over the editor's bound
        status, ans = await _post(client, "/ladder/networks", text="x" * (MAX_TEXT + 1))
        assert status == 400 and not ans["ok"]
        # another page's origin, or another host name (DNS rebinding), gets nothing
        for route in ("networks", "open", "edit", "undo", "redo"):
            r = await client.post(f"/ladder/{route}", json={"text": TEXT},
                                  headers={"Origin": "http://evil.example"})
            assert r.status == 403
            r = await client.post(f"/ladder/{route}", json={"text": TEXT},
                                  headers={"Host": f"evil.example:{client.port}"})
            assert r.status == 403 and "not this server's name" in await r.text()
        # the drawing is as it was: nothing was applied
        status, ans = await _post(client, "/ladder/undo", id=key, text=TEXT)
        assert status == 400 and "nothing to undo" in ans["message"]
    _run(tmp_path, body)


def test_drawings_are_bounded() -> None:
    d = ladderroutes.Drawings()
    keys = [d.open(TEXT, "OB1", 1)["id"] for _ in range(ladderroutes.MAX_DRAWINGS + 3)]
    op = {"op": "delete", "at": ["rung", "logic"]}
    for k in keys[:3]:
        with pytest.raises(PlcConfigError, match="closed"):
            d.step(k, TEXT, "edit", op)
    assert d.step(keys[3], TEXT, "edit", {
        "op": "operands", "at": ["rung", "logic"], "ops": ["I0.7"]})["ok"]


def test_new_network_is_added_after_the_blocks_last(tmp_path) -> None:
    async def body(client, panel, path):
        status, ans = await _post(client, "/ladder/new", text=TEXT.replace("\n", "\r\n"),
                                  block="OB1")
        assert status == 200 and ans["number"] == 4
        assert ans["text"] == TEXT.replace("\n", "\r\n").replace(
            "END_ORGANIZATION_BLOCK", "Network 4\r\nEND_ORGANIZATION_BLOCK")
        status, ans = await _post(client, "/ladder/new", text=TEXT, block="SBR0")
        assert status == 400 and "SBR0" in ans["message"]
    _run(tmp_path, body)
