"""Every command that reads a program takes the same program options.

README.md ("Command line") promises that the commands reading a program
(check, run, dump, show, debug, trace) all take ``--symbols F``,
``--data F``, ``--cpu NAME`` and ``--plant F``: a command line that works
for ``check`` works when ``check`` is replaced by ``dump``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from plcrt.cli import _build_parser, main

ROOT = Path(__file__).resolve().parents[2]
PROGRAM_OPTIONS = {"--symbols", "--data", "--cpu", "--plant"}


def _program_commands() -> dict[str, argparse.ArgumentParser]:
    parser = _build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {name: p for name, p in sub.choices.items()
            if any(a.dest == "programs" for a in p._actions)}


def test_every_command_that_reads_a_program_is_known() -> None:
    assert sorted(_program_commands()) == ["check", "debug", "dump", "run", "serve", "show",
                                              "trace"]


@pytest.mark.parametrize("command", sorted(_program_commands()))
def test_command_takes_the_program_options(command: str) -> None:
    options = {s for a in _program_commands()[command]._actions for s in a.option_strings}
    assert PROGRAM_OPTIONS <= options


def test_dump_reads_the_data_block_and_reports_its_errors(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``dump --data`` loads the data block as ``check`` does: a good one
    leaves the dump as it is, a bad one is an input error with its line."""
    monkeypatch.chdir(ROOT)
    program = "programs/em253/pos_run.awl"
    assert main(["dump", program]) == 0
    plain = capsys.readouterr().out
    assert main(["dump", program, "--data", "programs/em253/pos_run.db"]) == 0
    assert capsys.readouterr() == (plain, "")
    bad = tmp_path / "bad.db"
    bad.write_text("VB0 1, 2\nVW99999 7\n", encoding="utf-8")
    assert main(["dump", program, "--data", str(bad)]) == 1
    out, err = capsys.readouterr()
    assert out == "" and f"{bad}:2:" in err and "Traceback" not in err
