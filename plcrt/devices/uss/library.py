"""The USS protocol library of Micro/WIN as built-in blocks: USS_INIT (the
S7-200 SMART's, with a Port input, is USS_INIT_SMART), USS_CTRL, USS_RPM_W /
_D / _R and USS_WPM_W / _D / _R (S7-200 System Manual, "Using the USS
protocol library to control a MicroMaster drive"; interfaces in
library/uss.toml).

What it is: one :class:`Master` per CPU, shared by the call sites.
USS_INIT with Mode 1 puts the port in freeport at Baud with 8 data bits and
even parity (11 bits a character; SMB30 / SMB130) and takes its characters
(``Port.owner``); from then on the master polls the drives of the Active
mask in turn, one telegram (:mod:`.telegram`) at a time over the port's
exact-timed serial model: each telegram goes out 2 character times after
the line went quiet (the USS start delay), carries the STW and HSW the
drive's USS_CTRL set last and, when a parameter request of USS_RPM_x /
USS_WPM_x waits for that drive, its PKW (the next telegram goes to that
drive).  The response ends with its last character (LGE tells the
length); none within the manual's poll time for the baud rate (table
"Communications times": 50 ms at 9600 ...) from the request's end is
Error 1.  USS_CTRL reports the drive's last response (Resp_R one scan for
each new one); a parameter request finishes with the response to its
telegram.  Mode 0 gives the port back to PPI.

What it is not: the library's code.  Its V-memory area and interrupt
routines are not simulated; DB_Ptr is checked (16 bytes of V memory) but
not written.  The Error numbers are the manual's table "USS protocol
library execution error codes"; numbers the manual does not give are
plcrt's choice (PLCRT_CHOICES; a load-time warning names them).  A
protected, empty SUBROUTINE_BLOCK of the export named like one of these
blocks runs it (``plcrt.blocks.register_protected``).
"""

from __future__ import annotations

import math
from typing import Any, Optional

from ...blocks import register_block, register_protected
from ...blocks.library import LibraryBlock, per_cpu_state
from ...engine.serial import BAUD_CODE
from .telegram import (STW, STX, TASK, ZSW, Telegram, bits_real, decode, encode,
                       param_code, real_bits, speed_word, word_speed)

__all__ = ["Master", "master_of", "ERRORS", "PLCRT_CHOICES", "POLL_MS"]

#: Error of every USS block (S7-200 System Manual, "USS protocol library
#: execution error codes"; 23 is plcrt's: PLCRT_CHOICES)
ERRORS = {0: "no error", 1: "drive did not respond", 2: "checksum error in the drive's response",
          3: "parity error in the drive's response",
          4: "error caused by interference from the user program",
          5: "illegal command attempted", 6: "illegal drive address supplied",
          7: "communication port not set up for USS protocol",
          8: "communication port busy processing an instruction",
          9: "drive speed input out of range", 10: "length of the drive's response incorrect",
          11: "first character of the drive's response incorrect (not STX)",
          12: "length character of the drive's response not supported by USS instructions",
          13: "wrong drive responded", 14: "DB_Ptr address supplied incorrect",
          15: "parameter number supplied incorrect", 16: "invalid protocol selected",
          17: "USS active; change not allowed", 18: "illegal baud rate specified",
          19: "no communications: the drive is not ACTIVE",
          20: "parameter or value in the drive's response incorrect or an error code",
          21: "double word value returned instead of the word value requested",
          22: "word value returned instead of the double word value requested",
          23: "invalid port (S7-200 SMART Port not 0 or 1, or the CPU has no such port)"}
#: the numbers plcrt decided (no manual entry found): docs/uss.md
PLCRT_CHOICES = {"USS_INIT": (23,)}
#: baud -> the manual's time between polls of one active drive, ms (table
#: "Communications times"); here the response timeout from a request's end
POLL_MS = {1200: 240, 2400: 130, 4800: 75, 9600: 50, 19200: 35, 38400: 30, 57600: 25,
           115200: 25}
