"""Table tests for plcrt.isa.control: JMP/LBL, FOR/NEXT, the watchdog, CALL
with parameters, CRET/RET/END/STOP and SCR segments (S7-200 System Manual,
"Program control instructions" and "Sequence control relay instructions";
digest sections 3.1, 4 and 4.1)."""

from __future__ import annotations

import time

import pytest

import plcrt
from plcrt.errors import PlcCompileError, PlcRuntimeError
from stl_helpers import ob1_text


def _sbr(number: int, *networks: str, interface: str = "", name: str | None = None) -> str:
    """A subroutine block ``name:SBRn`` with an optional VAR_... interface text."""
    lines = [f"SUBROUTINE_BLOCK {name or f'SBR_{number}'}:SBR{number}",
             "TITLE=SUBROUTINE COMMENTS"]
    if interface:
        lines.extend(ln.strip() for ln in interface.strip().splitlines())
    lines.append("BEGIN")
    for i, net in enumerate(networks, 1):
        lines.append(f"Network {i}")
        lines.extend(ln.strip() for ln in net.strip().splitlines())
    lines.append("END_SUBROUTINE_BLOCK")
    return "\n".join(lines) + "\n"


def _load(*networks: str, extra: str = "", scan_ms: float = 10.0) -> plcrt.Plc:
    """OB1 made of ``networks`` followed by the blocks in ``extra``."""
    return plcrt.load(ob1_text(*networks) + extra, scan_ms=scan_ms)


# -- JMP / LBL ------------------------------------------------------------------
def test_forward_jump_skips_networks() -> None:
    """JMP n with a 1 on top continues after LBL n; with a 0 it falls through."""
    p = _load("LD I0.0\nJMP 4", "LD SM0.0\n= Q0.0", "LD SM0.0\nINCW VW0",
              "LBL 4", "LD SM0.0\nINCW VW2")
    p.scan()
    assert (p["Q0.0"], p["VW0"], p["VW2"]) == (1, 1, 1)
    p["I0.0"] = 1
    p["Q0.0"] = 0
    p.scan()
    assert (p["Q0.0"], p["VW0"], p["VW2"]) == (0, 1, 2)


def test_backward_jump_loops_until_the_condition_fails() -> None:
    """A backward JMP repeats the networks between LBL and JMP within one scan."""
    p = _load("LD SM0.0\nMOVW +0, VW0", "LBL 3\nLD SM0.0\nINCW VW0", "LDW< VW0, +5\nJMP 3")
    p.scan()
    assert p["VW0"] == 5


def test_label_in_the_middle_of_a_network() -> None:
    """A jump lands on an LBL that follows other instructions of a network."""
    p = _load("LD I0.0\nJMP 7", "LD SM0.0\nINCW VW0\nLBL 7\nLD SM0.0\nINCW VW2")
    p["I0.0"] = 1
    p.scan()
    assert (p["VW0"], p["VW2"]) == (0, 1)


@pytest.mark.parametrize("body,message", [
    (("LD SM0.0\nJMP 7",), "label 7"),
    (("LD SM0.0\nJMP 2", "LBL 1"), "label 2"),
    (("LBL 1", "LBL 1"), "label 1 is defined twice"),
])
def test_jump_label_errors(body: tuple[str, ...], message: str) -> None:
    """A jump to a missing label (or a duplicate label) is a compile error naming it."""
    with pytest.raises(PlcCompileError) as exc:
        _load(*body)
    assert message in str(exc.value)
    assert "<string>:" in str(exc.value)


def test_jump_into_another_block_is_a_compile_error() -> None:
    """JMP and LBL must be in the same POU."""
    with pytest.raises(PlcCompileError, match="label 1, which is not defined in OB1"):
        _load("LD SM0.0\nJMP 1", "LD SM0.0\nCALL SBR_0",
              extra=_sbr(0, "LBL 1", "LD SM0.0\n= Q0.0"))


# -- FOR / NEXT ------------------------------------------------------------------
FOR_TABLE = [
    ("1 to 5", "+1", "+5", 1, 5, 6),
    ("3 to 3", "+3", "+3", 1, 1, 4),
    ("-2 to 2", "-2", "+2", 1, 5, 3),
    ("init > final", "+5", "+1", 1, 0, 5),
    ("not enabled", "+1", "+5", 0, 0, 0),
]


