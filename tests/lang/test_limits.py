"""Limits on hostile input: file size, special files, instruction count.

Each test pins one refusal: the error is a PlcError naming the file (or the
instruction) and the limit, and it comes before memory or time run out.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

import plcrt
from plcrt import PlcCompileError, PlcConfigError, PlcSyntaxError
from plcrt.cli import main
from plcrt.lang.limits import MAX_FILE_MB, file_limit, read_capped

from stl_helpers import ob1_text


def test_a_file_over_the_limit_is_refused_naming_file_and_limit(tmp_path: Path) -> None:
    """A program file larger than max_file_mb is refused before parsing."""
    path = tmp_path / "big.awl"
    path.write_text(ob1_text("LD I0.0\n= Q0.0") + "// x\n" * 30_000, encoding="utf-8")
    with pytest.raises(PlcSyntaxError) as info:
        plcrt.load(path, max_file_mb=0.1)
    err = info.value
    assert err.loc is not None and err.loc.file == str(path) and err.loc.line == 1
    assert "larger than the limit of 0.1 MB (104857 bytes)" in err.message
    assert "--max-file-mb" in err.message


def test_raising_the_limit_loads_the_same_file(tmp_path: Path) -> None:
    """max_file_mb raises the limit: the same file then loads and runs."""
    path = tmp_path / "big.awl"
    path.write_text(ob1_text("LD SM0.0\n= Q0.0") + "// x\n" * 30_000, encoding="utf-8")
    plc = plcrt.load(path, max_file_mb=1)
    plc.scan()
    assert plc["Q0.0"] == 1


def test_the_default_limits_admit_the_benchmark_programs() -> None:
    """16 MB by default: far above any S7-200 export, and room for the
    generated load benchmarks of 100 000 statements (about 1.3 MB)."""
    from plcrt.lang.limits import MAX_INSTRUCTIONS
    assert MAX_FILE_MB == 16.0 and file_limit() == 16 * 1024 * 1024
    assert MAX_INSTRUCTIONS >= 100_000


def test_read_capped_reads_at_most_limit_plus_one_bytes(tmp_path: Path) -> None:
    """Exactly the limit is fine; one byte more is refused."""
    path = tmp_path / "f.awl"
    path.write_bytes(b"x" * 100)
    assert read_capped(path, 100) == b"x" * 100
    with pytest.raises(PlcSyntaxError, match="larger than the limit"):
        read_capped(path, 99)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
def test_dev_zero_is_refused_at_once() -> None:
    """A device is not a program file: refused without reading it."""
    start = time.perf_counter()
    with pytest.raises(PlcSyntaxError, match="not a regular file") as info:
        plcrt.load(Path("/dev/zero"))
    assert time.perf_counter() - start < 5
    assert info.value.loc is not None and info.value.loc.file == "/dev/zero"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_is_refused_without_blocking(tmp_path: Path) -> None:
    """Opening a FIFO with no writer would block; it is refused instead."""
    fifo = tmp_path / "pipe.awl"
    os.mkfifo(fifo)
    with pytest.raises(PlcSyntaxError, match="not a regular file"):
        plcrt.load(fifo)


def test_symbol_and_data_files_share_the_limit(tmp_path: Path) -> None:
    """The limit applies to the symbol table and the data block too."""
    sym = tmp_path / "s.sdf"
    sym.write_text("Start\tI0.0\n" * 20_000, encoding="utf-8")
    with pytest.raises(PlcSyntaxError, match="larger than the limit") as info:
        plcrt.load(ob1_text("LD I0.0\n= Q0.0"), symbols=sym, max_file_mb=0.1)
    assert info.value.loc is not None and info.value.loc.file == str(sym)
    data = tmp_path / "d.txt"
    data.write_text("VB0 1\n" * 30_000, encoding="utf-8")
    with pytest.raises(PlcSyntaxError, match="larger than the limit"):
        plcrt.load(ob1_text("LD I0.0\n= Q0.0"), data=data, max_file_mb=0.1)


def test_program_text_given_directly_has_the_limit_too() -> None:
    text = ob1_text("LD I0.0\n= Q0.0") + "// x\n" * 30_000
    with pytest.raises(PlcSyntaxError, match="characters long, more than the limit"):
        plcrt.load(text, max_file_mb=0.1)


@pytest.mark.parametrize("bad", [0, -1, float("nan"), float("inf"), "1", True])
def test_a_bad_limit_is_a_config_error(bad: object) -> None:
    with pytest.raises(PlcConfigError, match="max-file-mb"):
        plcrt.load(ob1_text("LD I0.0\n= Q0.0"), max_file_mb=bad)


def test_too_many_instructions_is_a_compile_error_at_the_first_one_past(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The instruction cap keeps compile memory bounded; the error points at
    the first instruction past the limit."""
    monkeypatch.setattr("plcrt.compiler.MAX_INSTRUCTIONS", 5)
    text = ob1_text("LD I0.0\n= Q0.0", "LD I0.1\n= Q0.1", "LD I0.2\n= Q0.2")
    with pytest.raises(PlcCompileError) as info:
        plcrt.load(text)
    err = info.value
    assert "6 instructions, more than plcrt compiles (5)" in str(err)
    assert err.loc is not None and (err.loc.line, err.loc.block, err.loc.network) == \
        (11, "OB1", 3)


