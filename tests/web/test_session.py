"""The panel's PLC runner without any web code: run modes, speed, set and
force, watch formats, breakpoints, trends in simulated time, frames and
the one-slot mailbox."""

from __future__ import annotations

import time

import pytest

from plcrt.web.session import Mailbox, PanelSession

from .conftest import REPO, load_sample


def session(**kw) -> PanelSession:
    s = PanelSession(load_sample(**kw))
    s.apply({"type": "speed", "mode": "max"})
    return s


def finish(s: PanelSession, limit: int = 10000) -> None:
    """Tick until a step or until-run has ended."""
    for _ in range(limit):
        if s.state == "stopped":
            return
        s.tick(wait=False)
    raise AssertionError("the run did not stop")


def test_step_runs_exactly_n_scans_then_stops() -> None:
    s = session()
    s.apply({"type": "step", "scans": 7})
    finish(s)
    assert s.plc.scans == 7 and s.state == "stopped"
    s.apply({"type": "step"})
    finish(s)
    assert s.plc.scans == 8


def test_set_presses_a_button_and_the_seal_holds() -> None:
    s = session()
    s.apply({"type": "set", "addr": "Start_PB", "value": "1"})
    s.apply({"type": "step"})
    finish(s)
    s.apply({"type": "set", "addr": "I0.0", "value": "0"})
    s.apply({"type": "step", "scans": 3})
    finish(s)
    f = s.frame()
    assert f["io"]["Q0.0"] == 1 and f["io"]["I0.0"] == 0


def test_set_values_are_checked_like_run_set() -> None:
    s = session()
    s.apply({"type": "set", "addr": "VB0", "value": "300"})
    assert s.last_error is not None and "set VB0=300" in s.last_error["message"]
    s.apply({"type": "set", "addr": "VW0", "value": "twelve"})
    assert "set VW0=twelve" in s.last_error["message"]
    s.apply({"type": "set", "addr": "VW0", "value": "16#FF"})
    assert s.plc.read("VW0") == 255


def test_until_stops_when_the_timer_is_done_in_simulated_time() -> None:
    s = session()
    s.apply({"type": "force", "addr": "I0.0", "value": "1"})
    s.apply({"type": "until", "cond": "T37:BIT"})
    finish(s)
    # the timer starts in the first scan (0.01 s) and counts 5 s
    assert s.plc.time == pytest.approx(5.01, abs=0.011)
    assert s.plc.read("Q0.1") == 1 and s.plc.read("T37", "BIT") == 1


def test_until_gives_up_at_its_timeout() -> None:
    s = session()
    c = s.connect()
    s.apply({"type": "until", "cond": "Q0.0", "timeout": 0.5})
    finish(s)
    assert s.plc.time == pytest.approx(0.5)
    notes = [m for m in c.mailbox.take() if m["type"] == "notice"]
    assert any("still false" in m["message"] for m in notes)


def test_force_holds_against_the_program_and_is_marked_in_the_watch_table() -> None:
    s = session()
    s.apply({"type": "watch", "spec": "Q0.0"})
    s.apply({"type": "watch", "spec": "QB0", "format": "hex"})
    s.apply({"type": "force", "addr": "Q0.0", "value": "1"})
    s.apply({"type": "step", "scans": 3})
    finish(s)
    rows = s.frame()["watch"]
    assert rows[0] == {"spec": "Q0.0", "format": "auto", "value": "1", "forced": True}
    assert rows[1]["value"] == "16#01" and rows[1]["forced"] is True
    s.apply({"type": "unforce", "addr": "Q0.0"})
    s.apply({"type": "set", "addr": "I0.1", "value": "1"})   # stop breaks the seal
    s.apply({"type": "step"})
    finish(s)
    assert s.frame()["watch"][0] == {"spec": "Q0.0", "format": "auto", "value": "0",
                                     "forced": False}