@pytest.mark.parametrize("label,init,final,enable,runs,indx", FOR_TABLE,
                         ids=[r[0] for r in FOR_TABLE])
def test_for_next(label: str, init: str, final: str, enable: int, runs: int, indx: int) -> None:
    """FOR runs the body while INDX <= FINAL; INDX ends at FINAL + 1; a 0 enable skips it."""
    p = _load(f"LD I0.0\nFOR VW0, {init}, {final}", "LD SM0.0\nINCW VW2", "NEXT",
              "LD SM0.0\n= Q0.0")
    p["I0.0"] = enable
    p.scan()
    assert (p["VW2"], p["VW0"], p["Q0.0"]) == (runs, indx, 1)


def test_nested_for_loops() -> None:
    """Nested FOR/NEXT: the inner body runs outer x inner times; both indexes stay visible."""
    p = _load("LD SM0.0\nFOR VW0, +1, +3", "LD SM0.0\nFOR VW4, +1, +4",
              "LD SM0.0\nINCW VW2", "NEXT", "LD SM0.0\nINCW VW6", "NEXT")
    p.scan()
    assert (p["VW0"], p["VW4"], p["VW2"], p["VW6"]) == (4, 5, 12, 3)


def test_for_final_from_memory_and_body_in_the_for_network() -> None:
    """FINAL may be a word operand; the body may share the FOR's and NEXT's networks."""
    p = _load("LD SM0.0\nFOR VW0, +1, VW10\nINCW VW2\nNEXT")
    p["VW10"] = 7
    p.scan()
    assert (p["VW0"], p["VW2"]) == (8, 7)


def test_for_without_next_is_a_compile_error() -> None:
    """FOR and NEXT must match."""
    with pytest.raises(PlcCompileError, match="FOR without a matching NEXT"):
        _load("LD SM0.0\nFOR VW0, +1, +3")
    with pytest.raises(PlcCompileError, match="NEXT without a matching FOR"):
        _load("NEXT")


def test_for_nesting_deeper_than_eight_is_a_compile_error() -> None:
    """FOR loops nest at most eight levels."""
    fors = [f"LD SM0.0\nFOR VW{2 * i}, +1, +1" for i in range(9)]
    with pytest.raises(PlcCompileError, match="deeper than 8"):
        _load(*fors, *["NEXT"] * 9)


# -- watchdog ----------------------------------------------------------------------
WATCHDOG = [
    ("FOR to 32767 wraps forever", ("LD SM0.0\nFOR VW0, +1, +32767",
                                    "LD SM0.0\nINCW VW2\nNEXT")),
    ("empty FOR delay loop", ("LD SM0.0\nFOR VW0, +1, +32767", "NEXT")),
    ("FOR with FINAL 32767 from memory", ("LD SM0.0\nMOVW +32767, VW10\nFOR VW0, +1, VW10",
                                          "LD SM0.0\nINCW VW2", "NEXT")),
    ("endless backward JMP", ("LBL 1", "LD SM0.0\nJMP 1")),
    ("JMP loop in one network", ("LBL 2\nLD SM0.0\nINCW VW0\nJMP 2",)),
]


@pytest.mark.parametrize("label,networks", WATCHDOG, ids=[w[0] for w in WATCHDOG])
def test_endless_loops_trip_the_watchdog_quickly(label: str, networks: tuple[str, ...]) -> None:
    """An endless loop raises a watchdog PlcRuntimeError, stops the CPU, and does so fast."""
    p = _load(*networks, "LD SM0.0\n= Q0.0")
    start = time.process_time()   # CPU time: the machine may be shared
    with pytest.raises(PlcRuntimeError, match="watchdog"):
        p.scan()
    assert time.process_time() - start < 1.0
    assert p.mode == "STOP" and p.mem.areas["PQ"][0] == 0
    p.scan()
    assert p.mode == "STOP"


def test_a_long_but_finite_loop_is_not_a_watchdog_fault() -> None:
    """A 10000-pass loop stays under the 500 ms estimate and completes."""
    p = _load("LD SM0.0\nFOR VW0, +1, +10000", "LD SM0.0\nINCW VW2", "NEXT")
    p.scan()
    assert (p["VW2"], p.mode) == (10000, "RUN")


