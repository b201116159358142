"""A small reference interpreter for S7-200 STL, used as a test oracle.

This module is written independently from :mod:`plcrt.compiler`: it walks the
parsed IR (:func:`plcrt.lang.parse_program`) one instruction at a time, keeps
the logic stack in a plain Python list and reads and writes its own copy of
the memory image with ``int.from_bytes`` / ``int.to_bytes``.  Clarity comes
before speed; it is the side of the differential test that should be easy to
check by reading it next to the S7-200 System Manual
(``/work/shared/reference/s7-200-stl.md`` sections 3.2-3.6).

The only piece shared with the compiler is
:func:`plcrt.compiler.operands.parse_address`, which classifies operand text
(``VW1``, ``T37``, ``Q0.3``).  Area names and sizes are taken from
:class:`plcrt.memory.MemoryImage` so that images can be compared byte by
byte.

Supported subset (anything else raises :class:`Unsupported`):

* bit logic: ``LD LDN A AN O ON NOT EU ED ALD OLD LPS LRD LPP = S R``
  (``S``/``R`` over bit ranges; ``R`` also resets timers and counters);
* compares ``LD|A|O`` x ``B|W|D`` x ``= <> < <= > >=``;
* moves ``MOVB MOVW MOVD`` (no pointers);
* integer math ``+I -I *I /I +D -D *D /D INCB DECB INCW DECW INCD DECD``
  with the SMB1 flags;
* word logic ``ANDW ORW XORW`` (the test uses them only when the compiled
  engine has them);
* ``TON`` for the 100 ms timers T37-T63 and T101-T255, and ``CTU``;
* strings in V memory and ``"..."`` constants: ``SLEN SCPY SCAT SSCPY SFND
  CFND ITS DTS RTS STI STD STR`` and the compares ``LDS= LDS<> AS= AS<> OS=
  OS<>`` (System Manual, "String instructions"; the choices of
  docs/decisions.md, "Strings").
* tables ``ATT FIFO LIFO FND= FND<> FND< FND>`` (direct word addresses)
  with SM1.4 / SM1.5 and the 0091 range error (SM4.3);
* ASCII conversions ``ITA DTA RTA ATH HTA`` (direct byte addresses).

Conventions that the manual leaves open follow the choices documented in
plcrt's own docstrings (``plcrt/isa/math_int.py``, ``plcrt/engine/*.py``);
each is marked "plcrt convention" below.
"""

from __future__ import annotations

import math
import operator
import re
import struct
from fractions import Fraction
from typing import Callable

from plcrt.compiler.operands import Addr, parse_address
from plcrt.lang import ir, parse_program
from plcrt.memory import MemoryImage, cpu_model

#: S7-200 logic stack: nine levels; a tenth push loses the bottom level.
STACK_LEVELS = 9

#: Largest timer / counter current value (INT).
MAX_CURRENT_VALUE = 32767

#: ``Sx.y`` bit positions in SMB0 and SMB1.
SM0_ALWAYS_ON, SM0_FIRST_SCAN, SM0_RUN_FROM_POWER_UP = 0, 1, 3
SM0_CLOCK_60S, SM0_CLOCK_1S, SM0_CLOCK_SCAN, SM0_MODE_SWITCH_RUN = 4, 5, 6, 7
SM1_ZERO, SM1_OVERFLOW, SM1_NEGATIVE, SM1_DIVIDE_BY_ZERO = 0, 1, 2, 3

RELATIONS: dict[str, Callable[[int, int], bool]] = {
    "=": operator.eq, "<>": operator.ne, "<": operator.lt,
    "<=": operator.le, ">": operator.gt, ">=": operator.ge,
}
COMPARE_RE = re.compile(r"(LD|A|O)([BWD])(=|<>|<=|>=|<|>)")

#: Width letter -> (bytes, signed).  Bytes compare unsigned, INT/DINT signed.
WIDTHS: dict[str, tuple[int, bool]] = {"B": (1, False), "W": (2, True), "D": (4, True)}

#: Two-operand math ``OP IN1, OUT``: OUT := f(OUT, IN1) (STL math is destructive).
MATH: dict[str, tuple[int, Callable[[int, int], int]]] = {
    "+I": (2, lambda out, in1: out + in1),
    "-I": (2, lambda out, in1: out - in1),
    "*I": (2, lambda out, in1: out * in1),
    "+D": (4, lambda out, in1: out + in1),
    "-D": (4, lambda out, in1: out - in1),
    "*D": (4, lambda out, in1: out * in1),
}
DIVIDE: dict[str, int] = {"/I": 2, "/D": 4}

#: ``INCx / DECx OUT``: (bytes, signed, step).
INC_DEC: dict[str, tuple[int, bool, int]] = {
    "INCB": (1, False, +1), "DECB": (1, False, -1),
    "INCW": (2, True, +1), "DECW": (2, True, -1),
    "INCD": (4, True, +1), "DECD": (4, True, -1),
}

