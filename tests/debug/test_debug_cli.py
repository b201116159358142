"""``plcrt debug`` on the command line (:mod:`plcrt.debug.cli`): scripts,
piped stdin, a (simulated) terminal, options and exit statuses.

``plcrt.cli.main`` is called in-process; no path may print a traceback.
"""

from __future__ import annotations

import builtins
import io
import sys
from pathlib import Path

import pytest
from debug_helpers import DATA, ROOT, check_golden

from plcrt.cli import main

STEPS = str(DATA / "steps.awl")
FAULT = str(DATA / "fault.awl")


@pytest.fixture(autouse=True)
def _in_root(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def script(tmp_path: Path, text: str) -> str:
    path = tmp_path / "session.plcrt"
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_script_file_with_break_and_watch_options(tmp_path: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "debug", STEPS, "--break", "OB1/4", "--watch", "VW0",
                             "--watch", "Q0.1", "--script", script(tmp_path, (
                                 "# from a file\nset I0.0=1\nscan\nprint Q0.0 Q0.1\n"
                                 "continue\nbreaks\n")))
    assert (code, err) == (0, "")
    check_golden("cli_script", out)
    assert out.startswith("(plcrt) set I0.0=1\nI0.0 = 1\n(plcrt) scan\n"
                          'break at OB1/4 "Second output" (t=0.000 s, scan 1)\n')
    assert "(plcrt OB1/4) print Q0.0 Q0.1\nQ0.0 = 1\nQ0.1 = 0\n" in out
    assert out.endswith("(plcrt) breaks\nbreakpoint before OB1/4 \"Second output\"\n")
    assert "\x1b[" not in out        # plain text when not on a terminal


def test_stdin_pipe(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(sys, "stdin", io.StringIO("set I0.0=1\nscan 3\nprint VW0 Q0.1\n"))
    code, out, err = run_cli(capsys, "debug", STEPS)
    assert (code, err) == (0, "")
    assert out == ("(plcrt) set I0.0=1\nI0.0 = 1\n(plcrt) scan 3\nt=0.030 s  scan 3  RUN\n"
                   "(plcrt) print VW0 Q0.1\nVW0 = 3\nQ0.1 = 1\n")


def test_em253_from_the_command_line(monkeypatch: pytest.MonkeyPatch,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(sys, "stdin", io.StringIO("set M2.0=1\nrun 10s\naxes\n"))
    code, out, _ = run_cli(capsys, "debug", "programs/em253/pos_goto_r.awl", "--plant",
                           "programs/em253/plant.toml", "--scan-ms", "1")
    assert code == 0
    assert out.endswith("(plcrt) axes\nslot  axis  position  mechanical  speed Hz  status\n"
                        "   0     0    620000      620000     80000  moving\n"
                        "   0     1         0           0         0  stopped\n")


def test_exit_status_1_after_an_error(tmp_path: Path,
                                      capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(capsys, "debug", STEPS, "--script",
                           script(tmp_path, "scan\nbogus\nscan\n"))
    assert code == 1
    assert "(plcrt) bogus\nerror: unknown command 'bogus' (type 'help' for the list)\n" in out
    assert out.endswith("t=0.020 s  scan 2  RUN\n")   # the session went on


def test_exit_status_2_after_a_fault(tmp_path: Path,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(capsys, "debug", FAULT, "--script",
                           script(tmp_path, "set VB500=200 I0.1=1\nscan\nprint VW0\n"))
    assert code == 2
    assert ("tests/debug/data/fault.awl:9:1: error: block move runs past the end of its "
            "memory area [OB1 network 2]\n") in out
    assert out.endswith("(plcrt) print VW0\nVW0 = 1\n")


@pytest.mark.parametrize("argv, message", [
    (["--break", "OB1/7"],
     "plcrt: error: --break OB1/7: no network OB1/7 (networks of OB1: 1..4)"),
    (["--break", "SBR9/1"],
     "plcrt: error: --break SBR9/1: no block 'SBR9' in the program (blocks: OB1, SBR0)"),
    (["--watch", "XYZ"], "plcrt: error: --watch XYZ: 'XYZ' is not an address"),
    (["--script", "no/such/file"],
     "plcrt: error: cannot read the script no/such/file: no such file"),
])
def test_bad_options_exit_1(argv: list[str], message: str,
                            capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "debug", STEPS, *argv)
    assert code == 1
    assert out == ""
    assert err.strip() == message


def test_bad_program_exit_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.awl"
    bad.write_text("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD I0.0\nFOO Q0.0\n"
                   "END_ORGANIZATION_BLOCK\n", encoding="utf-8")
    code, out, err = run_cli(capsys, "debug", str(bad), "--script", str(bad))
    assert code == 1
    assert out == ""
    assert "error: unknown instruction 'FOO' [OB1 network 1]" in err
    code, _, err = run_cli(capsys, "debug", "missing.awl")
    assert code == 1 and "missing.awl" in err


def test_program_without_ob1_exit_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sbr = tmp_path / "sbr.awl"
    sbr.write_text("SUBROUTINE_BLOCK S:SBR0\nBEGIN\nNetwork 1\nLD SM0.0\n= Q0.0\n"
                   "END_SUBROUTINE_BLOCK\n", encoding="utf-8")
    code, _, err = run_cli(capsys, "debug", str(sbr))
    assert code == 1
    assert "no main program block (OB1)" in err


def test_terminal_session_prompts_without_echo(monkeypatch: pytest.MonkeyPatch,
                                               tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    """stdin a terminal: a banner, the prompt passed to input(), no echo,
    Ctrl-C at the prompt drops the line, Ctrl-D ends the session."""
    import plcrt.debug.cli as debug_cli

    monkeypatch.setenv("HOME", str(tmp_path))     # the readline history goes here
    monkeypatch.setattr(debug_cli, "_isatty", lambda stream: True)
    answers: list[object] = ["set I0.0=1", KeyboardInterrupt(), "break 4", "scan",
                             "print Q0.1", "c", "show 1", EOFError()]
    prompts: list[str] = []

    def fake_input(prompt: str = "") -> str:
        prompts.append(prompt)
        answer = answers.pop(0)
        if isinstance(answer, BaseException):
            raise answer
        return str(answer)

    monkeypatch.setattr(builtins, "input", fake_input)
    code, out, _ = run_cli(capsys, "debug", STEPS)
    assert code == 0
    assert prompts == ["(plcrt) ", "(plcrt) ", "(plcrt) ", "(plcrt) ", "(plcrt OB1/4) ",
                       "(plcrt OB1/4) ", "(plcrt) ", "(plcrt) "]
    assert out.startswith("plcrt debug: tests/debug/data/steps.awl (5 network(s), scan 10 ms); "
                          "type 'help' for the commands\nI0.0 = 1\n^C\n")
    assert "(plcrt) " not in out                    # input() showed the prompts
    assert "Q0.1 = 0\n" in out
    assert "\x1b[" in out                           # the ladder view is in colour


@pytest.mark.parametrize("bad, reason", [("/dev/zero", "not a regular file"),
                                         ("missing.plcrt", "no such file")])
def test_script_that_is_not_a_readable_regular_file(bad: str, reason: str,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """--script reads only a regular file of at most the file size limit:
    /dev/zero is refused at once instead of being read without end."""
    code, out, err = run_cli(capsys, "debug", STEPS, "--script", bad)
    assert code == 1 and out == ""
    assert f"cannot read the script {bad}: " in err and reason in err
