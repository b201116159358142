"""Calls of the EM253 library instructions (library/EM253_Ext_v1.0.toml).

Compile time: every ``CALL NAME, args...`` of a library instruction is
checked against the instruction's interface -- argument count, operand
width, addresses where the block writes -- and each problem is a located
:class:`plcrt.PlcCompileError` (file:line:col, block and network).

Run time: misuse the compiler cannot see (no MOTION_EN3 earlier in the
scan, InnerState not 0 or written by the program, SpdSs above SpdSet,
Step > 32, a slot without a module) gives a warning in ``plc.diagnostics``
that names the instruction and the CALL's location.  docs/em253.md lists
the behaviour these tests pin.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import plcrt
from plcrt.blocks.interface import interfaces
from plcrt.errors import Diagnostic

# ---------------------------------------------------------------------------
# Program builders
# ---------------------------------------------------------------------------

EN3 = "CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4, VW0"
GOTO = ("CALL   POS_GOTO_R, 0, 0, +100, +100, VD300, VD304, +100000, VD100, VB104, "
        "M2.1, M2.0, VW106, VD108, VD112")
SPD = ("CALL   SPD_CTRL, 0, 0, +100, +100, VD300, VD304, VD100, VB104, M1.1, M1.2, M1.0, "
       "VW106, VD108")
RUN = ("CALL   POS_RUN, 0, 0, 0, +1000, &VB1000, VB50, VD100, VB104, M3.1, M3.0, "
       "VW106, VD108, VD112, VB116")

#: One plant with the module in slot 0 and a plain axis 0.
PLANT: dict[str, Any] = {"module": {"0": {"axis": {"0": {}, "1": {}}}}}


def _ob1(*networks: str) -> str:
    """An OB1 whose networks each run one line under SM0.0."""
    lines = ["ORGANIZATION_BLOCK MAIN:OB1", "TITLE=library call test", "BEGIN"]
    for i, body in enumerate(networks, 1):
        lines += [f"Network {i}", "LD     SM0.0", *body.split("\n")]
    lines.append("END_ORGANIZATION_BLOCK")
    return "\n".join(lines) + "\n"


def _line_of(text: str, fragment: str, nth: int = 1) -> int:
    """1-based line number of the ``nth`` line containing ``fragment``."""
    seen = 0
    for n, line in enumerate(text.split("\n"), 1):
        if fragment in line:
            seen += 1
            if seen == nth:
                return n
    raise AssertionError(f"{fragment!r} not in the program")


def _call_line(text: str, network: int) -> int:
    """Line number of the first CALL in ``Network n``."""
    lines = text.split("\n")
    start = lines.index(f"Network {network}")
    return next(n for n, line in enumerate(lines[start:], start + 1) if line.startswith("CALL"))


def _compile_error(tmp_path: Path, text: str) -> plcrt.PlcCompileError:
    path = tmp_path / "prog.awl"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(plcrt.PlcCompileError) as info:
        plcrt.load(str(path), plant=PLANT)
    return info.value


def _errors(err: plcrt.PlcError) -> list[Diagnostic]:
    return [d for d in err.diagnostics if d.severity == "error"]


# ---------------------------------------------------------------------------
# The interface file itself
# ---------------------------------------------------------------------------

def test_library_file_lists_the_seven_instructions_in_manual_order() -> None:
    """The manual's seven instructions, each with its parameter table's order."""
    itf = interfaces()
    assert {"MOTION_EN3", "GET_ABSPOS", "SET_ABSPOS", "SPD_CTRL", "POS_GOTO_R",
            "POS_RUN", "HOMING"} <= set(itf)
    assert [p.name for p in itf["GET_ABSPOS"].params] == ["EmNo", "AxisNo", "C_Pos",
                                                         "C_Status"]
    assert len(itf["POS_GOTO_R"].params) == 14
    assert len(itf["POS_RUN"].params) == 14
    assert len(itf["HOMING"].params) == 11
    # the block owns InnerState, Update and Start: they must be addresses
    for name in ("SPD_CTRL", "POS_GOTO_R", "POS_RUN", "HOMING"):
        inner = next(p for p in itf[name].params if p.name == "InnerState")
        assert (inner.type, inner.address, inner.written) == ("DWORD", True, True)
    # HOMING's PosOffset is a DINT although the manual's table says byte
    off = next(p for p in itf["HOMING"].params if p.name == "PosOffset")
    assert off.type == "DINT"


# ---------------------------------------------------------------------------
# Compile-time checks
# ---------------------------------------------------------------------------

COMPILE_CASES = [
    # (id, body of network 2, expected fragments of the error message)
    ("too few arguments", "CALL   GET_AbsPos, 0, 0, VD120",
     ["GET_AbsPos takes 4 arguments (EmNo, AxisNo, C_Pos, C_Status)", "passes 3"]),
    ("too many arguments", "CALL   GET_AbsPos, 0, 0, VD120, VW124, VW126",
     ["GET_AbsPos takes 4 arguments", "passes 5"]),
    ("MOTION_EN3 without Status", "CALL   MOTION_EN3, 0, M0.0, M0.1, M0.2, M0.3, M0.4",
     ["MOTION_EN3 takes 7 arguments", "passes 6"]),
    ("word for the DWORD InnerState", GOTO.replace("VD100", "VW100"),
     ["POS_GOTO_R argument InnerState (IN DWORD)", "VW100", "this is a word"]),
    ("word for the DINT SpdSs", GOTO.replace("VD300", "VW300"),
     ["POS_GOTO_R argument SpdSs (IN DINT)", "VW300", "this is a word"]),
    ("word for the DINT output C_Pos", "CALL   GET_AbsPos, 0, 0, VW120, VW124",
     ["GET_AbsPos argument C_Pos (OUT DINT)", "VW120", "this is a word"]),
    ("word for the BYTE output C_Step", RUN.replace("VB116", "VW116"),
     ["POS_RUN argument C_Step (OUT BYTE)", "this is a word"]),
    ("constant InnerState", GOTO.replace("VD100", "0"),
     ["POS_GOTO_R argument InnerState (IN DWORD)", "must be an address", "'0'"]),
    ("constant Update", SPD.replace("VB104", "0"),
     ["SPD_CTRL argument Update (IN BYTE)", "must be an address"]),
    ("constant Start", "CALL   SET_AbsPos, 0, 0, +100, 1, VW10",
     ["SET_AbsPos argument Start (IN BOOL)", "must be an address"]),
    ("constant C_Status", "CALL   GET_AbsPos, 0, 0, VD120, 5",
     ["GET_AbsPos argument C_Status (OUT WORD)", "must be an address"]),
    ("constant C_Pos", "CALL   GET_AbsPos, 0, 0, +7, VW124",
     ["GET_AbsPos argument C_Pos (OUT DINT)", "must be an address"]),
    ("constant Status of MOTION_EN3", "CALL   MOTION_EN3, 1, M0.0, M0.1, M0.2, M0.3, M0.4, 4",
     ["MOTION_EN3 argument Status (OUT WORD)", "must be an address"]),
    ("constant Clr (written back)",
     "CALL   MOTION_EN3, 1, M0.0, M0.1, M0.2, 0, M0.4, VW2",
     ["MOTION_EN3 argument Clr0 (IN BOOL)"]),
    ("HOMING InnerState a word",
     "CALL   HOMING, 0, 0, +1, +500, +5000, +0, VW100, M1.1, M1.0, VW106, VD108",
     ["HOMING argument InnerState (IN DWORD)", "this is a word"]),
    ("read-only output", "CALL   GET_AbsPos, 0, 0, VD120, SMW0",
     ["GET_AbsPos argument C_Status (OUT WORD)"]),
]


@pytest.mark.parametrize("body,fragments", [c[1:] for c in COMPILE_CASES],
                         ids=[c[0] for c in COMPILE_CASES])
def test_bad_call_is_a_located_compile_error(tmp_path: Path, body: str,
                                             fragments: list[str]) -> None:
    """The error names file:line:col, the block and network, and the parameter."""
    text = _ob1(EN3, body)
    err = _compile_error(tmp_path, text)
    errors = _errors(err)
    assert len(errors) == 1, [str(d) for d in errors]
    d = errors[0]
    line = _call_line(text, 2)
    assert d.loc is not None
    assert (d.loc.line, d.loc.block, d.loc.network) == (line, "OB1", 2)
    source_line = text.splitlines()[line - 1]
    if " argument " in fragments[0]:
        # an argument error points at that argument's own column
        arg = source_line[d.loc.column - 1:].split(",")[0].strip()
        assert d.loc.column > 1 and arg and arg in str(d), (arg, str(d))
    else:
        assert d.loc.column == 1
    assert d.loc.file.endswith("prog.awl")
    first = str(err).splitlines()[0]
    assert first.startswith(f"{tmp_path / 'prog.awl'}:{line}:{d.loc.column}: error: ")
    assert first.endswith("[OB1 network 2]")
    for fragment in fragments:
        assert fragment in d.message, d.message


def test_every_bad_call_is_reported_at_once(tmp_path: Path) -> None:
    """Three bad calls in three networks give three errors in one exception."""
    text = _ob1(EN3, "CALL   GET_AbsPos, 0, 0, VD120",
                GOTO.replace("VD100", "0"), "CALL   SET_AbsPos, 0, 0, +1, 1, VW10")
    errors = _errors(_compile_error(tmp_path, text))
    assert [(d.loc.line, d.loc.network) for d in errors if d.loc] == [
        (_line_of(text, "GET_AbsPos"), 2), (_line_of(text, "POS_GOTO_R"), 3),
        (_line_of(text, "SET_AbsPos"), 4)]


def test_error_in_a_subroutine_names_the_subroutine(tmp_path: Path) -> None:
    """A library call inside SBR0 is located in that block and its network."""
    text = (_ob1(EN3, "CALL   AXIS_SUB")
            + "SUBROUTINE_BLOCK AXIS_SUB:SBR0\nTITLE=axis\nBEGIN\nNetwork 1\n"
            + "LD     SM0.0\nCALL   GET_AbsPos, 0, 0, VW120, VW124\n"
            + "END_SUBROUTINE_BLOCK\n")
    (d,) = _errors(_compile_error(tmp_path, text))
    assert d.loc is not None
    assert (d.loc.line, d.loc.block, d.loc.network) == (_line_of(text, "GET_AbsPos"),
                                                        "SBR0", 1)
    assert "C_Pos" in d.message


def test_call_with_the_export_form_name_colon_sbr_is_accepted() -> None:
    """Micro/WIN exports library calls as ``CALL NAME:SBRn, ...``; the number
    is the library's subroutine number and is ignored."""
    text = _ob1(EN3.replace("MOTION_EN3,", "MOTION_EN3:SBR5,"),
                "CALL   GET_AbsPos:SBR1, 0, 0, VD120, VW124")
    plc = plcrt.load(text, plant=PLANT, scan_ms=1)
    plc.scan(2)
    assert plc["VW0"] == 1
    assert plc["VW124"] == 1
    assert plc.diagnostics == []


