"""--auto-symbols: an address for each symbol no table defines, of the kind
its uses need, always reported (plcrt.compiler.autosym; docs/decisions.md,
"Symbols")."""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt
from plcrt.cli import main
from plcrt.errors import PlcCompileError

CORPUS = Path(__file__).resolve().parents[3] / "shared" / "corpus"


def ob1(*networks: str, extra: str = "") -> str:
    body = "".join(f"Network {i}\n{n}\n" for i, n in enumerate(networks, 1))
    return f"ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n{body}END_ORGANIZATION_BLOCK\n{extra}"


def assigned(plc: plcrt.Plc) -> dict[str, str]:
    return {name: sym.address for name, sym in plc.symbols.entries.items()
            if sym.comment == "assigned by auto-symbols"}


def test_bits_get_free_m_bits_from_the_top_and_values_free_v_from_the_top() -> None:
    """M31 is used by the program, so bits start at M30.7; a word and a
    double word come from the top of V (CPU 226: 10240 bytes), aligned."""
    plc = plcrt.load(ob1("LD Start\n= Motor\n= M31.0", "LD SM0.0\nMOVW Speed, Target\n"
                         "MOVD Total, VD0"), auto_symbols=True)
    assert assigned(plc) == {"Start": "M30.7", "Motor": "M30.6", "Speed": "VW10238",
                             "Target": "VW10236", "Total": "VD10232"}
    messages = [d.message for d in plc.diagnostics if d.code == "auto-symbol"]
    assert len(messages) == 5
    assert "'Start' is not in a symbol table; it is M30.7 (a bit" in messages[0]


def test_the_assigned_addresses_run() -> None:
    plc = plcrt.load(ob1("LD Start\n= Motor", "LD SM0.0\nMOVW Speed, Target"),
                     auto_symbols=True)
    plc.write("Start", 1)
    plc.write("Speed", 1234)
    plc.scan()
    assert plc.read("Motor") == 1 and plc.read("Target") == 1234


def test_immediate_instructions_get_input_and_output_bits() -> None:
    """LDI reads a real input, =I writes a real output: I15.7 and Q15.7; a
    plain contact on the same name is served by that input."""
    plc = plcrt.load(ob1("LD EStop\nLDI EStop\nOLD\n=I Horn"), auto_symbols=True)
    assert assigned(plc) == {"EStop": "I15.7", "Horn": "Q15.7"}


def test_call_arguments_take_the_parameters_types() -> None:
    sbr = ("SUBROUTINE_BLOCK S:SBR0\nVAR_INPUT\nOn:BOOL;\nSet:INT;\nEND_VAR\n"
           "VAR_OUTPUT\nOut:DWORD;\nEND_VAR\nBEGIN\nNetwork 1\nLD #On\n"
           "ITD #Set, #Out\nEND_SUBROUTINE_BLOCK\n")
    plc = plcrt.load(ob1("LD SM0.0\nCALL S, Run, Setpoint, Result", extra=sbr),
                     auto_symbols=True)
    assert assigned(plc) == {"Run": "M31.7", "Setpoint": "VW10238", "Result": "VD10232"}


def test_the_data_block_and_the_programs_own_addresses_are_not_taken() -> None:
    plc = plcrt.load(ob1("LD SM0.0\nMOVW Speed, VW10238"), data="VD10234 16#01020304\n",
                     auto_symbols=True)
    assert assigned(plc) == {"Speed": "VW10232"}


def test_a_name_used_with_two_widths_gets_no_address_and_each_use_is_an_error() -> None:
    with pytest.raises(PlcCompileError) as info:
        plcrt.load(ob1("LD Flag\n= Q0.0", "LD SM0.0\nMOVW Flag, VW0"), auto_symbols=True)
    diags = info.value.diagnostics
    assert any(d.code == "auto-symbol" and "'Flag' is used as a bit and, at line 8" in d.message
               for d in diags)
    assert sum("unknown symbol 'Flag'" in d.message for d in diags) == 2


def test_a_table_symbol_wins_and_nothing_is_reported_without_unknown_names() -> None:
    plc = plcrt.load(ob1("LD Start\n= Q0.0"), symbols="Start\tI0.0\n", auto_symbols=True)
    assert assigned(plc) == {} and not [d for d in plc.diagnostics if d.code == "auto-symbol"]


def test_without_the_option_an_unknown_symbol_is_still_an_error() -> None:
    with pytest.raises(PlcCompileError, match="unknown symbol 'Start'"):
        plcrt.load(ob1("LD Start\n= Q0.0"))


