"""Table and property tests for plcrt.isa.strings: SLEN SCPY SCAT SSCPY SFND
CFND ITS DTS RTS STI STD STR and the string compares LDS= LDS<> AS= AS<>
OS= OS<>, with string constants in the program and the data block.

Rows come from the S7-200 System Manual's definitions and examples ("String
instructions", "String conversion instructions"); the choices where it is
silent are the "Strings" rows of docs/decisions.md.
"""

from __future__ import annotations

import struct
from decimal import Decimal
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.engine.runtime import parse_sources
from plcrt.isa.registry import KNOWN_UNIMPLEMENTED, lookup
from plcrt.isa.shape import shape
from plcrt.memory import cpu_model
from plcrt.view.ladder import Box, Contact, to_ladder
from stl_helpers import ob1_text

SPACE8 = b" " * 8
V_SIZE = cpu_model(None).v_bytes  #: V memory of the default CPU


def _program(lines: list[str]) -> str:
    body = "\n".join(["LD SM0.0"] + lines)
    return f"ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\n{body}\nEND_ORGANIZATION_BLOCK\n"


def put(p: plcrt.Plc, offset: int, data: bytes) -> None:
    """Store ``data`` as a string (length byte first) at VB<offset>."""
    v = p.mem.areas["V"]
    v[offset] = len(data)
    v[offset + 1:offset + 1 + len(data)] = data


def get(p: plcrt.Plc, offset: int) -> bytes:
    """The characters of the string at VB<offset>."""
    v = p.mem.areas["V"]
    return bytes(v[offset + 1:offset + 1 + v[offset]])


def run(lines: list[str], strings: dict[int, bytes] | None = None,
        preset: dict | None = None) -> plcrt.Plc:
    """One scan of ``LD SM0.0`` + lines + ``AENO / = Q0.0`` (Q0.0 = ENO)."""
    p = plcrt.load(_program(lines + ["AENO", "= Q0.0"]))
    for offset, data in (strings or {}).items():
        put(p, offset, data)
    for addr, value in (preset or {}).items():
        p[addr] = value
    p.scan()
    return p


def _check(p: plcrt.Plc, strings: dict[int, bytes], values: dict) -> None:
    got_s = {o: get(p, o) for o in strings}
    got_v = {a: p["Q0.0" if a == "ENO" else a] for a in values}
    assert (got_s, got_v) == (strings, values)


