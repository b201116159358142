"""Table tests for plcrt.isa.ascii: ITA, DTA, RTA, ATH, HTA (S7-200 System
Manual, "Conversion instructions", ASCII; SMART System Manual 7.5: FMT =
ssss c nnn, right-justified text, spaces for nnn > 5 or a field too small,
SM1.7 for an illegal ASCII hex character)."""

from __future__ import annotations

import struct
from decimal import Decimal

import pytest
from hypothesis import example, given, settings, strategies as st

import plcrt
from plcrt.isa.ascii import integer_text, real_text
from stl_helpers import load_ob1


def _run(body: str, preset: dict | None = None, v: dict[int, bytes] | None = None
         ) -> plcrt.Plc:
    """``LD SM0.0`` + body + ``AENO / = Q0.0``; ``v`` = bytes written at VB offsets."""
    p = load_ob1("LD SM0.0\n" + body + "\nAENO\n= Q0.0")
    for addr, value in (preset or {}).items():
        p.write(addr, value) if isinstance(value, float) else p.__setitem__(addr, value)
    for off, data in (v or {}).items():
        p.mem.areas["V"][off:off + len(data)] = data
    p.scan()
    return p


def _text(p: plcrt.Plc, off: int, n: int) -> bytes:
    return bytes(p.mem.areas["V"][off:off + n])


# ITA: (id, IN, FMT, the 8 characters or None for "OUT unchanged", ENO)
ITA = [
    # the manual's figure: c = 0, nnn = 3
    ("12", 12, 0x03, b"   0.012", 1),
    ("-123", -123, 0x03, b"  -0.123", 1),
    ("1234", 1234, 0x03, b"   1.234", 1),
    ("-12345", -12345, 0x03, b" -12.345", 1),
    ("comma 12345", 12345, 0x0B, b"  12,345", 1),
    ("nnn 0 no separator", -32768, 0x00, b"  -32768", 1),
    ("nnn 5", -32768, 0x05, b"-0.32768", 1),
    ("zero", 0, 0x02, b"    0.00", 1),
    ("nnn 6 fills spaces", 5, 0x06, b"        ", 0),
    ("nnn 7 with comma", 5, 0x0F, b"        ", 0),
    ("upper bits: no output", 5, 0x13, None, 0),
]


@pytest.mark.parametrize("value,fmt,text,eno", [c[1:] for c in ITA], ids=[c[0] for c in ITA])
def test_ita(value, fmt, text, eno):
    """ITA writes 8 right-justified characters in the FMT's format."""
    p = _run(f"ITA VW0, VB10, {fmt}", {"VW0": value}, {10: b"XXXXXXXX"})
    assert (_text(p, 10, 8), p["Q0.0"]) == (text or b"XXXXXXXX", eno)


DTA = [
    ("max", 2147483647, 0x00, b"  2147483647", 1),
    ("min nnn 5", -2147483648, 0x05, b"-21474.83648", 1),
    ("-12 nnn 4", -12, 0x04, b"     -0.0012", 1),
    ("comma", 123456, 0x0A, b"     1234,56", 1),
    ("nnn 6", 1, 0x06, b"            ", 0),
    ("upper bits", 1, 0x80, None, 0),
]


@pytest.mark.parametrize("value,fmt,text,eno", [c[1:] for c in DTA], ids=[c[0] for c in DTA])
def test_dta(value, fmt, text, eno):
    """DTA writes 12 right-justified characters in the FMT's format."""
    p = _run(f"DTA VD0, VB10, {fmt}", {"VD0": value}, {10: b"X" * 12})
    assert (_text(p, 10, 12), p["Q0.0"]) == (text or b"X" * 12, eno)


RTA = [
    # the manual's examples: ssss = 6, nnn = 1
    ("1234.5", 1234.5, 0x61, b"1234.5", 1),
    ("-0.0004 loses its sign", -0.0004, 0x61, b"   0.0", 1),
    ("-3.67526", -3.67526, 0x61, b"  -3.7", 1),
    ("1.95 rounds up", 1.95, 0x61, b"   2.0", 1),
    # the manual's STL example RTA VD10, VB14, 16#A3: ten characters, three decimals
    ("123.45 in 10", 123.45, 0xA3, b"   123.450", 1),
    ("comma", -2.5, 0x59, b" -2,5", 1),
    ("nnn 0 rounds half away", 2.5, 0x30, b"  3", 1),
    ("nnn 0 negative half", -2.5, 0x30, b" -3", 1),
    ("15 wide", -1234567.0, 0xF5, b" -1234567.00000", 1),
    ("too small fills spaces", 12345.0, 0x41, b"    ", 0),
    ("ssss < nnn + 3 fills spaces", 1.0, 0x33, b"   ", 0),
    ("nnn 6 fills spaces", 1.0, 0x86, b"        ", 0),
    ("3e38 fills spaces", -3.0e38, 0xF0, b" " * 15, 0),
    ("1e15 in float32 has 15 digits", 1.0e15, 0xF0, b"999999986991104", 1),
    ("1e16 fills spaces", 1.0e16, 0xF0, b" " * 15, 0),
    ("ssss 2: no output", 1.0, 0x20, None, 0),
    ("ssss 0: no output", 1.0, 0x01, None, 0),
]


@pytest.mark.parametrize("value,fmt,text,eno", [c[1:] for c in RTA], ids=[c[0] for c in RTA])
def test_rta(value, fmt, text, eno):
    """RTA writes ssss characters, the fraction rounded to nnn digits; spaces
    when nnn > 5 or the field is too small; nothing for ssss < 3."""
    p = _run(f"RTA VD0, VB10, {fmt}", {"VD0": value}, {10: b"X" * 16})
    want = (text if text is not None else b"") + b"X" * (16 - len(text or b""))
    assert (_text(p, 10, 16), p["Q0.0"]) == (want, eno)