# -- CALL ---------------------------------------------------------------------------
INTERFACE = """
VAR_INPUT
inb:BOOL;
inby:BYTE;
inw:WORD;
ind:DWORD;
END_VAR
VAR_IN_OUT
iob:BOOL;
iow:WORD;
END_VAR
VAR_OUTPUT
outb:BOOL;
outby:BYTE;
outw:INT;
outd:DWORD;
END_VAR
VAR
tmp:WORD;
END_VAR
"""

SBR_BODY = ("LD #inb\n= #outb",
            ("LD SM0.0\nMOVB #inby, #outby\nMOVW #inw, #tmp\n+I +1, #tmp\nMOVW #tmp, #outw\n"
             "MOVD #ind, #outd\nINCD #outd"),
            "LDN #iob\n= #iob",
            "LD SM0.0\n+I +100, #iow")

CALL = "CALL SBR_0, I0.0, VB0, VW2, VD4, M0.0, VW8, Q0.0, VB10, VW12, VD14"


@pytest.mark.parametrize("inb", [0, 1])
def test_call_passes_in_in_out_and_out_parameters(inb: int) -> None:
    """CALL copies IN/IN_OUT into L, runs the SBR, copies IN_OUT/OUT back (Micro/WIN order)."""
    p = _load(f"LD SM0.0\n{CALL}", extra=_sbr(0, *SBR_BODY, interface=INTERFACE))
    p["I0.0"] = inb
    p["VB0"] = 200
    p["VW2"] = -5
    p["VD4"] = 100000
    p["VW8"] = 7
    p.scan()
    assert [p[a] for a in ("Q0.0", "VB10", "VW12", "VD14", "M0.0", "VW8")] == \
        [inb, 200, -4, 100001, 1, 107]
    p.scan()
    assert (p["M0.0"], p["VW8"]) == (0, 207)            # IN_OUT read back each call


def test_call_accepts_constants_for_inputs() -> None:
    """IN parameters of BYTE/WORD/DWORD may be constants."""
    p = _load("LD SM0.0\nCALL SBR_0, I0.0, 16#10, -3, 16#10000, M0.0, VW8, Q0.0, VB10, "
              "VW12, VD14", extra=_sbr(0, *SBR_BODY, interface=INTERFACE))
    p.scan()
    assert (p["VB10"], p["VW12"], p["VD14"]) == (16, -2, 0x10001)


def test_call_without_power_flow_does_not_run_the_subroutine() -> None:
    """CALL is a box: with a 0 on top the subroutine is not executed."""
    p = _load("LD I0.0\nCALL SBR_0", extra=_sbr(0, "LD SM0.0\nINCW VW0"))
    p.scan(3)
    assert p["VW0"] == 0
    p["I0.0"] = 1
    p.scan(2)
    assert p["VW0"] == 2


def test_call_by_block_id_and_symbolic_name() -> None:
    """A subroutine is called by its name (as exports do) or by its SBRn id."""
    p = _load("LD SM0.0\nCALL Init_Step\nCALL SBR3",
              extra=_sbr(3, "LD SM0.0\nINCW VW0", name="Init_Step"))
    p.scan()
    assert p["VW0"] == 2


def test_subroutine_starts_with_a_fresh_stack_and_restores_the_caller_stack() -> None:
    """The caller's logic stack survives the call."""
    p = _load("LD I0.0\nLPS\nCALL SBR_0\nLPP\n= Q0.0",
              extra=_sbr(0, "LDN SM0.0\nLD SM0.0\n= Q0.1"))
    p["I0.0"] = 1
    p.scan()
    assert (p["Q0.0"], p["Q0.1"]) == (1, 1)


@pytest.mark.parametrize("call,message", [
    ("CALL SBR_0, I0.0", "takes 10 parameter(s)"),
    ("CALL SBR_0, I0.0, VB0, VW2, VD4, M0.0, VW8, 1, VB10, VW12, VD14", "#outb"),
    ("CALL SBR_0, I0.0, VW0, VW2, VD4, M0.0, VW8, Q0.0, VB10, VW12, VD14", "#inby"),
    ("CALL SBR_7", "no subroutine named 'SBR_7'"),
])
def test_call_parameter_errors(call: str, message: str) -> None:
    """Wrong parameter counts or kinds and unknown subroutines are compile errors."""
    with pytest.raises(PlcCompileError) as exc:
        _load(f"LD SM0.0\n{call}", extra=_sbr(0, *SBR_BODY, interface=INTERFACE))
    assert message in str(exc.value)


