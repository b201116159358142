"""A subroutine-only export runs with ``--entry BLOCK`` (``plcrt.load(...,
entry=BLOCK)``): the chosen block runs as the main program each scan, with
the main program's local memory; without OB1 and without --entry the error
names the blocks that could run.  run, trace, debug and serve take it."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

import plcrt
from plcrt.cli import _build_parser, load_from_args, main

HERE = Path(__file__).resolve().parent
SBR_ONLY = str(HERE / "data" / "sbr_only.awl")
SUBROUTINE = str(HERE.parents[1] / "programs" / "subroutine.awl")
BLOCKS = "SBR0 (COUNT_UP), SBR1 (DOUBLE)"


def _cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_without_ob1_and_entry_the_error_names_the_blocks(
        capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = _cli(capsys, "run", SBR_ONLY, "--scans", "1")
    assert code == 1
    assert f"{SBR_ONLY}:1:1: error: the program has no main program block (OB1)" in err
    assert "--entry BLOCK" in err and f"its blocks: {BLOCKS} [SBR0]" in err
    assert "INT0" not in err        # an interrupt routine is not a main program


@pytest.mark.parametrize("entry", ["SBR0", "sbr0", "COUNT_UP", "count_up"])
def test_run_entry_by_number_or_name(capsys: pytest.CaptureFixture[str], entry: str) -> None:
    code, out, err = _cli(capsys, "run", SBR_ONLY, "--entry", entry, "--scans", "3",
                          "--watch", "VW0", "--watch", "VW2", "--watch", "Q0.0", "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert obj["values"] == {"VW0": 3, "VW2": 6, "Q0.0": 1}
    assert "note" not in err and "error" not in err


def test_entry_replaces_ob1_and_parameters_are_its_l_addresses(
        capsys: pytest.CaptureFixture[str]) -> None:
    """SCALE's IN parameters Raw, Limit are LW0, LW2, its OUT Value, High
    LW4, L6.0: --set writes them before the first scan, OB1 does not run."""
    code, out, err = _cli(capsys, "run", SUBROUTINE, "--entry", "SCALE", "--scans", "2",
                          "--set", "LW0=3200", "--set", "LW2=50", "--set", "AIW0=32000",
                          "--watch", "LW4", "--watch", "L6.0", "--watch", "VW10", "--json")
    assert code == 0, err
    assert json.loads(out)["values"] == {"LW4": 100, "L6.0": 1, "VW10": 0}


@pytest.mark.parametrize("entry, message", [
    ("SBR9", f"entry 'SBR9': the program has no such block; the blocks that can run as "
             f"the main program: {BLOCKS}"),
    ("INT0", "entry 'INT0': INT0 is an interrupt routine, which runs on its event"),
    ("x" * 100, "entry must name a block"),
])
def test_a_bad_entry_is_an_error_naming_the_blocks(
        capsys: pytest.CaptureFixture[str], entry: str, message: str) -> None:
    code, out, err = _cli(capsys, "run", SBR_ONLY, "--entry", entry, "--scans", "1")
    assert code == 1
    assert err.startswith(f"plcrt: error: {message}")
    assert "Traceback" not in err


def test_trace_entry(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    csv = tmp_path / "t.csv"
    code, out, err = _cli(capsys, "trace", SBR_ONLY, "--entry", "SBR0", "--scans", "3",
                          "--signal", "VW0", "--csv", str(csv), "--quiet")
    assert code == 0, err
    assert csv.read_text(encoding="utf-8").splitlines()[-1].endswith(",3")


def test_debug_entry(capsys: pytest.CaptureFixture[str],
                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("sys.stdin", io.StringIO("scan 2\nprint VW2\n"))
    code, out, err = _cli(capsys, "debug", SBR_ONLY, "--entry", "COUNT_UP")
    assert code == 0, err
    assert "VW2 = 4" in out


def test_serve_loads_the_entry() -> None:
    """serve loads through the same helper and option as run."""
    args = _build_parser().parse_args(["serve", SBR_ONLY, "--entry", "SBR0"])
    plc = load_from_args(args)
    plc.run(scans=2)
    assert plc.main_block == "SBR0" and plc["VW0"] == 2


def test_the_api_entry_survives_fork_and_keeps_ob1_as_default() -> None:
    plc = plcrt.load(SBR_ONLY, entry="count_up")
    assert plc.main_block == "SBR0"
    assert [d for d in plc.diagnostics if d.code == "no-ob1"] == []
    plc.run(scans=2)
    twin = plc.fork()
    twin.run(scans=1)
    assert (plc["VW0"], twin["VW0"], twin.main_block) == (2, 3, "SBR0")
    assert plcrt.load(SUBROUTINE).main_block == "OB1"
