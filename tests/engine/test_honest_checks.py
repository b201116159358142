"""Honest checks: a program that cannot run is refused everywhere, each
structural problem is reported once, the watchdog names its loop, a data
block lists all its problems in one run, and long runs can be bounded in
wall-clock time.
"""

from __future__ import annotations

import io
from pathlib import Path

import pytest

import plcrt
from plcrt import PlcCompileError, PlcConfigError, PlcRuntimeError, PlcSyntaxError
from plcrt.cli import main
from plcrt.term.progress import WallTimeExceeded, run_with_progress

from stl_helpers import ob1_text

SBR = ("SUBROUTINE_BLOCK S:SBR0\nBEGIN\nNetwork 1\nLD SM0.0\n= Q0.0\n"
       "END_SUBROUTINE_BLOCK\n")


def _file(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# -- programs that cannot run -------------------------------------------------------
@pytest.mark.parametrize("text", ["", "// only a comment\n", "\n\n"])
def test_load_refuses_an_empty_program_at_line_1(tmp_path: Path, text: str) -> None:
    path = _file(tmp_path, "empty.awl", text)
    with pytest.raises(PlcCompileError) as info:
        plcrt.load(path)
    err = info.value
    assert err.loc is not None and (err.loc.file, err.loc.line) == (str(path), 1)
    assert "holds no program block" in err.message


def test_load_refuses_a_program_without_ob1_at_its_first_block(tmp_path: Path) -> None:
    """Scans of a program without OB1 would do nothing, and a test asserting
    that nothing changes would pass: load() refuses it."""
    path = _file(tmp_path, "sbr.awl", SBR)
    with pytest.raises(PlcCompileError) as info:
        plcrt.load(path)
    err = info.value
    assert err.loc is not None and (err.loc.line, err.loc.block) == (1, "SBR0")
    assert "no main program block (OB1), so there is nothing to run" in err.message


def test_library_true_compiles_a_subroutine_library(tmp_path: Path) -> None:
    plc = plcrt.load(_file(tmp_path, "sbr.awl", SBR), library=True)
    notes = [d for d in plc.diagnostics if d.severity == "note"]
    assert len(notes) == 1 and "checked as a subroutine library" in notes[0].message
    with pytest.raises(PlcCompileError, match="holds no program block"):
        plcrt.load("// nothing\n\n", library=True)


def test_the_library_and_its_main_program_load_together(tmp_path: Path) -> None:
    main_text = ob1_text("LD SM0.0\nCALL SBR0")
    plc = plcrt.load([main_text, _file(tmp_path, "sbr.awl", SBR)])
    plc.scan()
    assert plc["Q0.0"] == 1


def test_check_of_a_library_is_ok_with_a_note(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    path = _file(tmp_path, "sbr.awl", SBR)
    assert main(["check", str(path)]) == 0
    err = capsys.readouterr().err
    assert (f"{path}:1:1: note: no main program block (OB1): checked as a subroutine "
            f"library, which cannot run on its own [SBR0]") in err
    assert f"{path}: 0 errors, 0 warnings (1 block(s)" in err


@pytest.mark.parametrize("text", ["", "// comments only\n"])
def test_check_of_a_file_without_blocks_is_an_error(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str) -> None:
    path = _file(tmp_path, "empty.awl", text)
    assert main(["check", str(path)]) == 1
    err = capsys.readouterr().err
    assert f"{path}:1:1: error: the file holds no program block" in err


@pytest.mark.parametrize("command", [["run", "--scans", "1"], ["trace", "--signal", "Q0.0",
                                                                "--scans", "1"],
                                     ["show", "--status"]])
def test_commands_that_run_refuse_a_library_with_the_same_error(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], command: list[str]) -> None:
    path = _file(tmp_path, "sbr.awl", SBR)
    assert main([command[0], str(path), *command[1:]]) == 1
    err = capsys.readouterr().err
    assert f"{path}:1:1: error: the program has no main program block (OB1)" in err


# -- each structural problem once ---------------------------------------------------
@pytest.mark.parametrize("networks,message", [
    (("LD SM0.0\nFOR VW0, +1, +3", "LD I0.0\n= Q0.0"), "FOR without a matching NEXT"),
    (("LD I0.0\n= Q0.0", "NEXT"), "NEXT without a matching FOR"),
    (("LSCR S0.0", "LD I0.0\n= Q0.0"), "LSCR without a matching SCRE"),
    (("LD I0.0\nCSCRE",), "CSCRE outside an SCR segment"),
])
def test_an_unmatched_loop_or_segment_is_reported_once(networks: tuple[str, ...],
                                                       message: str) -> None:
    with pytest.raises(PlcCompileError) as info:
        plcrt.load(ob1_text(*networks))
    found = [d for d in info.value.diagnostics if message in d.message]
    assert len(found) == 1, [str(d) for d in info.value.diagnostics]
    assert len(info.value.diagnostics) == 1


# -- the watchdog names the loop ----------------------------------------------------
def test_watchdog_names_the_for_loop_and_its_lines() -> None:
    plc = plcrt.load(ob1_text("LD SM0.0\nFOR VW0, +1, +32767", "LD SM0.0\nINCW VW2\nNEXT"))
    with pytest.raises(PlcRuntimeError) as info:
        plc.scan()
    err = info.value
    assert "in the loop from FOR at line 5 to NEXT at line 9 of OB1" in err.message
    assert err.loc is not None and (err.loc.line, err.loc.block, err.loc.network) == \
        (5, "OB1", 1)
    count = int(err.message.split("about ")[1].split()[0])
    assert 400_000 < count < 450_000       # 500 ms at 1.2 µs per instruction


@pytest.mark.parametrize("last", ["LD SM0.0\nJMP 1", "LD SM0.0\nJMP 1\nLD I0.0\n= Q0.0"])
def test_watchdog_names_the_backward_jump(last: str) -> None:
    """The JMP is named even when more instructions follow it in its network."""
    plc = plcrt.load(ob1_text("LBL 1", "LD SM0.0\nINCW VW2", last))
    with pytest.raises(PlcRuntimeError) as info:
        plc.scan()
    assert "in the loop from LBL at line 4 to JMP at line 10 of OB1" in info.value.message


def test_watchdog_after_wdr_names_the_wdr_and_counts_all_the_work() -> None:
    """WDR resets the estimate; the hard cap's message counts every
    instruction of the scan's loops, not the few since the last WDR."""
    plc = plcrt.load(ob1_text("LBL 1", "LD SM0.0\nWDR\nINCW VW2", "LD SM0.0\nJMP 1"))
    with pytest.raises(PlcRuntimeError) as info:
        plc.scan()
    err = info.value
    assert "the loop around WDR at line 7 ran ten times the 500 ms" in err.message
    count = int(err.message.split("about ")[1].split()[0])
    assert count > 4_000_000
    assert err.loc is not None and err.loc.line == 7


# -- data block: syntax and range errors together ----------------------------------
def test_data_block_lists_syntax_and_range_errors_in_one_run(tmp_path: Path) -> None:
    data = _file(tmp_path, "d.txt", "VB0 1\nVB1 x\nVW10239 5\nVB2 2 3\n")
    with pytest.raises(PlcSyntaxError) as info:
        plcrt.load(ob1_text("LD I0.0\n= Q0.0"), data=data)
    lines = sorted(d.loc.line for d in info.value.diagnostics if d.loc is not None)
    assert lines == [2, 3, 4]
    assert any("V memory has only 10240 bytes" in d.message for d in info.value.diagnostics)
    # the CPU decides the size
    with pytest.raises(PlcSyntaxError) as info:
        plcrt.load(ob1_text("LD I0.0\n= Q0.0"), data=data, cpu="CPU224")
    assert any("only 8192 bytes" in d.message for d in info.value.diagnostics)


# -- wall-clock limit and progress lines --------------------------------------------
class _Clock:
    """A fake monotonic clock: each reading advances by ``step`` seconds."""

    def __init__(self, step: float) -> None:
        self.t = 0.0
        self.step = step

    def __call__(self) -> float:
        self.t += self.step
        return self.t


def test_max_wall_stops_between_scans_and_reports_the_simulated_time() -> None:
    plc = plcrt.load(ob1_text("LD SM0.0\nINCW VW0"))
    with pytest.raises(WallTimeExceeded) as info:
        run_with_progress(plc, seconds=1e12, max_wall=1.0, clock=_Clock(0.1),
                          stream=io.StringIO())
    assert isinstance(info.value, plcrt.PlcError)
    assert plc.mode == "RUN" and 0 < plc.scans < 10_000_000
    assert plc["VW0"] == plc.scans & 0x7FFF or plc["VW0"] < 0
    assert f"at {plc.time:g} s simulated ({plc.scans} of 100000000000000 scans run)" \
        in info.value.message


def test_a_run_that_ends_in_time_is_not_stopped() -> None:
    plc = plcrt.load(ob1_text("LD SM0.0\nINCW VW0"))
    run_with_progress(plc, scans=500, max_wall=1e6, clock=_Clock(0.001), stream=io.StringIO())
    assert plc.scans == 500 and plc["VW0"] == 500


def test_progress_lines_off_a_terminal() -> None:
    """--progress on a pipe: plain lines with scans, simulated and wall time."""
    plc = plcrt.load(ob1_text("LD SM0.0\nINCW VW0"))
    out = io.StringIO()
    run_with_progress(plc, scans=20_000, progress=True, clock=_Clock(1.0), stream=out)
    lines = out.getvalue().splitlines()
    assert len(lines) >= 2 and all(ln.startswith("plcrt: ") for ln in lines)
    assert lines[-1].startswith("plcrt: 20000/20000 scans (100.0 %), 200 s simulated")
    assert plc.scans == 20_000


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), float("inf")])
def test_a_bad_max_wall_is_refused(bad: float) -> None:
    plc = plcrt.load(ob1_text("LD SM0.0\nINCW VW0"))
    with pytest.raises(PlcConfigError, match="--max-wall must be a positive number"):
        run_with_progress(plc, scans=1, max_wall=bad)