@pytest.mark.parametrize("spec, fmt, value, shown", [
    ("VW0", "int", -2, "-2"), ("VD0", "dint", 70000, "70000"), ("VD0", "real", 1.5, "1.5"),
    ("VW0", "hex", 255, "16#00FF"), ("I0.0", "bit", 1, "1"),
])
def test_watch_formats(spec, fmt, value, shown) -> None:
    s = session()
    s.apply({"type": "set", "addr": spec, "value": str(value)})
    s.apply({"type": "watch", "spec": spec, "format": fmt})
    assert s.frame()["watch"][0]["value"] == shown


def test_a_watch_format_that_does_not_fit_is_refused() -> None:
    s = session()
    s.apply({"type": "watch", "spec": "VW0", "format": "real"})
    assert "REAL needs a double word" in s.last_error["message"]
    assert s.watches == []


def test_frames_carry_ladder_status_of_the_viewed_block() -> None:
    s = session()
    s.apply({"type": "set", "addr": "I0.0", "value": "1"})
    s.apply({"type": "step"})
    finish(s)
    net = s.frame()["nets"]["OB1/1"]
    # the coil is powered: the last wire key (the coil) is on
    assert "1" in net["p"] and set(net["p"]) <= {"0", "1", "?"}
    assert s.frame()["nets"]["OB1/4"]["v"][-2:] == ["+0", "+0"]


def test_reset_is_power_up_but_forces_and_watches_stay() -> None:
    s = session()
    s.apply({"type": "watch", "spec": "VW2"})
    s.apply({"type": "force", "addr": "VW0", "value": "9"})
    s.apply({"type": "step", "scans": 5})
    finish(s)
    assert s.plc.read("VW2") == 9
    s.apply({"type": "reset"})
    assert s.plc.scans == 0 and s.plc.time == 0 and s.plc.read("VW2") == 0
    assert s.plc.forces == {"VW0": 9} and [w.spec for w in s.watches] == ["VW2"]


def test_trend_records_one_sample_per_scan_in_simulated_time() -> None:
    s = session()
    s.apply({"type": "trend", "signals": ["I0.0", "T37"]})
    s.apply({"type": "force", "addr": "I0.0", "value": "1"})
    s.apply({"type": "step", "scans": 100})
    finish(s)
    tr = s._trend_message()
    assert tr["signals"] == ["I0.0", "T37"]
    assert tr["end"] == 101 and len(tr["t"]) == 101     # the sample at the start + 100
    assert tr["t"][-1] == pytest.approx(1.0) and tr["v"][-1] == [1, 9]
    assert tr["v"][0] == [0, 0]
    # a frame carries only what is new since the previous one
    s.frame()
    s.plc.scan(2)
    f = s.frame()["trend"]
    assert (f["start"], f["end"], len(f["t"])) == (101, 103, 2)


def test_realtime_pacing_follows_the_wall_clock() -> None:
    now = [0.0]
    s = PanelSession(load_sample(), clock=lambda: now[0], sleep=lambda dt: None)
    s.apply({"type": "run"})
    for _ in range(20):
        now[0] += 0.05
        s.tick(wait=False)
    assert s.plc.time == pytest.approx(1.0, abs=0.02)
    s.apply({"type": "speed", "mode": "factor", "factor": 10})
    for _ in range(20):
        now[0] += 0.05
        s.tick(wait=False)
    assert s.plc.time == pytest.approx(11.0, abs=0.1)


def test_breakpoint_pauses_inside_the_scan_and_continue_goes_on() -> None:
    s = session()
    c = s.connect()
    s.start()
    try:
        s.submit(c, {"type": "break", "network": "OB1/3"})
        s.submit(c, {"type": "step", "scans": 3})
        f = _wait_frame(c, lambda f: f["run"] == "paused")
        assert f["paused_at"] == "OB1/3" and f["scans"] == 0   # inside the first scan
        s.submit(c, {"type": "set", "addr": "VW0", "value": "5"})
        _wait_frame(c, lambda f: f["run"] == "paused" and f["io"] is not None)
        s.submit(c, {"type": "unbreak", "network": "OB1/3"})
        s.submit(c, {"type": "continue"})
        f = _wait_frame(c, lambda f: f["run"] == "stopped" and f["scans"] >= 3)
        assert f["scans"] == 3 and s.plc.read("VW2") == 5
    finally:
        s.close()