EVEN = 0x40     #: SMB30 parity bits pp = 01: even
_V = 0x08       #: pointer area code of V
DB_SIZE = 16    #: bytes at DB_Ptr (System Manual, USS_RPM_x: a 16-byte buffer)
#: the STW bits every USS_CTRL telegram has set: pulse enable, ramp function
#: generator enable and start, setpoint enable, control from the PLC
_STW_ALWAYS = STW["pulse_enable"] | STW["rfg_enable"] | STW["rfg_start"] \
    | STW["setpoint_enable"] | STW["plc_control"]
#: value kind -> (bytes, word task, indexed word task, EEPROM, indexed EEPROM)
_WRITE_TASK = {"W": (TASK["write_word"], TASK["write_word_index"], TASK["write_word_eeprom"],
                     TASK["write_word_index_eeprom"]),
               "D": (TASK["write_dword"], TASK["write_dword_index"],
                     TASK["write_dword_eeprom"], TASK["write_dword_index_eeprom"])}



class Slot:
    """What the master knows of one drive."""

    def __init__(self) -> None:
        self.stw = 0            #: control word USS_CTRL set last
        self.hsw = 0            #: setpoint word
        self.status = 0         #: ZSW of the last good response
        self.hiw = 0            #: HIW of the last good response
        self.responses = 0      #: good responses so far
        self.error = 0          #: Error of the last transaction


class Request:
    """One USS_RPM_x / USS_WPM_x request in progress or finished."""

    def __init__(self, site: Any, drive: int, kind: str, task: int, param: int, index: int,
                 pwe: int) -> None:
        self.site, self.drive, self.kind = site, drive, kind
        self.task, self.param, self.index, self.pwe = task, param, index, pwe
        self.error: Optional[int] = None
        self.value: Any = 0
        self.drive_error: Optional[int] = None   #: the drive's error number (response 7)


class _Exchange:
    """One telegram and its response."""

    def __init__(self, drive: int, req: Optional[Request]) -> None:
        self.drive, self.req = drive, req
        self.rx = bytearray()
        self.parity = False
        self.times: dict[str, int] = {}