@pytest.mark.parametrize("command", [
    ["run", "--watch", "VW0"], ["trace", "--signal", "VW0"], ["show", "--status"]])
def test_cli_max_wall_exit_status_3(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                    command: list[str]) -> None:
    """--seconds 1e12 would run for ever; --max-wall ends it with status 3."""
    path = _file(tmp_path, "p.awl", ob1_text("LD SM0.0\nINCW VW0"))
    code = main([command[0], str(path), *command[1:], "--seconds", "1e12",
                 "--max-wall", "0.3"])
    err = capsys.readouterr().err
    assert code == 3
    assert "plcrt: error: stopped by --max-wall after 0.3 s of wall-clock time, at " in err


# -- recursion and nesting depth (System Manual, CALL) -----------------------------
RECURSIVE = """\
ORGANIZATION_BLOCK OB1
BEGIN
Network 1
LD SM0.0
MOVW +0, VW0
MOVW +0, VW40
MOVW +0, VW62
CALL SBR0, 1
AENO
= Q0.0
END_ORGANIZATION_BLOCK
SUBROUTINE_BLOCK SBR_0:SBR0
VAR_INPUT
n:INT;
END_VAR
BEGIN
Network 1
LD SM0.0
INCW VW0
Network 2
LDW< VW0, VW20
MOVW #n, VW50
INCW VW50
CALL SBR0, VW50
AENO
INCW VW62
Network 3
LD SM0.0
+I #n, VW40
END_SUBROUTINE_BLOCK
"""


