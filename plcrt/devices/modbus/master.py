"""The Modbus RTU master library of Micro/WIN as built-in blocks: MBUS_CTRL
(S7-200; the S7-200 SMART's with a Port input is MBUS_CTRL_SMART) and
MBUS_MSG (S7-200 System Manual, "Using the Modbus protocol library",
"Instructions for the Modbus master"; interfaces in
library/modbus_master.toml).

What it is: one :class:`Master` per CPU, shared by the call sites.
MBUS_CTRL with Mode 1 puts the port in freeport at the Baud and Parity
given (SMB30 / SMB130) and takes its characters (``Port.owner``); Mode 0
gives the port back to PPI.  MBUS_MSG with First sends one request over the
port's exact-timed serial model (:meth:`plcrt.engine.ports.Port.send`);
the response ends when the line stays quiet for 3.5 characters, a missing
response after Timeout ms from the request's end; the next MBUS_MSG call
of that site checks it (parity, CRC, slave, function, length, exception),
copies the data to or from V memory at DataPtr and reports Done and Error.

What it is not: the library's code.  Its V-memory area (the library
memory Micro/WIN asks for) and its interrupt routines are not simulated;
the Error numbers are the manual's tables, plcrt's own choice where the
manual has none (PLCRT_CHOICES; a load-time warning names them).
A protected, empty SUBROUTINE_BLOCK of the export named like one of these
blocks runs it (``plcrt.blocks.register_protected``;
plcrt.blocks.call.protected_call).
"""

from __future__ import annotations

from typing import Any, Optional

from ...blocks import register_block, register_protected
from ...blocks.library import LibraryBlock, per_cpu_state
from ...engine.serial import BAUD_CODE
from ...safetext import excerpt
from .rtu import READS, WRITES, check_crc, frame, gap_us

__all__ = ["Master", "master_of", "CTRL_ERRORS", "MSG_ERRORS", "RANGES"]

#: MBUS_CTRL Error (S7-200 SMART System Manual V2.3, 9.3.2.4 "Modbus RTU
#: master execution error codes"; 0..4 as the S7-200 System Manual's table)
CTRL_ERRORS = {0: "no error", 1: "invalid parity type", 2: "invalid baud rate",
               3: "invalid timeout", 4: "invalid mode", 9: "invalid port number",
               10: "port 1 missing or not configured (the CPU has one port)"}
#: MBUS_MSG Error (same table; 107 and 108 are plcrt's: PLCRT_CHOICES)
MSG_ERRORS = {0: "no error", 1: "parity error in response", 2: "not used",
              3: "receive timeout (no response from the slave)",
              4: "error in request parameter (Slave, RW, Addr, Count or DataPtr)",
              5: "Modbus master not enabled (MBUS_CTRL)",
              6: "Modbus is busy with another request",
              7: "error in response: it does not answer the request",
              8: "CRC error in response",
              101: "slave does not support the function (exception 1)",
              102: "slave does not support the data address (exception 2)",
              103: "slave does not support the data type (exception 3)",
              104: "slave device failure (exception 4)",
              105: "slave accepted the message, the response is delayed (exception 5)",
              106: "slave busy, message rejected (exception 6)",
              107: "slave rejected the message (another exception code)",
              108: "slave memory parity error (exception 8)"}
#: the numbers plcrt decided (no manual entry found): docs/modbus.md
PLCRT_CHOICES = {"MBUS_MSG": (107, 108)}
#: Modbus address ranges of Addr -> (first, last, table, bits, writable)
#: (System Manual, MBUS_MSG: 00001-09999 coils, 10001-19999 inputs,
#: 30001-39999 input registers, 40001-49999 holding registers)
RANGES = ((1, 9999, "coils", True, True), (10001, 19999, "inputs", True, False),
          (30001, 39999, "input_registers", False, False),
          (40001, 49999, "holding", False, True))
#: Count limits (System Manual, MBUS_MSG: at most 1920 bits or 120 words)
MAX_BITS, MAX_WORDS = 1920, 120
#: Parity 0 none, 1 odd, 2 even -> SMB30 bits pp (00 none, 11 odd, 01 even)
PARITY_BITS = {0: 0x00, 1: 0xC0, 2: 0x40}
_V = 0x08     #: pointer area code of V (plcrt.compiler.operands.POINTER_AREAS)



class Request:
    """One MBUS_MSG request in progress or finished."""

    def __init__(self, site: Any, slave: int, fn: int, frame: bytes, read: Optional[tuple],
                 ptr: int) -> None:
        self.site, self.slave, self.fn, self.frame = site, slave, fn, frame
        self.read = read            #: (bits, count, data bytes) of a read, else None
        self.ptr = ptr
        self.rx = bytearray()
        self.parity = False
        self.gen = 0
        self.error: Optional[int] = None   #: set when finished
        self.data = b""             #: a read's data bytes (when error 0)
        self.times: dict[str, int] = {}


