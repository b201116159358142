"""Real Micro/WIN exports compile; the only errors are the instructions
plcrt does not implement yet, each reported with its location.

Reads the public corpus from ../shared/corpus (skipped when absent).
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest

from plcrt.engine.runtime import Plc, parse_sources
from plcrt.errors import PlcCompileError
from plcrt.isa.registry import KNOWN_UNIMPLEMENTED, lookup
from plcrt.lang import parse_symbols, read_source

CORPUS = Path(__file__).resolve().parents[2].parent / "shared" / "corpus"
DATA = Path(__file__).resolve().parents[1] / "data"
P = "bulaofen0036-coder__Smart200-MicroWIN-MCP__"
X = "xzcnmb__Smart200MCP__"

# (files compiled together, symbol table) -- subroutine exports are checked
# together with the file that calls them, as they live in one project.
GROUPS = [
    ([P + "roundtrip.awl"], DATA / "roundtrip_symbols.sdf"),
    ([P + "demo_v2.awl"], None),
    ([P + "main_ob1.awl", P + "ext_final_out.awl"], None),
    ([P + "motor.awl"], CORPUS / (P + "sym_a.sdf")),
    ([P + "probe_ops.awl"], None),
    (["haoyuesheng88__200smart-V28__bag-pulse-dust-collector-4bags-ob1.awl"], None),
    (["siemens_manual__S7-200_System_Manual__reconstructed_examples.awl"], None),
    ([X + "cylinder_control_template__MAIN.awl", X + "cylinder_control_template__CYL_CTRL.awl"], None),
    ([X + "new_pressure_test__MAIN.awl", X + "new_pressure_test__PRESSURE_TEST.awl"], None),
]

#: lines of the corpus that are wrong in Micro/WIN too: the probe file tries
#: NETR/NETW with one operand (the instructions take a table and a port; the
#: SMART rejects NETR/NETW altogether, reference digest "Communication")
INVALID = {P + "probe_ops.awl": ["NETR takes a table and a port", "NETW takes a table and a port"]}

pytestmark = pytest.mark.skipif(not CORPUS.is_dir(), reason="shared/corpus not available")


def _inventory() -> dict:
    return json.loads((CORPUS / "INVENTORY.json").read_text(encoding="utf-8"))


@pytest.mark.parametrize("files,symbols", GROUPS, ids=[g[0][-1][:40] for g in GROUPS])
def test_only_unimplemented_instructions_are_reported(files: list[str], symbols: Path | None) -> None:
    """Every compile error is 'not implemented yet', once per use, with its location."""
    paths = [CORPUS / f for f in files]
    program = parse_sources(paths)
    table = parse_symbols(read_source(symbols), str(symbols)) if symbols else None
    expected = Counter(
        i.mnemonic for p in program.pous for n in p.networks for i in n.insns
        if lookup(i.mnemonic) is None
    )
    assert set(expected) <= KNOWN_UNIMPLEMENTED
    try:
        Plc(program, symbols=table, library=True)   # subroutine exports without OB1
        reported: Counter[str] = Counter()
        others: list[str] = []
    except PlcCompileError as e:
        errors = [d for d in e.diagnostics if d.severity == "error"]
        others = [str(d) for d in errors if d.code != "unimplemented"]
        reported = Counter(d.message.split()[1] for d in errors if d.code == "unimplemented")
        for d in errors:
            assert d.loc is not None and d.loc.line > 0 and d.loc.block is not None
    invalid = [w for f in files for w in INVALID.get(f, [])]
    assert len(others) == len(invalid)
    assert all(any(w in o for o in others) for w in invalid)
    assert reported == expected


def test_unimplemented_set_matches_inventory() -> None:
    """Across the corpus, the unimplemented mnemonics are exactly the inventory's
    mnemonics that have no registry entry."""
    inv = _inventory()
    mnemonics = {m for entry in inv.values() for m in entry["mnemonics"]}
    missing = {m for m in mnemonics if lookup(m) is None}
    assert missing <= KNOWN_UNIMPLEMENTED
    # the core instruction set of this release is all implemented
    core = {"LD", "A", "O", "ALD", "OLD", "LPS", "LRD", "LPP", "TON", "TONR", "TOF", "CTU",
            "CTD", "CTUD", "MOVB", "MOVW", "MOVD", "MOVR", "+I", "/R", "JMP", "LBL", "FOR",
            "NEXT", "CALL", "CRET", "STOP", "WDR", "LSCR", "SCRT", "SCRE", "SHRB", "SEG",
            "ENCO", "DECO", "BCDI", "IBCD", "ROUND", "TRUNC", "FILL", "BIR", "BIW", "SWAP"}
    assert not (core & missing)
