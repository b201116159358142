"""Simulated MicroMaster-style drives on a USS bus at a CPU port, from the
plant file.

Plant keys (every problem a PlcConfigError naming the file and key)::

    [port.0.uss]
    baud = 9600                  # optional: the drives' rate (else the port's setting)
    [[port.0.uss.drive]]
    address = 1                  # USS address 0..31 (P2011)
    model = "mm4"                # "mm4": signed setpoint and actual value; "mm3": magnitudes
    base_hz = 50.0               # reference frequency: 16#4000 = 100 % (P2000)
    max_hz = 50.0                # optional, the highest frequency (P1082); base_hz
    ramp_up_s = 10.0             # 0 -> base_hz (P1120)
    ramp_down_s = 10.0           # base_hz -> 0 (P1121)
    off3_ramp_s = 1.0            # base_hz -> 0 on OFF3 (P1135)
    response_delay_ms = 2        # from the request's last stop bit to the answer
    word = { 700 = 5, 1000 = 5 } # parameters: number = value, or a list (indexed)
    dword = { 2013 = 4 }
    real = { 1082 = 50.0, 1120 = 10.0 }
    read_only = [1082]           # writes are refused (drive error 1)

What it is: :class:`UssBus`, the port's peer, holding the drives by
address; each transmission of the CPU is one telegram (:mod:`.telegram`),
taken when its last stop bit ends.  A telegram in another framing than the
drives' (8 data bits, even parity, 1 stop bit at their rate), with a bad
STX, LGE or BCC, or for an address no drive has gets no answer.  The
addressed :class:`Drive` follows the control word (System Manual, USS_CTRL;
MicroMaster 4 r0054) and the setpoint, ramps its output frequency in exact
simulated time (rational arithmetic, so the setpoint is reached at the
analytic instant), answers *response_delay_ms* after the request with its
status word and actual frequency and the answer to the parameter task
(response 1/2/4/5, or 7 with the drive's error number: 0 no such
parameter, 1 read-only, 3 bad index, 5 wrong data type, 106 task not
supported).  The ramp times are parameters 1120, 1121 and 1135 when the
real table has them (so USS_WPM_R can change them).  r0021 (actual
frequency, REAL) and r0052 (status word) are there unless the tables
define them.  Tests read ``frequency``, ``status``, ``fault``; ``trip()``
puts a drive in fault; ``corrupt`` answers with a wrong BCC, ``bad_parity``
with a parity error.

What it is not: no motor, no current, no V/f; no PKW of variable length;
one device per port.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Optional

from ...engine.serial import Framing
from ...errors import PlcConfigError
from ..keys import checked_table
from ..peer import PortPeer, baud_key
from .telegram import (FULL_SCALE, RESPONSE, STW, TASK, ZSW, Telegram, bits_real, decode,
                       encode, real_bits)

__all__ = ["DriveConfig", "BusConfig", "parse_uss", "UssBus", "Drive"]

_BUS_KEYS = {"baud", "drive"}
_DRIVE_KEYS = {"address", "model", "base_hz", "max_hz", "ramp_up_s", "ramp_down_s", "off3_ramp_s",
               "response_delay_ms", "word", "dword", "real", "read_only"}
#: parameter type -> largest value (None: a REAL)
_TYPES = {"word": 0xFFFF, "dword": 0xFFFFFFFF, "real": None}
#: write task -> (value type, indexed, EEPROM)
_WRITES = {TASK["write_word"]: ("word", False, False), TASK["write_dword"]: ("dword", False, False),
           TASK["write_word_index"]: ("word", True, False),
           TASK["write_dword_index"]: ("dword", True, False),
           TASK["write_word_eeprom"]: ("word", False, True),
           TASK["write_dword_eeprom"]: ("dword", False, True),
           TASK["write_word_index_eeprom"]: ("word", True, True),
           TASK["write_dword_index_eeprom"]: ("dword", True, True)}
_READS = {TASK["read"]: False, TASK["read_index"]: True}
#: drive error numbers of response 7 (MicroMaster 4, "USS" parameter channel)
DRIVE_ERRORS = {0: "no such parameter", 1: "parameter is read-only", 3: "bad index",
                5: "wrong data type", 106: "task not supported"}
#: ramp parameters (MicroMaster 4 P1120, P1121, P1135) -> config attribute
_RAMPS = {1120: "ramp_up_s", 1121: "ramp_down_s", 1135: "off3_ramp_s"}
_ACTUAL, _STATUS = 21, 52   #: r0021 actual frequency, r0052 status word


@dataclass
class DriveConfig:
    address: int
    model: str = "mm4"
    base_hz: float = 50.0
    max_hz: float = 50.0
    ramp_up_s: float = 10.0
    ramp_down_s: float = 10.0
    off3_ramp_s: float = 1.0
    delay_us: int = 0
    params: dict[int, tuple[str, Any]] = field(default_factory=dict)
    read_only: frozenset[int] = frozenset()


@dataclass
class BusConfig:
    baud: Optional[int] = None
    drives: list[DriveConfig] = field(default_factory=list)


def _num(raw: dict, key: str, where: str, default: float, lo: float, hi: float) -> float:
    v = raw.get(key, default)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
            or not lo <= v <= hi:
        raise PlcConfigError(f"{where}.{key} must be a number in {lo:g}..{hi:g}, got {v!r:.40}")
    return float(v)


def _value(v: Any, typ: str, where: str) -> Any:
    top = _TYPES[typ]
    if top is None:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                or abs(v) > 3.4e38:
            raise PlcConfigError(f"{where} must be a REAL number, got {v!r:.40}")
        return bits_real(real_bits(float(v)))
    if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= top:
        raise PlcConfigError(f"{where} must be a whole number 0..{top}, got {v!r:.40}")
    return v


def _params(raw: dict, where: str) -> dict[int, tuple[str, Any]]:
    out: dict[int, tuple[str, Any]] = {}
    for typ in _TYPES:
        table = raw.get(typ, {})
        if not isinstance(table, dict):
            raise PlcConfigError(f"{where}.{typ} must be a table {{number = value, ...}}")
        for key, v in table.items():
            w = f"{where}.{typ}.{key}"
            if not str(key).isdigit() or not 0 <= int(key) <= 3999:
                raise PlcConfigError(f"{w}: a parameter number is 0..3999")
            if int(key) in out:
                raise PlcConfigError(f"{w}: parameter {int(key)} is already in another table")
            if isinstance(v, list):
                if not 1 <= len(v) <= 256:
                    raise PlcConfigError(f"{w}: an indexed parameter has 1..256 values")
                val: Any = [_value(x, typ, f"{w}[{i}]") for i, x in enumerate(v)]
            else:
                val = _value(v, typ, w)
            out[int(key)] = (typ, val)
    return out


def parse_uss(raw: Any, where: str) -> BusConfig:
    """``[port.N.uss]`` with its ``[[port.N.uss.drive]]`` entries."""
    raw = checked_table(raw, where, _BUS_KEYS, ("drive",))
    bus = BusConfig()
    bus.baud = baud_key(raw, where)
    drives = raw["drive"]
    if not isinstance(drives, list) or not drives:
        raise PlcConfigError(f"{where}.drive must be an array of tables ([[...uss.drive]])")
    for i, d in enumerate(drives):
        w = f"{where}.drive[{i}]"
        d = checked_table(d, w, _DRIVE_KEYS, ("address",))
        a = d["address"]
        if isinstance(a, bool) or not isinstance(a, int) or not 0 <= a <= 31:
            raise PlcConfigError(f"{w}.address must be a USS address 0..31, got {a!r:.40}")
        if any(x.address == a for x in bus.drives):
            raise PlcConfigError(f"{w}.address: another drive already has address {a}")
        cfg = DriveConfig(a)
        cfg.model = d.get("model", "mm4")
        if cfg.model not in ("mm3", "mm4"):
            raise PlcConfigError(f"{w}.model must be \"mm3\" or \"mm4\", got {cfg.model!r:.40}")
        cfg.base_hz = _num(d, "base_hz", w, 50.0, 1.0, 650.0)
        cfg.max_hz = _num(d, "max_hz", w, cfg.base_hz, 0.0, 650.0)
        for key in ("ramp_up_s", "ramp_down_s", "off3_ramp_s"):
            setattr(cfg, key, _num(d, key, w, getattr(cfg, key), 0.0, 650.0))
        cfg.delay_us = int(round(_num(d, "response_delay_ms", w, 0.0, 0.0, 1000.0) * 1000))
        cfg.params = _params(d, w)
        ro = d.get("read_only", [])
        if not isinstance(ro, list) or any(isinstance(x, bool) or not isinstance(x, int)
                                           for x in ro):
            raise PlcConfigError(f"{w}.read_only must be a list of parameter numbers")
        cfg.read_only = frozenset(ro)
        bus.drives.append(cfg)
    return bus


class _Refused(Exception):
    def __init__(self, code: int) -> None:
        super().__init__(code)
        self.code = code


class Drive:
    """One simulated drive (see the module docstring).  Frequencies are
    exact fractions of Hz; ``frequency`` gives it as a float."""

    def __init__(self, cfg: DriveConfig) -> None:
        self.cfg = cfg
        self.address = cfg.address
        self.params = {k: (t, list(v) if isinstance(v, list) else v)
                       for k, (t, v) in cfg.params.items()}
        self.eeprom: dict[tuple[int, int], Any] = {}   #: (param, index) -> value written to EEPROM
        self.t = 0
        self.f = Fraction(0)          #: output frequency, Hz (positive: clockwise)
        self.sp = Fraction(0)         #: setpoint, Hz
        self.on = False               #: pulses enabled
        self.mode = ""                #: "run", "off1", "off3" or "" (off)
        self.inhibit = False          #: switch-on inhibit
        self.fault = 0                #: fault code (0: none)
        self.stw = 0                  #: the last control word taken
        self.telegrams = 0            #: telegrams answered

    # -- time
    def _ramp_s(self, key: str) -> float:
        for number, attr in _RAMPS.items():
            if attr == key and number in self.params and self.params[number][0] == "real":
                v = self.params[number][1]
                return max(0.0, float(v if not isinstance(v, list) else v[0]))
        return getattr(self.cfg, key)

    def _rate(self, key: str) -> Optional[Fraction]:
        """Hz per second of a ramp; None: at once."""
        s = self._ramp_s(key)
        return None if s <= 0 else Fraction(self.cfg.base_hz) / Fraction(s)

    def _target(self) -> Fraction:
        return self.sp if self.on and self.mode == "run" and not self.fault else Fraction(0)

    def advance(self, t: int) -> None:
        """Ramp the output frequency on to *t* (µs)."""
        dt = Fraction(t - self.t, 1_000_000)
        self.t = max(self.t, t)
        while dt > 0 and self.f != self._target():
            f, target = self.f, self._target()
            towards_zero = f != 0 and (target == 0 or (target > 0) != (f > 0)
                                       or abs(target) < abs(f))
            goal = target if not towards_zero or target == 0 or (target > 0) == (f > 0) \
                else Fraction(0)
            rate = self._rate("off3_ramp_s" if self.mode == "off3" else
                              "ramp_down_s" if towards_zero else "ramp_up_s")
            need = Fraction(0) if rate is None else abs(goal - f) / rate
            if need <= dt:
                self.f, dt = goal, dt - need
            else:
                self.f, dt = f + (rate * dt if goal > f else -rate * dt), Fraction(0)
        if self.f == 0 and self.mode in ("off1", "off3"):
            self.on, self.mode = False, ""

    @property
    def frequency(self) -> float:
        return float(self.f)

    def trip(self, code: int = 1) -> None:
        """A fault: the output coasts (pulses off at once) and the drive
        reports the fault until F_ACK (control word bit 7) acknowledges it."""
        self.fault = code
        self.on, self.mode, self.f, self.inhibit = False, "", Fraction(0), True

    # -- control word (System Manual, USS_CTRL; MicroMaster 4 r0054)
    def control(self, t: int, stw: int, hsw: int) -> None:
        """Take the control word and setpoint of a telegram received at *t*."""
        self.advance(t)
        if not stw & STW["plc_control"]:
            return                       # the drive is not controlled from the bus
        rising = stw & ~self.stw
        self.stw = stw
        if self.fault and rising & STW["fault_ack"]:
            self.fault = 0               # acknowledged; the inhibit stays until ON is 0
        # MicroMaster 4: a signed setpoint; MicroMaster 3: its magnitude
        v = hsw - 0x10000 if hsw & 0x8000 and self.cfg.model == "mm4" else hsw
        sp = Fraction(v * 1, FULL_SCALE) * Fraction(self.cfg.base_hz)
        if stw & STW["reverse"]:
            sp = -sp
        if not stw & STW["setpoint_enable"]:
            sp = Fraction(0)
        top = Fraction(self.cfg.max_hz)
        self.sp = max(-top, min(top, sp))
        if self.fault:
            return
        if not stw & STW["no_off2"] or not stw & STW["pulse_enable"]:
            # OFF2: pulses off, the motor coasts (the frequency is 0 at once)
            self.on, self.mode, self.f = False, "", Fraction(0)
            self.inhibit = self.inhibit or not stw & STW["no_off2"]
        elif not stw & STW["no_off3"]:
            if self.on:
                self.mode = "off3"       # fast stop on the OFF3 ramp
            self.inhibit = True
        elif stw & STW["on"]:
            if not self.inhibit:
                self.on, self.mode = True, "run"
        else:
            if self.on:
                self.mode = "off1"       # OFF1: down the ramp, then pulses off
            self.inhibit = False
        self.advance(t)

    def status(self) -> int:
        """The status word ZSW now (MicroMaster 4 r0052)."""
        z = ZSW["pzd_control"] | ZSW["no_current_limit"] | ZSW["no_motor_overload"] \
            | ZSW["no_inverter_overload"]
        if not self.fault:
            z |= ZSW["ready_on"]
        if self.on:
            z |= ZSW["ready_run"] | ZSW["running"]
        if self.fault:
            z |= ZSW["fault"]
        if self.stw & STW["no_off2"] or not self.stw & STW["plc_control"]:
            z |= ZSW["no_off2"]
        if self.stw & STW["no_off3"] or not self.stw & STW["plc_control"]:
            z |= ZSW["no_off3"]
        if self.inhibit:
            z |= ZSW["inhibit"]
        if self.on and self.mode == "run" and self.f == self.sp:
            z |= ZSW["at_setpoint"]
        if self.cfg.max_hz and abs(self.f) >= self.cfg.max_hz:
            z |= ZSW["at_max"]
        if self.f > 0 or (self.f == 0 and self.sp >= 0):
            z |= ZSW["clockwise"]
        return z

    def actual_word(self) -> int:
        """The actual frequency as HIW (16384 = base_hz), two's complement."""
        v = round(self.f * FULL_SCALE / Fraction(self.cfg.base_hz))
        if self.cfg.model == "mm3":
            v = abs(v)                   # the direction is the status word's bit 14
        v = max(-0x8000, min(0x7FFF, v))
        return v & 0xFFFF

    # -- parameters
    def _param(self, number: int) -> tuple[str, Any]:
        if number in self.params:
            return self.params[number]
        if number == _ACTUAL:
            return "real", bits_real(real_bits(float(self.f)))
        if number == _STATUS:
            return "word", self.status()
        raise _Refused(0)

    def answer(self, tel: Telegram) -> tuple[int, int]:
        """(response ID, PWE) of *tel*'s parameter task."""
        task = tel.task
        if task == TASK["none"]:
            return RESPONSE["none"], 0
        try:
            return self._task(task, tel.param, tel.ind & 0xFF, tel.pwe)
        except _Refused as e:
            return RESPONSE["error"], e.code

    def _task(self, task: int, number: int, index: int, pwe: int) -> tuple[int, int]:
        if task in _READS:
            typ, val = self._param(number)
            indexed = _READS[task]
        elif task in _WRITES:
            wtyp, indexed, eeprom = _WRITES[task]
            typ, val = self._param(number)
            if number in self.cfg.read_only or number in (_ACTUAL, _STATUS) \
                    and number not in self.params:
                raise _Refused(1)
            if (wtyp == "word") != (typ == "word"):
                raise _Refused(5)
        else:
            raise _Refused(106)
        if isinstance(val, list):
            if index >= len(val):
                raise _Refused(3)
        elif index:
            raise _Refused(3)
        if task in _WRITES:
            new: Any = pwe & 0xFFFF if typ == "word" else (
                bits_real(pwe) if typ == "real" else pwe & 0xFFFFFFFF)
            if isinstance(val, list):
                val[index] = new
            else:
                self.params[number] = (typ, new)
            if eeprom:
                self.eeprom[(number, index)] = new
            val = self.params[number][1]
        v = val[index] if isinstance(val, list) else val
        word = typ == "word"
        bits = v if typ != "real" else real_bits(v)
        resp = ("word" if word else "dword") + ("_index" if indexed else "")
        return RESPONSE[resp], bits & (0xFFFF if word else 0xFFFFFFFF)


