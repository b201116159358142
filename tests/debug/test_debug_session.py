"""The debugger's command interpreter (:mod:`plcrt.debug.session`), driven
by scripts and compared with golden transcripts in ``golden/``.

Besides the golden comparison every test asserts the lines that carry its
point (a value seen in the middle of a scan, an exit status), so the
behaviour stays pinned when golden files are regenerated.  See
``debug_helpers.py`` for ``PLCRT_UPDATE_GOLDEN=1``.
"""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest
from debug_helpers import DATA, ROOT, check_golden, commands, session, transcript, watch_values

from plcrt.debug.session import COMMANDS, lookup, strip_comment

STEPS = str(DATA / "steps.awl")
FAULT = str(DATA / "fault.awl")


@pytest.fixture(autouse=True)
def _in_root(monkeypatch: pytest.MonkeyPatch) -> None:
    # file names in diagnostics and banners are then the short relative ones
    monkeypatch.chdir(ROOT)


def test_seal_in_set_scan_watch_force_unforce() -> None:
    text, status = transcript("programs/seal_in.awl", """
        # the classic seal-in: start latches, stop wins
        watch Q0.0 Q0.1
        set I0.0=1
        scan
        set I0.0=0
        scan 2            # Q0.0 holds itself
        force I0.1 1
        scan
        forces
        w
        unforce I0.1
        scan
        print Q0.0 I0.1
        status
    """)
    assert status == 0
    check_golden("seal_in", text)
    out = commands(text)
    assert [c for c, _ in out][:5] == ["watch Q0.0 Q0.1", "set I0.0=1", "scan", "set I0.0=0",
                                       "scan 2"]
    assert out[2][1].startswith("t=0.010 s  scan 1  RUN\n")
    assert watch_values(out[2][1]) == {"Q0.0": "1", "Q0.1": "1"}
    assert watch_values(out[4][1]) == {"Q0.0": "1", "Q0.1": "1"}      # sealed in
    assert watch_values(out[6][1]) == {"Q0.0": "0", "Q0.1": "0"}      # forced stop
    assert out[7] == ("forces", "I0.1 = 1\n")
    assert out[8][1] == "address  value\nQ0.0         0\nQ0.1         0\n"
    assert out[9] == ("unforce I0.1",
                      "released I0.1 (from the next scan on it reads its input terminal again)\n")
    # the stop button is not pressed: the input image follows the terminal again
    assert out[11] == ("print Q0.0 I0.1", "Q0.0 = 0\nI0.1 = 0\n")


def test_timer_run_until_and_durations() -> None:
    text, status = transcript("programs/timers.awl", """
        watch T37 Q0.0
        set I0.0=1
        run until T37 >= 100 timeout 15s
        run until Q0.1 timeout 1s
        run 1.5s
        r 200ms
        run 2
    """)
    check_golden("timers", text)
    # a 100 ms timer reaches 100 after 10 s: the default timeout would be too short
    assert "'T37 >= 100' is true after 10.01 s\nt=10.010 s  scan 1001  RUN\n" in text
    # a timeout prints the harness's message and the session goes on
    assert ("error: 'Q0.1' did not become true within 1 s of simulated time (100 scans); "
            "at t = 11.010 s, scan 1101\n") in text
    assert "t=14.710 s  scan 1471  RUN" in text
    assert status == 1


def test_breakpoint_stops_inside_the_scan_then_next_and_continue() -> None:
    text, status = transcript(STEPS, """
        watch Q0.0 Q0.1 VW0
        scan 2
        set I0.0=1
        break OB1/2
        breaks
        scan 2
        print Q0.0 Q0.1 VW0
        next
        print VW0
        next
        next
        print VW2 Q0.1
        continue
        continue
    """)
    assert status == 0
    check_golden("breakpoints", text)
    assert 'break at OB1/2 "Count the scans" (t=0.020 s, scan 3)\n' in text
    # Scan 3, paused before network 2: network 1 has run in this scan (Q0.0
    # follows the new I0.0), network 4 has not (Q0.1 is still last scan's 0),
    # and the count of network 2 is still 2.
    assert "(plcrt OB1/2) print Q0.0 Q0.1 VW0\nQ0.0 = 1\nQ0.1 = 0\nVW0 = 2\n" in text
    # next: network 2 ran; then into the subroutine CALLed by network 3
    assert "(plcrt OB1/2) next\nstopped before OB1/3" in text
    assert "(plcrt OB1/3) print VW0\nVW0 = 3\n" in text
    assert "(plcrt OB1/3) next\nstopped before SBR0/1" in text
    assert "(plcrt SBR0/1) next\nstopped before OB1/4" in text
    assert "(plcrt OB1/4) print VW2 Q0.1\nVW2 = 6\nQ0.1 = 0\n" in text
    # continue: the run goes on, and scan 4 stops at the breakpoint again
    assert 'break at OB1/2 "Count the scans" (t=0.030 s, scan 4)\n' in text
    assert text.endswith("t=0.040 s  scan 4  RUN\naddress  value\nQ0.0         1\n"
                         "Q0.1         1\nVW0          4\n")