def test_recursion_compiles_with_a_warning_naming_the_cycle() -> None:
    plc = plcrt.load(RECURSIVE)
    warnings = [d for d in plc.diagnostics if d.code == "recursion"]
    assert len(warnings) == 1
    assert warnings[0].message.startswith("recursion: SBR0 -> SBR0; the S7-200 allows it")
    assert warnings[0].loc is not None and warnings[0].loc.line == 24


def test_indirect_recursion_names_every_block_of_the_cycle() -> None:
    text = (ob1_text("LD SM0.0\nCALL SBR0")
            + "SUBROUTINE_BLOCK SBR0\nBEGIN\nNetwork 1\nLDW< VW0, +3\nINCW VW0\nCALL SBR1\n"
              "END_SUBROUTINE_BLOCK\n"
            + "SUBROUTINE_BLOCK SBR1\nBEGIN\nNetwork 1\nLD SM0.0\nCALL SBR0\n"
              "END_SUBROUTINE_BLOCK\n")
    plc = plcrt.load(text)
    assert [d.message.split(";")[0] for d in plc.diagnostics if d.code == "recursion"] == \
        ["recursion: SBR0 -> SBR1 -> SBR0"]
    plc.scan()
    assert plc["VW0"] == 3


def test_recursion_three_levels_deep_runs_with_its_own_locals_per_level() -> None:
    """Each level has its own L memory: the sum of #n over the levels is
    1 + 2 + 3, which a shared buffer would overwrite."""
    plc = plcrt.load(RECURSIVE)
    plc["VW20"] = 3
    plc.scan()
    assert (plc["VW0"], plc["VW40"], plc["SM4.3"], plc["Q0.0"]) == (3, 6, 0, 1)
    assert plc["VW62"] == 2            # ENO 1 after the two recursive calls
    assert not [d for d in plc.diagnostics if d.code == "runtime"]