def test_unknown_local_is_a_compile_error() -> None:
    """#name must be declared in the block's interface."""
    with pytest.raises(PlcCompileError, match="unknown local variable '#nope'"):
        _load("LD SM0.0\nCALL SBR_0", extra=_sbr(0, "LD #nope\n= Q0.0"))


def _chain(depth: int) -> str:
    """SBR0 calls SBR1 ... SBR(depth-1), the last one counts in VW0."""
    return "".join(_sbr(i, f"LD SM0.0\nCALL SBR_{i + 1}" if i < depth - 1
                        else "LD SM0.0\nINCW VW0") for i in range(depth))


def test_eight_nesting_levels_are_allowed() -> None:
    """OB1 -> SBR0 -> ... -> SBR7 (eight levels) compiles and runs."""
    p = _load("LD SM0.0\nCALL SBR_0", extra=_chain(8))
    p.scan()
    assert p["VW0"] == 1


def test_nine_nesting_levels_run_eight_and_skip_the_ninth() -> None:
    """Subroutines nest at most eight levels deep (System Manual, CALL): a
    chain of nine compiles with a warning; at run time the ninth call is not
    executed and SM4.3 is set."""
    p = _load("LD SM0.0\nCALL SBR_0", extra=_chain(9))
    assert any("nest 9 levels deep" in d.message and d.severity == "warning"
               for d in p.diagnostics)
    p.scan()
    assert (p["VW0"], p["SM4.3"], p.mode) == (0, 1, "RUN")


@pytest.mark.parametrize("blocks", [
    _sbr(0, "LDW< VW0, +3\nINCW VW0\nCALL SBR_0"),
    _sbr(0, "LDW< VW0, +3\nINCW VW0\nCALL SBR_1") + _sbr(1, "LD SM0.0\nCALL SBR_0"),
])
def test_bounded_recursion_runs(blocks: str) -> None:
    """Direct and indirect recursion are allowed (a warning names the
    cycle); three levels run as written."""
    p = _load("LD SM0.0\nCALL SBR_0", extra=blocks)
    assert any(d.code == "recursion" for d in p.diagnostics)
    p.scan()
    assert (p["VW0"], p["SM4.3"]) == (3, 0)


# -- CRET / RET / END / STOP --------------------------------------------------------
def test_cret_returns_from_the_subroutine_conditionally() -> None:
    """CRET with a 1 on top leaves the subroutine; the caller continues."""
    p = _load("LD SM0.0\nCALL SBR_0", "LD SM0.0\n= Q0.1",
              extra=_sbr(0, "LD I0.1\nCRET", "LD SM0.0\nINCW VW0"))
    p.scan()
    p["I0.1"] = 1
    p.scan()
    assert (p["VW0"], p["Q0.1"]) == (1, 1)


def test_ret_returns_unconditionally() -> None:
    """RET ends the subroutine wherever it stands."""
    p = _load("LD SM0.0\nCALL SBR_0",
              extra=_sbr(0, "LD SM0.0\nINCW VW0", "RET", "LD SM0.0\nINCW VW2"))
    p.scan()
    assert (p["VW0"], p["VW2"]) == (1, 0)


def test_end_ends_the_main_program_conditionally() -> None:
    """END with a 1 on top ends OB1 for this scan; later networks are skipped."""
    p = _load("LD SM0.0\nINCW VW0", "LD I0.0\nEND", "LD SM0.0\nINCW VW2")
    p.scan()
    p["I0.0"] = 1
    p.scan()
    assert (p["VW0"], p["VW2"]) == (2, 1)


@pytest.mark.parametrize("body,extra,message", [
    (("LD SM0.0\nCRET",), "", "CRET is only allowed in a subroutine"),
    (("RET",), "", "RET is only allowed in a subroutine"),
    (("LD SM0.0\nCALL SBR_0",), _sbr(0, "LD SM0.0\nEND"), "END is only allowed"),
])
def test_return_instructions_in_the_wrong_block(body: tuple, extra: str, message: str) -> None:
    """CRET/RET belong to subroutines, END to the main program."""
    with pytest.raises(PlcCompileError, match=message):
        _load(*body, extra=extra)


