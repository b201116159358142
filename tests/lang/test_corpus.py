"""The STL parser, symbol reader and decoder against the shared real-file corpus.

Each ``.awl`` file in ``../shared/corpus`` (relative to the repository root)
must parse to exactly the blocks, network count, instruction count and
mnemonic set recorded in its ``INVENTORY.json``.  The corpus is test input
only and is never copied into the project; every test here skips when the
directory is absent.
"""

from __future__ import annotations

import json
import re
import time
from pathlib import Path

import pytest

from plcrt.lang import (
    SYSTEM_SYMBOLS,
    parse_program,
    parse_symbols,
    read_source,
    resolve_symbol,
)
from plcrt.lang.ir import Program

CORPUS = Path(__file__).resolve().parents[2].parent / "shared" / "corpus"
INVENTORY = CORPUS / "INVENTORY.json"
ROUNDTRIP = "bulaofen0036-coder__Smart200-MicroWIN-MCP__roundtrip.awl"


def _inventory() -> dict[str, dict]:
    if not INVENTORY.is_file():
        return {}
    return json.loads(INVENTORY.read_text(encoding="utf-8"))


def _awl_params() -> list:
    names = sorted(_inventory())
    if not names:
        return [pytest.param(None, marks=pytest.mark.skip(
            reason=f"corpus not found at {CORPUS}"))]
    return names


def _need_corpus() -> None:
    if not INVENTORY.is_file():
        pytest.skip(f"corpus not found at {CORPUS}")


def _block_label(program: Program) -> list[str]:
    return [p.ident if p.name == p.ident else f"{p.name}:{p.ident}"
            for p in program.pous]


@pytest.mark.parametrize("name", _awl_params())
def test_corpus_file_matches_inventory(name: str) -> None:
    """Each corpus file yields the inventory's blocks, counts and mnemonics."""
    expected = _inventory()[name]
    program = parse_program(read_source(CORPUS / name), name)
    assert _block_label(program) == expected["blocks"]
    assert program.network_count() == expected["networks"]
    assert program.instruction_count() == expected["instructions"]
    mnemonics = {i.mnemonic for p in program.pous for n in p.networks
                 for i in n.insns}
    assert mnemonics == set(expected["mnemonics"])


@pytest.mark.parametrize("name", _awl_params())
def test_corpus_locations_carry_block_and_network(name: str) -> None:
    """Every instruction and operand loc names its file, block and network."""
    program = parse_program(read_source(CORPUS / name), name)
    for pou in program.pous:
        assert pou.loc.block == pou.ident and pou.loc.network is None
        for network in pou.networks:
            for insn in network.insns:
                for loc in [insn.loc] + [o.loc for o in insn.operands]:
                    assert loc.file == name
                    assert loc.block == pou.ident
                    assert loc.network == network.number
                    assert loc.line >= 1 and loc.column >= 1


def test_corpus_crlf_flag_matches_and_parses() -> None:
    """Files recorded as CRLF really are CRLF and still parse."""
    _need_corpus()
    crlf = [n for n, e in _inventory().items() if e["crlf"]]
    assert crlf, "the inventory lists at least one CRLF file"
    for name in crlf:
        assert b"\r\n" in (CORPUS / name).read_bytes()
        assert parse_program(read_source(CORPUS / name), name).pous


def test_roundtrip_parse_time() -> None:
    """The 1178-line roundtrip export parses in well under 0.5 s."""
    _need_corpus()
    text = read_source(CORPUS / ROUNDTRIP)
    parse_program(text, ROUNDTRIP)  # builds the parser; not what we time
    best = min(_timed(lambda: parse_program(text, ROUNDTRIP)) for _ in range(3))
    assert best < 0.5, f"roundtrip.awl took {best:.3f} s"


def _timed(action) -> float:
    # CPU time of this process: on a shared machine wall time also counts
    # the other processes' turns
    start = time.process_time()
    action()
    return time.process_time() - start


def test_corpus_sdf_symbols() -> None:
    """The SMART .sdf export gives the four motor symbols with comments."""
    _need_corpus()
    name = "bulaofen0036-coder__Smart200-MicroWIN-MCP__sym_a.sdf"
    table = parse_symbols(read_source(CORPUS / name), name)
    assert {s: table.entries[s].address for s in table.entries} == {
        "电机启动": "I0.0", "电机停止": "I0.1", "电机运行": "Q0.0",
        "运行时间": "VD100"}
    assert table.lookup("电机启动").comment == "启动按钮"
    assert table.lookup("电机启动").loc.line == 2


def test_corpus_motor_operands_resolve_through_sdf() -> None:
    """Every operand of motor.awl is a symbol defined in sym_a.sdf."""
    _need_corpus()
    table = parse_symbols(read_source(
        CORPUS / "bulaofen0036-coder__Smart200-MicroWIN-MCP__sym_a.sdf"))
    program = parse_program(read_source(
        CORPUS / "bulaofen0036-coder__Smart200-MicroWIN-MCP__motor.awl"))
    operands = [o.text for p in program.pous for n in p.networks
                for i in n.insns for o in i.operands]
    assert operands and all(resolve_symbol(table, o) for o in operands)


def test_corpus_system_symbol_operands_are_known() -> None:
    """Every ASCII symbolic operand in roundtrip.awl is a block or system symbol."""
    _need_corpus()
    program = parse_program(read_source(CORPUS / ROUNDTRIP), ROUNDTRIP)
    block_names = {p.name for p in program.pous}
    address = re.compile(r"(?:[IQMVSLT]|SM|AI|AQ|AC|HC|C)[BWD]?\d+(?:\.\d)?", re.I)
    symbolic = {o.text for p in program.pous for n in p.networks
                for i in n.insns for o in i.operands
                if re.fullmatch(r"[A-Za-z_]\w*", o.text, re.A)
                and not address.fullmatch(o.text)}
    unknown = {s for s in symbolic - block_names if s not in SYSTEM_SYMBOLS}
    assert symbolic and not unknown