def test_the_manual_style_arguments_are_accepted() -> None:
    """Pointers (&VB, a VD holding one), signed constants, AC and indirect
    operands are valid where the interface allows them."""
    text = _ob1(EN3, RUN.replace("&VB1000", "VD40"),
                "CALL   GET_AbsPos, 0, 0, AC1, VW124\n"
                "CALL   GET_AbsPos, 0, 1, *VD44, VW126")
    plc = plcrt.load(text, plant=PLANT, scan_ms=1)
    plc["VD44"] = 0x08000000 | 600  # &VB600
    plc.scan()
    assert plc["VW124"] == 1 and plc["VW126"] == 1


def test_unknown_name_is_still_a_missing_subroutine(tmp_path: Path) -> None:
    """A name that is neither a library instruction nor a subroutine."""
    (d,) = _errors(_compile_error(tmp_path, _ob1(EN3, "CALL   POS_GOTO_A, 0, 0")))
    assert "no subroutine named 'POS_GOTO_A'" in d.message


# ---------------------------------------------------------------------------
# Run-time diagnostics
# ---------------------------------------------------------------------------

def _load(*networks: str, plant: dict | None = None) -> tuple[plcrt.Plc, str]:
    text = _ob1(*networks)
    return plcrt.load(text, plant=PLANT if plant is None else plant, scan_ms=1), text


