"""Data block text: all value forms, S7-200 byte order, continuation lines,
range errors with locations, overlap warnings and apply()."""

from __future__ import annotations

import struct

import pytest

from plcrt.errors import PlcSyntaxError
from plcrt.lang import DataBlock, DataEntry, parse_datablock


def image(text: str, size: int = 64) -> bytearray:
    buf = bytearray(size)
    parse_datablock(text).apply(buf)
    return buf


def error_of(text: str) -> PlcSyntaxError:
    with pytest.raises(PlcSyntaxError) as info:
        parse_datablock(text, "db.txt")
    return info.value


def test_byte_and_hex_and_binary() -> None:
    """VB takes decimal, 16# and 2# (with _) constants."""
    buf = image("VB0 255\nVB1 16#7F\nVB2 2#1010_0101\nVB3 0")
    assert buf[:4] == bytes([255, 0x7F, 0b10100101, 0])


def test_words_are_big_endian_and_consecutive() -> None:
    """VW2 256, 700, 2 writes three big-endian words from VB2."""
    block = parse_datablock("VW2     256, 700, 2        // consecutive words")
    assert [(e.offset, e.data) for e in block.entries] == [
        (2, b"\x01\x00"), (4, b"\x02\xbc"), (6, b"\x00\x02")]
    assert [e.loc.column for e in block.entries] == [9, 14, 19]


def test_negative_word_and_dint_are_twos_complement() -> None:
    """Negative INT/DINT values are stored as two's complement."""
    buf = image("VW0 -1\nVD4 -5\nVW8 +7")
    assert buf[:10] == bytes.fromhex("ffff0000fffffffb0007")


def test_real_and_hex_dword() -> None:
    """VD with a dotted or exponent constant stores an IEEE REAL."""
    buf = image("VD10 3.14\nVD14 16#FFFF\nVD18 1E3\nVD22 -1.0")
    assert buf[10:14] == struct.pack(">f", 3.14)
    assert buf[14:18] == b"\x00\x00\xff\xff"
    assert buf[18:22] == struct.pack(">f", 1000.0)
    assert buf[22:26] == struct.pack(">f", -1.0)


def test_char_and_string_constants() -> None:
    """'ABC' stores ASCII bytes; "ab" stores a length byte first."""
    buf = image("VB20 'A,B//C' // not a comment inside\nVB30 \"hi\", 'x'")
    assert buf[20:26] == b"A,B//C"
    assert buf[30:34] == b"\x02hix"


def test_bit_form() -> None:
    """V100.3 1 sets one bit and leaves the others alone; more values go on."""
    buf = bytearray(128)
    buf[100] = 0b1000_0001
    block = parse_datablock("V100.3 1\nV100.0 0\nV100.7 1, 1")
    assert block.entries[0] == DataEntry(100, b"\x01", block.entries[0].loc, 3)
    block.apply(buf)
    assert buf[100] == 0b1000_1000 and buf[101] == 0b0000_0001


def test_continuation_lines_and_comments() -> None:
    """Indented lines without an address continue after the last value."""
    text = "// header\n\nVW0 1, 2,\n    3\n\t4 // four\nVB10 7\n   8\n"
    buf = image(text)
    assert buf[:8] == bytes.fromhex("0001000200030004")
    assert buf[10:12] == b"\x07\x08"


def test_lower_case_addresses() -> None:
    """Addresses are case-insensitive."""
    assert image("vb1 9\nvw2 16#0102")[1:4] == b"\x09\x01\x02"


@pytest.mark.parametrize(("text", "column", "fragment"), [
    ("VB0 256", 5, "out of range for VB"),
    ("VB0 -1", 5, "out of range for VB"),
    ("VW0 70000", 5, "out of range for VW"),
    ("VW0 -32769", 5, "out of range for VW"),
    ("VD0 16#1_0000_0000", 5, "out of range for VD"),
    ("VW0 1.5", 5, "needs a VD"),
    ("VD0 1E39", 5, "REAL value"),
    ("VB0 2#102", 5, "bad constant"),
    ("VB0 'Ω'", 5, "not in code page CP1252"),
    ("VB0 'abc", 5, "unterminated"),
    ("VB0 1 2", 7, "expected ','"),
    ("VB0 1,,2", 7, "missing value"),
    ("MB0 1", 1, "only initialise V memory"),
    ("VX0 1", 1, "expected a V memory address"),
    ("V1.8 1", 1, "bit number"),
    ("V1.0 2", 6, "0 or 1"),
    ("VB0", 4, "missing value"),
])
def test_bad_values(text: str, column: int, fragment: str) -> None:
    """Each bad line is a PlcSyntaxError at the offending column."""
    err = error_of("// first line\n" + text)
    assert (err.loc.file, err.loc.line, err.loc.column) == ("db.txt", 2, column)
    assert fragment in err.message


def test_all_errors_listed() -> None:
    """Several bad lines are all reported, in order, with file:line:col."""
    err = error_of("VB0 256\nVW2 1\nVW4 70000\n  -99999\n")
    assert [str(d.loc) for d in err.diagnostics] == [
        "db.txt:1:5", "db.txt:3:5", "db.txt:4:3"]


def test_continuation_before_any_address_is_error() -> None:
    """An indented value line before the first address is an error."""
    assert "before the first address" in error_of("   1, 2\n").message


def test_overlaps_allowed_later_wins_with_warning() -> None:
    """Overlapping entries are applied in order and produce a warning."""
    block = parse_datablock("VW0 16#0102\nVB1 9\n", "o.txt")
    buf = bytearray(4)
    block.apply(buf)
    assert buf[:2] == b"\x01\x09"
    assert [(w.severity, str(w.loc)) for w in block.warnings] == [("warning", "o.txt:2:5")]
    assert "o.txt:1:5" in block.warnings[0].message


def test_apply_out_of_range_names_entry_and_writes_nothing() -> None:
    """An entry past the buffer end raises naming it; nothing is written."""
    block = parse_datablock("VB0 1\nVD300 1\n", "r.txt")
    buf = bytearray(302)
    with pytest.raises(PlcSyntaxError) as info:
        block.apply(buf)
    assert str(info.value.loc) == "r.txt:2:7"
    assert buf[0] == 0
    assert block.extent == 304


def test_empty_datablock() -> None:
    """Comments and blank lines only give an empty block."""
    block = parse_datablock("// nothing\n\n   \n")
    assert block == DataBlock(entries=[], file="<string>", warnings=[])
    assert block.extent == 0


def test_random_text_only_raises_syntax_errors() -> None:
    """Arbitrary text parses (and applies) or raises PlcSyntaxError only."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    @settings(max_examples=300, deadline=None)
    @given(st.one_of(st.text(max_size=120), st.lists(st.sampled_from(
        ["VB0", "VW2", "VD4", "V1.3", " ", ",", "'", '"', "//", "\n", "\t",
         "16#", "2#", "-", "1", "1.5", "E", "x", "\x00"]), max_size=30).map("".join)))
    def check(text: str) -> None:
        try:
            parse_datablock(text, "f.txt").apply(bytearray(16))
        except PlcSyntaxError as err:
            assert err.loc is not None and err.loc.file == "f.txt"

    check()