class UssBus(PortPeer):
    """The drives of one port (see the module docstring)."""

    def __init__(self, cfg: BusConfig) -> None:
        self.baud = cfg.baud
        self.drives = {d.address: Drive(d) for d in cfg.drives}
        self.port: Any = None
        self.busy_until = 0
        self.telegrams: list[tuple[int, bytes]] = []   #: (time the telegram ended, bytes)
        self.answers: list[tuple[int, bytes]] = []     #: (time the answer starts, bytes)
        self.ignored = 0                               #: telegrams that got no answer
        self.corrupt = 0                               #: next answers sent with a wrong BCC
        self.bad_parity = 0                            #: next answers with a parity error

    def framing(self) -> Framing:
        """The drives' framing: 8 data bits, even parity, at their rate."""
        return Framing(self.baud or self.port.framing().baud, 8, "even", "freeport")

    def transmit(self, port: Any, t: int, fr: Any, data: bytes) -> None:
        """The CPU sends *data* from *t*: one telegram, taken at its last stop bit."""
        if not data:
            return
        mine = self.framing()
        garbled = (fr.baud, fr.data_bits, fr.parity) != (mine.baud, 8, mine.parity)
        port.push(fr.end(t, len(data)), self.take, bytes(data), garbled)

    def take(self, t: int, data: bytes, garbled: bool = False) -> None:
        """A telegram whose last stop bit ended at *t* (*garbled*: sent in
        another framing): the addressed drive answers, or nobody."""
        self.telegrams.append((t, data))
        tel, _ = decode(data)
        drive = self.drives.get(tel.address) if tel is not None else None
        if garbled or drive is None:
            self.ignored += 1           # bad framing, STX, LGE or BCC, or nobody there
            return
        drive.control(t, tel.stw, tel.hsw)
        resp, pwe = drive.answer(tel)
        drive.telegrams += 1
        out = encode(Telegram(drive.address, resp << 12 | tel.pke & 0x7FF, tel.ind, pwe,
                              drive.status(), drive.actual_word()))
        if self.corrupt:
            self.corrupt -= 1
            out = out[:-1] + bytes((out[-1] ^ 0xFF,))
        bad: frozenset[int] = frozenset()
        if self.bad_parity:
            self.bad_parity -= 1
            bad = frozenset((7,))        # one character of PWE arrives with a parity error
        fr = self.framing()
        start = max(t + drive.cfg.delay_us, self.busy_until)
        self.port.receive(start, fr, out, bad)
        self.answers.append((start, out))
        self.busy_until = fr.end(start, len(out))