def _warnings(plc: plcrt.Plc, name: str) -> list[Diagnostic]:
    return [d for d in plc.diagnostics if d.severity == "warning" and d.message.startswith(name)]


def _the_warning(plc: plcrt.Plc, name: str, text: str, fragment: str,
                 line_fragment: str, network: int) -> Diagnostic:
    found = [d for d in _warnings(plc, name) if fragment in d.message]
    assert len(found) == 1, [str(d) for d in plc.diagnostics]
    d = found[0]
    assert d.loc is not None
    assert (d.loc.line, d.loc.block, d.loc.network) == (_line_of(text, line_fragment),
                                                        "OB1", network)
    return d


def _start_goto(plc: plcrt.Plc, ss: int = 1000, s: int = 50_000) -> None:
    plc["VD300"] = ss
    plc["VD304"] = s
    plc["M2.0"] = 1


def test_motion_call_before_motion_en3_is_ignored_and_reported() -> None:
    """MOTION_EN3 must run earlier in the same scan (manual 3.2.1)."""
    plc, text = _load(GOTO, EN3)
    _start_goto(plc)
    plc.scan(20)
    _the_warning(plc, "POS_GOTO_R", text, "MOTION_EN3 for slot 0 has not run", "POS_GOTO_R", 1)
    assert plc.axis(0, 0)["position"] == 0
    assert plc["VW106"] == 0            # C_Status: never ran
    assert plc["VD100"] == 0            # InnerState untouched


