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
* ``TON`` for the 100 ms timers T37-T63 and T101-T255, and ``CTU``.

Conventions that the manual leaves open follow the choices documented in
plcrt's own docstrings (``plcrt/isa/math_int.py``, ``plcrt/engine/*.py``);
each is marked "plcrt convention" below.
"""

from __future__ import annotations

import operator
import re
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

    # -- instructions ---------------------------------------------------------
    def execute(self, insn: ir.Insn, key: tuple[int, int, int]) -> None:
        """Execute one instruction; ``key`` identifies it (for EU/ED memory)."""
        m = insn.mnemonic
        ops = [o.text for o in insn.operands]
        if m in ("LD", "LDN", "A", "AN", "O", "ON"):
            bit = self.read_bit(ops[0])
            if m.endswith("N"):
                bit ^= 1
            if m.startswith("LD"):
                self.push(bit)
            elif m.startswith("A"):
                self.top = self.top & bit
            else:
                self.top = self.top | bit
        elif COMPARE_RE.fullmatch(m):
            self._compare(m, ops)
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
            if m not in (*MOVES, *MATH, *DIVIDE, *INC_DEC, *WORD_LOGIC):
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
        else:
            raise Unsupported(m)

    def _compare(self, mnemonic: str, ops: list[str]) -> None:
        match = COMPARE_RE.fullmatch(mnemonic)
        assert match is not None
        how, width, relation = match.groups()
        nbytes, signed = WIDTHS[width]
        a = self.read_value(ops[0], nbytes, signed)
        b = self.read_value(ops[1], nbytes, signed)
        result = int(RELATIONS[relation](a, b))
        if how == "LD":
            self.push(result)
        elif how == "A":
            self.top = self.top & result
        else:
            self.top = self.top | result

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