# (id, lines, preset strings, preset values, expected strings, expected values)
CASES = [
    # SLEN (System Manual, "String length")
    ("SLEN", ["SLEN VB0, VB100"], {0: b"HELLO"}, {}, {}, {"VB100": 5, "ENO": 1}),
    ("SLEN constant", ['SLEN "ABC", AC0'], {}, {}, {}, {"AC0": 3}),
    ("SLEN empty", ["SLEN VB0, VB100"], {0: b""}, {"VB100": 9}, {}, {"VB100": 0}),
    ("SLEN keeps SMB1", ["SLEN VB0, VB100"], {0: b"A"}, {"SMB1": 0x07}, {},
     {"SMB1": 0x07}),
    ("SLEN length 255 is out of range", ["SLEN VB0, VB100"], {}, {"VB0": 255, "VB100": 9},
     {}, {"VB100": 9, "SMB1": 0, "ENO": 0}),
    # SCPY / SCAT / SLEN: the manual's example (append "WORLD" to "HELLO ",
    # copy it to VB100, its length into AC0)
    ("manual SCAT/SCPY/SLEN", ['SCAT "WORLD", VB0', "SCPY VB0, VB100", "SLEN VB100, AC0"],
     {0: b"HELLO "}, {}, {0: b"HELLO WORLD", 100: b"HELLO WORLD"}, {"AC0": 11, "ENO": 1}),
    ("SCPY keeps bytes after the string", ["SCPY VB0, VB100"], {0: b"HI", 100: b"ABCDE"},
     {}, {100: b"HI"}, {"VB104": ord("D"), "VB105": ord("E")}),
    ("SCPY empty constant", ['SCPY "", VB100'], {100: b"ABC"}, {}, {100: b""}, {"ENO": 1}),
    ("SCPY overlapping forward", ["SCPY VB0, VB2"], {0: b"ABCDE"}, {}, {2: b"ABCDE"}, {}),
    ("SCPY overlapping backward", ["SCPY VB2, VB0"], {2: b"ABCDE"}, {}, {0: b"ABCDE"}, {}),
    ("SCPY through a pointer", ["MOVD &VB200, AC1", 'SCPY "XY", *AC1'], {}, {},
     {200: b"XY"}, {"ENO": 1}),
    ("SCPY from a pointer", ["MOVD &VB0, VD50", "SCPY *VD50, VB200"], {0: b"PQR"}, {},
     {200: b"PQR"}, {}),
    ("SCPY length 255 is out of range", ["SCPY VB0, VB100"], {100: b"OLD"},
     {"VB0": 255}, {100: b"OLD"}, {"ENO": 0}),
    ("SCAT to an empty string", ["SCAT VB0, VB100"], {0: b"AB", 100: b""}, {},
     {100: b"AB"}, {"ENO": 1}),
    ("SCAT a string to itself", ["SCAT VB0, VB0"], {0: b"AB"}, {}, {0: b"ABAB"}, {}),
    ("SCAT cut at 254", ["SCAT VB300, VB0"], {0: b"x" * 250, 300: b"0123456789"}, {},
     {0: b"x" * 250 + b"0123"}, {"ENO": 0, "SMB1": 0}),
    ("SCAT exactly 254", ["SCAT VB300, VB0"], {0: b"x" * 250, 300: b"0123"}, {},
     {0: b"x" * 250 + b"0123"}, {"ENO": 1}),
    ("SCAT invalid OUT", ["SCAT VB300, VB0"], {300: b"AB"}, {"VB0": 255}, {},
     {"VB0": 255, "ENO": 0}),
    # SSCPY: the manual's example copies 5 characters from the 7th
    ("manual SSCPY", ["SSCPY VB0, 7, 5, VB20"], {0: b"HELLO WORLD"}, {}, {20: b"WORLD"},
     {"ENO": 1}),
    ("SSCPY last character", ["SSCPY VB0, 11, 1, VB20"], {0: b"HELLO WORLD"}, {},
     {20: b"D"}, {}),
    ("SSCPY N 0 is an empty string", ["SSCPY VB0, 3, 0, VB20"], {0: b"HELLO", 20: b"X"},
     {}, {20: b""}, {"ENO": 1}),
    ("SSCPY INDX 0", ["SSCPY VB0, 0, 2, VB20"], {0: b"HELLO", 20: b"OLD"}, {},
     {20: b"OLD"}, {"ENO": 0, "SMB1": 0}),
    ("SSCPY past the end", ["SSCPY VB0, 4, 3, VB20"], {0: b"HELLO", 20: b"OLD"}, {},
     {20: b"OLD"}, {"ENO": 0}),
    ("SSCPY operands from memory", ["SSCPY VB0, VB90, VB91, VB20"], {0: b"ABCDEF"},
     {"VB90": 2, "VB91": 3}, {20: b"BCD"}, {}),
    ("SSCPY from a constant", ['SSCPY "ABCDEF", 5, 2, VB20'], {}, {}, {20: b"EF"}, {}),
    # SFND: the manual's pump example ("On" in "Turn Pump On" from 1)
    ("manual SFND", ["MOVB 1, AC0", "SFND VB0, VB20, AC0"],
     {0: b"Turn Pump On", 20: b"On", 30: b"Off"}, {}, {}, {"AC0": 11, "ENO": 1}),
    ("SFND not found is 0", ["MOVB 1, AC0", "SFND VB0, VB30, AC0"],
     {0: b"Turn Pump On", 30: b"Off"}, {}, {}, {"AC0": 0, "ENO": 1}),
    ("SFND from a later start", ["SFND VB0, \"BC\", VB90"], {0: b"ABCABC"}, {"VB90": 3},
     {}, {"VB90": 5}),
    ("SFND start on the match", ["SFND VB0, \"BC\", VB90"], {0: b"ABCABC"}, {"VB90": 5},
     {}, {"VB90": 5}),
    ("SFND start 0", ["SFND VB0, \"BC\", VB90"], {0: b"ABCABC"}, {"VB90": 0},
     {}, {"VB90": 0, "ENO": 0}),
    ("SFND start past the string", ["SFND VB0, \"BC\", VB90"], {0: b"ABC"}, {"VB90": 4},
     {}, {"VB90": 4, "ENO": 0}),
    ("SFND empty IN2", ["SFND VB0, \"\", VB90"], {0: b"ABC"}, {"VB90": 1}, {},
     {"VB90": 0, "ENO": 1}),
    ("SFND IN2 longer than the rest", ["SFND VB0, \"CD\", VB90"], {0: b"ABC"}, {"VB90": 1},
     {}, {"VB90": 0}),
    # CFND and STR: the manual's example (the number in "Temp 98.6 F")
    ("manual CFND + STR", ["MOVB 1, AC0", "CFND VB0, VB20, AC0", "STR VB0, AC0, VD200"],
     {0: b"Temp 98.6 F", 20: b"1234567890+-"}, {}, {}, {"AC0": 6, "ENO": 1}),
    ("CFND none is 0", ["CFND VB0, \"0123456789\", VB90"], {0: b"ABC"}, {"VB90": 1}, {},
     {"VB90": 0, "ENO": 1}),
    ("CFND from a later start", ["CFND VB0, \"0123456789\", VB90"], {0: b"A1B2"},
     {"VB90": 3}, {}, {"VB90": 4}),
    ("CFND start 0", ["CFND VB0, \"1\", VB90"], {0: b"A1"}, {"VB90": 0}, {},
     {"VB90": 0, "ENO": 0}),
    # ITS (System Manual, "Integer to string"): the figure's values with
    # c = 0 and nnn = 3, 8 characters after a length byte of 8
    ("ITS 12", ["ITS VW0, VB100, 16#03"], {}, {"VW0": 12}, {100: b"   0.012"},
     {"ENO": 1}),
    ("ITS -123", ["ITS VW0, VB100, 16#03"], {}, {"VW0": -123}, {100: b"  -0.123"}, {}),
    ("ITS 1234", ["ITS VW0, VB100, 16#03"], {}, {"VW0": 1234}, {100: b"   1.234"}, {}),
    ("ITS -12345", ["ITS VW0, VB100, 16#03"], {}, {"VW0": -12345}, {100: b" -12.345"}, {}),
    ("ITS comma", ["ITS 1234, VB100, 16#0B"], {}, {}, {100: b"   1,234"}, {}),
    ("ITS no decimals", ["ITS -32768, VB100, 0"], {}, {}, {100: b"  -32768"}, {}),
    ("ITS five decimals", ["ITS -32768, VB100, 5"], {}, {}, {100: b"-0.32768"}, {}),
    ("ITS zero", ["ITS 0, VB100, 2"], {}, {}, {100: b"    0.00"}, {}),
    ("ITS writes 9 bytes only", ["ITS 7, VB100, 0"], {}, {"VB109": 0x55},
     {100: b"       7"}, {"VB109": 0x55}),
    ("ITS nnn 6 is 8 spaces", ["ITS 7, VB100, 6"], {}, {}, {100: SPACE8}, {"ENO": 0}),
    ("ITS high nibble set", ["ITS 7, VB100, 16#13"], {100: b"OLD"}, {}, {100: b"OLD"},
     {"ENO": 0, "SMB1": 0}),
    # DTS (System Manual, "Double integer to string"): 12 characters
    ("DTS min", ["DTS VD0, VB100, 0"], {}, {"VD0": -2147483648}, {100: b" -2147483648"},
     {"ENO": 1}),
    ("DTS two decimals", ["DTS 12345678, VB100, 2"], {}, {}, {100: b"   123456.78"}, {}),
    ("DTS small value", ["DTS 1, VB100, 16#0D"], {}, {}, {100: b"     0,00001"}, {}),
    ("DTS nnn 7", ["DTS 1, VB100, 7"], {}, {}, {100: b" " * 12}, {"ENO": 0}),
    # RTS (System Manual, "Real to string"): FMT 16#61 = 6 characters, 1
    # decimal, the manual's RTA examples
    ("RTS 1234.5", ["RTS VD0, VB100, 16#61"], {}, {"VD0": 1234.5}, {100: b"1234.5"},
     {"ENO": 1}),
    ("RTS -0.0004", ["RTS VD0, VB100, 16#61"], {}, {"VD0": -0.0004}, {100: b"   0.0"}, {}),
    ("RTS -3.67526", ["RTS VD0, VB100, 16#61"], {}, {"VD0": -3.67526}, {100: b"  -3.7"},
     {}),
    ("RTS 1.95", ["RTS VD0, VB100, 16#61"], {}, {"VD0": 1.95}, {100: b"   2.0"}, {}),
    ("RTS comma", ["RTS 1234.5, VB100, 16#69"], {}, {}, {100: b"1234,5"}, {}),
    ("RTS no decimals", ["RTS 2.5, VB100, 16#30"], {}, {}, {100: b"  3"}, {}),
    ("RTS 15 characters", ["RTS -12345.678, VB100, 16#F5"], {}, {},
     {100: b"   -12345.67773"}, {}),
    ("RTS too small is spaces", ["RTS 1234.5, VB100, 16#41"], {}, {}, {100: b"    "},
     {"ENO": 0}),
    ("RTS ssss < nnn + 3 is spaces", ["RTS 1.0, VB100, 16#42"], {}, {}, {100: b"    "},
     {"ENO": 0}),
    ("RTS nnn 6 is spaces", ["RTS 1.0, VB100, 16#A6"], {}, {}, {100: b" " * 10},
     {"ENO": 0}),
    ("RTS ssss 2 leaves OUT", ["RTS 1.0, VB100, 16#20"], {100: b"OLD"}, {}, {100: b"OLD"},
     {"ENO": 0}),
    ("RTS 1e38 is spaces", ["RTS VD0, VB100, 16#F5"], {}, {"VD0": 1e38},
     {100: b" " * 15}, {"ENO": 0}),
    ("RTS 1e16 is spaces", ["RTS VD0, VB100, 16#F0"], {}, {"VD0": 1e16},
     {100: b" " * 15}, {"ENO": 0}),
    ("RTS 15 whole digits", ["RTS VD0, VB100, 16#F0"], {}, {"VD0": 1e15},
     {100: b"999999986991104"}, {"ENO": 1}),
    ("RTS -inf is spaces", ["RTS VD0, VB100, 16#61"], {}, {"VD0": 0xFF800000},
     {100: b" " * 6}, {"ENO": 0}),
    ("RTS NaN is spaces", ["RTS VD0, VB100, 16#61"], {}, {"VD0": 0x7FC00000},
     {100: b" " * 6}, {"ENO": 0}),
    # STI / STD (System Manual, "Substring to integer"): the manual's valid
    # and invalid inputs
    ("STI 123", ["STI VB0, 1, VW100"], {0: b"123"}, {"SMB1": 0x02},
     {}, {"VW100": 123, "SMB1": 0, "ENO": 1}),
    ("STI -00456", ["STI VB0, 1, VW100"], {0: b"-00456"}, {}, {}, {"VW100": -456}),
    ("STI 123.45", ["STI VB0, 1, VW100"], {0: b"123.45"}, {}, {}, {"VW100": 123}),
    ("STI +2345", ["STI VB0, 1, VW100"], {0: b"+2345"}, {}, {}, {"VW100": 2345}),
    ("STI 000000123ABCD", ["STI VB0, 1, VW100"], {0: b"000000123ABCD"}, {}, {},
     {"VW100": 123}),
    ("STI leading spaces", ['STI "   -7 ", 1, VW100'], {}, {}, {}, {"VW100": -7}),
    ("STI from INDX", ["STI VB0, 7, VW100"], {0: b"Speed 1500 rpm"}, {}, {},
     {"VW100": 1500}),
    ("STI 32768 overflows", ["STI VB0, 1, VW100"], {0: b"32768"}, {"VW100": 9}, {},
     {"VW100": 9, "SM1.1": 1, "ENO": 0}),
    ("STI -32768", ["STI VB0, 1, VW100"], {0: b"-32768"}, {}, {}, {"VW100": -32768}),
    ("STI A123", ["STI VB0, 1, VW100"], {0: b"A123"}, {"VW100": 9}, {},
     {"VW100": 9, "SM1.1": 1, "ENO": 0}),
    ("STI empty", ["STI VB0, 1, VW100"], {0: b""}, {"VW100": 9}, {},
     {"VW100": 9, "SM1.1": 1, "ENO": 0}),
    ("STI ++123", ["STI VB0, 1, VW100"], {0: b"++123"}, {"VW100": 9}, {},
     {"VW100": 9, "SM1.1": 1, "ENO": 0}),
    ("STI +-123", ["STI VB0, 1, VW100"], {0: b"+-123"}, {"VW100": 9}, {},
     {"VW100": 9, "SM1.1": 1, "ENO": 0}),
    ("STI + 123", ["STI VB0, 1, VW100"], {0: b"+ 123"}, {"VW100": 9}, {},
     {"VW100": 9, "SM1.1": 1, "ENO": 0}),
    ("STI INDX past the string", ["STI VB0, 4, VW100"], {0: b"123"}, {"VW100": 9}, {},
     {"VW100": 9, "SM1.1": 1, "ENO": 0}),
    ("STI INDX 0", ["STI VB0, 0, VW100"], {0: b"123"}, {"VW100": 9}, {},
     {"VW100": 9, "SM1.1": 0, "ENO": 0}),
    ("STI INDX is not written", ["STI VB0, VB90, VW100"], {0: b"12ab"}, {"VB90": 1}, {},
     {"VB90": 1, "VW100": 12}),
    ("STD beyond INT", ["STD VB0, 1, VD100"], {0: b"-2147483648"}, {}, {},
     {"VD100": -2147483648, "ENO": 1}),
    ("STD overflow", ["STD VB0, 1, VD100"], {0: b"2147483648"}, {"VD100": 5}, {},
     {"VD100": 5, "SM1.1": 1, "ENO": 0}),
    # STR: "[spaces] [+ or -] [digits] [. or ,] [digits]"; no exponent
    ("STR 1.234E6 stops at E", ['STR "1.234E6", 1, VD100'], {}, {"SMB1": 2}, {},
     {"SMB1": 0, "ENO": 1}),
    ("STR overflow", ["STR VB0, 1, VD100"], {0: b"9" * 60}, {"VD100": 5}, {},
     {"VD100": 5, "SM1.1": 1, "ENO": 0}),
    ("STR lone point", ['STR ".", 1, VD100'], {}, {"VD100": 5}, {},
     {"VD100": 5, "SM1.1": 1, "ENO": 0}),
]


