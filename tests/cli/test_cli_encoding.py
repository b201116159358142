"""``--encoding`` on the commands that read programs, and what the command
line says about files that do not decode (:mod:`plcrt.lang.encoding`)."""

from __future__ import annotations

from pathlib import Path

import pytest

from plcrt.cli import main

DATA = Path(__file__).resolve().parents[1] / "lang" / "data" / "encodings"
DE_AWL, DE_SYM = str(DATA / "de_table.awl"), str(DATA / "de_table.sym")

#: each command that reads a program, with the options it needs to run
COMMANDS = {
    "check": [],
    "run": ["--scans", "1"],
    "dump": [],
    "show": [],
    "debug": [],
    "trace": ["--scans", "1", "--signal", "Q0.0"],
}


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_program_command_refuses_an_unknown_encoding(
        command: str, capsys: pytest.CaptureFixture[str]) -> None:
    """--encoding is accepted by each command and checked before loading."""
    code, out, err = run_cli(capsys, command, DE_AWL, *COMMANDS[command],
                             "--encoding", "klingon")
    assert code == 1
    assert "unknown encoding 'klingon'" in err


def test_run_decodes_program_and_table_in_one_encoding(
        capsys: pytest.CaptureFixture[str]) -> None:
    """The umlaut symbols of the German table resolve in the program."""
    code, out, err = run_cli(capsys, "run", DE_AWL, "--symbols", DE_SYM, "--scans", "1",
                             "--set", "Start_Förderband=1", "--watch", "Förderband_Ein",
                             "--json")
    assert code == 0, err
    assert '"Förderband_Ein": 1' in out


def test_dump_shows_the_lines_in_the_encoding_loaded_with(
        capsys: pytest.CaptureFixture[str]) -> None:
    """dump quotes the STL lines decoded as the program was (here a forced
    GBK), not with a new guess."""
    code, out, err = run_cli(capsys, "dump", DE_AWL, "--symbols", DE_SYM, "--encoding", "gbk")
    assert code == 0, err
    assert "LD     Start_F鰎derband" in out


def test_check_reports_a_file_that_does_not_decode(capsys: pytest.CaptureFixture[str]) -> None:
    """GNU-style location of the first bad byte and the encoding used."""
    ru = str(DATA / "ru_cp1251.awl")
    code, out, err = run_cli(capsys, "check", ru, "--encoding", "utf-8")
    assert code == 1
    assert f"{ru}:2:7: error: the file does not decode as UTF-8: byte 0xCE" in err


def test_check_notes_the_guess_after_a_syntax_error(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The note about a guessed encoding follows the syntax error."""
    path = tmp_path / "cz.awl"
    path.write_bytes(("ORGANIZATION_BLOCK MAIN:OB1\r\nBEGIN\r\nNetwork 1 // Čerpadlo\r\n"
                      "LD     I0.0 ;;\r\nEND_ORGANIZATION_BLOCK\r\n").encode("cp1250"))
    code, out, err = run_cli(capsys, "check", str(path))
    assert code == 1
    lines = err.splitlines()
    assert ": error: " in lines[0] and lines[0].startswith(f"{path}:4:")
    assert lines[1].startswith(f"{path}:4:")
    assert "note: the file was decoded as CP1252, a guess" in lines[1]
    code, out, err = run_cli(capsys, "check", str(path), "--encoding", "cp1250")
    assert "note:" not in err
