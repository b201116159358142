"""Operand classification and resolution (IR operand text -> typed operand).

The front end keeps operands as text; this module turns ``VW100``, ``T37``,
``+10``, ``16#FF``, ``&VB0``, ``*AC1``, ``#Start`` or a symbol name into one of
the typed operands below, checking that the address fits the CPU model.  It is
used by the compiler and by the slow-path address API (``plc["VW100"]``).

It does not know which operand kinds an instruction accepts; that is the
instruction registry's job (:mod:`plcrt.isa.registry`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Union

from ..lang.codepage import DEFAULT_CODEPAGE, string_bytes
from ..lang.limits import MAX_DIGITS, too_many_digits
from ..memory.cpu import CpuModel
from ..safetext import excerpt

# Areas that can be addressed as bit / byte / word / dword, with their
# accepted prefixes.  T and C are special: bit in bit context, current value
# (INT) in word context (S7-200 System Manual, "Addressing the timer memory").
BYTE_AREAS = ("I", "Q", "M", "V", "SM", "S", "L")

_BIT_RE = re.compile(r"(SM|I|Q|M|V|S|L)(\d+)\.(\d+)", re.I)
_SIZED_RE = re.compile(r"(SM|I|Q|M|V|S|L)([BWD])(\d+)", re.I)
_ANALOG_RE = re.compile(r"(AI|AQ)W(\d+)", re.I)
_TC_RE = re.compile(r"(T|C)(\d+)", re.I)
_AC_RE = re.compile(r"AC(\d+)", re.I)
_HC_RE = re.compile(r"HC(\d+)", re.I)
_DEC_RE = re.compile(r"[+-]?\d+")
_HEX_RE = re.compile(r"16#([0-9A-F_]+)", re.I)
_BIN_RE = re.compile(r"2#([01_]+)", re.I)
_REAL_RE = re.compile(r"[+-]?(\d+\.\d*|\.\d+|\d+)([E][+-]?\d+)?", re.I)

WIDTH_OF = {"B": 1, "W": 2, "D": 4}

#: Pointer area codes stored in the high byte of a 32-bit pointer
#: (``&VB100`` -> ``0x08000064``).  The manual leaves the encoding open; only
#: the low 24 bits (the byte offset) may be changed by pointer arithmetic.
POINTER_AREAS: dict[str, int] = {
    "I": 0x01, "Q": 0x02, "M": 0x03, "S": 0x04, "SM": 0x05, "AI": 0x06,
    "AQ": 0x07, "V": 0x08, "T": 0x09, "C": 0x0A,
}
POINTER_AREA_NAMES = {v: k for k, v in POINTER_AREAS.items()}


@dataclass(frozen=True, slots=True)
class Addr:
    """A direct memory location.

    ``width`` is 0 for a bit, 1/2/4 bytes for values, and ``None`` where the
    instruction decides (``T37``, ``C5``, ``AC0``).  For T/C ``offset`` is the
    timer/counter number; for AC the register number; otherwise a byte offset.
    """

    area: str
    offset: int
    width: int | None
    bit: int = 0
    text: str = ""

    @property
    def is_bit(self) -> bool:
        return self.width == 0


@dataclass(frozen=True, slots=True)
class Const:
    """A literal: ``int``, ``float`` (REAL) or ``bytes`` (ASCII/string).

    A string constant (``is_string``) holds its length byte followed by the
    characters, exactly as the string is laid out in memory."""

    value: int | float | bytes
    text: str = ""
    is_real: bool = False
    is_string: bool = False  #: written with double quotes (length-prefixed)


@dataclass(frozen=True, slots=True)
class Pointer:
    """``&VB100``: the address of a byte location, as a 32-bit pointer."""

    target: Addr
    text: str = ""

    @property
    def value(self) -> int:
        off = self.target.offset * 2 if self.target.area in ("T", "C") else self.target.offset
        return POINTER_AREAS[self.target.area] << 24 | off


@dataclass(frozen=True, slots=True)
class Indirect:
    """``*AC1``, ``*VD200``, ``*LD10``: dereference the 32-bit pointer held at ``ptr``."""

    ptr: Addr
    text: str = ""


@dataclass(frozen=True, slots=True)
class Name:
    """A bare identifier that is not an address (label number, block name...)."""

    name: str
    text: str = ""


Resolved = Union[Addr, Const, Pointer, Indirect, Name]


class OperandError(ValueError):
    """The operand text is not valid; the message says why."""


def parse_constant(text: str) -> Const | None:
    """Parse a literal, or return ``None`` if the text is not one.

    Raises:
        OperandError: if it looks like a literal but is malformed or infinite.
    """
    t = text.strip()
    if not t:
        return None
    if too_many_digits(t) and t[0] not in "'\"":
        raise OperandError(f"{excerpt(t)}: a number with more than {MAX_DIGITS} digits is "
                           f"out of range")
    if t[0] == '"':
        return string_constant(t, DEFAULT_CODEPAGE)
    if t[0] == "'":
        if len(t) < 2 or t[-1] != t[0]:
            raise OperandError(f"unterminated literal {excerpt(text)!r}")
        body = t[1:-1]
        try:
            data = body.encode("latin-1")
        except UnicodeEncodeError:
            raise OperandError(f"literal {excerpt(text)!r} holds characters outside "
                               f"one byte") from None
        return Const(data, text)
    m = _HEX_RE.fullmatch(t)
    if m:
        return Const(int(m.group(1).replace("_", ""), 16), text)
    m = _BIN_RE.fullmatch(t)
    if m:
        return Const(int(m.group(1).replace("_", ""), 2), text)
    if _DEC_RE.fullmatch(t):
        return Const(int(t), text)
    if _REAL_RE.fullmatch(t):
        v = float(t)
        if not math.isfinite(v):
            raise OperandError(f"real constant {excerpt(text)!r} is out of range")
        return Const(v, text, is_real=True)
    up = t.upper()
    if up in ("TRUE", "ON"):
        return Const(1, text)
    if up in ("FALSE", "OFF"):
        return Const(0, text)
    return None


def string_constant(text: str, codepage: str) -> Const:
    """A double-quoted string constant (``"ABC"``) as a :class:`Const`
    holding the length byte and the characters in ``codepage``.

    Inside the quotes a doubled quote (``""``) stands for one, as in the
    STL grammar and the data block; every other character, ``$`` included,
    stands for itself (docs/decisions.md, "Strings").

    Raises:
        OperandError: unterminated or malformed literal, a character outside
            the code page, or more than 254 characters.
    """
    t = text.strip()
    if len(t) < 2 or t[0] != '"' or t[-1] != '"':
        raise OperandError(f"unterminated string constant {excerpt(text)!r}")
    raw = t[1:-1]
    if raw.replace('""', "").count('"'):
        raise OperandError(f"string constant {excerpt(text)!r}: a quote inside the "
                           f"string is written twice (\"\")")
    try:
        data = string_bytes(raw.replace('""', '"'), codepage)
    except ValueError as e:
        raise OperandError(f"string constant {excerpt(text)!r}: {e}") from None
    return Const(bytes((len(data),)) + data, text, is_string=True)


def _check_range(model: CpuModel, area: str, offset: int, width: int, text: str) -> None:
    size = area_size(model, area)
    span = max(width, 1)
    if offset < 0 or offset + span > size:
        if size == 0:
            raise OperandError(f"{excerpt(text)}: the {model.name} has no {area} memory")
        last = size - span
        raise OperandError(f"{excerpt(text)} is out of range for the {model.name} "
                           f"({area} offsets 0..{last} for this size)")


def area_size(model: CpuModel, area: str) -> int:
    """Size in bytes of a byte-addressable area."""
    return {
        "I": model.i_bytes, "Q": model.q_bytes, "M": model.m_bytes,
        "V": model.v_bytes, "SM": model.sm_bytes, "S": model.s_bytes,
        "L": model.l_bytes, "AI": model.ai_bytes, "AQ": model.aq_bytes,
        "T": model.timers * 2, "C": model.counters * 2,
    }[area]


def parse_address(text: str, model: CpuModel) -> Addr | None:
    """Parse a direct address, or return ``None`` if the text is not one.

    Raises:
        OperandError: for a well-formed address that is out of range.
    """
    t = text.strip()
    if too_many_digits(t):
        raise OperandError(f"{excerpt(t)}: a number with more than {MAX_DIGITS} digits is "
                           f"out of range")
    m = _BIT_RE.fullmatch(t)
    if m:
        area, byte, bit = m.group(1).upper(), int(m.group(2)), int(m.group(3))
        if bit > 7:
            raise OperandError(f"{excerpt(t)}: bit number must be 0..7")
        _check_range(model, area, byte, 1, t)
        return Addr(area, byte, 0, bit, t)
    m = _SIZED_RE.fullmatch(t)
    if m:
        area, w, byte = m.group(1).upper(), WIDTH_OF[m.group(2).upper()], int(m.group(3))
        _check_range(model, area, byte, w, t)
        return Addr(area, byte, w, 0, t)
    m = _ANALOG_RE.fullmatch(t)
    if m:
        area, byte = m.group(1).upper(), int(m.group(2))
        if byte % 2:
            raise OperandError(f"{excerpt(t)}: analog words start at even addresses")
        _check_range(model, area, byte, 2, t)
        return Addr(area, byte, 2, 0, t)
    m = _AC_RE.fullmatch(t)
    if m:
        n = int(m.group(1))
        if n >= model.accumulators:
            raise OperandError(f"{excerpt(t)}: accumulators are AC0..AC{model.accumulators - 1}")
        return Addr("AC", n, None, 0, t)
    m = _HC_RE.fullmatch(t)
    if m:
        n = int(m.group(1))
        if n >= model.hsc:
            raise OperandError(f"{excerpt(t)}: high-speed counters are HC0..HC{model.hsc - 1}")
        return Addr("HC", n, 4, 0, t)
    m = _TC_RE.fullmatch(t)
    if m:
        area, n = m.group(1).upper(), int(m.group(2))
        limit = model.timers if area == "T" else model.counters
        if n >= limit:
            raise OperandError(f"{excerpt(t)}: {'timers' if area == 'T' else 'counters'} "
                               f"are {area}0..{area}{limit - 1}")
        return Addr(area, n, None, 0, t)
    return None


def parse_operand(text: str, model: CpuModel) -> Resolved:
    """Classify one operand text (symbols and ``#locals`` are resolved by the caller).

    Raises:
        OperandError: for malformed or out-of-range operands.
    """
    t = text.strip()
    if t.startswith("&"):
        target = parse_address(t[1:], model)
        if target is None or target.width == 0 or target.area not in POINTER_AREAS:
            raise OperandError(f"{excerpt(t)}: '&' needs a byte, word or dword address "
                               f"in I, Q, M, S, SM, V, AI, AQ, T or C")
        return Pointer(target, t)
    if t.startswith("*"):
        ptr = parse_address(t[1:], model)
        if ptr is None or not (
            (ptr.area == "AC" and ptr.offset > 0)
            or (ptr.area in ("V", "L") and ptr.width == 4)
        ):
            raise OperandError(f"{excerpt(t)}: indirect addressing needs *AC1..*AC3, "
                               f"*VDn or *LDn")
        if ptr.area == "AC":
            ptr = Addr("AC", ptr.offset, 4, 0, ptr.text)
        return Indirect(ptr, t)
    addr = parse_address(t, model)
    if addr is not None:
        return addr
    const = parse_constant(t)
    if const is not None:
        return const
    return Name(t, t)