#: Word logic ``OP IN1, OUT``: OUT := IN1 op OUT (bit patterns, unsigned).
WORD_LOGIC: dict[str, Callable[[int, int], int]] = {
    "ANDW": operator.and_, "ORW": operator.or_, "XORW": operator.xor,
}

MOVES: dict[str, int] = {"MOVB": 1, "MOVW": 2, "MOVD": 4}

#: String compares: ``LDS=`` ... ``OS<>`` (the ``S`` is the string type).
STRING_COMPARE_RE = re.compile(r"(LD|A|O)S(=|<>)")

#: Longest string: a length byte of 0..254.
MAX_STRING = 254

#: Box instructions on strings.
STRING_BOXES = ("SLEN", "SCPY", "SCAT", "SSCPY", "SFND", "CFND",
                "ITS", "DTS", "RTS", "STI", "STD", "STR")

#: ``STI``/``STD``: (bytes of OUT, smallest, largest); ``ITS``/``DTS``: (bytes of
#: IN, characters of the string).
STRING_TO_INT = {"STI": (2, -32768, 32767), "STD": (4, -2**31, 2**31 - 1)}
INT_TO_STRING = {"ITS": (2, 8), "DTS": (4, 12)}

#: The number forms of STI/STD and STR: spaces, a sign, digits (and for a
#: real a point or comma with more digits).
INTEGER_TEXT = re.compile(rb" *([+-]?)([0-9]+)")
REAL_TEXT = re.compile(rb" *([+-]?)([0-9]*)(?:[.,]([0-9]*))?")

#: FND's compare (the entry on the left, PATRN on the right), INT values.
FIND = {"FND=": operator.eq, "FND<>": operator.ne, "FND<": operator.lt, "FND>": operator.gt}
TABLE_MAX = 100                     #: entries a table can hold
SM1_TABLE_FULL, SM1_TABLE_EMPTY, SM1_ILLEGAL_ASCII = 4, 5, 7
SM4_RUNTIME_ERROR = 3
#: ASCII conversions: mnemonic -> characters written (RTA: from FMT)
ASCII_WIDTH = {"ITA": 8, "DTA": 12}
HEX_CHARS = "0123456789ABCDEF"
NEW_BOXES = ("ATT", "FIFO", "LIFO", *FIND, "ITA", "DTA", "RTA", "ATH", "HTA")


class Unsupported(Exception):
    """The program uses something outside the reference subset."""


def value_range(nbytes: int, signed: bool) -> tuple[int, int]:
    """Smallest and largest value of an integer of ``nbytes`` bytes."""
    if signed:
        return -(1 << (8 * nbytes - 1)), (1 << (8 * nbytes - 1)) - 1
    return 0, (1 << (8 * nbytes)) - 1


def wrap(value: int, nbytes: int, signed: bool) -> int:
    """Reduce ``value`` to ``nbytes`` bytes, two's complement if ``signed``."""
    raw = value & ((1 << (8 * nbytes)) - 1)
    if signed and raw >> (8 * nbytes - 1):
        raw -= 1 << (8 * nbytes)
    return raw


def parse_integer_constant(text: str) -> int | None:
    """``+50``, ``-13``, ``100``, ``16#FFFF``, ``2#1010`` -> int, else ``None``."""
    t = text.strip().replace("_", "")
    upper = t.upper()
    if upper.startswith("16#"):
        return int(t[3:], 16)
    if upper.startswith("2#"):
        return int(t[2:], 2)
    if re.fullmatch(r"[+-]?\d+", t):
        return int(t)
    return None