def _wait_frame(client, pred, timeout: float = 10.0) -> dict:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        for m in client.mailbox.take():
            if m["type"] == "frame" and pred(m):
                return m
        time.sleep(0.01)
    raise AssertionError("no such frame")


def test_mailbox_keeps_only_the_newest_frame_and_every_message() -> None:
    calls = []
    mb = Mailbox(lambda: calls.append(1))
    mb.put_frame({"seq": 1})
    mb.put({"type": "error"})
    mb.put_frame({"seq": 2})
    assert mb.take() == [{"type": "error"}, {"seq": 2}]
    assert mb.skipped == 1 and len(calls) == 3 and mb.take() == []


def test_a_slow_client_never_holds_up_the_scan() -> None:
    s = session()
    slow = s.connect()         # never reads
    s.apply({"type": "step", "scans": 2000})
    t0 = time.monotonic()
    finish(s, limit=100000)
    s._publish()
    assert s.plc.scans == 2000 and time.monotonic() - t0 < 20
    assert len([m for m in slow.mailbox.take() if m["type"] == "frame"]) == 1


def test_a_fault_stops_the_run_with_a_notice() -> None:
    # two nested loops of 32767 passes: the watchdog ends the scan
    prog = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD SM0.0\nFOR VW0, +1, +32767\n" \
           "Network 2\nLD SM0.0\nFOR VW2, +1, +32767\nNetwork 3\nNEXT\nNetwork 4\nNEXT\n" \
           "END_ORGANIZATION_BLOCK\n"
    s = PanelSession(load_sample(prog, symbols=None))
    c = s.connect()
    s.apply({"type": "speed", "mode": "max"})
    s.apply({"type": "step", "scans": 2})
    finish(s)
    notes = [m for m in c.mailbox.take() if m["type"] == "notice"]
    assert notes and notes[0]["level"] == "error"
    assert s.frame()["mode"] == "STOP (fault)"


def _state(s: PanelSession) -> tuple:
    return s.plc.scans, s.plc.now_us, {k: bytes(v) for k, v in s.plc.mem.areas.items()}


def test_breakpoints_cost_nothing_until_set_then_the_scan_moves_builds() -> None:
    """A session starts in the build without probes; the first breakpoint
    moves it, in exactly its state, to the build with probes; clearing the
    last one moves it back at the next round.  Watches, the trend and the
    forces go along: the run ends exactly as in a session that never
    moved."""
    def drive(s: PanelSession, breaks: bool) -> None:
        s.apply({"type": "watch", "spec": "T37"})
        s.apply({"type": "trend", "signals": ["T37", "Q0.0"]})
        s.apply({"type": "force", "addr": "I0.0", "value": "1"})
        s.apply({"type": "step", "scans": 70})
        finish(s)
        if breaks:
            before = _state(s)
            s.apply({"type": "break", "network": "OB1/4"})
            assert s.plc.coverage is not None and _state(s) == before
            assert s.frame()["breaks"] == ["OB1/4"]
            s.apply({"type": "unbreak", "network": "OB1/4"})
        s.apply({"type": "step", "scans": 130})
        finish(s)

    s, ref = session(), session()
    assert s.plc.coverage is None and s.hello()["breakable"]
    drive(s, True)
    drive(ref, False)
    assert s.plc.coverage is None                     # back without probes
    assert s.plc.forces == {"I0.0": 1}
    assert _state(s) == _state(ref) and s.plc.read("T37") == 19   # 1.9 s of 100 ms ticks
    assert s._watch_row(s.watches[0]) == ref._watch_row(ref.watches[0])
    assert s._trend_message() == ref._trend_message()


def test_reset_in_the_probe_build_is_power_up() -> None:
    s = session()
    s.apply({"type": "step", "scans": 4})
    finish(s)
    s.apply({"type": "break", "network": "OB1/2"})
    s.apply({"type": "reset"})
    assert s.plc.coverage is not None and s.plc.scans == 0 and s.plc.time == 0
    assert s.frame()["breaks"] == ["OB1/2"]