class Master:
    """The USS master of one CPU (see the module docstring)."""

    def __init__(self, plc: Any) -> None:
        self.plc = plc
        self.port: Any = None
        self.enabled = False
        self.setting: tuple = ()
        self.baud = 9600
        self.active: list[int] = []          #: active drive addresses, ascending
        self.slots: dict[int, Slot] = {}
        self.turn = 0                        #: index in active of the next drive polled
        self.gen = 0                         #: bumped by USS_INIT: drops stale events
        self.request: Optional[Request] = None
        self.exchange: Optional[_Exchange] = None
        self.log: list[dict[str, int]] = []  #: times, drive and Error of every exchange

    def busy(self) -> bool:
        return self.request is not None and self.request.error is None

    # -- USS_INIT
    def enable(self, port: int, baud: int, active: int) -> None:
        p = self.plc.ports[port]
        if self.port is not None and self.port is not p:
            self.disable()
        p.sm[p.control] = EVEN | BAUD_CODE[baud] << 2 | 0x01
        p.owner, self.port = self, p
        self.enabled, self.setting, self.baud = True, (port, baud, active), baud
        self.active = [a for a in range(32) if active >> a & 1]
        self.slots = {a: Slot() for a in self.active}
        self.turn, self.request, self.exchange = 0, None, None
        self.gen += 1
        if self.active:
            t = self.plc._irq_t
            self.port.push(self._delay(t), self._poll, self.gen)

    def disable(self) -> None:
        p = self.port
        if p is not None:
            p.sm[p.control] = 0x00            # PPI slave
            p.owner = None
        self.gen += 1
        self.port, self.enabled, self.setting = None, False, ()
        self.active, self.slots, self.request, self.exchange = [], {}, None, None

    def _delay(self, t: int) -> int:
        """*t* plus the start delay of 2 characters."""
        return self.port.framing().end(t, 2)

    # -- the polling
    def _poll(self, t: int, gen: int) -> None:
        if gen != self.gen or not self.enabled:
            return
        req = self.request if self.busy() else None
        if req is not None:
            drive = req.drive                 # a parameter request goes next
        else:
            drive = self.active[self.turn % len(self.active)]
            self.turn = (self.turn + 1) % len(self.active)
        slot = self.slots[drive]
        pke = ind = pwe = 0
        if req is not None:
            pke, ind = param_code(req.param, req.index)
            pke |= req.task << 12
            pwe = req.pwe
        ex = _Exchange(drive, req)
        self.exchange = ex
        end = self.port.send(t, encode(Telegram(drive, pke, ind, pwe, slot.stw, slot.hsw)))
        ex.times.update(drive=drive, sent=t, sent_end=end)
        self.port.push(end + POLL_MS[self.baud] * 1000, self._timeout, ex, gen)

    def char(self, t: int, byte: int, err: bool) -> None:
        """A character received at the port (its stop bit ended at *t*)."""
        ex = self.exchange
        if ex is None or "finished" in ex.times:
            return                          # nothing asked: the library drops it
        if not ex.rx:
            ex.times["first_char"] = t
        ex.rx.append(byte)
        ex.parity |= err
        ex.times["last_char"] = t
        rx = ex.rx
        if rx[0] == STX and len(rx) >= 2 and len(rx) == rx[1] + 2:
            self._finish(t, ex, self._check(ex))

    def _timeout(self, t: int, ex: _Exchange, gen: int) -> None:
        if gen == self.gen and ex is self.exchange and "finished" not in ex.times:
            rx = ex.rx
            self._finish(t, ex, 1 if not rx else 11 if rx[0] != STX else 10)

    def _check(self, ex: _Exchange) -> int:
        """The Error of a complete response; a good one updates the slot."""
        if ex.parity:
            return 3
        tel, why = decode(bytes(ex.rx))
        if tel is None:
            return {"stx": 11, "length": 10, "lge": 12, "bcc": 2}[why]
        if tel.address != ex.drive:
            return 13
        slot = self.slots[ex.drive]
        slot.status, slot.hiw = tel.stw, tel.hsw
        slot.responses += 1
        if ex.req is not None:
            self._answer(ex.req, tel)
        return 0

    @staticmethod
    def _answer(req: Request, tel: Telegram) -> None:
        """The parameter request's result from the response's PKW."""
        resp = tel.task
        if resp == 0:
            return                            # no answer yet: the task goes again
        if resp == 7:
            req.error, req.drive_error = 20, tel.pwe & 0xFFFF
        elif tel.param != req.param or resp not in (1, 2, 4, 5):
            req.error = 20
        elif req.kind == "W":
            req.error = 21 if resp in (2, 5) else 0
            req.value = tel.pwe & 0xFFFF
        else:
            req.error = 22 if resp in (1, 4) else 0
            req.value = tel.pwe if req.kind == "D" else bits_real(tel.pwe)

    def _finish(self, t: int, ex: _Exchange, error: int) -> None:
        ex.times["finished"] = t
        self.slots[ex.drive].error = error
        if error and ex.req is not None and ex.req.error is None:
            ex.req.error = error
        self.log.append({**ex.times, "error": error})
        self.exchange = None
        self.port.push(self._delay(t), self._poll, self.gen)
        # the time line stops here, so the scan after sees it
        self.plc._sources_on = True


#: *plc*'s USS master (one per CPU).
master_of = per_cpu_state(Master)


