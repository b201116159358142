"""Symbol tables: Micro/WIN tab-separated text, SMART .sdf CSV, system
symbols, precedence and duplicate detection."""

from __future__ import annotations

import pytest

from plcrt.errors import PlcSyntaxError
from plcrt.lang import (
    SYSTEM_SYMBOLS,
    Symbol,
    SymbolTable,
    parse_symbols,
    resolve_symbol,
)

SDF = ('"Symbol","Address","Comment"\r\n'
       '"电机启动","I0.0","启动按钮"\r\n'
       '"Speed, set","VW100","comma, inside"\r\n'
       '"Lamp","Q0.0",""\r\n')


def test_sdf_csv_format() -> None:
    """A SMART .sdf export gives names, addresses and comments; header skipped."""
    table = parse_symbols(SDF, "a.sdf")
    assert list(table.entries) == ["电机启动", "Speed, set", "Lamp"]
    assert table.lookup("Speed, set") == Symbol(
        "Speed, set", "VW100", "comma, inside", table.entries["Speed, set"].loc)
    loc = table.entries["Lamp"].loc
    assert (loc.file, loc.line, loc.column) == ("a.sdf", 4, 1)
    assert table.lookup("Lamp").comment == ""


def test_sdf_without_header() -> None:
    """Quoted CSV rows are read even without the header line."""
    table = parse_symbols('"A","I0.0","x"\n"B","Q0.1","y"\n')
    assert [(s.name, s.address) for s in table.entries.values()] == [("A", "I0.0"), ("B", "Q0.1")]


def test_tab_separated_with_header_and_blank_lines() -> None:
    """Micro/WIN tab text: header row optional, blank lines ignored."""
    text = "Symbol\tAddress\tComment\n\nStart_PB\tI0.0\tstart button\n\nMotor\tQ0.0\n"
    table = parse_symbols(text, "s.txt")
    assert [(s.name, s.address, s.comment) for s in table.entries.values()] == [
        ("Start_PB", "I0.0", "start button"), ("Motor", "Q0.0", "")]
    assert table.entries["Motor"].loc.line == 5


def test_tab_separated_micro_win_4_leading_columns() -> None:
    """Leading empty or ``|`` status columns of a Micro/WIN 4 copy are skipped."""
    text = "\t\tStart\tI0.0\tgo\n|\tStop\tI0.1\tstop\n\t|\tLamp\tQ0.0\tlight\n"
    table = parse_symbols(text, "m.txt")
    assert [(s.name, s.address, s.comment) for s in table.entries.values()] == [
        ("Start", "I0.0", "go"), ("Stop", "I0.1", "stop"), ("Lamp", "Q0.0", "light")]
    assert table.entries["Start"].loc.column == 3


def test_pipe_and_blank_separated_lines() -> None:
    """Lines without TABs may use ``|`` or blanks between the columns."""
    table = parse_symbols("|Lamp|Q0.0|x\nFan VW0 fan speed set point\n")
    assert [(s.name, s.address, s.comment) for s in table.entries.values()] == [
        ("Lamp", "Q0.0", "x"), ("Fan", "VW0", "fan speed set point")]


def test_address_kept_as_written() -> None:
    """The address text is not validated or normalised here."""
    table = parse_symbols("X\tvw7\nY\tQX0.0\n")
    assert [s.address for s in table.entries.values()] == ["vw7", "QX0.0"]


def test_duplicate_names_are_errors_with_both_locations() -> None:
    """A repeated name raises PlcSyntaxError pointing at both definitions."""
    with pytest.raises(PlcSyntaxError) as info:
        parse_symbols("A\tI0.0\nB\tI0.1\nA\tI0.2\n", "d.txt")
    err = info.value
    assert (err.loc.line, err.loc.column) == (3, 1)
    assert "duplicate symbol 'A'" in err.message and "d.txt:1:1" in err.message
    assert [(d.severity, d.loc.line) for d in err.diagnostics] == [("error", 3), ("note", 1)]


def test_missing_address_is_error() -> None:
    """A row without an address is an error; all bad rows are listed."""
    with pytest.raises(PlcSyntaxError) as info:
        parse_symbols("A\t\tcomment\nB\tI0.0\nC\n", "e.txt")
    assert [d.loc.line for d in info.value.diagnostics] == [1, 3]


def test_system_symbols_table() -> None:
    """The SMART system symbols map to the documented SM addresses."""
    assert SYSTEM_SYMBOLS["Always_On"] == "SM0.0"
    assert SYSTEM_SYMBOLS["First_Scan_On"] == "SM0.1"
    assert SYSTEM_SYMBOLS["Clock_1s"] == "SM0.5"
    assert SYSTEM_SYMBOLS["HSC0_Ctrl"] == "SMB37"
    assert SYSTEM_SYMBOLS["PLS1_Cycle"] == "SMW78"
    assert SYSTEM_SYMBOLS["PTO0_PC"] == "SMD72"
    assert SYSTEM_SYMBOLS["P1_Max_Char"] == "SMB194"
    assert len(SYSTEM_SYMBOLS) == 56


def test_resolve_symbol_user_first_then_system() -> None:
    """User symbols hide system symbols; system ones resolve without a table."""
    table = parse_symbols("Clock_1s\tM0.0\nStart\tI0.0\n")
    assert resolve_symbol(table, "Clock_1s").address == "M0.0"
    assert resolve_symbol(table, "Always_On").address == "SM0.0"
    assert resolve_symbol(None, "Clock_1s").address == "SM0.5"
    assert resolve_symbol(table, "Nope") is None
    assert resolve_symbol(table, "start") is None  # names are case-sensitive


def test_with_system_merges_and_prefers_user() -> None:
    """with_system() returns a new table with both, user entries winning."""
    table = parse_symbols("Clock_1s\tM0.0\n")
    merged = table.with_system()
    assert isinstance(merged, SymbolTable) and merged is not table
    assert merged.lookup("Clock_1s").address == "M0.0"
    assert merged.lookup("Always_On").address == "SM0.0"
    assert merged.lookup("Always_On").loc is None
    assert table.lookup("Always_On") is None


def test_empty_table() -> None:
    """Empty or blank text gives an empty table."""
    assert len(parse_symbols("")) == 0
    assert len(parse_symbols("\n\t\n")) == 0


def test_random_text_only_raises_syntax_errors() -> None:
    """Arbitrary text parses or raises PlcSyntaxError, never anything else."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    @settings(max_examples=300, deadline=None)
    @given(st.one_of(st.text(max_size=120), st.lists(st.sampled_from(
        ['"', ",", "\t", "|", "\n", "\r\n", "A", "I0.0", " ", "\x00", "Symbol",
         "Address"]), max_size=30).map("".join)))
    def check(text: str) -> None:
        try:
            parse_symbols(text, "f.txt")
        except PlcSyntaxError as err:
            assert err.loc is not None and err.loc.file == "f.txt"

    check()
