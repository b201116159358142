"""A Modbus RTU slave at a CPU port, from the plant file.

Plant keys (every problem a PlcConfigError naming the file and key)::

    [port.0.modbus_slave]
    address = 1                   # slave address 1..247
    delay_ms = 5                  # from the request's end (its 3.5-character gap) to the answer
    baud = 9600                   # optional: the slave's own rate and parity ("none", "even",
    parity = "even"               # "odd"); without them it follows the port's setting
    coils = [1, 0, 1]             # 00001.. : Modbus address 0..  (0/1 or true/false)
    discrete_inputs = [0, 1]      # 10001..
    input_registers = [100, 200]  # 30001..   0..65535
    holding_registers = [1, 2, 3] # 40001..   0..65535

A table's length is how many addresses the slave has; an address past it
is exception 2.  What it is: :class:`ModbusSlave`, the port's peer; each
transmission of the CPU is one frame; the slave knows it has ended after
the 3.5-character gap (Modbus over Serial Line 2.5.1.1), waits *delay_ms*
and answers in the port's framing: functions 1, 2, 3, 4, 5, 6, 15, 16;
exception 1 for any other function, 2 for an address outside its tables,
3 for a bad count or coil value; a frame with a bad CRC, for another
slave or sent at another rate or parity than the slave's own gets no
answer; address 0 (broadcast) runs
a write and gets no answer.  Tests read and write its tables (``coils``,
``inputs``, ``input_registers``, ``holding``; lists).  What it is not: no
diagnostics functions (8, 11, 12, 17), no Modbus ASCII.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

from ...engine.serial import Framing
from ...errors import PlcConfigError
from ..keys import checked_table
from ..peer import PortPeer, baud_key, parity_key
from .rtu import check_crc, frame, gap_us, serve

__all__ = ["SlaveConfig", "parse_slave", "ModbusSlave"]

_KEYS = {"address", "delay_ms", "coils", "discrete_inputs", "input_registers",
         "holding_registers", "baud", "parity"}
#: plant key -> (table attribute, largest value)
_TABLES = {"coils": ("coils", 1), "discrete_inputs": ("inputs", 1),
           "input_registers": ("input_registers", 0xFFFF),
           "holding_registers": ("holding", 0xFFFF)}


@dataclass
class SlaveConfig:
    address: int = 1
    delay_us: int = 0
    baud: Optional[int] = None       #: None: the port's setting
    parity: Optional[str] = None
    tables: dict[str, list[int]] = field(default_factory=dict)


def parse_slave(raw: Any, where: str) -> SlaveConfig:
    """``[port.N.modbus_slave]``."""
    raw = checked_table(raw, where, _KEYS)
    cfg = SlaveConfig()
    a = raw.get("address", 1)
    if isinstance(a, bool) or not isinstance(a, int) or not 1 <= a <= 247:
        raise PlcConfigError(f"{where}.address must be a slave address 1..247, got {a!r:.40}")
    cfg.address = a
    d = raw.get("delay_ms", 0)
    if isinstance(d, bool) or not isinstance(d, (int, float)) or not 0 <= d <= 60_000:
        raise PlcConfigError(f"{where}.delay_ms must be a number in 0..60000, got {d!r:.40}")
    cfg.delay_us = int(round(d * 1000))
    cfg.baud, cfg.parity = baud_key(raw, where), parity_key(raw, where)
    for key, (attr, top) in _TABLES.items():
        v = raw.get(key, [])
        if not isinstance(v, list) or len(v) > 65536 or any(
                not isinstance(x, int) or not 0 <= int(x) <= top for x in v):
            raise PlcConfigError(f"{where}.{key} must be a list of at most 65536 values "
                                 f"0..{top}")
        cfg.tables[attr] = [int(x) for x in v]
    return cfg


class ModbusSlave(PortPeer):
    """The slave of one port (see the module docstring)."""

    def __init__(self, cfg: SlaveConfig) -> None:
        self.address = cfg.address
        self.delay_us = cfg.delay_us
        self.baud, self.parity = cfg.baud, cfg.parity
        self.coils = list(cfg.tables["coils"])
        self.inputs = list(cfg.tables["inputs"])
        self.input_registers = list(cfg.tables["input_registers"])
        self.holding = list(cfg.tables["holding"])
        self.port: Any = None
        self.busy_until = 0
        self.requests: list[tuple[int, bytes]] = []   #: (time the frame ended, frame)
        self.ignored = 0                              #: frames that got no answer

    def framing(self) -> Framing:
        """The slave's framing: its own baud and parity, else the port's."""
        fr = self.port.framing()
        return Framing(self.baud or fr.baud, 8, self.parity or fr.parity, "freeport")

    def transmit(self, port: Any, t: int, fr: Any, data: bytes) -> None:
        """The CPU sends *data* from *t*: one frame, known ended after the gap."""
        if not data:
            return
        t_end = fr.end(t, len(data)) + gap_us(fr.bits, fr.baud)
        mine = self.framing()
        garbled = (fr.baud, fr.data_bits, fr.parity) != (mine.baud, 8, mine.parity)
        port.push(t_end, self._frame, data, garbled)

    def _frame(self, t: int, data: bytes, garbled: bool = False) -> None:
        self.requests.append((t, data))
        # another rate or format garbles every character: no answer
        if garbled or not check_crc(data) or data[0] not in (0, self.address):
            self.ignored += 1
            return
        body = self.answer(data[1], data[2:-2])
        if data[0] == 0:
            return                       # broadcast: executed, never answered
        fr = self.framing()
        out = frame(bytes((self.address,)) + body)
        start = max(t + self.delay_us, self.busy_until)
        self.port.receive(start, fr, out)
        self.busy_until = fr.end(start, len(out))

    def answer(self, fn: int, pdu: bytes) -> bytes:
        """The response PDU (function and data, or exception) of a request."""
        return serve(fn, pdu, self)

    # -- the tables (rtu.Tables), lists of the plant file's values
    def size(self, kind: str) -> int:
        return len(getattr(self, kind))

    def get(self, kind: str, start: int, count: int) -> list[int]:
        return getattr(self, kind)[start:start + count]

    def put(self, kind: str, start: int, values: list[int]) -> None:
        getattr(self, kind)[start:start + len(values)] = values