class _Block(LibraryBlock):
    family, bind_as = "uss", "ussmaster"
    state_of, state_attr = staticmethod(master_of), "master"

    @classmethod
    def notice(cls, itf: Any) -> str:
        # one short line: the details are in the docs' error table
        codes = ", ".join(str(k) for k in PLCRT_CHOICES["USS_INIT"])
        return (f"{itf.name}: the USS protocol library is emulated (no library memory, no "
                f"interrupt routines); plcrt's choice: Error {codes} (docs/uss.md)")

    def refuse(self, code: int, why: str = "") -> int:
        self.warn(f"Error {code}: {ERRORS[code]}{why}", f"err{code}")
        return code

    def drive_error(self, drive: int) -> int:
        """Error 7, 6 or 19 for a call naming *drive*, else 0."""
        m = self.master
        if not m.enabled:
            return self.refuse(7)
        if not 0 <= drive <= 31:
            return self.refuse(6, f" (Drive {drive}; 0..31)")
        if drive not in m.slots:
            return self.refuse(19, f" (Drive {drive} is not in USS_INIT's Active mask)")
        return 0


@register_block("USS_INIT")
@register_block("USS_INIT_SMART")
class UssInit(_Block):
    """USS_INIT(Mode, Baud, [Port,] Active) -> Done, Error."""

    def __call__(self, mode: int, baud: int, *rest: int) -> tuple:
        port, active = (0, rest[0]) if len(rest) == 1 else rest
        m = self.master
        if mode == 0:
            if m.enabled:
                m.disable()
            return 1, 0
        why = f" (Mode {mode}, Baud {baud}, Port {port}, Active 16#{active:08X})"
        for code, bad in ((16, mode != 1), (18, baud not in POLL_MS),
                          (23, port not in (0, 1) or port >= len(self.plc.ports)),
                          (17, m.enabled and m.setting != (port, baud, active))):
            if bad:
                return 1, self.refuse(code, why)
        if not m.enabled:
            m.enable(port, baud, active)
        return 1, 0


@register_block("USS_CTRL")
class UssCtrl(_Block):
    """USS_CTRL(RUN, OFF2, OFF3, F_ACK, DIR, Drive, Type, Speed_SP) ->
    Resp_R, Error, Status, Speed, Run_EN, D_Dir, Inhibit, Fault."""

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self.seen = 0

    def __call__(self, run: int, off2: int, off3: int, f_ack: int, direction: int, drive: int,
                 typ: int, speed_sp: float) -> tuple:
        error = self.drive_error(drive)
        if error:
            return 0, error, 0, 0.0, 0, 0, 0, 0
        slot = self.master.slots[drive]
        if typ not in (0, 1):
            error = self.refuse(5, f" (Type {typ}: 0 MicroMaster 3, 1 MicroMaster 4)")
        elif not math.isfinite(speed_sp) or not -200.0 <= speed_sp <= 200.0:
            error = self.refuse(9, f" (Speed_SP {speed_sp!r}; -200.0..200.0 %)")
        else:
            # Type 1 (MicroMaster 4): a signed setpoint, DIR 0 inverts it;
            # Type 0 (MicroMaster 3): the magnitude, the direction in STW bit 11
            reverse = not direction
            if typ == 0:
                reverse ^= speed_sp < 0
            slot.stw = _STW_ALWAYS | run * STW["on"] | (not off2) * STW["no_off2"] \
                | (not off3) * STW["no_off3"] | f_ack * STW["fault_ack"] \
                | reverse * STW["reverse"]
            slot.hsw = speed_word(speed_sp, typ == 1)
        resp = slot.responses != self.seen
        self.seen = slot.responses
        z = slot.status
        speed = word_speed(slot.hiw, typ == 1)
        if typ == 0 and not z & ZSW["clockwise"]:
            speed = -speed
        return (int(resp), error or slot.error, z, speed, int(bool(z & ZSW["running"])),
                int(bool(z & ZSW["clockwise"])), int(bool(z & ZSW["inhibit"])),
                int(bool(z & ZSW["fault"])))