def test_no_breakpoints_refuses_a_break() -> None:
    s = PanelSession(load_sample(), breakpoints=False)
    s.apply({"type": "break", "network": "OB1/2"})
    assert "breakpoints are off" in s.last_error["message"]
    assert s.plc.coverage is None and not s.hello()["breakable"]


def test_the_watch_table_is_bounded_and_says_its_limit() -> None:
    """Every row is read and sent to every page in every frame: a row past
    MAX_WATCH is refused with an error naming the limit."""
    from plcrt.web.protocol import MAX_WATCH
    s = session()
    for i in range(MAX_WATCH):
        s.apply({"type": "watch", "spec": f"VW{2 * i}"})
    assert len(s.watches) == MAX_WATCH and s.last_error is None
    s.apply({"type": "watch", "spec": "VW1000", "id": 9})
    assert len(s.watches) == MAX_WATCH
    assert s.last_error is not None and s.last_error["id"] == 9
    assert f"{MAX_WATCH} rows at most" in s.last_error["message"]
    s.apply({"type": "unwatch", "spec": "VW0"})
    s.apply({"type": "watch", "spec": "VW1000"})
    assert s.watches[-1].spec == "VW1000"


LESSON1 = REPO / "examples/course/01-seal-in"


def lesson1(kinds=None) -> PanelSession:
    import plcrt
    plc = plcrt.load(str(LESSON1 / "lesson.awl"), symbols=str(LESSON1 / "symbols.txt"))
    s = PanelSession(plc, kinds=kinds)
    s.apply({"type": "speed", "mode": "max"})
    return s


def test_input_kinds_come_from_the_symbol_comments_not_the_names() -> None:
    """Lesson 1's symbol table says Stop_PB_NC is a 'push button, normally
    closed' and Overload_OK an 'NC' relay: they rest at 1 from power-up on,
    so Start alone starts the motor; a name with 'PB' and no such comment
    is a switch."""
    s = lesson1()
    kinds = {io["addr"]: io["kind"] for io in s.hello()["inputs"]}
    assert kinds == {"I0.0": "button", "I0.1": "button_nc", "I0.2": "switch_nc"}
    assert s.plc.read("I0.1") == 1 and s.plc.read("I0.2") == 1 and s.plc.read("I0.0") == 0
    s.apply({"type": "set", "addr": "I0.0", "value": "1"})
    s.apply({"type": "step"})
    finish(s)
    s.apply({"type": "set", "addr": "I0.0", "value": "0"})
    s.apply({"type": "step", "scans": 3})
    finish(s)
    assert s.plc.read("Q0.0") == 1                         # sealed in
    s.apply({"type": "reset"})
    assert s.plc.read("I0.1") == 1 and s.plc.read("Q0.0") == 0   # the rest is the power-up
    bare = PanelSession(load_sample(symbols="Start_PB\tI0.0\t\nStop_PB\tI0.1\tstop\n"))
    assert {io["addr"]: io["kind"] for io in bare.hello()["inputs"]} == \
        {"I0.0": "switch", "I0.1": "switch"}


def test_the_lessons_own_kinds_win_over_the_symbol_comment() -> None:
    s = lesson1(kinds={"Stop_PB_NC": "switch", "I0.0": "button_nc"})
    kinds = {io["addr"]: io["kind"] for io in s.hello()["inputs"]}
    assert kinds == {"I0.0": "button_nc", "I0.1": "switch", "I0.2": "switch_nc"}
    assert s.plc.read("I0.0") == 1 and s.plc.read("I0.1") == 0


RECURSION = """\
ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1 // Call the subroutine
LD     SM0.0
CALL   SBR0
END_ORGANIZATION_BLOCK
SUBROUTINE_BLOCK SBR_0:SBR0
BEGIN
Network 1 // Count the depth
LD     SM0.0
INCW   VW0
Network 2 // Again
LD     SM0.0
CALL   SBR0
END_SUBROUTINE_BLOCK
"""