def test_finish_ends_the_run_after_this_scan() -> None:
    text, status = transcript(STEPS, """
        break SBR0/1
        run 1s
        finish
        status
    """)
    assert status == 0
    check_golden("finish", text)
    assert 'break at SBR0/1 "Copy and add" (t=0.000 s, scan 1)' in text
    assert ("(plcrt SBR0/1) finish\nscan 1 finished; the rest of the command is skipped\n"
            "t=0.010 s  scan 1  RUN\n") in text


def test_scan_refused_while_paused_and_quit_finishes_the_scan() -> None:
    text, status = transcript(STEPS, """
        break 4
        scan 3
        scan
        run 1s
        pulse I0.0
        set VW0=100
        force Q0.1 1
        forces
        quit
        print VW0
    """)
    check_golden("paused_refusal", text)
    assert ("(plcrt OB1/4) scan\nerror: 'scan' would run scans, but scan 1 is paused before "
            "OB1/4; use 'continue', 'next' or 'finish' first\n") in text
    assert "(plcrt OB1/4) run 1s\nerror: 'run' would run scans" in text
    assert "(plcrt OB1/4) pulse I0.0\nerror: 'pulse' would run scans" in text
    # quit while paused: the scan completes (not the other two), nothing after quit runs
    assert text.endswith("(plcrt OB1/4) quit\nt=0.010 s  scan 1  RUN\n")
    assert status == 1


def test_end_of_input_while_paused_runs_the_command_to_its_end() -> None:
    text, status = transcript(STEPS, """
        break 1
        scan 3
    """)
    assert status == 0
    assert text.endswith("end of input while paused: the command runs to its end without "
                         "stopping, then the session ends\nt=0.030 s  scan 3  RUN\n")
    assert text.count("break at") == 1


def test_bad_commands_report_errors_and_exit_status_1() -> None:
    text, status = transcript(STEPS, """
        frobnicate
        scan x
        scan 1 2
        run
        run soon
        run until
        run until VW0 >= many
        run until Q0.0 timeout
        break OB1/9
        break FOO/1
        break x/y
        delete 1
        continue
        next
        print
        print FOO
        print VW0:WORD
        set Q0.0
        set Q0.0=1.5
        set VW0=abc
        force Q0.0
        unforce Q0.0
        pulse VW0
        help nothing
        status now
        watch NOPE
        unwatch VW0
        scan
    """)
    assert status == 1
    check_golden("errors", text)
    errors = [ln for ln in text.splitlines() if ln.startswith("error: ")]
    assert len(errors) == 27
    assert errors[0] == "error: unknown command 'frobnicate' (type 'help' for the list)"
    assert "error: no network OB1/9 (networks of OB1: 1..4)" in errors
    assert "error: 'continue' only works while a scan is paused at a breakpoint" in errors
    # the session went on to the last command
    assert text.endswith("(plcrt) scan\nt=0.010 s  scan 1  RUN\n")


def test_run_time_fault_prints_the_location_and_stops_the_cpu() -> None:
    text, status = transcript(FAULT, """
        set VB500=40 I0.1=1
        scan 2
        set VB500=41
        scan
        print VW0
        scan 5
        status
    """)
    assert status == 2
    check_golden("fault", text)
    assert ("tests/debug/data/fault.awl:9:1: error: block move runs past the end of its "
            "memory area [OB1 network 2]\n") in text
    assert "t=0.020 s  scan 2  STOP (fault)" in text
    assert "note: the CPU is in STOP mode after a fault: scans do nothing" in text