def test_rta_not_a_number_fills_spaces():
    """A REAL that is no number (NaN, infinity) cannot be shown: spaces, ENO 0."""
    p = _run("RTA VD0, VB10, 16#62", {"VD0": 0x7FC00000}, {10: b"X" * 6})
    assert (_text(p, 10, 6), p["Q0.0"]) == (b"      ", 0)


def test_rta_format_from_memory():
    """FMT may be a byte in memory (VB), read at run time."""
    p = _run("RTA VD0, VB10, VB30", {"VD0": 0.5, "VB30": 0x52}, {10: b"X" * 6})
    assert _text(p, 10, 6) == b" 0.50X"


def test_ascii_needs_power_flow():
    """Without power flow nothing is written."""
    p = load_ob1("LD I0.0\nITA 5, VB0, 0\nHTA VB20, VB10, 2")
    p.mem.areas["V"][20] = 0xAB
    p.scan()
    assert _text(p, 0, 12) == bytes(12)


# ATH / HTA: (id, body, input bytes at VB30, preset output at VB40, output, SM1.7, ENO)
HEX = [
    # the manual's example: '3','E','A' -> 3E Ax, x the unchanged nibble
    ("ATH manual example", "ATH VB30, VB40, 3", b"3EA", b"\x00\x0F", b"\x3E\xAF", 0, 1),
    ("ATH even", "ATH VB30, VB40, 4", b"09AF", b"", b"\x09\xAF", 0, 1),
    ("ATH lower case is illegal", "ATH VB30, VB40, 2", b"1a", b"\x55", b"\x15", 1, 0),
    ("ATH stops at the illegal one", "ATH VB30, VB40, 4", b"12G4", b"\x00\x00",
     b"\x12\x00", 1, 0),
    ("ATH LEN 0", "ATH VB30, VB40, 0", b"", b"\x77", b"\x77", 0, 1),
    # HTA cannot fail on a character and leaves SM1.7 as it was (set here)
    ("HTA manual example", "HTA VB30, VB40, 3", b"\xE3\x1A", b"XXXX", b"E31X", 1, 1),
    ("HTA all digits", "HTA VB30, VB40, 4", b"\x09\xAF", b"", b"09AF", 1, 1),
    ("HTA LEN 0", "HTA VB30, VB40, 0", b"\x12", b"X", b"X", 1, 1),
]


@pytest.mark.parametrize("body,src,before,after,sm17,eno", [c[1:] for c in HEX],
                         ids=[c[0] for c in HEX])
def test_hex(body, src, before, after, sm17, eno):
    """ATH packs ASCII hex digits into nibbles (SM1.7 on an illegal one), HTA
    unpacks nibbles into upper-case ASCII."""
    # SM1.7 preset to the opposite of what ATH should leave (set for HTA)
    preset = 0x80 if body.startswith("HTA") or not sm17 else 0
    p = _run(body, {"SMB1": preset}, {30: src, 40: before})
    assert (_text(p, 40, len(after)), p["SM1.7"], p["Q0.0"]) == (after, sm17, eno)


def test_hex_length_from_memory_past_area_end_is_error_0091():
    """LEN from memory that runs past the end of V: error 0091, nothing written."""
    p = _run("HTA VB10230, VB0, VB100", {"VB100": 200}, {0: b"XX"})
    assert (_text(p, 0, 2), p["SM4.3"], p["Q0.0"], p.mode) == (b"XX", 1, 0, "RUN")


@settings(max_examples=200, deadline=None)
@given(value=st.integers(-32768, 32767), nnn=st.integers(0, 5), comma=st.booleans())
def test_ita_round_trips(value, nnn, comma):
    """ITA's text read back (separator removed) is the integer, right-justified in 8."""
    text = integer_text(value, nnn | comma << 3, 8)
    assert len(text) == 8 and text == text.rstrip()
    assert int(text.decode().replace(",", "").replace(".", "")) == value
    if nnn:
        assert text[-nnn - 1:-nnn] == (b"," if comma else b".")


@settings(max_examples=200, deadline=None)
@given(value=st.integers(-2**31, 2**31 - 1), nnn=st.integers(0, 5))
def test_dta_round_trips(value, nnn):
    """Every DINT fits DTA's 12 characters and reads back exactly."""
    text = integer_text(value, nnn, 12)
    assert len(text) == 12
    assert int(text.decode().replace(".", "")) == value


@settings(max_examples=200, deadline=None)
@given(bits=st.integers(0, 2**32 - 1), fmt=st.integers(0x30, 0xFF))
@example(bits=1_193_747_868, fmt=0xF5)     # 42789.609375: a tie at 5 digits
def test_rta_is_the_rounded_value(bits, fmt):
    """RTA's text, when not spaces, is the REAL rounded to nnn digits (within
    half a unit of the last digit), right-justified in ssss characters."""
    x = struct.unpack(">f", bits.to_bytes(4, "big"))[0]
    text = real_text(x, fmt)
    size, nnn = fmt >> 4, fmt & 7
    assert text is not None and len(text) == size
    if text.strip():
        # compared in decimal: a tie (42789.609375 shown as 42789.60938) is
        # exactly half a unit away, which a float subtraction can overstate
        shown = Decimal(text.decode().replace(",", "."))
        assert abs(shown - Decimal(x)) <= Decimal(5) * Decimal(10) ** -(nnn + 1)
