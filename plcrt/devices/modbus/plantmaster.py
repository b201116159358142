"""A scripted Modbus RTU master at a CPU port, from the plant file: it asks
the CPU's Modbus slave library (MBUS_INIT / MBUS_SLAVE) or any slave
program, and records what comes back.

Plant keys (every problem a PlcConfigError naming the file and key)::

    [port.0.modbus_master]
    timeout_ms = 100              # no answer this long after the request's end: a timeout
    baud = 9600                   # optional: the master's own rate and parity ("none",
    parity = "even"               # "even", "odd"); without them it follows the port's

    [[port.0.modbus_master.request]]
    at_ms = 10                    # first sent this long after power-up
    slave = 1                     # 0 (broadcast: writes only) .. 247
    function = 3                  # 1..127
    address = 0                   # the Modbus data address 0..65535 (40001 is 0)
    count = 2                     # reads (and unknown functions): how many
    values = [7, 8]               # writes: 5 one 0/1, 6 one word, 15 bits, 16 words
    period_ms = 100               # optional: again every period_ms ...
    repeat = 5                    # ... this many times in all (default 1; with a
                                  # period: no end)
    # raw = "01 03 00 00 00 01 84 0A"   instead of slave..values: exact bytes, no CRC added

What it is: :class:`PlantMaster`, the port's peer.  One request at a time:
a request due while another waits for its answer goes when that one has
ended.  A response has ended when the line stays quiet for 3.5 characters
(Modbus over Serial Line 2.5.1.1); a broadcast has ended with its own
gap.  ``responses`` records each request's times (µs: ``sent``,
``sent_end``, ``first_char``, ``last_char``, ``finished``) and outcome:
``values`` (reads), ``exception`` (its code), ``timeout``, or ``error``
("crc", "slave", "function", "length", "echo", "garbled"), with the bytes
received; ``unasked`` the bytes the CPU sent while no answer was awaited
(time of the last stop bit, bytes).  What it is not: no retries, no diagnostics functions, no ASCII.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

from ...engine.serial import Framing
from ...errors import PlcConfigError
from ..keys import checked_table
from ..peer import PortPeer, baud_key, parity_key
from .rtu import check_crc, frame, gap_us, pack_bits, unpack_bits

__all__ = ["MasterConfig", "MasterRequest", "parse_master", "PlantMaster"]

_KEYS = {"timeout_ms", "baud", "parity", "request"}
_REQ_KEYS = {"at_ms", "slave", "function", "address", "count", "values", "period_ms", "repeat",
             "raw"}
#: function -> (values: how many (None: a list 1..n), largest value)
_WRITE = {5: (1, 1), 6: (1, 0xFFFF), 15: (1968, 1), 16: (123, 0xFFFF)}


@dataclass
class MasterRequest:
    at_us: int
    frame: bytes
    slave: int
    function: int
    address: int = 0
    count: int = 0
    period_us: int = 0
    repeat: int = 1          #: 0: no end


@dataclass
class MasterConfig:
    timeout_us: int = 1_000_000
    baud: Optional[int] = None
    parity: Optional[str] = None
    requests: list[MasterRequest] = field(default_factory=list)


def _int(v: Any, where: str, lo: int, hi: int) -> int:
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise PlcConfigError(f"{where} must be a whole number in {lo}..{hi}, got {v!r:.40}")
    return v


def _ms(v: Any, where: str, lo: float = 0) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not lo <= v <= 1e9:
        raise PlcConfigError(f"{where} must be a number of ms in {lo:g}..1e9, got {v!r:.40}")
    return int(round(v * 1000))


def parse_master(raw: Any, where: str) -> MasterConfig:
    """``[port.N.modbus_master]`` with its ``[[...request]]`` tables."""
    raw = checked_table(raw, where, _KEYS, ("request",))
    cfg = MasterConfig()
    cfg.timeout_us = _ms(raw.get("timeout_ms", 1000), f"{where}.timeout_ms", 1)
    cfg.baud, cfg.parity = baud_key(raw, where), parity_key(raw, where)
    rows = raw["request"]
    if not isinstance(rows, list) or not rows:
        raise PlcConfigError(f"{where}.request must be an array of tables "
                             f"([[{where.split(': ')[-1]}.request]])")
    for i, r in enumerate(rows):
        cfg.requests.append(_request(r, f"{where}.request[{i}]"))
    return cfg


def _request(r: Any, rw: str) -> MasterRequest:
    r = checked_table(r, rw, _REQ_KEYS, ("at_ms",))
    at = _ms(r["at_ms"], f"{rw}.at_ms")
    period = _ms(r["period_ms"], f"{rw}.period_ms", 1) if "period_ms" in r else 0
    repeat = _int(r.get("repeat", 0 if period else 1), f"{rw}.repeat", 0 if period else 1,
                  10**9)
    if "raw" in r:
        extra = set(r) & {"slave", "function", "address", "count", "values"}
        if extra:
            raise PlcConfigError(f"{rw}: raw gives the exact bytes; {', '.join(sorted(extra))} "
                                 f"cannot go with it")
        text = r["raw"]
        try:
            data = bytes.fromhex(text.replace(",", " ")) if isinstance(text, str) else b""
        except ValueError:
            data = b""
        if not 1 <= len(data) <= 256:
            raise PlcConfigError(f"{rw}.raw must be 1..256 hex bytes such as \"01 03 00\"")
        return MasterRequest(at, data, data[0], data[1] if len(data) > 1 else 0,
                             period_us=period, repeat=repeat)
    for key in ("slave", "function", "address"):
        if key not in r:
            raise PlcConfigError(f"{rw}: {key} is missing")
    slave = _int(r["slave"], f"{rw}.slave", 0, 247)
    fn = _int(r["function"], f"{rw}.function", 1, 127)
    addr = _int(r["address"], f"{rw}.address", 0, 0xFFFF)
    head = bytes((slave, fn)) + addr.to_bytes(2, "big")
    if fn in _WRITE:
        most, top = _WRITE[fn]
        vals = r.get("values")
        if "count" in r or not isinstance(vals, list) or not 1 <= len(vals) <= most or any(
                isinstance(v, bool) and top != 1 or not isinstance(v, int)
                or not 0 <= int(v) <= top for v in vals):
            raise PlcConfigError(f"{rw}.values: function {fn} writes a list of 1..{most} "
                                 f"value(s) 0..{top} (and takes no count)")
        vals = [int(v) for v in vals]
        if fn == 5:
            body = head + (b"\xff\x00" if vals[0] else b"\x00\x00")
        elif fn == 6:
            body = head + vals[0].to_bytes(2, "big")
        elif fn == 15:
            data = pack_bits(vals)
            body = head + len(vals).to_bytes(2, "big") + bytes((len(data),)) + data
        else:
            data = b"".join(v.to_bytes(2, "big") for v in vals)
            body = head + len(vals).to_bytes(2, "big") + bytes((len(data),)) + data
        count = len(vals)
    else:
        if "values" in r:
            raise PlcConfigError(f"{rw}.values: function {fn} writes nothing (count says how "
                                 f"many to read)")
        if "count" not in r:
            raise PlcConfigError(f"{rw}: count is missing")
        count = _int(r["count"], f"{rw}.count", 0, 0xFFFF)
        body = head + count.to_bytes(2, "big")
        if slave == 0:
            raise PlcConfigError(f"{rw}.slave: 0 (broadcast) is for writes (5, 6, 15, 16) only")
    return MasterRequest(at, frame(body), slave, fn, addr, count, period, repeat)


class PlantMaster(PortPeer):
    """The master of one port (see the module docstring)."""

    def __init__(self, cfg: MasterConfig) -> None:
        self.cfg = cfg
        self.port: Any = None
        self.queue: list[int] = []             #: requests due, waiting for the line
        self.current: Optional[dict[str, Any]] = None
        self.rx = bytearray()
        self.garbled = False
        self.gen = 0
        self.responses: list[dict[str, Any]] = []
        self.unasked: list[tuple[int, bytes]] = []   #: (time, bytes) with no request out

    def attach(self, port: Any) -> None:
        super().attach(port)
        for k, req in enumerate(self.cfg.requests):
            port.push(req.at_us, self._due, k, 1)

    def framing(self) -> Framing:
        fr = self.port.framing()
        return Framing(self.cfg.baud or fr.baud, 8, self.cfg.parity or fr.parity, "freeport")

    def _due(self, t: int, k: int, n: int) -> None:
        req = self.cfg.requests[k]
        if req.period_us and (req.repeat == 0 or n < req.repeat):
            self.port.push(t + req.period_us, self._due, k, n + 1)
        self.queue.append(k)
        if self.current is None:
            self._send(t)

    def _send(self, t: int) -> None:
        req = self.cfg.requests[self.queue.pop(0)]
        fr = self.framing()
        end = fr.end(t, len(req.frame))
        self.current = cur = {"slave": req.slave, "function": req.function,
                              "address": req.address, "count": req.count, "sent": t,
                              "sent_end": end, "frame": req.frame, "values": None,
                              "exception": None, "timeout": False, "error": None,
                              "response": b""}
        self.rx, self.garbled = bytearray(), False
        self.port.receive(t, fr, req.frame)
        if req.slave == 0:
            self.port.push(end + gap_us(fr.bits, fr.baud), self._finish, cur)
        else:
            self.port.push(end + self.cfg.timeout_us, self._timeout, cur)

    def transmit(self, port: Any, t: int, fr: Any, data: bytes) -> None:
        """The CPU sends *data* from *t*: characters of the response."""
        if not data:
            return
        cur = self.current
        if cur is None or cur["slave"] == 0:
            self.unasked.append((fr.end(t, len(data)), data))
            return
        mine = self.framing()
        self.garbled |= (fr.baud, fr.data_bits, fr.parity) != (mine.baud, 8, mine.parity)
        if not self.rx:
            cur["first_char"] = fr.end(t, 1)
        self.rx += data
        last = fr.end(t, len(data))
        cur["last_char"] = last
        self.gen += 1
        port.push(last + gap_us(mine.bits, mine.baud), self._gap, cur, self.gen)

    def _timeout(self, t: int, cur: dict[str, Any]) -> None:
        if cur is self.current and not self.rx:
            cur["timeout"] = True
            self._finish(t, cur)

    def _gap(self, t: int, cur: dict[str, Any], gen: int) -> None:
        if cur is self.current and gen == self.gen:
            self._check(cur, bytes(self.rx))
            self._finish(t, cur)

    def _check(self, cur: dict[str, Any], r: bytes) -> None:
        cur["response"] = r
        fn = cur["function"]
        if self.garbled:
            cur["error"] = "garbled"
        elif not check_crc(r):
            cur["error"] = "crc"
        elif r[0] != cur["slave"]:
            cur["error"] = "slave"
        elif r[1] == fn | 0x80 and len(r) == 5:
            cur["exception"] = r[2]
        elif r[1] != fn:
            cur["error"] = "function"
        elif fn in (1, 2, 3, 4):
            n = (cur["count"] + 7) // 8 if fn < 3 else 2 * cur["count"]
            if len(r) != 5 + n or r[2] != n:
                cur["error"] = "length"
            elif fn < 3:
                cur["values"] = unpack_bits(r[3:3 + n], cur["count"])
            else:
                cur["values"] = [r[3 + 2 * i] << 8 | r[4 + 2 * i] for i in range(cur["count"])]
        elif fn in _WRITE and r[2:6] != cur["frame"][2:6]:
            cur["error"] = "echo"

    def _finish(self, t: int, cur: dict[str, Any]) -> None:
        if cur is not self.current:
            return
        cur["finished"] = t
        self.responses.append(cur)
        self.current = None
        if self.queue:
            self._send(t)