class _Param(_Block):
    """The common part of USS_RPM_x and USS_WPM_x."""

    kind = "W"        #: W word, D double word, R real

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self.kind = itf.name.upper()[-1]
        self.done, self.error, self.value = 0, 0, 0 if self.kind != "R" else 0.0
        self.mine: Optional[Request] = None

    def step(self, xmt_req: int, drive: int, param: int, index: int, db_ptr: int,
             write: Optional[tuple[int, int]]) -> None:
        """Finish a finished request; start one on XMT_REQ (*write*: the
        EEPROM flag and the value bits of a write)."""
        req = self.mine
        if req is not None and req.error is not None:
            self._complete(req)
        elif req is not None and self.master.request is not req:
            self.mine = None                  # USS_INIT ran again: the request is gone
            self.done, self.error = 1, self.refuse(4, " (USS_INIT while the request ran)")
        if xmt_req and self.mine is None:
            self._start(drive, param, index, db_ptr, write)

    def _start(self, drive: int, param: int, index: int, db_ptr: int,
               write: Optional[tuple[int, int]]) -> None:
        m = self.master
        error = self.drive_error(drive)
        if not error and m.busy():
            error = self.refuse(8, f" (a parameter request for drive {m.request.drive} runs)")
        if not error and (param > 3999 or index > 255):
            error = self.refuse(15, f" (Param {param}: 0..3999, Index {index}: 0..255)")
        if not error and (db_ptr >> 24 != _V or (db_ptr & 0xFFFFFF) + DB_SIZE
                          > len(self.plc.mem.areas["V"])):
            error = self.refuse(14, f" (DB_Ptr 16#{db_ptr:08X} is not {DB_SIZE} bytes of V "
                                    f"memory, &VBn)")
        if error:
            self.done, self.error = 1, error
            return
        if write is None:
            task, pwe = (TASK["read_index"] if index else TASK["read"]), 0
        else:
            eeprom, pwe = write
            tasks = _WRITE_TASK["W" if self.kind == "W" else "D"]
            task = tasks[2 * bool(eeprom) + bool(index)]
        req = Request(self, drive, self.kind, task, param, index, pwe)
        self.mine, self.done, self.error = req, 0, 0
        m.request = req

    def _complete(self, req: Request) -> None:
        self.mine = None
        self.done, self.error = 1, req.error
        if req.error:
            extra = f"; drive error number {req.drive_error}" if req.drive_error is not None \
                else ""
            self.warn(f"Error {req.error}: {ERRORS.get(req.error, '?')} (drive {req.drive}, "
                      f"parameter {req.param}, index {req.index}{extra})", f"err{req.error}")
        elif isinstance(self, UssRpm):
            self.value = req.value
        if self.master.request is req:
            self.master.request = None


@register_block("USS_RPM_W")
@register_block("USS_RPM_D")
@register_block("USS_RPM_R")
class UssRpm(_Param):
    """USS_RPM_x(XMT_REQ, Drive, Param, Index, DB_Ptr) -> Done, Error, Value."""

    def __call__(self, xmt_req: int, drive: int, param: int, index: int,
                 db_ptr: int) -> tuple:
        self.step(xmt_req, drive, param, index, db_ptr, None)
        return self.done, self.error, self.value


@register_block("USS_WPM_W")
@register_block("USS_WPM_D")
@register_block("USS_WPM_R")
class UssWpm(_Param):
    """USS_WPM_x(XMT_REQ, EEPROM, Drive, Param, Index, Value, DB_Ptr) -> Done, Error."""

    def __call__(self, xmt_req: int, eeprom: int, drive: int, param: int, index: int,
                 value: Any, db_ptr: int) -> tuple:
        bits = real_bits(value) if self.kind == "R" else int(value)
        self.step(xmt_req, drive, param, index, db_ptr, (eeprom, bits))
        return self.done, self.error


register_protected("USS", {"USS_INIT": ("USS_INIT", "USS_INIT_SMART"),
                           **{n: (n,) for n in ("USS_CTRL", "USS_RPM_W", "USS_RPM_D",
                                                "USS_RPM_R", "USS_WPM_W", "USS_WPM_D",
                                                "USS_WPM_R")}})