def test_em253_move_axes_panel_at_10_s() -> None:
    text, status = transcript("programs/em253/pos_goto_r.awl", """
        watch VW106 VD108
        set M2.0=1
        run 10s
        axes
        run until VW106 == 8 timeout 10s
        axes
    """, plant="programs/em253/plant.toml", scan_ms=1)
    assert status == 0
    check_golden("em253", text)
    # the manual's figure: 620 000 pulses after 10 s, at the full 80 kHz
    assert ("(plcrt) axes\nslot  axis  position  mechanical  speed Hz  status\n"
            "   0     0    620000      620000     80000  moving\n"
            "   0     1         0           0         0  stopped\n") in text
    # and the whole move of 1 000 000 pulses is done after 17 s
    assert "'VW106 == 8' is true after 7.001 s" in text
    assert "   0     0   1000000     1000000         0  stopped\n" in text


def test_axes_without_a_plant() -> None:
    text, status = transcript(STEPS, "axes")
    assert text == "(plcrt) axes\nno axes (load a --plant)\n"
    assert status == 0


def test_show_draws_ladder_with_live_values() -> None:
    text, status = transcript(STEPS, """
        set I0.0=1
        scan
        show 4
        show
    """)
    assert status == 0
    check_golden("show", text)
    assert "OB1 (MAIN)  Debugger test" in text
    assert "SBR0 (DOUBLE)  VW2 := 2 * VW0" in text


def test_show_falls_back_to_stl_without_the_ladder_view() -> None:
    s, out = session(STEPS)
    s._view = False             # as if plcrt.view could not be imported
    s.run(["show SBR0/1"])
    assert out.getvalue() == ("(plcrt) show SBR0/1\nSBR0 (DOUBLE)  VW2 := 2 * VW0\n"
                              "Network 1  Copy and add\nLD     SM0.0\nMOVW   VW0, VW2\n"
                              "+I     VW0, VW2\n")


def test_help_lists_every_command_and_explains_one() -> None:
    text, _ = transcript(STEPS, "help\nhelp b")
    for cmd in COMMANDS.values():
        assert f"  {cmd.usage} " in text
    assert "(plcrt) help b\nbreak NET  (short: b)\n" in text


def test_aliases_and_comments() -> None:
    assert lookup("s") is COMMANDS["scan"] and lookup("Q") is COMMANDS["quit"]
    assert strip_comment("set VW0=16#FF  # a hex value") == "set VW0=16#FF"
    assert strip_comment("   # only a comment") == ""
    text, status = transcript(STEPS, "s 2 # two scans\n\n#\np VW0")
    assert text == "(plcrt) s 2\nt=0.020 s  scan 2  RUN\n(plcrt) p VW0\nVW0 = 2\n"
    assert status == 0


def test_set_real_and_forced_marker_on_overlap() -> None:
    text, status = transcript(STEPS, """
        set VD4:REAL=2 VD8=1.5
        print VD4:REAL VD8:REAL VW4
        force QB0 16#FF
        print Q0.0 QB0 QW0 Q1.0
        unforce qb0
        forces
    """)
    assert status == 0
    out = dict(commands(text))
    # a real written to a double word reads back as a real
    assert out["set VD4:REAL=2 VD8=1.5"] == "VD4:REAL = 2\nVD8 = 1.5\n"
    assert out["print VD4:REAL VD8:REAL VW4"] == "VD4:REAL = 2\nVD8:REAL = 1.5\nVW4 = 16384\n"
    # forcing QB0 marks every address that overlaps it
    assert out["print Q0.0 QB0 QW0 Q1.0"] == ("Q0.0 = 1  (forced)\nQB0 = 255  (forced)\n"
                                             "QW0 = -256  (forced)\nQ1.0 = 0\n")
    assert out["unforce qb0"] == "released QB0 (it keeps 255 until the program changes it)\n"
    assert out["forces"] == "no forces\n"


def test_ctrl_c_stops_a_run_between_two_scans() -> None:
    s, out = session(STEPS)
    s.handle_interrupt = True

    def press_ctrl_c(plc: object) -> None:
        if s.plc.scans == 5:
            os.kill(os.getpid(), signal.SIGINT)

    s.plc.observers.append(press_ctrl_c)
    before = signal.getsignal(signal.SIGINT)
    s.run(["run 10s", "print VW0"])
    assert signal.getsignal(signal.SIGINT) is before
    assert "interrupted after 5 scan(s)\nt=0.050 s  scan 5  RUN\n" in out.getvalue()
    assert out.getvalue().endswith("VW0 = 5\n")


def test_session_needs_an_instrumented_plc() -> None:
    import plcrt
    from plcrt import PlcConfigError
    from plcrt.debug import Session

    plc = plcrt.load(Path(STEPS))
    with pytest.raises(PlcConfigError, match="instrument=True"):
        Session(plc)
