"""The Modbus RTU slave library of Micro/WIN as built-in blocks: MBUS_INIT
(S7-200; the S7-200 SMART's with a Port input is MBUS_INIT_SMART) and
MBUS_SLAVE (S7-200 System Manual, "Using the Modbus protocol library",
"Instructions for the Modbus slave protocol"; S7-200 SMART System Manual
V2.3, 9.3.3; interfaces in library/modbus_slave.toml).

What it is: one :class:`SlaveLib` per CPU, shared by the call sites.
MBUS_INIT with Mode 1 checks its parameters, puts the port in freeport at
Baud and Parity (SMB30 / SMB130) and takes its characters
(``Port.owner``); Mode 0 gives the port back to PPI.  A request has ended
when the line stays quiet for 3.5 characters plus Delay ms after a
character (the manual: Delay extends the end-of-message timeout); it waits
for MBUS_SLAVE.  Each MBUS_SLAVE call serves one waiting request against
the CPU's memory (manual's slave address table)::

    00001 + n   coil n          Q image bit n (Q0.0 ..)     n < MaxIQ
    10001 + n   input n         I image bit n (I0.0 ..)     n < MaxIQ
    30001 + n   input register  AIW(2n)                     n < MaxAI
    40001 + n   holding reg.    the V word at HoldStart+2n  n < MaxHold

and sends the response (or exception) at the call's µs over the port's
exact-timed serial model (:meth:`plcrt.engine.ports.Port.send`); Done 1
and Error as the manual's table (:data:`ERRORS`).

What it is not: the library's code.  Its V-memory area and interrupt
routines are not simulated (so Error 5, holding registers overlapping the
library's symbols, never occurs); forced Q points are written like others.
The numbers plcrt decided are :data:`PLCRT_CHOICES` (a load-time warning
names them; docs/modbus.md).  A protected, empty SUBROUTINE_BLOCK of the
export named MBUS_INIT / MBUS_SLAVE runs these
(``plcrt.blocks.register_protected``).
"""

from __future__ import annotations

import re
from collections import deque
from typing import Any, Optional

from ...blocks import register_block, register_protected
from ...blocks.library import LibraryBlock, per_cpu_state
from ...safetext import excerpt
from .master import BAUD_CODE, PARITY_BITS
from .rtu import check_crc, frame, gap_us, serve

__all__ = ["SlaveLib", "slave_of", "ERRORS", "PLCRT_CHOICES", "LIMITS"]

#: MBUS_INIT and MBUS_SLAVE Error (S7-200 System Manual, "Modbus slave
#: protocol execution error codes"; 11 and 12 from the S7-200 SMART System
#: Manual V2.3, 9.3.3.4)
ERRORS = {0: "no error", 1: "memory range error", 2: "illegal baud rate or parity",
          3: "illegal slave address", 4: "illegal value for a Modbus parameter",
          5: "holding registers overlap the Modbus slave symbols", 6: "receive parity error",
          7: "receive CRC error", 8: "illegal function request / function not supported",
          9: "illegal memory address in request", 10: "slave function not enabled",
          11: "invalid port number", 12: "port 1 missing or not configured"}
#: what plcrt decided where the manual has no word (docs/modbus.md)
#: the Error numbers a choice names ("Error 6 / 7" names 6 and 7)
_ERROR_NUMBER = re.compile(r"(?<=Error )\d+|(?<=Error \d / )\d+")

PLCRT_CHOICES = {
    "MBUS_INIT": ("Error 4 for Mode not 0 or 1 and for Delay above 32767 ms",),
    "MBUS_SLAVE": ("Error 9 also for an illegal data value (a count, coil value or "
                   "length; exception 3)",
                   "Done 1 with Error 6 / 7 for a frame with a parity / CRC error "
                   "(no answer)",
                   "Done 1 with Error 10 at every call before a successful MBUS_INIT")}
#: interface -> (largest MaxIQ, largest MaxAI) (S7-200: 00001..00128,
#: 30001..30032; S7-200 SMART: 00001..00256, 30001..30056)
LIMITS = {"MBUS_INIT": (128, 32), "MBUS_INIT_SMART": (256, 56)}
#: exception code -> MBUS_SLAVE Error
_EXC_ERROR = {1: 8, 2: 9, 3: 9}
#: the write functions (broadcasts run them; Modbus over Serial Line 2.1)
_WRITE_FN = (5, 6, 15, 16)
_V = 0x08     #: pointer area code of V (plcrt.compiler.operands.POINTER_AREAS)