def test_cli_max_file_mb(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--max-file-mb lowers or raises the limit; the message names file and limit."""
    path = tmp_path / "p.awl"
    path.write_text(ob1_text("LD I0.0\n= Q0.0"), encoding="utf-8")
    assert main(["check", str(path), "--max-file-mb", "0.00001"]) == 1
    err = capsys.readouterr().err
    assert f"{path}:1:1: error: cannot read file: it is larger than the limit of " \
           f"9.537e-06 MB (10 bytes)" in err
    assert main(["check", str(path), "--max-file-mb", "2"]) == 0


# -- long program text in messages -------------------------------------------------
LONG = "X" * 200_000


@pytest.mark.parametrize("network", [
    f"LD {LONG}",                       # unknown symbol
    f"{LONG} I0.0",                     # unknown instruction
    f"LD I0.0\nJMP {LONG}",             # bad label
    f"LD '{LONG}'\n= Q0.0",             # literal where a bit is needed
    f"LD I0.0\n= #{LONG}",              # unknown local variable
    f"LD I0.0\nCALL {LONG}",            # unknown subroutine
    f"LD I0.0\nMOVW 16#{'F' * 5000}, VW0",   # a constant of thousands of digits
    f"LD V{'9' * 5000}.0\n= Q0.0",      # an address of thousands of digits
    f"LD I0.0; {LONG}\n= Q0.0",         # a syntax error
])
def test_messages_quote_at_most_40_characters_of_program_text(network: str) -> None:
    """Every message quoting program text shows 40 characters and an ellipsis."""
    with pytest.raises(plcrt.PlcError) as info:
        plcrt.load(ob1_text(network))
    text = str(info.value)
    assert "\u2026" in text
    assert len(text) < 300, text[:300]


def test_numbers_of_thousands_of_digits_are_range_errors_not_crashes(tmp_path: Path) -> None:
    """Python refuses int() of more than 4300 digits; plcrt reports an
    out-of-range number instead (operands, network and block numbers, data)."""
    digits = "9" * 5000
    text = (f"ORGANIZATION_BLOCK OB{digits}\nBEGIN\nNetwork {digits}\nLD I0.0\n"
            f"END_ORGANIZATION_BLOCK\n")
    with pytest.raises(PlcSyntaxError) as info:
        plcrt.load(text)
    messages = [d.message for d in info.value.diagnostics]
    assert any(m.startswith("block number of 'OB9999") and "out of range" in m
               for m in messages)
    assert any(m.startswith("network number '9999") and "out of range" in m for m in messages)
    data = tmp_path / "d.txt"
    data.write_text(f"VB0 {digits}\nVB{digits} 1\n", encoding="utf-8")
    with pytest.raises(PlcSyntaxError) as info:
        plcrt.load(ob1_text("LD I0.0\n= Q0.0"), data=data)
    messages = [d.message for d in info.value.diagnostics]
    assert messages[0].startswith("value 9999") and messages[0].endswith("out of range for VB")
    assert messages[1].startswith("address VB9999") and "out of range" in messages[1]


# -- many errors --------------------------------------------------------------------
def _many_errors(tmp_path: Path, n: int = 250) -> Path:
    path = tmp_path / "many.awl"
    path.write_text(ob1_text(*["LDX I0.0"] * n), encoding="utf-8")
    return path


def test_plc_error_str_lists_the_first_100_and_counts_the_rest(tmp_path: Path) -> None:
    with pytest.raises(PlcCompileError) as info:
        plcrt.load(_many_errors(tmp_path))
    lines = str(info.value).splitlines()
    assert len(lines) == 101
    assert lines[-1] == "... and 150 more errors not listed (the first 100 are shown)"
    assert len(info.value.diagnostics) == 250   # all of them are still there


def test_check_prints_the_first_100_errors_and_a_summary(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _many_errors(tmp_path)
    assert main(["check", str(path)]) == 1
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 102
    assert lines[99].startswith(f"{path}:202:1: error: unknown instruction 'LDX'")
    assert lines[100] == "plcrt: ... and 150 more errors not listed (the first 100 are shown)"
    assert lines[101] == f"{path}: 250 errors, 0 warnings"


def test_run_caps_the_list_too(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(_many_errors(tmp_path)), "--scans", "1"]) == 1
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 101 and lines[-1].startswith("plcrt: ... and 150 more errors")


def test_errors_are_listed_before_a_flood_of_warnings() -> None:
    """With more diagnostics than the cap, errors are kept first."""
    from plcrt.errors import Diagnostic, SourceLoc, capped
    diags = [Diagnostic("warning", f"w{i}", SourceLoc("f", i, 1)) for i in range(1, 150)]
    diags.append(Diagnostic("error", "the one error", SourceLoc("f", 500, 1)))
    kept, more = capped(diags, ordered=True)
    assert len(kept) == 100 and kept[-1].message == "the one error"
    assert more == "... and 50 more warnings not listed (the first 100 are shown)"


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
def test_a_plant_file_has_the_same_limits() -> None:
    """--plant /dev/zero is refused, not read for ever."""
    with pytest.raises(PlcConfigError, match="/dev/zero: cannot read plant file: it is not "
                                             "a regular file"):
        plcrt.load(ob1_text("LD I0.0\n= Q0.0"), plant=Path("/dev/zero"))


def test_too_many_networks_is_a_compile_error_at_the_first_one_past(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Even empty networks cost a generated function each: they are capped too."""
    monkeypatch.setattr("plcrt.compiler.MAX_NETWORKS", 2)
    with pytest.raises(PlcCompileError) as info:
        plcrt.load(ob1_text("LD I0.0\n= Q0.0", "LD I0.1\n= Q0.1", "LD I0.2\n= Q0.2"))
    err = info.value
    assert err.message == "the program has 3 networks, more than plcrt compiles (2)"
    assert err.loc is not None and (err.loc.line, err.loc.network) == (9, 3)


def test_a_long_block_name_is_quoted_short_in_call_errors() -> None:
    name = "Y" * 3000
    text = (ob1_text("LD I0.0\nCALL SBR0, 1")
            + f"SUBROUTINE_BLOCK {name}:SBR0\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\n"
              f"END_SUBROUTINE_BLOCK\n")
    with pytest.raises(PlcCompileError) as info:
        plcrt.load(text)
    assert "SBR0 (" + "Y" * 40 + "\u2026) takes 0 parameter(s)" in str(info.value)
    assert len(str(info.value)) < 300