def test_motion_call_without_any_motion_en3() -> None:
    plc, text = _load("CALL   GET_AbsPos, 0, 0, VD120, VW124")
    plc.scan(3)
    d = _the_warning(plc, "GET_AbsPos", text, "has not run", "GET_AbsPos", 1)
    assert "SM0.0" in d.message
    assert plc["VW124"] == 0


def test_inner_state_not_zero_at_first_use_blocks_the_instruction() -> None:
    """Manual: the InnerState variable must be initialised to 0."""
    plc, text = _load(EN3, GOTO)
    plc["VD100"] = 5
    _start_goto(plc)
    plc.scan(20)
    _the_warning(plc, "POS_GOTO_R", text, "InnerState must be 0", "POS_GOTO_R", 2)
    assert plc.axis(0, 0)["position"] == 0
    assert plc["VD100"] == 5
    assert plc["VW106"] == 0


def test_inner_state_is_257_while_in_use() -> None:
    plc, _ = _load(EN3, GOTO)
    _start_goto(plc)
    plc.scan(5)
    assert plc["VD100"] == 257
    assert plc["VW106"] == 1


def test_inner_state_written_by_the_program_stops_the_axis() -> None:
    """Writing InnerState while running stops the axis at once (C_Status 8);
    the block writes 257 back."""
    plc, text = _load(EN3, GOTO)
    _start_goto(plc)
    plc.scan(50)
    assert plc.axis(0, 0)["status"] == "moving"
    plc["VD100"] = 0
    plc.scan()
    d = _the_warning(plc, "POS_GOTO_R", text, "InnerState was changed", "POS_GOTO_R", 2)
    assert "stopped" in d.message
    ax = plc.axis(0, 0)
    assert ax["status"] == "stopped" and ax["speed"] == 0
    assert plc["VW106"] == 8
    assert plc["VD100"] == 257


def test_spd_ss_above_spd_set_does_not_start() -> None:
    """Manual note 4: with the start speed above the run speed the motor
    does not start."""
    plc, text = _load(EN3, GOTO)
    _start_goto(plc, ss=20_000, s=10_000)
    plc.scan(20)
    _the_warning(plc, "POS_GOTO_R", text, "SpdSs (20000 Hz)", "POS_GOTO_R", 2)
    assert plc.axis(0, 0)["position"] == 0
    assert plc["VW106"] == 0


def test_spd_ctrl_spd_ss_above_spd_set_does_not_start() -> None:
    plc, text = _load(EN3, SPD)
    plc["VD300"] = 9000
    plc["VD304"] = 3000
    plc["M1.0"] = 1
    plc.scan(20)
    _the_warning(plc, "SPD_CTRL", text, "SpdSs (9000 Hz)", "SPD_CTRL", 2)
    assert plc.axis(0, 0)["status"] == "stopped"


@pytest.mark.parametrize("steps", [33, 0, 255])
def test_pos_run_step_out_of_range_does_not_start(steps: int) -> None:
    """Manual 3.2.6: Step is 1..32; above 32 the motor does not start."""
    plc, text = _load(EN3, RUN)
    for i in range(40):  # a valid table, so only Step is wrong
        base = 1000 + 12 * i
        plc[f"VW{base}"] = 100
        plc[f"VW{base + 2}"] = 100
        plc[f"VD{base + 4}"] = 5000
        plc[f"VD{base + 8}"] = 1000
    plc["VB50"] = steps
    plc["M3.0"] = 1
    plc.scan(20)
    d = _the_warning(plc, "POS_RUN", text, f"Step is {steps}", "POS_RUN", 2)
    assert "does not start" in d.message
    assert plc.axis(0, 0)["position"] == 0
    assert plc["VW106"] == 0


