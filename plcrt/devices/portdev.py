"""What the plant puts at the CPU's communication ports and on its Ethernet.

Plant keys (TOML; every problem is a PlcConfigError naming the file and the
key; unknown keys are refused)::

    [port.0]
    address = 2              # this CPU's PPI station address (NETR/NETW), 0..126
    ppi_baud = 9600          # the PPI rate of the system block: 9600, 19200, 187500

    [[port.0.reply]]         # a scripted device: a request and its answer
    request = "01 03 00 00 00 02 C4 0B"   # exact bytes, hex
    reply = "01 03 04 00 2A 00 07 6B F6"
    delay_ms = 5             # from the request's last stop bit to the reply's start
    bad_parity = [2]         # reply bytes (0 = first) sent with a parity error

    [[port.0.send]]          # the device sends unasked
    at = 0.5                 # s after power-up
    data = "02 31 32 33 03"
    bad_parity = []

    [ethernet]
    ip = "192.168.2.10"      # this CPU's address for GET/PUT
    latency_ms = 1.0         # one way, request or answer

What it is: the parsing of these keys, and :class:`ScriptedDevice`, which
answers a port: the bytes of one transmission are taken in order, and
whenever the bytes since the last answer equal a request, the device sends
its reply (in the port's framing, *delay_ms* after that request's last stop
bit, and after anything it is still sending); bytes left over at the end of
a transmission went unanswered and are reported in ``plc.diagnostics``.
What it is not: no protocol: requests are exact bytes; a Modbus RTU
slave is ``[port.N.modbus_slave]`` (:mod:`plcrt.devices.modbus.slave`), a
Modbus RTU master ``[port.N.modbus_master]``
(:mod:`plcrt.devices.modbus.plantmaster`), USS drives ``[port.N.uss]``
(:mod:`plcrt.devices.uss.drive`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

from ..errors import PlcConfigError
from .keys import checked_table
from .peer import PortPeer

__all__ = ["PortConfig", "DeviceConfig", "EthernetConfig", "parse_ports", "parse_ethernet",
           "ScriptedDevice"]

#: the devices a port may have at its other end (one), by their plant keys
_DEVICE_KEYS = {"a scripted device (reply/send)": ("reply", "send"),
                "a Modbus slave (modbus_slave)": ("modbus_slave",),
                "a Modbus master (modbus_master)": ("modbus_master",),
                "USS drives (uss)": ("uss",)}
_PORT_KEYS = {"address", "ppi_baud"} | {k for keys in _DEVICE_KEYS.values() for k in keys}
_REPLY_KEYS = {"request", "reply", "delay_ms", "bad_parity"}
_SEND_KEYS = {"at", "data", "bad_parity"}
_ETH_KEYS = {"ip", "latency_ms"}
#: PPI rates of the system block (System Manual, "Configuring the port")
PPI_BAUDS = (9600, 19200, 187500)
_HEX_RE = re.compile(r"[0-9A-Fa-f]{2}")
_IP_RE = re.compile(r"(\d{1,3})\.(\d{1,3})\.(\d{1,3})\.(\d{1,3})")


@dataclass
class DeviceConfig:
    """A scripted device: (request, reply, delay µs, bad reply bytes) rows,
    and (time µs, data, bad bytes) messages it sends unasked."""

    replies: list[tuple[bytes, bytes, int, frozenset[int]]] = field(default_factory=list)
    sends: list[tuple[int, bytes, frozenset[int]]] = field(default_factory=list)


@dataclass
class PortConfig:
    number: int
    address: int = 2
    ppi_baud: int = 9600
    device: DeviceConfig | None = None
    modbus: Any = None   #: a Modbus RTU slave (plcrt.devices.modbus.slave.SlaveConfig)
    uss: Any = None      #: USS drives (plcrt.devices.uss.drive.BusConfig)
    #: a scripted Modbus RTU master (plcrt.devices.modbus.plantmaster.MasterConfig)
    modbus_master: Any = None
    where: str = field(default="", compare=False)


@dataclass
class EthernetConfig:
    ip: bytes
    latency_us: int = 1000


def _hex(v: Any, where: str, empty: bool = False) -> bytes:
    if not isinstance(v, str):
        raise PlcConfigError(f"{where} must be a string of hex bytes such as \"01 03 FF\"")
    text = v.replace(" ", "").replace(",", "")
    if len(text) % 2 or not all(_HEX_RE.fullmatch(text[i:i + 2]) for i in range(0, len(text), 2)):
        raise PlcConfigError(f"{where} must be hex bytes such as \"01 03 FF\", got "
                             f"{v[:40]!r}")
    data = bytes.fromhex(text)
    if not data and not empty:
        raise PlcConfigError(f"{where} is empty")
    if len(data) > 255:
        raise PlcConfigError(f"{where} holds {len(data)} bytes; a freeport message is at most "
                             f"255")
    return data


def _int(v: Any, where: str, lo: int, hi: int) -> int:
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise PlcConfigError(f"{where} must be a whole number in {lo}..{hi}, got {v!r:.40}")
    return v


def _seconds(v: Any, where: str, hi: float) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
            or not 0 <= v <= hi:
        raise PlcConfigError(f"{where} must be a number in 0..{hi:g}, got {v!r:.40}")
    return int(round(v * 1e6))


def _bad(v: Any, where: str, n: int) -> frozenset[int]:
    if not isinstance(v, list) or any(isinstance(k, bool) or not isinstance(k, int)
                                      or not 0 <= k < n for k in v):
        raise PlcConfigError(f"{where} must be a list of byte positions 0..{n - 1}")
    return frozenset(v)


def parse_ports(raw: Any, file: str) -> dict[int, PortConfig]:
    """``[port.N]`` tables."""
    if not isinstance(raw, dict):
        raise PlcConfigError(f"{file}: [port] must be a table of ports ([port.0], [port.1])")
    out: dict[int, PortConfig] = {}
    for key, p in raw.items():
        where = f"{file}: port.{key}"
        if str(key) not in ("0", "1"):
            raise PlcConfigError(f"{where}: the CPU has ports 0 and 1")
        p = checked_table(p, where, _PORT_KEYS)
        cfg = PortConfig(int(key), where=where)
        cfg.address = _int(p.get("address", 2), f"{where}.address", 0, 126)
        cfg.ppi_baud = p.get("ppi_baud", 9600)
        if cfg.ppi_baud not in PPI_BAUDS or isinstance(cfg.ppi_baud, bool):
            raise PlcConfigError(f"{where}.ppi_baud must be one of "
                                 f"{', '.join(map(str, PPI_BAUDS))}, got {cfg.ppi_baud!r:.40}")
        # one device per port: what the plant puts at its other end
        present = [name for name, keys in _DEVICE_KEYS.items() if any(k in p for k in keys)]
        if len(present) > 1:
            raise PlcConfigError(f"{where}: the port has {' and '.join(present)}; "
                                 f"one device per port")
        if "reply" in p or "send" in p:
            cfg.device = _device(p, where)
        if "modbus_slave" in p:
            from .modbus.slave import parse_slave
            cfg.modbus = parse_slave(p["modbus_slave"], f"{where}.modbus_slave")
        if "modbus_master" in p:
            from .modbus.plantmaster import parse_master
            cfg.modbus_master = parse_master(p["modbus_master"], f"{where}.modbus_master")
        if "uss" in p:
            from .uss.drive import parse_uss
            cfg.uss = parse_uss(p["uss"], f"{where}.uss")
        out[int(key)] = cfg
    return out


def _device(p: dict, where: str) -> DeviceConfig:
    dev = DeviceConfig()
    replies, sends = p.get("reply", []), p.get("send", [])
    for name, rows in (("reply", replies), ("send", sends)):
        if not isinstance(rows, list):
            raise PlcConfigError(f"{where}.{name} must be an array of tables "
                                 f"([[{where.split(': ')[-1]}.{name}]])")
    for i, r in enumerate(replies):
        rw = f"{where}.reply[{i}]"
        r = checked_table(r, rw, _REPLY_KEYS, ("request", "reply"))
        req = _hex(r["request"], f"{rw}.request")
        rep = _hex(r["reply"], f"{rw}.reply")
        if any(req == x[0] for x in dev.replies):
            raise PlcConfigError(f"{rw}.request: the same request is already answered above")
        dev.replies.append((req, rep, _seconds(r.get("delay_ms", 0), f"{rw}.delay_ms",
                                               60_000) // 1000,
                            _bad(r.get("bad_parity", []), f"{rw}.bad_parity", len(rep))))
    for i, s in enumerate(sends):
        sw = f"{where}.send[{i}]"
        s = checked_table(s, sw, _SEND_KEYS, ("at", "data"))
        data = _hex(s["data"], f"{sw}.data", empty=True)
        dev.sends.append((_seconds(s["at"], f"{sw}.at", 1e6), data,
                          _bad(s.get("bad_parity", []), f"{sw}.bad_parity", max(len(data), 1))))
    dev.sends.sort(key=lambda x: x[0])
    return dev


def parse_ethernet(raw: Any, file: str) -> EthernetConfig:
    """``[ethernet]``: ip, latency_ms."""
    where = f"{file}: ethernet"
    raw = checked_table(raw, where, _ETH_KEYS, ("ip",))
    m = _IP_RE.fullmatch(str(raw["ip"]))
    if not isinstance(raw["ip"], str) or m is None or any(int(x) > 255 for x in m.groups()):
        raise PlcConfigError(f"{where}.ip must be an IPv4 address such as \"192.168.2.1\", "
                             f"got {str(raw['ip'])[:40]!r}")
    ip = bytes(int(x) for x in m.groups())
    if ip[0] in (0, 127) or ip[0] >= 224 or ip[3] in (0, 255):
        raise PlcConfigError(f"{where}.ip {raw['ip']} is not an address a CPU can have")
    latency = _seconds(raw.get("latency_ms", 1.0), f"{where}.latency_ms", 10_000) // 1000
    if latency < 2:
        raise PlcConfigError(f"{where}.latency_ms must be at least 0.002 (2 µs)")
    return EthernetConfig(ip, latency)


class ScriptedDevice(PortPeer):
    """The device of one port (see the module docstring)."""

    def __init__(self, cfg: DeviceConfig) -> None:
        self.cfg = cfg
        self.busy_until = 0          #: when what it sends ends
        self.port: Any = None
        self.answered = 0            #: requests answered

    def attach(self, port: Any) -> None:
        """Become *port*'s peer; schedule what is sent unasked."""
        super().attach(port)
        for k, (at, _, _) in enumerate(self.cfg.sends):
            port.push(at, self._send, k)

    def _send(self, t: int, k: int) -> None:
        _, data, bad = self.cfg.sends[k]
        self._emit(t, data, bad)

    def _reply(self, t: int, k: int) -> None:
        _, data, _, bad = self.cfg.replies[k]
        self._emit(t, data, bad)

    def _emit(self, t: int, data: bytes, bad: frozenset[int]) -> None:
        # the device speaks the port's framing (docs/decisions.md)
        fr = self.port.framing()
        start = max(t, self.busy_until)
        self.port.receive(start, fr, data, bad)
        self.busy_until = fr.end(start, len(data)) if data else fr.end(start, 0, bits=16)

    def transmit(self, port: Any, t: int, fr: Any, data: bytes) -> None:
        """*port* sends *data* from *t* (a break when empty)."""
        pending = b""
        for k, byte in enumerate(data):
            pending += bytes((byte,))
            for i, (req, _, delay, _) in enumerate(self.cfg.replies):
                if pending == req:
                    port.push(fr.end(t, k + 1) + delay, self._reply, i)
                    self.answered += 1
                    pending = b""
                    break
        if pending:
            port.no_answer(fr.end(t, len(data)), pending,
                           "the plant's device has no reply for them")
