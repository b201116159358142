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


def test_the_default_limit_is_one_megabyte() -> None:
    assert MAX_FILE_MB == 1.0 and file_limit() == 1024 * 1024


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
    assert "6 instructions, more than plcrt compiles (5)" in err.message
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