class SlaveLib:
    """The Modbus slave of one CPU (see the module docstring); also the
    four tables of :func:`plcrt.devices.modbus.rtu.serve` over memory."""

    def __init__(self, plc: Any) -> None:
        self.plc = plc
        self.port: Any = None
        self.enabled = False
        self.setting: tuple = ()
        self.address = 1
        self.delay_us = 0
        self.max_iq = self.max_ai = self.max_hold = 0
        self.hold = 0                      #: V offset of 40001
        self.rx = bytearray()
        self.rx_parity = False
        self.rx_t0 = 0
        self.gen = 0
        #: requests known ended, not yet served: (time known, bytes, parity
        #: error, first and last character's time)
        self.waiting: deque[tuple[int, bytes, bool, int, int]] = deque()
        #: every frame served or dropped: times (µs), address, function, Error, answer
        self.log: list[dict[str, Any]] = []

    # -- MBUS_INIT
    def enable(self, port: int, addr: int, baud: int, parity: int, delay_ms: int,
               max_iq: int, max_ai: int, max_hold: int, hold: int) -> None:
        p = self.plc.ports[port]
        setting = (port, addr, baud, parity, delay_ms, max_iq, max_ai, max_hold, hold)
        if self.enabled and self.setting == setting:
            return
        if self.port is not None and self.port is not p:
            self.disable()
        p.sm[p.control] = PARITY_BITS[parity] | BAUD_CODE[baud] << 2 | 0x01
        p.owner, self.port = self, p
        self.enabled, self.setting = True, setting
        self.address, self.delay_us = addr, delay_ms * 1000
        self.max_iq, self.max_ai, self.max_hold, self.hold = max_iq, max_ai, max_hold, hold
        self.rx, self.waiting = bytearray(), deque()

    def disable(self) -> None:
        p = self.port
        if p is not None:
            p.sm[p.control] = 0x00            # PPI slave
            if p.owner is self:
                p.owner = None
        self.port, self.enabled, self.setting = None, False, ()
        self.rx, self.waiting = bytearray(), deque()

    # -- the port's characters (Port.owner)
    def char(self, t: int, byte: int, err: bool) -> None:
        """A character received at the port (its stop bit ended at *t*)."""
        if not self.rx:
            self.rx_t0 = t
        self.rx.append(byte)
        self.rx_parity |= err
        self.gen += 1
        fr = self.port.framing()
        # the end-of-message timeout: 3.5 characters, plus Delay (MBUS_INIT)
        self.port.push(t + gap_us(fr.bits, fr.baud) + self.delay_us, self._gap, self.gen, t)

    def _gap(self, t: int, gen: int, last: int) -> None:
        if gen != self.gen or not self.enabled:
            return
        self.waiting.append((t, bytes(self.rx), self.rx_parity, self.rx_t0, last))
        self.rx, self.rx_parity = bytearray(), False
        # the time line stops here, so that the scan after sees the request
        self.plc._sources_on = True

    # -- MBUS_SLAVE
    def serve_one(self) -> tuple[int, int]:
        """Serve the oldest waiting request: (Done, Error); (0, 0) when
        there is none for this slave, or the port still sends the last
        answer (half duplex: the request waits for a later call)."""
        while self.waiting and self.port.tx_end is None:
            known, data, parity, t0, last = self.waiting.popleft()
            rec: dict[str, Any] = {"first_char": t0, "last_char": last, "known": known,
                                   "request": data}
            error, answer = self._answer(data, parity)
            if error is None:                 # not for this slave: the library drops it
                continue
            t = self.plc._irq_t
            rec.update(served=t, error=error)
            if answer is not None:
                end = self.port.send(t, answer)
                rec.update(answer=answer, answer_end=end)
            self.log.append(rec)
            return 1, error
        return 0, 0

    def _answer(self, data: bytes, parity: bool) -> tuple[Optional[int], Optional[bytes]]:
        """(Error, response frame or None); Error None: not for us."""
        if parity:
            return 6, None
        if not check_crc(data):
            return 7, None
        slave, fn, pdu = data[0], data[1], data[2:-2]
        if slave not in (0, self.address) or (slave == 0 and fn not in _WRITE_FN):
            return None, None                 # another slave's, or a broadcast read
        body = serve(fn, pdu, self)
        error = _EXC_ERROR.get(body[1], 9) if body[0] & 0x80 else 0
        if slave == 0:
            return error, None                # broadcast: run, never answered
        return error, frame(bytes((self.address,)) + body)

    # -- the tables (rtu.Tables) over the CPU's memory
    def size(self, kind: str) -> int:
        return {"coils": self.max_iq, "inputs": self.max_iq, "input_registers": self.max_ai,
                "holding": self.max_hold}[kind]

    def get(self, kind: str, start: int, count: int) -> list[int]:
        areas = self.plc.mem.areas
        if kind in ("coils", "inputs"):
            buf = areas["Q" if kind == "coils" else "I"]
            return [buf[n >> 3] >> (n & 7) & 1 for n in range(start, start + count)]
        buf, off = (areas["AI"], 0) if kind == "input_registers" else (areas["V"], self.hold)
        off += 2 * start
        return [buf[off + 2 * i] << 8 | buf[off + 2 * i + 1] for i in range(count)]

    def put(self, kind: str, start: int, values: list[int]) -> None:
        areas = self.plc.mem.areas
        if kind == "coils":
            q = areas["Q"]
            for n, v in enumerate(values, start):
                q[n >> 3] = q[n >> 3] | 1 << (n & 7) if v else q[n >> 3] & ~(1 << (n & 7)) & 0xFF
            return
        v_mem, off = areas["V"], self.hold + 2 * start
        for i, w in enumerate(values):
            v_mem[off + 2 * i:off + 2 * i + 2] = w.to_bytes(2, "big")