@pytest.mark.parametrize("lines,strings,preset,want_s,want_v", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_string_instructions(lines, strings, preset, want_s, want_v):
    """Each row: the manual's result, flags and ENO (Q0.0) for one instruction use."""
    _check(run(lines, strings, preset), want_s, want_v)


def _f32(x: float) -> float:
    return struct.unpack(">f", struct.pack(">f", x))[0]


@pytest.mark.parametrize("text,indx,value", [
    (b"123", 1, 123.0), (b"-00456", 1, -456.0), (b"123.45", 1, _f32(123.45)),
    (b"+2345", 1, 2345.0), (b"00.000000123", 1, _f32(0.000000123)),
    (b"1.234E6", 1, _f32(1.234)), (b"12,5", 1, 12.5), (b"5.", 1, 5.0), (b".5", 1, 0.5),
    (b"Temperature: 77.8", 13, _f32(77.8)), (b"Temp 98.6 F", 6, _f32(98.6)),
    (b"-0", 1, 0.0),
])
def test_str_values(text, indx, value):
    """STR converts the manual's valid real strings (and stops at an exponent)."""
    p = run([f"STR VB0, {indx}, VD100"], {0: text})
    assert (p.read("VD100", "REAL"), p["Q0.0"], p["SM1.1"]) == (value, 1, 0)
    if value == 0:
        assert p["VD100"] == 0  # "-0" is +0.0, not -0.0


# -- compares --------------------------------------------------------------------

@pytest.mark.parametrize("lines,strings,expect", [
    (['LDS= "ABC", VB0'], {0: b"ABC"}, 1),
    (['LDS= "ABC", VB0'], {0: b"ABD"}, 0),
    (['LDS= "ABC", VB0'], {0: b"AB"}, 0),
    (['LDS= "AB", VB0'], {0: b"ABC"}, 0),
    (['LDS= "", VB0'], {0: b""}, 1),
    (['LDS<> "ABC", VB0'], {0: b"ABC"}, 0),
    (['LDS<> "ABC", VB0'], {0: b"abc"}, 1),
    (["LDS= VB0, VB100"], {0: b"XY", 100: b"XY"}, 1),
    (['LDS= "XY", VB100'], {100: b"XY"}, 1),
    (['LD SM0.0', 'AS= "A", VB0'], {0: b"A"}, 1),
    (['LD SM0.0', 'AS<> "A", VB0'], {0: b"A"}, 0),
    (['LDN SM0.0', 'OS= "A", VB0'], {0: b"A"}, 1),
    (['LDN SM0.0', 'OS<> "A", VB0'], {0: b"A"}, 0),
    (['LDN SM0.0', 'AS= "A", VB0'], {0: b"A"}, 0),
])
def test_string_compares(lines, strings, expect):
    """LDS=/AS=/OS= push, AND or OR 'same characters'; <> is its negation."""
    p = plcrt.load(ob1_text("\n".join(lines + ["= Q0.0"])))
    for offset, data in strings.items():
        put(p, offset, data)
    p.scan()
    assert p["Q0.0"] == expect


def test_string_compare_runs_without_power_flow():
    """Compares run regardless of power flow: OS= after a 0 still ORs in its result."""
    p = plcrt.load(ob1_text('LDN SM0.0\nLPS\nOS= "Q", VB0\n= Q0.0\nLPP\n= Q0.1'))
    put(p, 0, b"Q")
    p.scan()
    assert (p["Q0.0"], p["Q0.1"]) == (1, 0)


def test_lds_logic_stack_instruction_is_undisturbed():
    """`LDS n` (copy a stack level) and `LDS=` (string compare) live side by side."""
    p = plcrt.load(ob1_text('LD SM0.0\nLDN SM0.0\nLDS 1\n= Q0.0\nLPP\n= Q0.1\n'
                            'LDS= "A", VB0\n= Q0.2'))
    put(p, 0, b"A")
    p.scan()
    assert (p["Q0.0"], p["Q0.1"], p["Q0.2"]) == (1, 0, 1)


def test_string_compare_past_memory_is_fatal():
    """A compare string that runs past the end of V memory stops the CPU at the compare."""
    p = plcrt.load(ob1_text('LDS= "A", *VD4\n= Q0.0'))
    size = len(p.mem.areas["V"])
    p["VD4"] = 0x08000000 | (size - 2)
    p.mem.areas["V"][size - 2] = 9
    with pytest.raises(plcrt.PlcRuntimeError, match="past the end of memory") as e:
        p.scan()
    assert e.value.loc.line == 4


@pytest.mark.parametrize("line", ['LDS= "A", VB0', "LDS= VB0, VB100", "LDS<> VB100, VB0",
                                  'LDS= "A", *VD200'])
def test_string_compare_of_a_too_long_string_is_fatal(line):
    """A length byte over 254 in a compare string stops the CPU (manual: fatal error)."""
    p = plcrt.load(ob1_text(f"{line}\n= Q0.0"))
    p["VB0"] = 255
    p["VD200"] = 0x08000000
    with pytest.raises(plcrt.PlcRuntimeError, match="longer than 254"):
        p.scan()


def test_string_compare_near_the_end_of_v_is_checked():
    """A direct string near the end of V memory is still checked against its end."""
    size = V_SIZE
    p = plcrt.load(ob1_text(f'LDS= "A", VB{size - 2}\n= Q0.0'))
    p.mem.areas["V"][size - 2] = 9
    with pytest.raises(plcrt.PlcRuntimeError, match="past the end of memory"):
        p.scan()
    p2 = plcrt.load(ob1_text(f'LDS= "A", VB{size - 2}\n= Q0.0'))
    p2.mem.areas["V"][size - 2:] = b"\x01A"
    p2.scan()
    assert p2["Q0.0"] == 1


def test_slen_near_the_end_of_v():
    """SLEN of a direct string whose length runs past the end of V is ENO 0."""
    size = V_SIZE
    p = plcrt.load(_program([f"SLEN VB{size - 3}, VB0", "AENO", "= Q0.0"]))
    p.mem.areas["V"][size - 3] = 3
    p["VB0"] = 7
    p.scan()
    assert (p["VB0"], p["Q0.0"]) == (7, 0)
    p.mem.areas["V"][size - 3] = 2
    p.scan()
    assert (p["VB0"], p["Q0.0"]) == (2, 1)


def test_string_past_memory_is_out_of_range():
    """A string that would run past the end of V memory is 0091: ENO 0, nothing written."""
    p = plcrt.load(_program(["SCPY VB20, *VD4", "AENO", "= Q0.0"]))
    size = len(p.mem.areas["V"])
    p["VD4"] = 0x08000000 | (size - 3)
    put(p, 20, b"ABC")
    p.scan()
    assert (p["Q0.0"], p.mem.areas["V"][size - 3]) == (0, 0)


# -- string constants: quoting, code page, roles -----------------------------------

@pytest.mark.parametrize("constant,stored", [
    ('"A""B"', b'A"B'),
    ('"$41"', b"$41"),
    ('"a, b // c"', b"a, b // c"),
    ('"Förder"', "Förder".encode("cp1252")),
    ('"' + "z" * 254 + '"', b"z" * 254),
])
def test_string_constant_bytes(constant, stored):
    """A doubled quote stands for one; `$`, commas and `//` are characters; the
    characters are stored in the code page (CP1252 for a program given as text)."""
    p = run([f"SCPY {constant}, VB100"])
    assert get(p, 100) == stored


def test_string_constant_in_the_file_code_page(tmp_path: Path):
    """A GBK export's string constant is stored as its GBK bytes."""
    f = tmp_path / "gbk.awl"
    f.write_bytes(_program(['SCPY "电机", VB100']).encode("gbk"))
    p = plcrt.load(f, encoding="gbk")
    p.scan()
    assert get(p, 100) == "电机".encode("gbk")


@pytest.mark.parametrize("line,fragment", [
    ('SCPY "\U0001F600", VB0', "not in code page CP1252"),   # in no ANSI code page
    ('SCPY "' + "z" * 255 + '", VB0', "at most 254"),
    ('MOVB "A", VB0', "only valid where a string is"),
    ("SCPY 'ABC', VB0", "double quotes"),
    ('SCPY VB0, "ABC"', "cannot be written"),
    ('LDS= VB0, "ABC"', "only be the first operand"),
    ('AS<> VB0, "ABC"', "only be the first operand"),
    ("SCPY VW0, VB2", "length byte"),
    ("SCPY MB0, VB2", "length byte"),
    ("SLEN VB0, VW2", "byte"),
    ("STI VB0, 1, VD2", "word"),
])
def test_bad_string_operands_are_located_errors(line, fragment):
    """Bad string operands are compile errors at the instruction's line."""
    with pytest.raises(plcrt.PlcCompileError) as e:
        plcrt.load(_program([line]))
    d = e.value.diagnostics[0]
    assert fragment in d.message and (d.loc.line, d.loc.network) == (5, 1)


def test_constant_text_never_reaches_generated_code():
    """A string constant reaches the generated module as bound bytes, not as source."""
    p = plcrt.load(ob1_text('LD SM0.0\nSCPY "__import__(\'os\')", VB100',
                            'LDS= "pwn\\n", VB100\n= Q0.0'))
    p.scan()
    assert "import" not in p.source and "pwn" not in p.source
    assert (get(p, 100), p["Q0.0"]) == (b"__import__('os')", 0)


def test_string_constant_in_a_subroutine_l_memory():
    """Strings live in L memory too: a temporary string in a subroutine."""
    src = ("ORGANIZATION_BLOCK OB1\nBEGIN\nNetwork 1\nLD SM0.0\nCALL SBR0\n"
           "END_ORGANIZATION_BLOCK\n"
           "SUBROUTINE_BLOCK SBR0\nBEGIN\nNetwork 1\nLD SM0.0\n"
           'SCPY "LOCAL", LB10\nSCAT "!", LB10\nSCPY LB10, VB100\n'
           "END_SUBROUTINE_BLOCK\n")
    p = plcrt.load(src)
    p.scan()
    assert get(p, 100) == b"LOCAL!"


# -- data block --------------------------------------------------------------------

def test_data_block_strings_feed_the_instructions():
    """A data block string (length byte first) is what SLEN and SCPY read."""
    p = plcrt.load(_program(["SLEN VB100, VB0", "SCPY VB100, VB200"]),
                   data='VB100 "Motor ""A"""\nVB150 \'xy\'')
    p.scan()
    assert (p["VB0"], get(p, 200), p["VB150"], p["VB151"]) == (9, b'Motor "A"',
                                                               ord("x"), ord("y"))


# -- ladder view --------------------------------------------------------------------

def test_shapes():
    """String compares are ==S / <>S contacts, the string instructions boxes."""
    assert (shape("LDS=").kind, shape("LDS=").lad, shape("LDS=").compare) == \
        ("contact", "==S", "S=")
    assert (shape("OS<>").op, shape("OS<>").lad) == ("or", "<>S")
    assert shape("LDS").kind == "stack"
    assert (shape("SSCPY").lad, shape("SSCPY").pins) == ("SSTR_CPY", "IN=0 INDX=1 N=2 OUT>3")
    assert shape("RTS").lad == "R_S" and shape("STR").lad == "S_R"


def test_ladder_draws_a_string_network():
    """A network with a string compare contact and a string box converts to LAD."""
    prog = parse_sources(ob1_text('LDS= "ON", VB0\nSCPY "RUN", VB100'))
    lad = to_ladder(prog.pous[0].networks[0])
    assert lad.ok
    assert isinstance(lad.rung.logic, Contact) and lad.rung.logic.above == '"ON"'
    box = lad.rung.outs[0]
    assert isinstance(box, Box) and box.title == "STR_CPY"


def test_mnemonics_are_implemented():
    """Every string mnemonic is registered and none is listed as unimplemented."""
    names = ("SLEN SCPY SCAT SSCPY SFND CFND ITS DTS RTS STI STD STR "
             "LDS= LDS<> AS= AS<> OS= OS<>").split()
    assert all(lookup(m) is not None for m in names)
    assert not set(names) & KNOWN_UNIMPLEMENTED


# -- properties --------------------------------------------------------------------

TEXT = st.binary(max_size=254)


def _machine(lines: list[str]) -> plcrt.Plc:
    return plcrt.load(_program(lines + ["AENO", "= Q0.0"]))


SCAT_PLC = _machine(["SCAT VB300, VB0"])


@settings(max_examples=60, deadline=None)
@given(TEXT, TEXT)
def test_scat_length_is_the_sum_capped(a, b):
    """SCAT: OUT = (OUT + IN) cut to 254 characters; ENO 1 exactly when nothing is cut."""
    p = SCAT_PLC
    put(p, 0, a)
    put(p, 300, b)
    p.scan()
    assert get(p, 0) == (a + b)[:254]
    assert p["Q0.0"] == int(len(a) + len(b) <= 254)


SSCPY_PLC = _machine(["SSCPY VB0, VB290, VB291, VB300"])


@settings(max_examples=80, deadline=None)
@given(TEXT, st.integers(0, 255), st.integers(0, 255))
def test_sscpy_stays_within_the_source(text, indx, n):
    """SSCPY copies text[INDX-1 : INDX-1+N] when that lies within IN; else ENO 0
    and OUT unchanged."""
    p = SSCPY_PLC
    put(p, 0, text)
    put(p, 300, b"OLD")
    p["VB290"], p["VB291"] = indx, n
    p.scan()
    if indx >= 1 and indx + n - 1 <= len(text):
        assert (get(p, 300), p["Q0.0"]) == (text[indx - 1:indx - 1 + n], 1)
    else:
        assert (get(p, 300), p["Q0.0"]) == (b"OLD", 0)


FIND_PLC = _machine(["MOVB VB290, VB291", "SFND VB0, VB100, VB291",
                     "MOVB VB290, VB292", "CFND VB0, VB100, VB292"])


@settings(max_examples=80, deadline=None)
@given(st.lists(st.sampled_from(b"abc"), max_size=30).map(bytes),
       st.lists(st.sampled_from(b"abc"), max_size=3).map(bytes), st.integers(1, 31))
def test_find_agrees_with_a_plain_search(text, sub, start):
    """SFND finds IN2 and CFND a character of IN2 at the first place from the start."""
    p = FIND_PLC
    put(p, 0, text)
    put(p, 100, sub)
    p["VB290"] = start
    p.scan()
    if start > len(text):
        assert (p["VB291"], p["VB292"]) == (start, start)
        return
    want_s = text.find(sub, start - 1) + 1 if sub else 0
    want_c = next((i + 1 for i in range(start - 1, len(text)) if text[i] in sub), 0)
    assert (p["VB291"], p["VB292"]) == (want_s, want_c)


ROUND_TRIP_PLC = _machine(["ITS VW0, VB100, VB2", "STI VB100, 1, VW10", "STR VB100, 1, VD20",
                           "DTS VD30, VB200, VB2", "STD VB200, 1, VD40"])


@settings(max_examples=80, deadline=None)
@given(st.integers(-32768, 32767), st.integers(-2**31, 2**31 - 1), st.integers(0, 5),
       st.booleans())
def test_its_then_sti_round_trips(v, d, nnn, comma):
    """ITS/DTS then STI/STD give back the whole part (all of it for nnn = 0), and
    STR the scaled value, whatever the separator."""
    p = ROUND_TRIP_PLC
    p["VW0"], p["VB2"], p["VD30"] = v, nnn | (8 if comma else 0), d
    p.scan()
    scale = 10 ** nnn
    assert p["VW10"] == int(v / scale)
    assert p["VD40"] == (abs(d) // scale) * (1 if d >= 0 else -1)
    assert p.read("VD20", "REAL") == _f32(float(Decimal(v).scaleb(-nnn)))
    assert (len(get(p, 100)), len(get(p, 200)), p["Q0.0"]) == (8, 12, 1)


RTS_PLC = _machine(["RTS VD0, VB100, VB4", "STR VB100, 1, VD10"])


@settings(max_examples=80, deadline=None)
@given(st.floats(-99999.0, 99999.0, width=32), st.integers(0, 5))
def test_rts_then_str_is_the_rounded_value(x, nnn):
    """RTS with room for the number, then STR, gives the value rounded to nnn
    decimals (half away from zero)."""
    p = RTS_PLC
    p["VD0"], p["VB4"] = x, 15 << 4 | nnn
    p.scan()
    want = Decimal(x).quantize(Decimal(1).scaleb(-nnn), rounding="ROUND_HALF_UP")
    assert p["Q0.0"] == 1
    assert p.read("VD10", "REAL") == _f32(float(abs(want) if want == 0 else want))


def test_a_unicode_program_with_chinese_constants_stores_them_in_gbk_with_a_note():
    """A UTF-8 export names no code page: CP1252 cannot hold 温度, GBK is the
    first ANSI code page that can, and a note says so."""
    plc = plcrt.load("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD SM0.0\n"
                     "SCPY \"温度\", VB100\nEND_ORGANIZATION_BLOCK\n")
    plc.scan()
    assert bytes(plc.mem.areas["V"][100:105]) == b"\x04" + "温度".encode("gbk")
    assert any(d.code == "codepage" and "GBK" in d.message for d in plc.diagnostics)


def test_a_unicode_program_whose_constants_fit_cp1252_gets_no_note():
    plc = plcrt.load("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD SM0.0\n"
                     "SCPY \"Müller\", VB100\nEND_ORGANIZATION_BLOCK\n")
    plc.scan()
    assert bytes(plc.mem.areas["V"][100:107]) == b"\x06" + "Müller".encode("cp1252")
    assert not [d for d in plc.diagnostics if d.code == "codepage"]
