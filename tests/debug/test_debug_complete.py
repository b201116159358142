"""Tab completion at the debugger's prompt (:mod:`plcrt.debug.complete`) and
the ``clear`` command.

``complete(line, vocabulary)`` is pure: these tests call it with the words
of real sessions and check what a Tab offers after each kind of command.
The readline glue is checked with a stand-in for the readline module.
"""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from debug_helpers import ROOT, check_golden, session, transcript

import plcrt
from plcrt.debug import Session
from plcrt.debug.cli import install_completion
from plcrt.debug.commands import COMMANDS
from plcrt.debug.complete import (AREA_PREFIXES, ReadlineCompleter, Vocabulary, complete,
                                  vocabulary)


@pytest.fixture(autouse=True)
def _in_root(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def words(program: str = "programs/subroutine.awl", **kw: object) -> tuple[Session, Vocabulary]:
    s, _ = session(program, **kw)  # type: ignore[arg-type]
    return s, vocabulary(s)


def test_first_word_completes_to_commands() -> None:
    _, v = words()
    assert complete("", v) == sorted(COMMANDS)
    assert complete("br", v) == ["break", "breaks"]
    assert complete("TR", v) == ["trace", "trend"]
    assert complete("cl", v) == ["clear"]
    assert complete("xyz", v) == []


def test_break_completes_networks_by_block_id_and_name() -> None:
    _, v = words()
    assert complete("break ", v) == ["MAIN/1", "MAIN/2", "OB1/1", "OB1/2", "SBR0/1",
                                     "SBR0/2", "SBR0/3", "SCALE/1", "SCALE/2", "SCALE/3"]
    assert complete("b sc", v) == ["SCALE/1", "SCALE/2", "SCALE/3"]
    assert complete("show OB", v) == ["OB1/1", "OB1/2"]
    assert complete("clear SBR0/", v) == ["SBR0/1", "SBR0/2", "SBR0/3"]


def test_delete_offers_the_breakpoints_that_are_set() -> None:
    s, v = words()
    assert complete("delete ", v) == ["all"]
    s.execute("break SCALE/2")
    s.execute("break 1")
    assert complete("delete ", vocabulary(s)) == ["OB1/1", "SBR0/2", "all"]


def test_addresses_of_the_program_and_area_prefixes() -> None:
    _, v = words()
    assert {"AIW0", "VW10", "VW20", "VW22", "VW24", "Q0.0", "Q0.1", "I0.0",
            "SM0.0"} <= set(v.addresses)
    assert complete("watch vw2", v) == ["VW20", "VW22", "VW24"]
    assert complete("print V", v) == ["V", "VB", "VD", "VW", "VW10", "VW20", "VW22", "VW24"]
    assert complete("set S", v) == ["S", "SB", "SD", "SM", "SM0.0", "SMB", "SMD", "SMW", "SW"]
    assert complete("pulse I", v) == ["I", "I0.0", "IB", "ID", "IW"]
    assert set(AREA_PREFIXES) >= {"I", "Q", "M", "V", "SM", "T", "C", "AIW"}


def test_timers_counters_and_read_suffixes() -> None:
    _, v = words("programs/counters.awl")
    assert complete("watch C", v)[:3] == ["C", "C0", "C1"]
    assert complete("print C0:", v) == ["C0:BIT"]
    assert complete("print VD4:", v) == ["VD4:REAL"]
    assert complete("print VD4:r", v) == ["VD4:REAL"]
    _, v = words("programs/timers.awl")
    assert {"T37", "T38", "T5"} <= set(complete("watch T", v))
    assert complete("watch T37:", v) == ["T37:BIT"]


def test_symbols_of_the_symbol_table() -> None:
    plc = plcrt.load(Path("examples/course/01-seal-in/lesson.awl"), instrument=True,
                     symbols=Path("examples/course/01-seal-in/symbols.txt"))
    s = Session(plc, io.StringIO())
    v = vocabulary(s)
    assert complete("watch St", v) == ["Start_PB", "Stop_PB_NC"]
    assert complete("set Mo", v) == ["Motor"]
    # a name that would not print as itself is never offered on a terminal
    plc.symbols.entries["Evil\x1b[2J"] = plc.symbols.entries["Motor"]
    assert complete("watch Ev", vocabulary(s)) == []


def test_arguments_that_are_values_get_nothing() -> None:
    _, v = words()
    assert complete("set VW10=", v) == []
    assert complete("set VW10=1", v) == []
    assert complete("force Q0.0 ", v) == []
    assert complete("pulse I0.0 ", v) == []
    assert complete("scan ", v) == []
    assert complete("run ", v) == ["until"]
    assert complete("run 2", v) == []
    assert complete("run until VW1", v) == ["VW10"]
    assert complete("run until VW10 >= 5 timeout ", v) == []
    assert complete("help tr", v) == ["trace", "trend"]


def test_unwatch_unforce_offer_what_is_watched_and_forced() -> None:
    s, _ = words()
    s.execute("watch VW10 Q0.0")
    s.execute("force I0.0 1")
    v = vocabulary(s)
    assert complete("unwatch ", v) == ["Q0.0", "VW10", "all"]
    assert complete("unforce ", v) == ["I0.0", "all"]


def test_trace_offers_axis_signals_with_a_plant() -> None:
    _, v = words("programs/em253/pos_goto_r.awl", plant="programs/em253/plant.toml")
    assert complete("trace axis0.0", v) == ["axis0.0.mechanical", "axis0.0.position",
                                            "axis0.0.speed"]
    assert "stop" in complete("trace ", v) and "clear" in complete("trace ", v)
    assert "stop" not in complete("trace VW106 ", v)
    _, v = words()
    assert complete("trace ax", v) == []


class FakeReadline:
    """What ReadlineCompleter and install_completion use of readline."""

    def __init__(self, buffer: str = "") -> None:
        self.buffer = buffer
        self.completer = None
        self.delims = None
        self.bindings: list[str] = []
        self.__doc__ = "GNU readline"

    def get_line_buffer(self) -> str:
        return self.buffer

    def get_endidx(self) -> int:
        return len(self.buffer)

    def set_completer(self, fn) -> None:  # noqa: ANN001
        self.completer = fn

    def set_completer_delims(self, delims: str) -> None:
        self.delims = delims

    def parse_and_bind(self, text: str) -> None:
        self.bindings.append(text)


def test_readline_completer_answers_state_by_state() -> None:
    s, _ = words()
    rl = FakeReadline("break SCALE/")
    c = ReadlineCompleter(s, rl)
    got = []
    state = 0
    while (word := c("SCALE/", state)) is not None:
        got.append(word)
        state += 1
    assert got == ["SCALE/1", "SCALE/2", "SCALE/3"]


def test_install_completion_binds_tab_with_blank_delimiters() -> None:
    s, _ = words()
    rl = FakeReadline()
    install_completion(rl, s)
    assert isinstance(rl.completer, ReadlineCompleter)
    assert rl.delims == " \t\n"            # OB1/3 and VD4:REAL stay one word
    assert rl.bindings == ["tab: complete"]
    rl = FakeReadline()
    rl.__doc__ = "Importing this module enables command line editing using libedit readline."
    install_completion(rl, s)
    assert rl.bindings == ["bind ^I rl_complete"]


# ---------------------------------------------------------------------------
# clear
# ---------------------------------------------------------------------------

def test_clear_in_a_transcript_changes_nothing_and_clear_net_deletes() -> None:
    text, status = transcript("programs/seal_in.awl", """
break 2
watch Q0.0
clear
breaks
clear OB1/2
breaks
clear OB1/1
""")
    check_golden("clear", text)
    assert status == 1     # the last clear names a network without a breakpoint
    assert "(plcrt) clear\n(plcrt) breaks\nbreakpoint before OB1/2" in text
    assert "\x1b" not in text
    assert "(plcrt) clear OB1/2\ndeleted the breakpoint before OB1/2\n" in text
    assert text.endswith("(plcrt) clear OB1/1\nerror: no breakpoint at OB1/1\n")


def test_clear_on_a_terminal_erases_the_screen() -> None:
    plc = plcrt.load(Path("programs/seal_in.awl"), instrument=True)
    out = io.StringIO()
    s = Session(plc, out, color=True)
    s.execute("clear")
    assert out.getvalue() == "\x1b[H\x1b[2J"
    assert s.errors == 0


def test_help_lists_clear() -> None:
    text, _ = transcript("programs/seal_in.awl", "help\nhelp clear\n")
    assert "  clear [NET...]" in text
    assert "'delete all' (breakpoints), 'unwatch all', 'unforce all', 'trace clear'" in text