class ReferencePlc:
    """Executes OB1 of a program scan by scan over its own memory image.

    Attributes:
        mem: area name -> bytearray, same names and sizes as
            :class:`plcrt.memory.MemoryImage`.
        scans: completed scans.
        time_us: simulated time at the start of the next scan (microseconds).
    """

    def __init__(self, source: str, *, scan_ms: float = 10.0, cpu: str | None = None) -> None:
        self.program = parse_program(source)
        self.model = cpu_model(cpu)
        self.mem: dict[str, bytearray] = {
            name: bytearray(len(buf)) for name, buf in MemoryImage(self.model).areas.items()
        }
        self.scan_us = int(round(scan_ms * 1000))
        self.scans = 0
        self.time_us = 0
        self.previous_scan_start: int | None = None
        self.ticks_100ms = 0
        # One logic stack for the whole run, as on the CPU (top = last item).
        # A valid network never reads below the levels it pushed itself, so
        # what earlier networks left behind is never observed.
        self.stack: list[int] = []
        # hidden state
        self.edge_memory: dict[tuple[int, int, int], int] = {}  # per EU/ED instruction
        self.timer_running: dict[int, bool] = {}
        self.counter_last_cu: dict[int, int] = {}
        self._addresses: dict[str, Addr | None] = {}
        obs = [p for p in self.program.pous if p.kind == "OB"]
        if len(obs) != 1:
            raise Unsupported("the reference runs exactly one OB1")
        self.ob1 = obs[0]

    # -- scan cycle -----------------------------------------------------------
    def scan(self, n: int = 1) -> None:
        """Run ``n`` scans, in the order of :mod:`plcrt.engine.runtime`."""
        for _ in range(n):
            self._scan_once()

    def _scan_once(self) -> None:
        now = self.time_us
        self.mem["I"][:] = self.mem["PI"]            # 1. read the inputs
        self._update_special_memory(now)             # 2. SMB0, scan-time words
        if self.previous_scan_start is None:         # 3. timer ticks of this scan
            self.ticks_100ms = 0
        else:
            self.ticks_100ms = now // 100_000 - self.previous_scan_start // 100_000
        self.previous_scan_start = now
        for n_index, network in enumerate(self.ob1.networks):  # 4. OB1
            for i_index, insn in enumerate(network.insns):
                self.execute(insn, (0, n_index, i_index))
        self.mem["PQ"][:] = self.mem["Q"]             # 5. write the outputs
        self.scans += 1
        self.time_us += self.scan_us

    def _update_special_memory(self, now_us: int) -> None:
        first = self.scans == 0
        bits = {
            SM0_ALWAYS_ON: True,
            SM0_FIRST_SCAN: first,
            SM0_RUN_FROM_POWER_UP: first,
            # plcrt convention for the phase: off for the first 30 s of each minute
            SM0_CLOCK_60S: now_us % 60_000_000 >= 30_000_000,
            SM0_CLOCK_1S: now_us % 1_000_000 >= 500_000,
            # plcrt convention: on in the first scan, then toggling
            SM0_CLOCK_SCAN: self.scans % 2 == 0,
            SM0_MODE_SWITCH_RUN: True,
        }
        self.mem["SM"][0] = sum(1 << bit for bit, on in bits.items() if on)
        # SMW22 / SMW24 / SMW26: last, shortest and longest scan time in ms;
        # every simulated scan lasts scan_ms.
        scan_ms = min(self.scan_us // 1000, 0xFFFF)
        for offset in (22, 24, 26):
            self.mem["SM"][offset:offset + 2] = scan_ms.to_bytes(2, "big")
        # SM66.7 / SM76.7: both pulse outputs idle (no PLS in these programs)
        if self.scans == 0:
            self.mem["SM"][66] = self.mem["SM"][76] = 0x80
            # SM4.5 / SM4.6: the ports' transmitters idle (no XMT in these
            # programs); a CPU 221/222/224 has port 0 only
            one_port = self.model.name in ("CPU221", "CPU222", "CPU224")
            self.mem["SM"][4] |= 0x20 if one_port else 0x60

    # -- operands -------------------------------------------------------------
    def address(self, text: str) -> Addr | None:
        if text not in self._addresses:
            self._addresses[text] = parse_address(text, self.model)
        return self._addresses[text]

    def read_bit(self, text: str) -> int:
        a = self.address(text)
        if a is None:
            raise Unsupported(f"not a bit address: {text}")
        if a.area in ("T", "C"):
            bits = self.mem["TB" if a.area == "T" else "CB"]
            return bits[a.offset // 8] >> (a.offset % 8) & 1
        return self.mem[a.area][a.offset] >> a.bit & 1

    def write_bit(self, area: str, bit_index: int, value: int) -> None:
        """Write bit number ``bit_index`` (byte * 8 + bit) of ``area``."""
        byte, bit = divmod(bit_index, 8)
        if value:
            self.mem[area][byte] |= 1 << bit
        else:
            self.mem[area][byte] &= ~(1 << bit) & 0xFF

    def _location(self, text: str, nbytes: int) -> tuple[bytearray, int]:
        a = self.address(text)
        if a is None:
            raise Unsupported(f"not an address: {text}")
        if a.area in ("T", "C"):  # T37 / C5 in word context: the current value
            if nbytes != 2:
                raise Unsupported(f"{text} is a word")
            return self.mem["TV" if a.area == "T" else "CV"], a.offset * 2
        if a.area not in ("I", "Q", "M", "V", "SM", "S") or a.width != nbytes:
            raise Unsupported(f"operand {text} for a {nbytes}-byte value")
        return self.mem[a.area], a.offset

    def read_value(self, text: str, nbytes: int, signed: bool) -> int:
        const = parse_integer_constant(text)
        if const is not None:
            return wrap(const, nbytes, signed)
        buf, offset = self._location(text, nbytes)
        return int.from_bytes(buf[offset:offset + nbytes], "big", signed=signed)

    def write_value(self, text: str, nbytes: int, value: int) -> None:
        buf, offset = self._location(text, nbytes)
        buf[offset:offset + nbytes] = wrap(value, nbytes, False).to_bytes(nbytes, "big")

    def set_flags(self, zero: bool, overflow: bool, negative: bool) -> None:
        """SM1.0 / SM1.1 / SM1.2; SM1.3 and up are left as they are."""
        for bit, on in ((SM1_ZERO, zero), (SM1_OVERFLOW, overflow), (SM1_NEGATIVE, negative)):
            self.write_bit("SM", 8 + bit, int(on))

    # -- logic stack ----------------------------------------------------------
    def push(self, value: int) -> None:
        self.stack.append(value)
        if len(self.stack) > STACK_LEVELS:
            del self.stack[0]  # the bottom level is lost

    def pop(self) -> int:
        if not self.stack:
            raise Unsupported("pop from an empty logic stack")
        return self.stack.pop()

    @property
    def top(self) -> int:
        if not self.stack:
            raise Unsupported("the logic stack is empty")
        return self.stack[-1]

    @top.setter
    def top(self, value: int) -> None:
        self.stack[-1] = value

    def contact(self, how: str, value: int) -> None:
        """A contact's or compare's value: loaded (LD), and-ed (A) or
        or-ed (O) onto the top of the stack."""
        if how == "LD":
            self.push(value)
        elif how == "A":
            self.top = self.top & value
        else:
            self.top = self.top | value

    # -- instructions ---------------------------------------------------------
    def execute(self, insn: ir.Insn, key: tuple[int, int, int]) -> None:
        """Execute one instruction; ``key`` identifies it (for EU/ED memory)."""
        m = insn.mnemonic
        ops = [o.text for o in insn.operands]
        if m in ("LD", "LDN", "A", "AN", "O", "ON"):
            bit = self.read_bit(ops[0])
            if m.endswith("N"):
                bit ^= 1
            self.contact(m.rstrip("N"), bit)
        elif COMPARE_RE.fullmatch(m):
            self._compare(m, ops)
        elif STRING_COMPARE_RE.fullmatch(m):
            self._string_compare(m, ops)
        elif m == "NOT":
            self.top = self.top ^ 1
        elif m in ("EU", "ED"):
            self._edge(m == "EU", key)
        elif m in ("ALD", "OLD"):
            value = self.pop()
            self.top = (self.top & value) if m == "ALD" else (self.top | value)
        elif m == "LPS":
            self.push(self.top)
        elif m == "LRD":
            if len(self.stack) < 2:
                raise Unsupported("LRD needs two levels")
            self.top = self.stack[-2]
        elif m == "LPP":
            if len(self.stack) < 2:
                raise Unsupported("LPP needs two levels")
            self.pop()
        elif m == "=":
            a = self.address(ops[0])
            assert a is not None and a.width == 0
            self.write_bit(a.area, a.offset * 8 + a.bit, self.top)
        elif m in ("S", "R"):
            if self.top:
                self._set_reset(m == "S", ops[0], int(ops[1]))
        elif m == "TON":
            self._ton(ops[0], ops[1])
        elif m == "CTU":
            self._ctu(ops[0], ops[1])
        elif not self.top:
            # every other supported instruction is a box: it runs only when
            # the top of the stack is 1 and it never changes the stack
            if m not in (*MOVES, *MATH, *DIVIDE, *INC_DEC, *WORD_LOGIC, *STRING_BOXES,
                         *NEW_BOXES):
                raise Unsupported(m)
        elif m in MOVES:
            nbytes = MOVES[m]
            self.write_value(ops[1], nbytes, self.read_value(ops[0], nbytes, False))
        elif m in MATH:
            self._math(m, ops)
        elif m in DIVIDE:
            self._divide(m, ops)
        elif m in INC_DEC:
            self._inc_dec(m, ops)
        elif m in WORD_LOGIC:
            result = WORD_LOGIC[m](self.read_value(ops[0], 2, False),
                                   self.read_value(ops[1], 2, False))
            self.write_value(ops[1], 2, result)
            self.write_bit("SM", 8 + SM1_ZERO, int(result == 0))
        elif m in STRING_BOXES:
            getattr(self, "_" + m.lower())(ops)
        elif m == "ATT":
            self._att(ops)
        elif m in ("FIFO", "LIFO"):
            self._take(m == "FIFO", ops)
        elif m in FIND:
            self._find(m, ops)
        elif m in ("ITA", "DTA", "RTA"):
            self._number_to_ascii(m, ops)
        elif m == "ATH":
            self._ascii_to_hex(ops)
        elif m == "HTA":
            self._hex_to_ascii(ops)
        else:
            raise Unsupported(m)

    def _compare(self, mnemonic: str, ops: list[str]) -> None:
        match = COMPARE_RE.fullmatch(mnemonic)
        assert match is not None
        how, width, relation = match.groups()
        nbytes, signed = WIDTHS[width]
        a = self.read_value(ops[0], nbytes, signed)
        b = self.read_value(ops[1], nbytes, signed)
        self.contact(how, int(RELATIONS[relation](a, b)))

    def _edge(self, rising: bool, key: tuple[int, int, int]) -> None:
        # Each EU/ED has its own memory.  Its first execution reports no edge.
        previous = self.edge_memory.get(key)
        current = self.top
        self.edge_memory[key] = current
        if previous is None:
            self.top = 0
        elif rising:
            self.top = int(previous == 0 and current == 1)
        else:
            self.top = int(previous == 1 and current == 0)

    def _set_reset(self, value: bool, operand: str, count: int) -> None:
        a = self.address(operand)
        assert a is not None
        if a.area == "T":
            if value:
                raise Unsupported("S on timers")
            for n in range(a.offset, a.offset + count):
                self._timer_reset(n)
        elif a.area == "C":
            if value:
                raise Unsupported("S on counters")
            for n in range(a.offset, a.offset + count):
                self._counter_store(n, 0, 0)
        else:
            start = a.offset * 8 + a.bit
            for bit_index in range(start, start + count):
                self.write_bit(a.area, bit_index, int(value))

    def _math(self, mnemonic: str, ops: list[str]) -> None:
        nbytes, function = MATH[mnemonic]
        in1 = self.read_value(ops[0], nbytes, True)
        out = self.read_value(ops[1], nbytes, True)
        result = function(out, in1)
        low, high = value_range(nbytes, True)
        if low <= result <= high:
            self.write_value(ops[1], nbytes, result)
            self.set_flags(result == 0, False, result < 0)
        else:
            # overflow: the output is not altered (plcrt convention: SM1.0
            # and SM1.2 are cleared along with setting SM1.1)
            self.set_flags(False, True, False)

    def _divide(self, mnemonic: str, ops: list[str]) -> None:
        nbytes = DIVIDE[mnemonic]
        divisor = self.read_value(ops[0], nbytes, True)
        if divisor == 0:
            self.write_bit("SM", 8 + SM1_DIVIDE_BY_ZERO, 1)  # other bits unchanged
            return
        self.write_bit("SM", 8 + SM1_DIVIDE_BY_ZERO, 0)
        dividend = self.read_value(ops[1], nbytes, True)
        quotient = abs(dividend) // abs(divisor)   # truncate toward zero
        if (dividend < 0) != (divisor < 0):
            quotient = -quotient
        low, high = value_range(nbytes, True)
        if low <= quotient <= high:
            self.write_value(ops[1], nbytes, quotient)
            self.set_flags(quotient == 0, False, quotient < 0)
        else:
            self.set_flags(False, True, False)

    def _inc_dec(self, mnemonic: str, ops: list[str]) -> None:
        # plcrt convention (math_int.py): INC/DEC wrap around and set SM1.1
        nbytes, signed, step = INC_DEC[mnemonic]
        result = self.read_value(ops[0], nbytes, signed) + step
        low, high = value_range(nbytes, signed)
        overflow = not low <= result <= high
        result = wrap(result, nbytes, signed)
        self.write_value(ops[0], nbytes, result)
        self.set_flags(result == 0, overflow, result < 0)

    # -- strings --------------------------------------------------------------
    # A string is a length byte and that many characters.  A length over 254,
    # or a string running past the end of V memory, is "operand out of range":
    # the box does nothing (ENO 0, which this subset does not model).

    def _string_place(self, text: str) -> tuple[bytearray, int]:
        a = self.address(text)
        if a is None or a.area != "V" or a.width != 1:
            raise Unsupported(f"string operand {text}")
        return self.mem["V"], a.offset

    def read_string(self, text: str) -> bytes | None:
        """The characters of a string operand, or None if it is out of range."""
        if text.startswith('"'):
            return text[1:-1].replace('""', '"').encode("cp1252")
        buf, offset = self._string_place(text)
        length = buf[offset]
        if length > MAX_STRING or offset + 1 + length > len(buf):
            return None
        return bytes(buf[offset + 1:offset + 1 + length])

    def write_string(self, text: str, chars: bytes) -> None:
        buf, offset = self._string_place(text)
        if offset + 1 + len(chars) <= len(buf):
            buf[offset:offset + 1 + len(chars)] = bytes([len(chars)]) + chars

    def _string_compare(self, mnemonic: str, ops: list[str]) -> None:
        match = STRING_COMPARE_RE.fullmatch(mnemonic)
        assert match is not None
        how, relation = match.groups()
        a, b = self.read_string(ops[0]), self.read_string(ops[1])
        if a is None or b is None:
            raise Unsupported("compare of an invalid string (a fatal error)")
        self.contact(how, int((a == b) == (relation == "=")))

    def _slen(self, ops: list[str]) -> None:
        s = self.read_string(ops[0])
        if s is not None:
            self.write_value(ops[1], 1, len(s))

    def _scpy(self, ops: list[str]) -> None:
        s = self.read_string(ops[0])
        if s is not None:
            self.write_string(ops[1], s)

    def _scat(self, ops: list[str]) -> None:
        tail, head = self.read_string(ops[0]), self.read_string(ops[1])
        if tail is not None and head is not None:
            self.write_string(ops[1], (head + tail)[:MAX_STRING])

    def _sscpy(self, ops: list[str]) -> None:
        s = self.read_string(ops[0])
        start = self.read_value(ops[1], 1, False)
        count = self.read_value(ops[2], 1, False)
        if s is not None and start >= 1 and start - 1 + count <= len(s):
            self.write_string(ops[3], s[start - 1:start - 1 + count])

    def _find_in_string(self, ops: list[str], match: Callable[[bytes, int, bytes], bool]) -> None:
        """SFND / CFND: OUT holds the start position and gets the result."""
        s, key = self.read_string(ops[0]), self.read_string(ops[1])
        start = self.read_value(ops[2], 1, False)
        if s is None or key is None or not 1 <= start <= len(s):
            return
        found = 0
        for position in range(start, len(s) + 1):
            if key and match(s, position - 1, key):
                found = position
                break
        self.write_value(ops[2], 1, found)

    def _sfnd(self, ops: list[str]) -> None:
        self._find_in_string(ops, lambda s, i, key: s[i:i + len(key)] == key)

    def _cfnd(self, ops: list[str]) -> None:
        self._find_in_string(ops, lambda s, i, key: s[i] in key)

    def _to_string(self, text: str, out: str, size: int) -> None:
        """The right-justified text of ITS/DTS/RTS, or spaces if it is too long."""
        self.write_string(out, text.rjust(size).encode() if len(text) <= size else b" " * size)

    @staticmethod
    def _decimal_text(magnitude: int, negative: bool, decimals: int, comma: bool) -> str:
        """``magnitude`` / 10**decimals as digits with a separator."""
        whole, fraction = divmod(magnitude, 10 ** decimals)
        text = str(whole)
        if decimals:
            text += ("," if comma else ".") + str(fraction).rjust(decimals, "0")
        return ("-" if negative else "") + text

    def _its(self, ops: list[str]) -> None:
        nbytes, size = INT_TO_STRING["ITS"]
        self._integer_to_string(ops, nbytes, size)

    def _dts(self, ops: list[str]) -> None:
        nbytes, size = INT_TO_STRING["DTS"]
        self._integer_to_string(ops, nbytes, size)

    def _integer_to_string(self, ops: list[str], nbytes: int, size: int) -> None:
        value = self.read_value(ops[0], nbytes, True)
        fmt = self.read_value(ops[2], 1, False)
        if fmt >= 16:
            return                      # format bits 7..4 must be 0
        decimals = fmt % 8
        if decimals > 5:
            self.write_string(ops[1], b" " * size)
            return
        text = self._decimal_text(abs(value), value < 0, decimals, fmt & 8 != 0)
        self._to_string(text, ops[1], size)

    def _rts(self, ops: list[str]) -> None:
        value = self.read_real(ops[0])
        fmt = self.read_value(ops[2], 1, False)
        size, decimals = fmt // 16, fmt % 8
        if size < 3:
            return
        if decimals > 5 or size < decimals + 3 or not math.isfinite(value):
            self.write_string(ops[1], b" " * size)
            return
        exact = Fraction(value)
        # round half away from zero: floor(|x| * 10**n + 1/2)
        magnitude = math.floor(abs(exact) * 10 ** decimals + Fraction(1, 2))
        negative = exact < 0 and magnitude != 0
        self._to_string(self._decimal_text(magnitude, negative, decimals, fmt & 8 != 0),
                        ops[1], size)

    def read_real(self, text: str) -> float:
        if text.startswith(("+", "-")) or text[:1].isdigit():
            return struct.unpack(">f", struct.pack(">f", float(text)))[0]
        buf, offset = self._location(text, 4)
        return struct.unpack(">f", bytes(buf[offset:offset + 4]))[0]

    def _string_number(self, ops: list[str], form: re.Pattern[bytes]
                       ) -> tuple[bool, bytes, bytes] | None | bool:
        """(negative, whole, fraction) at INDX; True if the instruction does
        nothing at all (bad string, INDX 0); None if there is no number."""
        s = self.read_string(ops[0])
        start = self.read_value(ops[1], 1, False)
        if s is None or start == 0:
            return True
        m = form.match(s, start - 1)
        if m is None:
            return None
        sign, whole, fraction = (m.groups() + (None,))[:3]
        if not whole and not fraction:
            return None
        return sign == b"-", whole, fraction or b""

    def _string_result(self, out: str, nbytes: int, value: int | None) -> None:
        """Store a converted value and clear SM1.1, or set SM1.1 (OUT kept)."""
        if value is None:
            self.write_bit("SM", 8 + SM1_OVERFLOW, 1)
        else:
            self.write_value(out, nbytes, value)
            self.write_bit("SM", 8 + SM1_OVERFLOW, 0)

    def _string_to_int(self, ops: list[str], mnemonic: str) -> None:
        nbytes, low, high = STRING_TO_INT[mnemonic]
        number = self._string_number(ops, INTEGER_TEXT)
        if number is True:
            return
        value = None
        if number is not None:
            negative, whole, _ = number
            value = -int(whole) if negative else int(whole)
            if not low <= value <= high:
                value = None
        self._string_result(ops[2], nbytes, value)

    def _sti(self, ops: list[str]) -> None:
        self._string_to_int(ops, "STI")

    def _std(self, ops: list[str]) -> None:
        self._string_to_int(ops, "STD")

    def _str(self, ops: list[str]) -> None:
        number = self._string_number(ops, REAL_TEXT)
        if number is True:
            return
        bits = None
        if number is not None:
            negative, whole, fraction = number
            exact = int(whole or b"0") + Fraction(int(fraction or b"0"), 10 ** len(fraction))
            try:
                packed = struct.pack(">f", float(-exact if negative else exact))
            except OverflowError:
                packed = None
            if packed is not None:
                bits = int.from_bytes(packed, "big")
        self._string_result(ops[2], 4, bits)

    # -- timers and counters --------------------------------------------------
    def _timer_number(self, operand: str) -> int:
        a = self.address(operand)
        assert a is not None and a.area == "T"
        return a.offset

    def _timer_store(self, n: int, current: int, bit: int) -> None:
        self.mem["TV"][2 * n:2 * n + 2] = wrap(current, 2, False).to_bytes(2, "big")
        self.write_bit("TB", n, bit)

    def _timer_reset(self, n: int) -> None:
        self.timer_running[n] = False
        self._timer_store(n, 0, 0)

    def _ton(self, timer: str, preset: str) -> None:
        """TON, 100 ms resolution: the current value changes only when the
        box executes; it then adds the 100 ms ticks between the previous scan
        start and this scan start."""
        n = self._timer_number(timer)
        if not (37 <= n <= 63 or 101 <= n <= 255):
            raise Unsupported(f"T{n} is not a 100 ms TON timer")
        pt = self.read_value(preset, 2, True)
        current = int.from_bytes(self.mem["TV"][2 * n:2 * n + 2], "big", signed=True)
        if not self.top:
            self._timer_reset(n)           # IN = 0 clears value and bit
            return
        if self.timer_running.get(n, False):
            current = min(current + self.ticks_100ms, MAX_CURRENT_VALUE)
        else:
            self.timer_running[n] = True   # starts timing from this scan on
        self._timer_store(n, current, int(current >= pt))

    def _counter_store(self, n: int, current: int, bit: int) -> None:
        self.mem["CV"][2 * n:2 * n + 2] = wrap(current, 2, False).to_bytes(2, "big")
        self.write_bit("CB", n, bit)

    def _ctu(self, counter: str, preset: str) -> None:
        """CTU: CU = second level, R = top; afterwards R is popped and CU
        stays on top (plcrt convention).  The edge memory starts at 0, so a
        CU of 1 in the first execution counts (plcrt convention)."""
        a = self.address(counter)
        assert a is not None and a.area == "C"
        n = a.offset
        if len(self.stack) < 2:
            raise Unsupported("CTU needs two levels")
        reset = self.stack[-1]
        cu = self.stack[-2]
        rising = cu == 1 and self.counter_last_cu.get(n, 0) == 0
        self.counter_last_cu[n] = cu
        pv = self.read_value(preset, 2, True)
        if reset:
            self._counter_store(n, 0, 0)
        else:
            current = int.from_bytes(self.mem["CV"][2 * n:2 * n + 2], "big", signed=True)
            if rising and current < MAX_CURRENT_VALUE:
                current += 1
            self._counter_store(n, current, int(current >= pv))
        self.pop()

    # -- tables (System Manual, "Table instructions") ---------------------------
    def _byte_address(self, text: str) -> tuple[bytearray, int]:
        """Area and byte offset of a direct V/M/I/Q/S/SM byte or word address."""
        a = self.address(text)
        if a is None or a.area not in ("I", "Q", "M", "V", "SM", "S") or not a.width:
            raise Unsupported(f"table or text operand {text}")
        return self.mem[a.area], a.offset

    def _word_at(self, buf: bytearray, offset: int) -> int:
        return int.from_bytes(buf[offset:offset + 2], "big", signed=True)

    def _range_error(self) -> None:
        """Run-time error 0091 (operand out of range): SM4.3, nothing else."""
        self.write_bit("SM", 4 * 8 + SM4_RUNTIME_ERROR, 1)

    def _entry_count(self, buf: bytearray, at: int) -> int | None:
        count = self._word_at(buf, at)
        if count < 0 or count > TABLE_MAX or at + 2 + 2 * count > len(buf):
            self._range_error()
            return None
        return count

    def _att(self, ops: list[str]) -> None:
        data = self.read_value(ops[0], 2, True)
        buf, tbl = self._byte_address(ops[1])
        count = self._entry_count(buf, tbl + 2)
        if count is None:
            return
        limit = min(self._word_at(buf, tbl), TABLE_MAX)
        if count >= limit:
            self.write_bit("SM", 8 + SM1_TABLE_FULL, 1)
            return
        place = tbl + 4 + 2 * count
        if place + 2 > len(buf):
            self._range_error()
            return
        buf[place:place + 2] = wrap(data, 2, False).to_bytes(2, "big")
        buf[tbl + 2:tbl + 4] = (count + 1).to_bytes(2, "big")
        self.write_bit("SM", 8 + SM1_TABLE_FULL, 0)

    def _take(self, oldest: bool, ops: list[str]) -> None:
        buf, tbl = self._byte_address(ops[0])
        count = self._entry_count(buf, tbl + 2)
        if count is None:
            return
        if count == 0:
            self.write_bit("SM", 8 + SM1_TABLE_EMPTY, 1)
            return
        entries = [self._word_at(buf, tbl + 4 + 2 * i) for i in range(count)]
        value = entries.pop(0) if oldest else entries.pop()
        if oldest:   # the rest move up one place; the word after them keeps its value
            for i, entry in enumerate(entries):
                buf[tbl + 4 + 2 * i:tbl + 6 + 2 * i] = wrap(entry, 2, False).to_bytes(2, "big")
        buf[tbl + 2:tbl + 4] = (count - 1).to_bytes(2, "big")
        self.write_bit("SM", 8 + SM1_TABLE_EMPTY, 0)
        self.write_value(ops[1], 2, value)

    def _find(self, mnemonic: str, ops: list[str]) -> None:
        buf, tbl = self._byte_address(ops[0])   # FND's TBL is the entry count
        pattern = self.read_value(ops[1], 2, True)
        start = self.read_value(ops[2], 2, False)
        count = self._entry_count(buf, tbl)
        if count is None:
            return
        index = count
        for i in range(start, count):
            if FIND[mnemonic](self._word_at(buf, tbl + 2 + 2 * i), pattern):
                index = i
                break
        self.write_value(ops[2], 2, index)

    # -- ASCII (System Manual, "Conversion instructions") -------------------------
    def _put_text(self, ops: list[str], text: str) -> None:
        buf, offset = self._byte_address(ops[1])
        if offset + len(text) > len(buf):
            self._range_error()
            return
        buf[offset:offset + len(text)] = text.encode("ascii")

    def _number_to_ascii(self, mnemonic: str, ops: list[str]) -> None:
        fmt = self.read_value(ops[2], 1, False)
        places, comma = fmt & 7, fmt & 8
        if mnemonic == "RTA":
            width = fmt >> 4
            if width < 3:
                return                                  # illegal format: no output
            raw = self.read_value(ops[0], 4, False).to_bytes(4, "big")
            x = struct.unpack(">f", raw)[0]
            if places > 5 or width < places + 3 or not math.isfinite(x):
                self._put_text(ops, " " * width)
                return
            # exact value of the REAL, rounded half away from zero
            scaled = Fraction(x) * 10 ** places
            magnitude = math.floor(abs(scaled) + Fraction(1, 2))
            value = -magnitude if scaled < 0 else magnitude
        else:
            width = ASCII_WIDTH[mnemonic]
            if fmt & 0xF0:
                return                                  # illegal format: no output
            if places > 5:
                self._put_text(ops, " " * width)
                return
            value = self.read_value(ops[0], 2 if mnemonic == "ITA" else 4, True)
        whole, fraction = divmod(abs(value), 10 ** places)
        text = ("-" if value < 0 else "") + str(whole)
        if places:
            text += ("," if comma else ".") + str(fraction).zfill(places)
        if len(text) > width:
            text = ""
        self._put_text(ops, text.rjust(width))

    def _ascii_to_hex(self, ops: list[str]) -> None:
        src, s_off = self._byte_address(ops[0])
        dst, d_off = self._byte_address(ops[1])
        length = self.read_value(ops[2], 1, False)
        if s_off + length > len(src) or d_off + (length + 1) // 2 > len(dst):
            self._range_error()
            return
        for i in range(length):
            char = chr(src[s_off + i])
            if char not in HEX_CHARS:               # upper case only (30..39, 41..46 hex)
                self.write_bit("SM", 8 + SM1_ILLEGAL_ASCII, 1)
                return
            nibble = HEX_CHARS.index(char)
            byte = d_off + i // 2
            if i % 2 == 0:
                dst[byte] = nibble << 4 | dst[byte] & 0x0F
            else:
                dst[byte] = dst[byte] & 0xF0 | nibble
        self.write_bit("SM", 8 + SM1_ILLEGAL_ASCII, 0)

    def _hex_to_ascii(self, ops: list[str]) -> None:
        src, s_off = self._byte_address(ops[0])
        dst, d_off = self._byte_address(ops[1])
        length = self.read_value(ops[2], 1, False)
        if s_off + (length + 1) // 2 > len(src) or d_off + length > len(dst):
            self._range_error()
            return
        digits = "".join(f"{src[s_off + i]:02X}" for i in range((length + 1) // 2))
        dst[d_off:d_off + length] = digits[:length].encode("ascii")