class Master:
    """The Modbus master of one CPU (see the module docstring)."""

    def __init__(self, plc: Any) -> None:
        self.plc = plc
        self.port: Any = None
        self.enabled = False
        self.setting: tuple = ()
        self.timeout_us = 1_000_000
        self.request: Optional[Request] = None
        self.log: list[dict[str, int]] = []   #: times and Error of every finished request

    def busy(self) -> bool:
        return self.request is not None and self.request.error is None

    # -- MBUS_CTRL
    def enable(self, port: int, baud: int, parity: int, timeout_ms: int) -> None:
        setting = (port, baud, parity)
        p = self.plc.ports[port]
        if not self.enabled or self.setting != setting:
            if self.port is not None and self.port is not p:
                self.disable()
            p.sm[p.control] = PARITY_BITS[parity] | BAUD_CODE[baud] << 2 | 0x01
            p.owner, self.port = self, p
            self.enabled, self.setting = True, setting
        self.timeout_us = timeout_ms * 1000

    def disable(self) -> None:
        p = self.port
        if p is not None:
            p.sm[p.control] = 0x00            # PPI slave
            p.owner = None
        self.port, self.enabled, self.setting, self.request = None, False, (), None

    # -- MBUS_MSG
    def send(self, req: Request) -> None:
        t = self.plc._irq_t
        p = self.port
        self.request = req
        end = p.send(t, req.frame)
        fr = p.framing()
        req.times.update(sent=t, sent_end=end)
        if req.slave == 0:
            # broadcast: no answer; the line is free after the gap
            p.push(end + gap_us(fr.bits, fr.baud), self._finish, req, 0)
        else:
            p.push(end + self.timeout_us, self._timeout, req)

    def char(self, t: int, byte: int, err: bool) -> None:
        """A character received at the port (its stop bit ended at *t*)."""
        req = self.request
        if req is None or req.error is not None or req.slave == 0:
            return                          # nothing asked: the library drops it
        if not req.rx:
            req.times["first_char"] = t
        req.rx.append(byte)
        req.parity |= err
        req.times["last_char"] = t
        req.gen += 1
        fr = self.port.framing()
        self.port.push(t + gap_us(fr.bits, fr.baud), self._gap, req, req.gen)

    def _timeout(self, t: int, req: Request) -> None:
        if req is self.request and req.error is None and not req.rx:
            self._finish(t, req, 3)

    def _gap(self, t: int, req: Request, gen: int) -> None:
        if req is self.request and req.error is None and gen == req.gen:
            self._finish(t, req, self.check(req))

    def _finish(self, t: int, req: Request, error: int) -> None:
        req.error = error
        req.times["finished"] = t
        self.log.append({**req.times, "error": error})
        # the time line stops here, so the scan after sees it (Port._post_now)
        self.plc._sources_on = True

    @staticmethod
    def check(req: Request) -> int:
        """The MBUS_MSG Error of the response received for *req*."""
        r = bytes(req.rx)
        if req.parity:
            return 1
        if not check_crc(r):
            return 8
        if r[0] != req.slave:
            return 7
        if r[1] == req.fn | 0x80 and len(r) == 5:
            return {1: 101, 2: 102, 3: 103, 4: 104, 5: 105, 6: 106, 8: 108}.get(r[2], 107)
        if r[1] != req.fn:
            return 7
        if req.read is not None:
            n = req.read[2]
            if len(r) != 5 + n or r[2] != n:
                return 7
            req.data = r[3:3 + n]
            return 0
        return 0 if r[2:6] == req.frame[2:6] and len(r) == 8 else 7


#: *plc*'s Modbus master (one per CPU).
master_of = per_cpu_state(Master)


class _Block(LibraryBlock):
    family, bind_as = "modbus", "mbmaster"
    state_of, state_attr = staticmethod(master_of), "master"

    @classmethod
    def notice(cls, itf: Any) -> str:
        # one short line: the details are in the docs' error table
        codes = ", ".join(str(k) for k in PLCRT_CHOICES["MBUS_MSG"])
        return (f"{itf.name}: the Modbus RTU master library is emulated (no library memory, "
                f"no interrupt routines); plcrt's choices: Error {codes} (docs/modbus.md)")


