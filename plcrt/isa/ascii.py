"""Instruction family: ASCII conversions (ITA DTA RTA ATH HTA).

S7-200 System Manual, "Conversion instructions" (ASCII); S7-200 SMART
System Manual 7.5 "Convert".  The string conversions that read or write
length-prefixed strings (ITS, DTS, RTS, STI, STD, STR) are not here.

``ITA IN, OUT, FMT`` / ``DTA`` write an INT / DINT as 8 / 12 characters at
OUT; ``RTA`` writes a REAL as ``ssss`` (3..15) characters.  FMT is
``ssss c nnn``: nnn digits after the separator (0..5; 0 means no
separator), c = 1 a comma, 0 a point, ssss RTA's field width (ITA/DTA:
the upper four bits must be 0).  The text is right-justified, a negative
value has a leading ``-``, leading zeros are suppressed except the digit
next to the separator, and RTA rounds the fraction to nnn digits (half
away from zero, on the REAL's exact value; a value that rounds to 0 has no
sign: -0.0004 is ``   0.0``).

Errors (ENO 0, no SMB1 bit): nnn > 5, or an RTA value that needs more than
ssss characters (or ssss < nnn + 3, the manual's minimum, or a REAL that
is no number) fill the field with ASCII spaces, as the manual says; an
illegal format the manual only lists as "no output" (ITA/DTA upper bits
not 0, RTA ssss < 3) leaves OUT unchanged.

``ATH IN, OUT, LEN`` packs LEN ASCII hex characters (``0``-``9``, ``A``-
``F`` only) into nibbles from OUT, the first into the high nibble; an odd
LEN leaves the low nibble of the last byte unchanged (the manual's
example).  An illegal character sets SM1.7 and ENO 0; the characters
before it are converted, the conversion stops there.  Success clears SM1.7.
``HTA IN, OUT, LEN`` writes LEN nibbles from IN as LEN characters
``0``-``9``, ``A``-``F``.  A run past the end of a memory area is run-time
error 0091 (SM4.3, ENO 0, nothing written).
"""

from __future__ import annotations

from decimal import ROUND_HALF_UP, Decimal
from typing import Callable

from ..gen.emit import Gen
from ..gen.recipe import CPU, Call, Item
from .region import region, runtime_error
from .registry import Role, Span, insn

F = "ascii"

SPACE = 0x20
HEX_DIGITS = b"0123456789ABCDEF"
#: ASCII code -> nibble of the legal characters 30..39, 41..46 hex
FROM_HEX: dict[int, int] = {c: i for i, c in enumerate(HEX_DIGITS)}
SM1_ILLEGAL_ASCII = 0x80   #: SM1.7


def fixed(value: int, nnn: int, comma: bool) -> str:
    """An integer scaled by 10**-nnn as text: sign, whole digits without
    leading zeros, separator and nnn digits (ITA, DTA)."""
    sign = "-" if value < 0 else ""
    digits = str(abs(value)).rjust(nnn + 1, "0")
    if nnn == 0:
        return sign + digits
    return f"{sign}{digits[:-nnn]}{',' if comma else '.'}{digits[-nnn:]}"


def integer_text(value: int, fmt: int, width: int) -> bytes | None:
    """The *width* characters ITA (8) or DTA (12) writes for *value*, or
    None for no output (upper four bits of FMT not 0)."""
    if fmt & 0xF0:
        return None
    nnn = fmt & 7
    if nnn > 5:
        return bytes([SPACE]) * width
    return fixed(value, nnn, bool(fmt & 8)).rjust(width).encode("ascii")


def real_text(value: float, fmt: int) -> bytes | None:
    """The ssss characters RTA writes for *value*, or None for no output
    (ssss < 3)."""
    size, nnn = fmt >> 4, fmt & 7
    if size < 3:
        return None
    blank = bytes([SPACE]) * size
    # 1e15 has 16 digits, more than the widest field: also keeps the
    # rounding within the decimal context's 28 digits
    if nnn > 5 or size < nnn + 3 or not abs(value) < 1e15:
        return blank
    scaled = int((Decimal(value) * (10 ** nnn)).quantize(Decimal(1), rounding=ROUND_HALF_UP))
    text = fixed(scaled, nnn, bool(fmt & 8))
    return blank if len(text) > size else text.rjust(size).encode("ascii")


