"""``plcrt show``: LAD drawings on the command line, with status."""

from __future__ import annotations

from pathlib import Path

import pytest

from plcrt.cli import main

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def _in_repo(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def test_show_draws_every_network(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", "programs/seal_in.awl"]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    assert out.startswith("OB1 (MAIN)  Seal-in circuit")
    assert "Network 1  Motor seal-in" in out and "Network 2  Running lamp" in out
    assert "┠──┬──┤ ├──┬───┤/├────( )" in out
    assert "\x1b" not in out  # no colour codes when not a terminal


def test_show_status_after_scans(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", "programs/seal_in.awl", "--status", "--scans", "3",
                 "--set", "I0.0=1"]) == 0
    out, _ = capsys.readouterr()
    assert out.startswith("status after 3 scan(s), 0.03 s simulated, mode RUN")
    assert "┣━━┳━━┫█┣━━┳━━━┫/┣━━━━(█)" in out
    assert "\x1b" not in out


def test_show_status_seconds_and_network(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", "programs/timers.awl", "--status", "--seconds", "2.5",
                 "--set", "I0.0=1", "--network", "1", "--network", "OB1/2"]) == 0
    out, _ = capsys.readouterr()
    assert "T37=+24" in out
    assert "Network 1" in out and "Network 2" in out and "Network 3" not in out
    assert "┣━━━┫█┣━━━━(█)" in out  # T37 done: Q0.0 on


def test_show_subroutine_network_by_name(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", "programs/subroutine.awl", "--network", "SBR0/3",
                 "--network", "SCALE/1"]) == 0
    out, _ = capsys.readouterr()
    assert "SBR0 (SCALE)" in out and "Network 3  High limit" in out
    assert "┤>=I├" in out and "MOV_W" in out


def test_show_stl(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", "programs/seal_in.awl", "--stl"]) == 0
    out, _ = capsys.readouterr()
    assert "AN     I0.1" in out and "┃" not in out and "not LAD" not in out


def test_show_wide_rungs_are_not_wrapped(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", "programs/em253/pos_goto_r.awl", "--network", "2"]) == 0
    out, _ = capsys.readouterr()
    assert "+1000000─┤PosSet" in out
    assert all(line.startswith(("┃", "┠", "OB1", "Network")) for line in out.splitlines()
               if line)


@pytest.mark.parametrize("argv, message", [
    (["show", "programs/seal_in.awl", "--network", "OB1/9"], "OB1 has no network 9"),
    (["show", "programs/seal_in.awl", "--network", "SBR3/1"], "no block SBR3"),
    (["show", "programs/seal_in.awl", "--network", "x/y"], "use BLOCK/N"),
    (["show", "programs/seal_in.awl", "--set", "I0.0=1"], "only make(s) sense with --status"),
    (["show", "programs/seal_in.awl", "--status", "--set", "I0.0"], "needs ADDR=VALUE"),
    (["show", "programs/seal_in.awl", "--status", "--set", "I9.9=1"], "I9.9"),
    (["show", "programs/seal_in.awl", "--status", "--scans", "-1"], "must not be negative"),
    (["show", "no_such_file.awl"], "cannot read file"),
    (["show", "programs/seal_in.awl", "--scans", "1", "--seconds", "1"], "not allowed"),
])
def test_show_errors(argv: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 1
    out, err = capsys.readouterr()
    assert message in err
    assert "Traceback" not in err and out == ""


def test_show_status_needs_ob1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sbr = tmp_path / "sbr.awl"
    sbr.write_text("SUBROUTINE_BLOCK SBR0\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\n"
                   "END_SUBROUTINE_BLOCK\n", encoding="utf-8")
    assert main(["show", str(sbr)]) == 0
    capsys.readouterr()
    assert main(["show", str(sbr), "--status"]) == 1
    assert "OB1" in capsys.readouterr().err


def test_show_draws_the_blocks_that_parsed_when_others_have_syntax_errors(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A large export with a few broken lines still shows every block that
    parsed; the errors come first and the exit code says the input is bad."""
    main_file = tmp_path / "main.awl"
    main_file.write_text("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0 ;;\n"
                         "= Q0.0\nEND_ORGANIZATION_BLOCK\n"
                         "SUBROUTINE_BLOCK S:SBR0\nBEGIN\nNetwork 1 // kept\nLD I0.2\n"
                         "= Q0.2\nEND_SUBROUTINE_BLOCK\n", encoding="utf-8")
    other = tmp_path / "other.awl"
    other.write_text("SUBROUTINE_BLOCK T:SBR1\nBEGIN\nNetwork 1\nLD ,\n"
                     "END_SUBROUTINE_BLOCK\n", encoding="utf-8")
    assert main(["show", str(main_file), str(other)]) == 1
    out, err = capsys.readouterr()
    assert f"{main_file}:4:" in err and f"{other}:4:" in err   # both files' errors
    assert out.startswith("SBR0 (S)")
    assert "Network 1  kept" in out and "I0.2" in out
    assert "OB1" not in out and "SBR1" not in out