@register_block("MBUS_CTRL")
@register_block("MBUS_CTRL_SMART")
class MbusCtrl(_Block):
    """MBUS_CTRL(Mode, Baud, Parity, [Port,] Timeout) -> Done, Error."""

    def __call__(self, mode: int, baud: int, parity: int, *rest: int) -> tuple:
        port, timeout = (0, rest[0]) if len(rest) == 1 else rest
        m = self.master
        if not mode:
            if m.enabled:
                m.disable()
            return 1, 0
        # System Manual, MBUS_CTRL: the checks in the order of its error codes
        for code, bad in ((1, parity not in PARITY_BITS), (2, baud not in BAUD_CODE),
                          (3, not 1 <= timeout <= 32767), (9, port not in (0, 1)),
                          (10, port >= len(self.plc.ports))):
            if bad:
                self.warn(f"Error {code}: {CTRL_ERRORS[code]} (Mode 1, Baud {baud}, Parity "
                          f"{parity}, Port {port}, Timeout {timeout})", f"err{code}")
                return 1, code
        m.enable(port, baud, parity, timeout)
        return 1, 0


@register_block("MBUS_MSG")
class MbusMsg(_Block):
    """MBUS_MSG(First, Slave, RW, Addr, Count, DataPtr) -> Done, Error."""

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self.done, self.error = 0, 0
        self.mine: Optional[Request] = None

    def __call__(self, first: int, slave: int, rw: int, addr: int, count: int,
                 ptr: int) -> tuple:
        m = self.master
        req = self.mine
        if req is not None and req.error is not None:
            self._complete(req)
        if first and not (req is not None and req.error is None and m.request is req):
            self._start(slave, rw, addr, count, ptr)
        return self.done, self.error

    def _refuse(self, code: int, why: str = "") -> None:
        self.warn(f"Error {code}: {MSG_ERRORS[code]}{why}", f"err{code}")
        self.done, self.error, self.mine = 1, code, None

    def _start(self, slave: int, rw: int, addr: int, count: int, ptr: int) -> None:
        m = self.master
        if not m.enabled:
            return self._refuse(5)
        if m.busy():
            return self._refuse(6)
        rng = next((r for r in RANGES if r[0] <= addr <= r[1]), None)
        size = 0
        why = ""
        if rng is not None:
            size = (count + 7) // 8 if rng[3] else 2 * count
        if not 0 <= slave <= 247:
            why = f"Slave {slave} is not 0..247"
        elif rw not in (0, 1):
            why = f"RW {rw} is not 0 (read) or 1 (write)"
        elif rng is None:
            why = f"Addr {addr} is in no Modbus address range"
        elif rw == 1 and not rng[4]:
            why = f"Addr {addr}: {rng[2]} cannot be written"
        elif slave == 0 and rw == 0:
            why = "a read from the broadcast address 0"
        elif not 1 <= count <= (MAX_BITS if rng[3] else MAX_WORDS) \
                or addr + count - 1 > rng[1]:
            why = f"Count {count} at Addr {addr}"
        elif ptr >> 24 != _V or (ptr & 0xFFFFFF) + size > len(self.plc.mem.areas["V"]):
            why = f"DataPtr 16#{ptr:08X} is not {size} bytes of V memory (&VBn)"
        if why:
            return self._refuse(4, f": {why}")
        first, _, table, bits, _ = rng
        start = addr - first
        v, off = self.plc.mem.areas["V"], ptr & 0xFFFFFF
        head = bytes((slave,))
        if rw == 0:
            fn = READS[table]
            body = head + bytes((fn,)) + start.to_bytes(2, "big") + count.to_bytes(2, "big")
            read: Optional[tuple] = (bits, count, size)
        else:
            data = bytes(v[off:off + size])
            one, many = WRITES[table]
            if count == 1:
                fn = one
                value = (0xFF00 if data[0] & 1 else 0) if bits else int.from_bytes(data, "big")
                body = head + bytes((fn,)) + start.to_bytes(2, "big") + value.to_bytes(2, "big")
            else:
                fn = many
                if bits:   # bits past Count in the last byte go as 0
                    data = data[:-1] + bytes((data[-1] & ((1 << (count % 8 or 8)) - 1),))
                body = head + bytes((fn,)) + start.to_bytes(2, "big") \
                    + count.to_bytes(2, "big") + bytes((size,)) + data
            read = None
        req = Request(self, slave, fn, frame(body), read, ptr)
        self.mine, self.done, self.error = req, 0, 0
        m.send(req)

    def _complete(self, req: Request) -> None:
        """The finished request's result: data into V, Done and Error."""
        self.mine = None
        self.done, self.error = 1, req.error
        if req.error:
            self.warn(f"Error {req.error}: {MSG_ERRORS.get(req.error, '?')} (slave {req.slave}, "
                      f"function {req.fn}; received {excerpt(bytes(req.rx).hex(' ').upper())})",
                      f"err{req.error}")
        elif req.read is not None:
            off = req.ptr & 0xFFFFFF
            self.plc.mem.areas["V"][off:off + len(req.data)] = req.data
        if self.master.request is req:
            self.master.request = None


register_protected("Modbus", {"MBUS_CTRL": ("MBUS_CTRL", "MBUS_CTRL_SMART"),
                               "MBUS_MSG": ("MBUS_MSG",)})