def test_check_prints_every_assignment(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = tmp_path / "p.awl"
    prog.write_text(ob1("LD 启动\n= 电机"), encoding="utf-8")
    assert main(["check", "--auto-symbols", str(prog)]) == 0
    err = capsys.readouterr().err
    assert "'启动' is not in a symbol table; it is M31.7" in err
    assert "'电机' is not in a symbol table; it is M31.6" in err
    assert err.splitlines()[-1].startswith(f"{prog}: 0 errors, 2 warnings")


@pytest.mark.skipif(not (CORPUS / "bulaofen0036-coder__Smart200-MicroWIN-MCP__roundtrip.awl")
                    .exists(), reason="the public corpus is not beside the project")
def test_the_corpus_export_without_its_symbol_table_has_no_unknown_symbol_left() -> None:
    """The largest SMART export was published without its table: with
    --auto-symbols none of its symbols stays unknown."""
    path = CORPUS / "bulaofen0036-coder__Smart200-MicroWIN-MCP__roundtrip.awl"
    try:
        plcrt.load(path, auto_symbols=True)
    except PlcCompileError as e:
        assert not [d for d in e.diagnostics if "unknown symbol" in d.message]
        assert not [d for d in e.diagnostics if d.code == "auto-symbol"
                    and "gets no address" in d.message]


# -- runs of memory: the instruction's spans (plcrt.isa.registry.Span) -----------
def test_a_bit_range_gets_whole_bytes_where_the_range_fits_and_the_program_loads() -> None:
    """RI Lamps, 8 needs 8 output bits from Lamps: Q15.0 (Q15.7 would run
    past the Q area); S Flags, 20 needs three whole M bytes: M29.0..M31.3."""
    plc = plcrt.load(ob1("LD SM0.0\nRI Lamps, 8\nS Flags, 20", "LD Flags\n= Q0.0"),
                     auto_symbols=True)
    assert assigned(plc) == {"Lamps": "Q15.0", "Flags": "M29.0"}
    messages = [d.message for d in plc.diagnostics if d.code == "auto-symbol"]
    assert "it is Q15.0 (an output bit (immediate), 8 bits from it" in messages[0]
    plc.scan()
    assert plc.read("MB29") == plc.read("MB30") == 255 and plc.read("MB31") == 0x0F


def test_every_instruction_with_a_run_reserves_the_whole_run() -> None:
    """Block moves (N constant or not), FILL, SHRB, a table, the clock
    buffer and an ASCII field get room for everything they reach, and the
    program loads and runs."""
    plc = plcrt.load(ob1(
        "LD SM0.0\nBMW Src, Dst, 10\nFILL +7, Filled, 3\nBMB Bytes, VB0, VB9",
        "LD I0.0\nSHRB I0.1, Reg, 16",
        "LD SM0.0\nATT VW0, Tbl\nTODR Clock\nITA VW0, Text, 16#00"), auto_symbols=True)
    got = assigned(plc)
    v = {name: int(addr[2:]) for name, addr in got.items() if addr.startswith("V")}
    runs = {"Src": 20, "Dst": 20, "Filled": 6, "Bytes": 255, "Tbl": 204, "Clock": 8, "Text": 8}
    spans = sorted((v[n], v[n] + size) for n, size in runs.items())
    assert all(a_end <= b_start for (_, a_end), (b_start, _) in zip(spans, spans[1:]))
    assert spans[-1][1] <= 10240
    assert got["Reg"] == "M30.0"            # 16 bits: M30.0..M31.7
    plc.scan()


def test_the_programs_own_ranges_are_not_given_away() -> None:
    """S M30.0, 16 takes M30 and M31: the first free bit is M29.7."""
    plc = plcrt.load(ob1("LD SM0.0\nS M30.0, 16", "LD Start\n= Q0.0"), auto_symbols=True)
    assert assigned(plc) == {"Start": "M29.7"}


# -- Name:ADDR, Micro/WIN's symbol with its address ------------------------------
def test_a_symbol_written_with_its_address_gets_that_address() -> None:
    plc = plcrt.load(ob1("LD Start:M2.0\n= Motor", "LD Start\n= Q0.0"), auto_symbols=True)
    got = assigned(plc)
    assert got["Start:M2.0"] == got["Start"] == "M2.0"
    assert got["Motor"] == "M31.7"
    message = next(d.message for d in plc.diagnostics if "Start:M2.0" in d.message)
    assert "it is M2.0 (the address written with 'Start')" in message
    plc.write("M2.0", 1)
    plc.scan()
    assert plc.read("Motor") == 1 and plc.read("Q0.0") == 1


#: a plain operand for each role, for instructions whose other operands
#: only need to be valid (counts are 8: the constant-count case)
_PLAIN = {"BIT_R": "M0.0", "BIT_W": "M0.1", "BIT_TC": "M0.2", "IBIT": "I0.0", "QBIT": "Q0.0",
          "B_R": "8", "B_W": "VB0", "W_R": "+8", "W_W": "VW2", "D_R": "+8", "D_W": "VD4",
          "R_R": "1.0", "R_W": "VD8", "N": "8"}


def _span_cases() -> list[tuple[str, int]]:
    from plcrt.isa.registry import REGISTRY, load_families
    load_families()
    return [(m, span.at) for m, spec in sorted(REGISTRY.items()) for span in spec.spans]


@pytest.mark.parametrize("mnemonic, at", _span_cases())
def test_every_run_an_instruction_declares_fits_where_its_symbol_is_placed(
        mnemonic: str, at: int) -> None:
    """For each instruction with a run (its Span), a symbol at the run's
    start is placed where the run fits: the program loads and scans."""
    from plcrt.isa.registry import lookup
    spec = lookup(mnemonic)
    assert spec is not None
    runs = {span.at for span in spec.spans}
    ops = [("Run" if i == at else f"Other{i}" if i in runs else _PLAIN[role.name])
           for i, role in enumerate(spec.roles)]
    plc = plcrt.load(ob1(f"LD SM0.0\n{mnemonic} {', '.join(ops)}"), auto_symbols=True)
    assert "Run" in assigned(plc)
    plc.scan()