def _helpers(plc) -> dict[str, Callable]:
    """Run-time conversions of *plc* (closures: a fork compiles its own)."""
    sm = plc.mem.areas["SM"]

    def out_of_area(mn: str, insn_id: int) -> int:
        return runtime_error(plc, insn_id, 0x0091, f"{mn}: the characters run past the end "
                             f"of their memory area; nothing is written")

    def put(text: bytes | None, where: tuple, mn: str, insn_id: int) -> int:
        buf, off = where
        if text is None:
            return 0
        if off + len(text) > len(buf):
            return out_of_area(mn, insn_id)
        buf[off:off + len(text)] = text
        return int(bool(text.strip()))   # a field of spaces is an error (ENO 0)

    def ita(value: int, where: tuple, fmt: int, insn_id: int) -> int:
        return put(integer_text(value, fmt, 8), where, "ITA", insn_id)

    def dta(value: int, where: tuple, fmt: int, insn_id: int) -> int:
        return put(integer_text(value, fmt, 12), where, "DTA", insn_id)

    def rta(value: float, where: tuple, fmt: int, insn_id: int) -> int:
        return put(real_text(value, fmt), where, "RTA", insn_id)

    def ath(src: tuple, dst: tuple, n: int, insn_id: int) -> int:
        sbuf, so = src
        dbuf, do = dst
        if so + n > len(sbuf) or do + (n + 1) // 2 > len(dbuf):
            return out_of_area("ATH", insn_id)
        chars = bytes(sbuf[so:so + n])
        for i, c in enumerate(chars):
            v = FROM_HEX.get(c)
            if v is None:
                sm[1] |= SM1_ILLEGAL_ASCII
                return 0
            at = do + i // 2
            dbuf[at] = (dbuf[at] & 0x0F | v << 4) if i % 2 == 0 else (dbuf[at] & 0xF0 | v)
        sm[1] &= ~SM1_ILLEGAL_ASCII & 255
        return 1

    def hta(src: tuple, dst: tuple, n: int, insn_id: int) -> int:
        sbuf, so = src
        dbuf, do = dst
        if so + (n + 1) // 2 > len(sbuf) or do + n > len(dbuf):
            return out_of_area("HTA", insn_id)
        packed = bytes(sbuf[so:so + (n + 1) // 2])
        dbuf[do:do + n] = bytes(HEX_DIGITS[packed[i // 2] >> (4 * (1 - i % 2)) & 15]
                                for i in range(n))
        return 1

    return {"ITA": ita, "DTA": dta, "RTA": rta, "ATH": ath, "HTA": hta}


def _helper(g: Gen, mn: str) -> str:
    hooks = g.unit.hooks
    if "ascii" not in hooks:
        hooks["ascii"] = Call(_helpers, (CPU,))
    return g.bind(Item(hooks["ascii"], mn), mn.lower())


#: the most characters RTA writes (FMT's ssss)
RTA_MAX = 15
#: mnemonic -> characters written at OUT (at most)
OUT_CHARS = {"ITA": 8, "DTA": 12, "RTA": RTA_MAX}
#: ATH / HTA: LEN characters or nibbles at IN and at OUT (bits each)
HEX_UNITS = {"ATH": (8, 4), "HTA": (4, 8)}

#: mnemonic -> (IN role, IN kind, bytes checked at OUT at compile time, summary)
NUMBER: dict[str, tuple[Role, str, int, str]] = {
    "ITA": (Role.W_R, "W", 8, "8 characters at OUT := INT IN formatted by FMT"),
    "DTA": (Role.D_R, "D", 12, "12 characters at OUT := DINT IN formatted by FMT"),
    "RTA": (Role.R_R, "R", 1, "FMT's ssss characters at OUT := REAL IN formatted by FMT"),
}


def _make_number(mn: str) -> None:
    role, kind, nbytes, summary = NUMBER[mn]

    def emit(g: Gen, value, out, fmt) -> None:
        fn = _helper(g, mn)
        where = region(g, out, nbytes, "OUT")
        with g.box():
            g.eno(f"{fn}({g.rd(value, kind)}, {where}, {g.rd(fmt, 'B')}, {g.insn_id})")

    insn(mn, role, Role.B_MW, Role.B_R, family=F, may_fail=True, summary=summary,
         spans=(Span(1, 8, OUT_CHARS[mn]),))(emit)


def _make_hex(mn: str, summary: str) -> None:
    def emit(g: Gen, src, out, n) -> None:
        fn = _helper(g, mn)
        a = region(g, src, 1, "IN")
        b = region(g, out, 1, "OUT")
        with g.box():
            g.eno(f"{fn}({a}, {b}, {g.rd(n, 'B')}, {g.insn_id})")

    unit_in, unit_out = HEX_UNITS[mn]
    insn(mn, Role.B_M, Role.B_MW, Role.B_R, family=F, may_fail=True, summary=summary,
         spans=(Span(0, unit_in, 255, by=2), Span(1, unit_out, 255, by=2)))(emit)


for _mn in NUMBER:
    _make_number(_mn)
_make_hex("ATH", "nibbles at OUT := LEN ASCII hex characters at IN (SM1.7 if illegal)")
_make_hex("HTA", "LEN ASCII hex characters at OUT := LEN nibbles at IN")
