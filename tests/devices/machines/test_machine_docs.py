"""docs/machines.md keeps up with the machines: each kind's section names
its parameters with their defaults, its own faults, and every field of its
state, so the page that animates ``state()`` can rely on the doc."""

from __future__ import annotations

import re

import pytest

import plcrt
from plcrt.devices.machines import KINDS

from machine_helpers import MANUAL, ROOT

DOC = (ROOT / "docs" / "machines.md").read_text(encoding="utf-8")


def section(kind: str) -> str:
    m = re.search(rf"^## [^\n]*\(`{kind}`\)\n(.*?)(?=^## |\Z)", DOC, re.S | re.M)
    assert m, f"docs/machines.md has no section for {kind}"
    return m.group(1)


@pytest.mark.parametrize("kind", list(KINDS))
def test_each_machine_is_documented(kind: str) -> None:
    text = " ".join(section(kind).split())
    cls = KINDS[kind]
    for name, p in cls.PARAMS.items():
        default = f'"{p.default}"' if p.text else f"{p.default:g}"
        assert f"`{name}` {default}" in text, f"{kind}: parameter {name} {default}"
    for fault in cls.OWN_FAULTS:
        assert f"`{fault}`" in text
    plc = plcrt.load(MANUAL, plant={"machine": {kind: {}}})
    state = plc.machine(kind).state()
    common = {"kind", "name", "t", "inputs", "outputs", "faults"}
    for key in set(state) - common:
        assert f"`{key}`" in text, f"{kind}: state field {key}"
    for sig in (*cls.INPUTS, *cls.OUTPUTS):
        assert f"`{sig}`" in text or re.search(rf"`{sig[:-1]}1` \.\. `", text), sig