def test_a_ninth_nesting_level_is_not_executed_and_sets_sm4_3() -> None:
    """As decided in docs/decisions.md: the CALL that would be the ninth
    level is skipped with ENO 0 and SM4.3 set; the CPU keeps running."""
    plc = plcrt.load(RECURSIVE)
    plc["VW20"] = 20
    plc.scan()
    assert (plc["VW0"], plc["VW40"]) == (8, sum(range(1, 9)))
    assert plc["SM4.3"] == 1 and plc.mode == "RUN"
    assert plc["VW62"] == 7           # ENO 0 after the refused ninth-level call
    assert plc["Q0.0"] == 1           # the outermost call itself succeeded
    warnings = [d for d in plc.diagnostics if d.code == "runtime"]
    assert len(warnings) == 1 and "deeper than the S7-200's limit of 8" in warnings[0].message
    assert warnings[0].loc is not None and warnings[0].loc.line == 24
    plc.scan()
    assert plc.mode == "RUN" and plc["VW0"] == 8


def test_a_fork_of_a_recursive_program_keeps_its_locals() -> None:
    plc = plcrt.load(RECURSIVE)
    plc["VW20"] = 3
    plc.scan()
    twin = plc.fork()
    twin.scan()
    assert (twin["VW0"], twin["VW40"]) == (3, 6)


def test_a_nine_level_chain_warns_at_compile_time_and_stops_at_run_time() -> None:
    blocks = "".join(
        f"SUBROUTINE_BLOCK SBR{i}\nBEGIN\nNetwork 1\nLD SM0.0\n"
        + (f"INCW VW0\nCALL SBR{i + 1}\n" if i < 8 else "INCW VW0\n")
        + "END_SUBROUTINE_BLOCK\n" for i in range(9))
    plc = plcrt.load(ob1_text("LD SM0.0\nCALL SBR0") + blocks)
    assert any(d.code == "nesting" and "nest 9 levels deep" in d.message
               for d in plc.diagnostics)
    plc.scan()
    assert plc["VW0"] == 8 and plc["SM4.3"] == 1


def _blocks(n: int, cyclic: bool) -> str:
    return "".join(
        f"SUBROUTINE_BLOCK SBR{i}\nBEGIN\nNetwork 1\nLD SM0.0\nINCW VW0\n"
        + (f"CALL SBR{(i + 1) % n}\n" if cyclic or i < n - 1 else "")
        + "END_SUBROUTINE_BLOCK\n" for i in range(n))


@pytest.mark.parametrize("cyclic", [False, True])
def test_call_graphs_deeper_than_pythons_recursion_limit(cyclic: bool) -> None:
    """A chain or a cycle of 1200 blocks is analysed without recursion (no
    internal error) and runs 8 levels deep; a long cycle is named shortly."""
    plc = plcrt.load(ob1_text("LD SM0.0\nCALL SBR0") + _blocks(1200, cyclic))
    if cyclic:
        (warning,) = [d for d in plc.diagnostics if d.code == "recursion"]
        assert warning.message.startswith(
            "recursion: SBR0 -> SBR1 -> SBR2 -> ... (1200 blocks) ... -> SBR1199 -> SBR0;")
    else:
        assert any("nest 1200 levels deep" in d.message for d in plc.diagnostics)
    plc.scan()
    assert (plc["VW0"], plc["SM4.3"]) == (8, 1)


def test_programs_without_recursion_pay_nothing_for_the_nesting_check() -> None:
    """The run-time nesting count is generated only where it can matter."""
    plain = plcrt.load(ob1_text("LD SM0.0\nCALL SBR0") + SBR)
    assert "WD[3]" not in plain.source
    assert "WD[3] >= 8" in plcrt.load(RECURSIVE).source


def test_cli_progress_prints_plain_lines_off_a_terminal(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _file(tmp_path, "p.awl", ob1_text("LD SM0.0\nINCW VW0"))
    assert main(["run", str(path), "--scans", "300", "--progress", "--watch", "VW0"]) == 0
    out, err = capsys.readouterr()
    assert "plcrt: 300/300 scans (100.0 %), 3 s simulated, " in err
    assert "VW0      300" in out