def test_stop_completes_the_scan_then_stops() -> None:
    """STOP: the rest of the scan runs, then mode is STOP, outputs go off and scans do nothing."""
    p = _load("LD I0.0\nSTOP", "LD SM0.0\nINCW VW0\n= Q0.0")
    p.scan()
    assert (p.mode, p["VW0"], p.mem.areas["PQ"][0]) == ("RUN", 1, 1)
    p["I0.0"] = 1
    p.scan()
    assert (p.mode, p["VW0"]) == ("STOP", 2)
    assert p.mem.areas["PQ"][0] == 0
    t = p.time
    p.scan(5)
    p.run(seconds=1.0)
    assert (p["VW0"], p.time) == (2, t)


def test_stop_inside_a_subroutine() -> None:
    """STOP works from a subroutine as well."""
    p = _load("LD SM0.0\nCALL SBR_0", "LD SM0.0\nINCW VW0", extra=_sbr(0, "LD SM0.0\nSTOP"))
    p.scan(3)
    assert (p.mode, p["VW0"]) == ("STOP", 1)


# -- SCR ------------------------------------------------------------------------------
# A three-step sequence exported the Micro/WIN SMART way: LSCR, each SCRT and
# SCRE in networks of their own.
SEQUENCE = (
    "LD SM0.1\nS S0.0, 1",
    "LSCR S0.0",
    "LD SM0.0\n= Q0.0",
    "LD I0.0\nSCRT S0.1",
    "SCRE",
    "LSCR S0.1",
    "LD SM0.0\n= Q0.1\nINCW VW0",
    "LD I0.1\nSCRT S0.2",
    "LD I0.3\nCSCRE",
    "LD SM0.0\nINCW VW2",
    "SCRE",
    "LSCR S0.2",
    "LD SM0.0\n= Q0.2",
    "LD I0.2\nSCRT S0.0",
    "SCRE",
    "LD SM0.0\nINCW VW4",
)


def _steps(p: plcrt.Plc) -> tuple[int, int, int]:
    return p["S0.0"], p["S0.1"], p["S0.2"]


def test_scr_sequence_moves_the_step_bit() -> None:
    """SCRT resets the current step bit and sets the next; only active segments run."""
    p = _load(*SEQUENCE)
    p.scan()
    assert _steps(p) == (1, 0, 0) and (p["Q0.0"], p["Q0.1"], p["VW0"]) == (1, 0, 0)
    p.scan(3)
    assert _steps(p) == (1, 0, 0) and p["VW0"] == 0          # step 1 skipped
    p["I0.0"] = 1
    p.scan()
    assert _steps(p) == (0, 1, 0)
    p["I0.0"] = 0
    p.scan(2)
    # the segment of S0.0 is inactive: its output keeps its last state
    assert p["Q0.0"] == 1 and p["Q0.1"] == 1
    p["I0.1"] = 1
    p.scan()
    p["I0.1"] = 0
    assert _steps(p) == (0, 0, 1)
    vw0 = p["VW0"]
    p.scan(4)
    assert p["VW0"] == vw0 and p["Q0.2"] == 1
    p["I0.2"] = 1
    p.scan()
    assert _steps(p) == (1, 0, 0)
    assert p["VW4"] == p.scans                               # after the segments: every scan


def test_scr_transition_takes_effect_in_the_same_scan_for_later_segments() -> None:
    """The S bit set by SCRT is read by a later LSCR in the same scan (plcrt's choice)."""
    p = _load(*SEQUENCE)
    p.scan()
    p["I0.0"] = 1
    p.scan()
    assert p["VW0"] == 1        # S0.1's segment already ran in the transition scan


def test_cscre_ends_the_segment_conditionally() -> None:
    """CSCRE with a 1 on top skips the rest of the segment but not what follows SCRE."""
    p = _load(*SEQUENCE)
    p["I0.0"] = 1
    p.scan(2)                   # S0.1 runs in both scans (transition scan included)
    p["I0.0"] = 0
    p.scan()
    assert (p["VW0"], p["VW2"]) == (3, 3)
    p["I0.3"] = 1
    p.scan(3)
    assert (p["VW0"], p["VW2"], p["VW4"]) == (6, 3, 6)