#: *plc*'s Modbus slave library (one per CPU).
slave_of = per_cpu_state(SlaveLib)


class _Block(LibraryBlock):
    family, bind_as = "modbus-slave", "mbslave"
    state_of, state_attr = staticmethod(slave_of), "lib"

    @classmethod
    def notice(cls, itf: Any) -> str:
        # one short line naming the Error numbers; what was chosen is in the docs
        numbers = {int(n) for cs in PLCRT_CHOICES.values() for c in cs
                   for n in _ERROR_NUMBER.findall(c)}
        codes = ", ".join(map(str, sorted(numbers)))
        return (f"{itf.name}: the Modbus RTU slave library is emulated (no library memory, "
                f"no interrupt routines); plcrt's choices: Error {codes} (docs/modbus.md)")


@register_block("MBUS_INIT")
@register_block("MBUS_INIT_SMART")
class MbusInit(_Block):
    """MBUS_INIT(Mode, Addr, Baud, Parity, [Port,] Delay, MaxIQ, MaxAI,
    MaxHold, HoldStart) -> Done, Error."""

    def __call__(self, mode: int, addr: int, baud: int, parity: int, *rest: int) -> tuple:
        if len(rest) == 6:
            port, (delay, max_iq, max_ai, max_hold, hold) = rest[0], rest[1:]
        else:
            port, (delay, max_iq, max_ai, max_hold, hold) = 0, rest
        lib = self.lib
        if mode == 0:
            if lib.enabled:
                lib.disable()
            return 1, 0
        top_iq, top_ai = LIMITS[self.name]
        areas = self.plc.mem.areas
        off = hold & 0xFFFFFF
        # the checks in the order of the manual's error codes
        for code, bad, why in (
                (1, hold >> 24 != _V or off + 2 * max_hold > len(areas["V"]),
                 f"HoldStart 16#{hold:08X} and MaxHold {max_hold} are not V memory (&VBn)"),
                (2, baud not in BAUD_CODE or parity not in PARITY_BITS,
                 f"Baud {baud}, Parity {parity}"),
                (3, not 1 <= addr <= 247, f"Addr {addr} is not 1..247"),
                (4, mode != 1, f"Mode {mode} is not 0 or 1"),
                (4, delay > 32767, f"Delay {delay} ms is above 32767"),
                (4, max_iq > min(top_iq, 8 * len(areas["Q"]), 8 * len(areas["I"])),
                 f"MaxIQ {max_iq} is above {top_iq}"),
                (4, max_ai > min(top_ai, len(areas["AI"]) // 2),
                 f"MaxAI {max_ai} is above {top_ai}"),
                (11, port not in (0, 1), f"Port {port} is not 0 or 1"),
                (12, port >= len(self.plc.ports), f"the CPU has no port {port}")):
            if bad:
                self.warn(f"Error {code}: {ERRORS[code]} ({why})", f"err{code}")
                return 1, code
        lib.enable(port, addr, baud, parity, delay, max_iq, max_ai, max_hold, off)
        return 1, 0


@register_block("MBUS_SLAVE")
class MbusSlave(_Block):
    """MBUS_SLAVE() -> Done, Error: one waiting request served per call."""

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self.error = 0

    def __call__(self) -> tuple:
        lib = self.lib
        if not lib.enabled:
            self.warn(f"Error 10: {ERRORS[10]} (no MBUS_INIT with Mode 1 ran without error)",
                      "err10")
            self.error = 10
            return 1, 10
        done, error = lib.serve_one()
        if done:
            self.error = error
            if error:
                rec = lib.log[-1]
                self.warn(f"Error {error}: {ERRORS[error]} (request "
                          f"{excerpt(rec['request'].hex(' ').upper())})", f"err{error}")
        # the manual: Error changes only when Done is on
        return done, self.error


register_protected("Modbus", {"MBUS_INIT": ("MBUS_INIT", "MBUS_INIT_SMART"),
                               "MBUS_SLAVE": ("MBUS_SLAVE",)})
