"""The debugger with untrusted input: control characters in program text and
in commands, bytes that are not UTF-8 on stdin, and values the memory cannot
hold.  Nothing may reach the transcript raw, and no line may end the session.
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import pytest
from debug_helpers import DATA, ROOT

import plcrt
from plcrt.cli import main
from plcrt.debug import Session

STEPS = str(DATA / "steps.awl")
TITLE_PROGRAM = ("ORGANIZATION_BLOCK OB1\nTITLE=block \x1b[2J\nBEGIN\n"
                 "Network 1 // ti\x1b]0;x\x07tle\ttab\nLD     I0.0\n=      Q0.0\n"
                 "END_ORGANIZATION_BLOCK\n")


@pytest.fixture(autouse=True)
def _in_root(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def _raw_controls(text: str) -> list[str]:
    return [c for c in text if (ord(c) < 32 and c != "\n") or 0x7f <= ord(c) < 0xa0]


def _run(program: str, lines: list[str]) -> tuple[str, int]:
    plc = plcrt.load(program, instrument=True)
    out = io.StringIO()
    status = Session(plc, out, echo=True).run(lines)
    return out.getvalue(), status


def test_titles_and_commands_are_escaped_in_the_transcript() -> None:
    out, status = _run(TITLE_PROGRAM, ["break 1", "scan", "show", "status", "continue",
                                       "print \x1b[2J", "bogus\x07"])
    assert _raw_controls(out) == []
    assert 'break at OB1/1 "ti\\x1b]0;x\\x07tle tab" (t=0.000 s, scan 1)' in out
    assert "OB1  block \\x1b[2J\n" in out              # the block heading of 'show'
    assert "(plcrt) print \\x1b[2J\nerror: '\\x1b[2J' is not an address\n" in out
    assert "(plcrt) bogus\\x07\nerror: unknown command 'bogus\\x07'" in out
    assert status == 1


def test_stl_fallback_escapes_program_text() -> None:
    from plcrt.debug.panels import draw_network
    plc = plcrt.load(TITLE_PROGRAM)
    pou = plc.program.pous[0]
    out = io.StringIO()
    draw_network(out, plc, pou, pou.networks[0], view=False, color=False)
    assert out.getvalue().startswith("Network 1  ti\\x1b]0;x\\x07tle tab\n")
    assert _raw_controls(out.getvalue()) == []


def test_undecodable_stdin_fails_one_command_not_the_session(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    # A strict UTF-8 stdin (PYTHONIOENCODING=utf-8) used to raise at the first
    # read, losing every command: an internal error and no transcript.
    raw = b"set I0.0=1\nprint \xff\xfe\nscan\nprint Q0.0\n"
    stdin = io.TextIOWrapper(io.BytesIO(raw), encoding="utf-8", errors="strict")
    monkeypatch.setattr(sys, "stdin", stdin)
    code = main(["debug", STEPS])
    out, err = capsys.readouterr()
    assert (code, err) == (1, "")
    assert "(plcrt) print \ufffd\ufffd\nerror: '\ufffd\ufffd' is not an address\n" in out
    assert out.endswith("(plcrt) print Q0.0\nQ0.0 = 1\n")


def test_unforce_by_symbol_releases_a_force_made_by_address(tmp_path: Path) -> None:
    symbols = tmp_path / "s.sym"
    symbols.write_text("Start\tI0.0\tstart button\n", encoding="utf-8")
    plc = plcrt.load(Path(STEPS), symbols=symbols, instrument=True)
    out = io.StringIO()
    status = Session(plc, out, echo=True).run(
        ["force I0.0 1", "force Start 0", "forces", "unforce start", "unforce Start",
         "forces"])
    text = out.getvalue()
    assert "(plcrt) forces\nStart = 0\n" in text           # one force, the last name
    assert "(plcrt) unforce start\nerror: 'start' is not an address" in text  # case counts
    assert "(plcrt) unforce Start\nreleased Start (from the next scan on it reads" in text
    assert text.endswith("(plcrt) forces\nno forces\n")
    assert status == 1


@pytest.mark.parametrize("command, message", [
    ("set I0.0=2", "error: I0.0: a bit takes 0 or 1, got 2"),
    ("force Q0.0 7", "error: Q0.0: a bit takes 0 or 1, got 7"),
    ("set VD0=1e39", "error: VD0: 1e39 is out of the range of a REAL"),
    ("set VD0:REAL=-1e39", "error: VD0:REAL: -1e39 is out of the range of a REAL"),
    # used to store infinity (the literal overflowed to inf before any check)
    ("set VD0=1e999", "error: VD0: 1e999 is out of the range of a REAL"),
    ("set VB0=-1", "error: VB0: -1 does not fit in a byte (BYTE), which takes 0 to 255"),
    ("set SM0.0=0", "error: SM0.0: SMB0 (SM0.0 always on"),
    # used to end in "internal error" (more digits than int() converts)
    ("set VW0=" + "9" * 5000, "error: VW0: bad value '99999999999999999999...' (5000 "
                              "characters): too long for a number"),
    ("set VW0=" + "9" * 60, "error: VW0: 999999999999999999999999999999999999999999999999999999999999"
                            " does not fit in a word"),
    ("run until VW0 >=", "error: cannot read the condition 'VW0 >='"),
])
def test_values_and_conditions_that_cannot_be_used(command: str, message: str) -> None:
    out, status = _run(STEPS, [command, "print VW0"])
    assert message in out
    assert "internal error" not in out
    assert out.endswith("(plcrt) print VW0\nVW0 = 0\n") and status == 1