def test_pos_run_with_32_steps_starts() -> None:
    plc, _ = _load(EN3, RUN)
    for i in range(32):
        base = 1000 + 12 * i
        plc[f"VW{base}"] = 5
        plc[f"VW{base + 2}"] = 5
        plc[f"VD{base + 4}"] = 20_000
        plc[f"VD{base + 8}"] = 100
    plc["VB50"] = 32
    plc["M3.0"] = 1
    plc.run(seconds=2)
    assert _warnings(plc, "POS_RUN") == []
    assert plc.axis(0, 0)["position"] == 3200
    assert (plc["VW106"], plc["VB116"]) == (8, 32)


def test_motion_en3_for_an_empty_slot_gives_status_4() -> None:
    """Manual 3.2.1: Status 1 in normal operation, 4 otherwise."""
    plc, text = _load(EN3.replace("MOTION_EN3, 0", "MOTION_EN3, 3"), GOTO)
    _start_goto(plc)
    plc.scan(3)
    assert plc["VW0"] == 4
    d = _the_warning(plc, "MOTION_EN3", text, "no EM253 module in slot 3", "MOTION_EN3", 1)
    assert "Status 4" in d.message
    # slot 0 was never enabled in this scan: the move does not start
    _the_warning(plc, "POS_GOTO_R", text, "has not run", "POS_GOTO_R", 2)
    assert plc.axis(0, 0)["position"] == 0


def test_motion_en3_status_1_with_a_module() -> None:
    plc, _ = _load(EN3)
    plc.scan()
    assert plc["VW0"] == 1
    assert plc.diagnostics == []


def test_motion_instruction_for_an_empty_slot() -> None:
    """A motion instruction naming a slot without a module does nothing."""
    plc, text = _load(EN3, GOTO.replace("POS_GOTO_R, 0, 0", "POS_GOTO_R, 2, 0"))
    _start_goto(plc)
    plc.scan(3)
    _the_warning(plc, "POS_GOTO_R", text, "no EM253 module in slot 2", "POS_GOTO_R", 2)
    assert plc["VW106"] == 0


def test_program_without_a_plant_reports_the_missing_module() -> None:
    text = _ob1(EN3)
    plc = plcrt.load(text, scan_ms=1)
    plc.scan()
    assert plc["VW0"] == 4
    assert _warnings(plc, "MOTION_EN3")


def test_a_warning_is_given_once_per_call_site() -> None:
    """Diagnostics do not repeat every scan."""
    plc, _ = _load(GOTO, EN3)
    plc.scan(100)
    assert len(_warnings(plc, "POS_GOTO_R")) == 1


def test_two_call_sites_each_report() -> None:
    text_calls = (GOTO, GOTO.replace("VD100", "VD200").replace("VB104", "VB204"), EN3)
    plc, text = _load(*text_calls)
    plc.scan(3)
    lines = sorted(d.loc.line for d in _warnings(plc, "POS_GOTO_R") if d.loc)
    assert lines == [_line_of(text, "POS_GOTO_R", 1), _line_of(text, "POS_GOTO_R", 2)]


@pytest.mark.parametrize("mb0,axis", [(0b01000, 0), (0b10000, 1)])
def test_bit_arguments_of_one_byte_reach_their_own_parameters(mb0: int, axis: int) -> None:
    """MOTION_EN3's five BOOL inputs all come from MB0 (read once): the CLR
    bit of one axis starts that axis's CLR pulse only (manual 3.2.1)."""
    plc, _ = _load(EN3)
    plc["MB0"] = mb0
    plc.scan()
    mod = plc.modules[0]
    assert [u is not None for u in mod.clr_until] == [axis == 0, axis == 1]
    assert plc["MB0"] == mb0                   # the pulse holds the bit for 200 ms
    plc.run(seconds=0.3)
    assert plc["MB0"] == 0 and mod.clr_until == [None, None]


def test_logic_after_a_library_call_under_sm0_0_sees_the_power() -> None:
    """A box under SM0.0 runs without a test; the network's logic after it
    still has SM0.0's 1 on the stack (``= Q0.0``) and can combine it."""
    plc, _ = _load(EN3 + "\n= Q0.0\nAN M5.0\n= Q0.1")
    plc.scan()
    assert (plc["Q0.0"], plc["Q0.1"], plc["VW0"]) == (1, 1, 1)
    plc["M5.0"] = 1
    plc.scan()
    assert (plc["Q0.0"], plc["Q0.1"]) == (1, 0)