def _diagnostics(c) -> list[dict]:
    return [m for m in c.mailbox.take() if m["type"] == "diagnostics"]


def test_diagnostics_at_load_and_while_running_reach_the_pages_with_their_network() -> None:
    """What ``plcrt run`` prints on stderr: the recursion warning at load
    (in ``hello``) and the CALL that is not executed while running (a
    ``diagnostics`` message with both), each naming network SBR0/2; the
    same warning after a power-up reset is not listed again."""
    s = PanelSession(load_sample(RECURSION, symbols=None))
    c = s.connect()
    (load,) = s.hello()["diagnostics"]["items"]
    assert load["severity"] == "warning" and load["network"] == "SBR0/2"
    assert load["message"].startswith("recursion: SBR0 -> SBR0")
    assert load["text"] == str(s.plc.diagnostics[0]) and load["where"] == "<string>:14:1"
    s.apply({"type": "step"})
    finish(s)
    s._publish()
    (msg,) = _diagnostics(c)
    assert [d["network"] for d in msg["items"]] == ["SBR0/2", "SBR0/2"]
    assert msg["items"][1]["message"].startswith("CALL not executed")
    assert msg["more"] is None
    assert len(s.hello()["diagnostics"]["items"]) == 2     # a page that connects later
    s.apply({"type": "reset"})
    s.apply({"type": "step"})
    finish(s)
    s._publish()
    assert _diagnostics(c) == []


def test_a_fault_is_a_diagnostic_of_its_network() -> None:
    prog = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD SM0.0\nMOVB 200, VB0\n"
            "Network 2 // past the end\nLD SM0.0\nFILL +0, VW10200, VB0\n"
            "END_ORGANIZATION_BLOCK\n")
    s = PanelSession(load_sample(prog, symbols=None))
    c = s.connect()
    assert s.hello()["diagnostics"] == {"items": [], "more": None}
    s.apply({"type": "step"})
    finish(s)
    s._publish()
    (msg,) = _diagnostics(c)
    (fault,) = msg["items"]
    assert fault["severity"] == "error" and fault["network"] == "OB1/2"
    assert fault["message"] == "FILL runs past the end of its memory area"


def test_the_list_of_diagnostics_is_bounded() -> None:
    """A program that warns without end: the session keeps KEEP of them,
    the pages get the first MAX_LISTED and a count of the rest."""
    from plcrt.errors import MAX_LISTED, Diagnostic
    from plcrt.web.diagnostics import KEEP
    s = PanelSession(load_sample())
    c = s.connect()
    for i in range(KEEP + 50):
        s.plc.diagnostics.append(Diagnostic("warning", f"warning {i}", None, "runtime"))
    s._publish()
    (msg,) = _diagnostics(c)
    assert len(msg["items"]) == MAX_LISTED
    assert msg["more"] == f"... and {KEEP - MAX_LISTED} more warnings not listed (the first " \
                          f"{MAX_LISTED} are shown); 50 more not kept"
    assert msg["items"][0]["network"] is None and msg["items"][0]["where"] == ""


def test_a_power_up_reset_sends_the_new_trend() -> None:
    """The trend starts again at the reset: every page gets it whole (one
    sample at the time of power-up), and frames go on after it."""
    s = session()
    c = s.connect()
    s.apply({"type": "trend", "signals": ["Q0.0"]})
    s.apply({"type": "step", "scans": 20})
    finish(s)
    s._publish()
    c.mailbox.take()
    s.apply({"type": "reset"})
    msgs = c.mailbox.take()
    (tr,) = [m for m in msgs if m["type"] == "trend"]
    assert tr["t"] == [0.0] and tr["end"] == 1
    s._publish()     # the next frame does not carry that sample again
    (f,) = [m for m in c.mailbox.take() if m["type"] == "frame"]
    assert f["trend"]["start"] == 1 and f["trend"]["end"] == 1 and f["trend"]["t"] == []