@pytest.mark.parametrize("networks,message", [
    (("LD SM0.0\nSCRT S0.1",), "outside an SCR segment"),
    (("LSCR S0.0", "LD SM0.0\n= Q0.0"), "LSCR without a matching SCRE"),
    (("SCRE",), "outside an SCR segment"),
    (("LSCR S0.0", "LSCR S0.1", "SCRE", "SCRE"), "cannot nest"),
    (("LSCR S0.0", "LD SM0.0\nJMP 1", "SCRE", "LBL 1"), "crosses an SCR segment"),
    (("LSCR S0.0", "LD SM0.0\nFOR VW0, +1, +2", "NEXT", "SCRE"),
     "FOR is not allowed inside an SCR segment"),
    (("LSCR S0.0", "LD I0.0\nEND", "SCRE"), "END is not allowed inside an SCR segment"),
])
def test_scr_structure_errors(networks: tuple[str, ...], message: str) -> None:
    """Unbalanced or nested SCR segments and jumps out of a segment are compile errors."""
    with pytest.raises(PlcCompileError, match=message):
        _load(*networks)


def test_end_before_lscr_in_the_same_network_is_outside_the_segment() -> None:
    """Only instructions after LSCR belong to its segment."""
    p = _load("LD I0.0\nEND\nLSCR S0.0", "LD SM0.0\nINCW VW0", "SCRE")
    p["S0.0"] = 1
    p.scan()
    p["I0.0"] = 1
    p.scan()
    assert p["VW0"] == 1


def test_scr_in_an_interrupt_routine_is_a_compile_error() -> None:
    """SCR segments belong to the main program and subroutines only."""
    interrupt = ("INTERRUPT_BLOCK INT_0:INT0\nBEGIN\nNetwork 1\nLSCR S0.0\nNetwork 2\nSCRE\n"
                 "END_INTERRUPT_BLOCK\n")
    with pytest.raises(PlcCompileError, match="interrupt routine"):
        _load("LD SM0.0\n= Q0.0", extra=interrupt)


def test_scr_segments_work_in_a_subroutine() -> None:
    """LSCR/SCRT/SCRE inside a subroutine step just like in OB1."""
    p = _load("LD SM0.1\nS S1.0, 1", "LD SM0.0\nCALL SBR_0",
              extra=_sbr(0, "LSCR S1.0", "LD I0.0\nSCRT S1.1", "SCRE",
                         "LSCR S1.1", "LD SM0.0\nINCW VW0", "SCRE"))
    p.scan(2)
    assert (p["S1.0"], p["VW0"]) == (1, 0)
    p["I0.0"] = 1
    p.scan(2)
    assert (p["S1.0"], p["S1.1"], p["VW0"]) == (0, 1, 2)


PACKED = """
VAR_INPUT
a:BOOL;
b:BOOL;
c:BYTE;
END_VAR
VAR_IN_OUT
d:BYTE;
e:DWORD;
END_VAR
VAR_OUTPUT
f:BOOL;
g:BOOL;
END_VAR
"""


def test_parameter_layout_in_l_memory_follows_micro_win() -> None:
    """Parameters sit in L from L0.0 in the order IN, IN_OUT, OUT; BOOLs pack, bytes align."""
    # a=L0.0 b=L0.1 c=LB1 d=LB2 e=LD3 f=L7.0 g=L7.1: read them by address.
    sbr = _sbr(0, "LD L0.1\n= #f\nLD L0.0\n= #g",
               "LD SM0.0\nMOVB LB1, VB20\nINCB #d\nMOVD LD3, VD24\n+D +10, #e",
               interface=PACKED)
    p = _load("LD SM0.0\nCALL SBR_0, I0.0, I0.1, VB0, VB1, VD4, Q0.0, Q0.1", extra=sbr)
    p["I0.1"] = 1
    p["VB0"] = 0x5A
    p["VB1"] = 255
    p["VD4"] = -20
    p.scan()
    assert (p["Q0.0"], p["Q0.1"], p["VB20"], p["VD24"]) == (1, 0, 0x5A, -20)
    assert (p["VB1"], p["VD4"]) == (0, -10)      # IN_OUT BYTE wraps, DWORD adds
