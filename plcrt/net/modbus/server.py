"""The Modbus TCP server of a served PLC: MBAP framing over the shared
TCP plumbing (:class:`plcrt.net.tcp.TcpService`), each request run at a
scan boundary through the door.

MBAP (Modbus Messaging on TCP/IP Implementation Guide V1.0b, 3.1.3): a
7-byte header — transaction id, protocol id (0), length (the bytes that
follow: unit id and PDU), unit id — then the PDU.  Bounded:

- a length below 2 or above 254 (a PDU of at most 253 bytes) cannot be
  framed: the connection is closed (counted ``bad_frames``);
- a frame whose protocol id is not 0 is read and dropped without an
  answer (the guide: not a Modbus frame), the connection stays;
- a frame cut short ends when the client closes or stays silent past the
  idle timeout: that connection is closed;
- one request per connection is in flight; the answer is written before
  the next request is read, and a client that does not read its answers
  is closed after the idle timeout.

Every unit id is answered (a server that is not a gateway; the guide
recommends 0xFF, clients send 0 or 1 as well).  The door full is
exception 6 (server busy); the door closed ends the connection.

What it is: the framing and the session.  What it is not: the functions
(:mod:`.pdu`) or the map (:mod:`.addrmap`).
"""

from __future__ import annotations

import asyncio
import logging
import struct
from dataclasses import dataclass, fields
from typing import Any

from ...devices.modbus.slavelib import slave_of
from ...engine.runtime import Plc
from ..door import DoorBusy, DoorClosed, ScanDoor
from ..options import ServerOptions
from ..tcp import ClosedByPeer, TcpService
from .addrmap import DEFAULTS, AddressMap, library_map, load_map
from .pdu import ModbusException, Refused, Request, execute, parse

__all__ = ["ModbusOptions", "ModbusService", "create", "with_map"]

log = logging.getLogger("plcrt.net")

_HEAD = struct.Struct(">HHHB")
#: the MBAP length field's bounds: unit id + function at least, unit id +
#: a 253-byte PDU at most
MIN_LENGTH, MAX_LENGTH = 2, 254
#: exception for a full door (Modbus Application Protocol 7: server busy)
BUSY = 6
#: exception for a job that failed in the PLC's thread (server failure)
FAILURE = 4
#: library maps kept per parameter set
_CACHE = 16


@dataclass(frozen=True)
class ModbusOptions(ServerOptions):
    """A Modbus server's options: the common ones and a custom address
    ``map`` (a TOML file, a dict or an :class:`AddressMap`; None: the
    slave library's map)."""

    map: Any = None


def with_map(options: ServerOptions, amap: Any) -> ModbusOptions:
    """``options`` with a custom address map."""
    common = {f.name: getattr(options, f.name) for f in fields(ServerOptions)}
    return ModbusOptions(**common, map=amap)


class ModbusService(TcpService):
    """Modbus TCP on one address for one PLC (see the module doc).

    Args:
        door: the PLC's door.
        options: address, limits, the write guard.
        amap: a custom map (None: the slave library's map, with the
            program's MBUS_INIT parameters once they ran, else
            :data:`~plcrt.net.modbus.addrmap.DEFAULTS`).
    """

    name = "Modbus TCP"

    def __init__(self, door: ScanDoor, options: ServerOptions,
                 amap: AddressMap | None = None) -> None:
        super().__init__(door, options)
        self.map = amap
        #: library maps by parameters (used in the PLC's thread only)
        self._maps: dict[tuple[int, int, int, int], AddressMap] = {}

    # -- the PLC's side (door jobs) -------------------------------------------
    def map_of(self, plc: Plc) -> tuple[AddressMap, bool]:
        """The map requests use now and whether it is the library's (run
        in the PLC's thread)."""
        if self.map is not None:
            return self.map, False
        lib = slave_of(plc)
        params = (lib.max_iq, lib.max_ai, lib.max_hold, lib.hold) if lib.enabled \
            else DEFAULTS
        m = self._maps.get(params)
        if m is None:
            if len(self._maps) >= _CACHE:
                self._maps.clear()
            m = self._maps[params] = library_map(plc.mem.areas, params)
        return m, True

    def _job(self, req: Request) -> Any:
        guard = self.options.guard

        def job(plc: Plc) -> bytes:
            amap, library = self.map_of(plc)
            return execute(plc.mem.areas, amap, req, guard, library)
        return job

    # -- the client's side ----------------------------------------------------
    async def answer(self, pdu: bytes, peer: str = "") -> bytes:
        """The response PDU of the request PDU ``pdu`` (asks the PLC at
        the next scan boundary when the request is well formed).

        Raises:
            ClosedByPeer: the PLC is not served any more.
        """
        try:
            req = parse(pdu)
            return await self.ask(self._job(req))
        except Refused as e:
            self.stats["refused_writes"] += 1
            if self.stats["refused_writes"] <= 20 or not self.stats["refused_writes"] % 1000:
                log.warning("Modbus TCP: write of function %d refused (%s; read-only or not "
                            "in the allow-list)%s", pdu[0], e.what,
                            f" from {peer}" if peer else "")
            return bytes((pdu[0] | 0x80, e.code))
        except ModbusException as e:
            self.stats["exceptions"] += 1
            return bytes(((pdu[0] if pdu else 0) | 0x80, e.code))
        except DoorBusy:
            self.stats["busy"] += 1
            return bytes((pdu[0] | 0x80, BUSY))
        except DoorClosed:
            raise ClosedByPeer() from None

    async def session(self, reader: asyncio.StreamReader,
                      writer: asyncio.StreamWriter) -> None:
        peer = writer.get_extra_info("peername")
        who = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) and len(peer) >= 2 else ""
        timeout = self.options.idle_timeout or None
        while True:
            head = await self.read_exactly(reader, _HEAD.size, first=True)
            tid, proto, length, unit = _HEAD.unpack(head)
            if not MIN_LENGTH <= length <= MAX_LENGTH:
                self.stats["bad_frames"] += 1
                return                           # no framing to trust: close
            pdu = await self.read_exactly(reader, length - 1)
            if proto != 0:
                self.stats["bad_frames"] += 1
                continue                         # not Modbus: dropped
            self.stats["requests"] += 1
            out = await self.answer(pdu, who)
            writer.write(_HEAD.pack(tid, 0, len(out) + 1, unit) + out)
            try:
                await asyncio.wait_for(writer.drain(), timeout)
            except asyncio.TimeoutError:
                self.stats["slow_readers"] += 1
                return


def create(door: ScanDoor, plc: Plc, options: ServerOptions) -> ModbusService:
    """The factory :data:`plcrt.net.host.SERVICES` holds: a custom map of
    :class:`ModbusOptions` is read and checked against ``plc``'s areas here
    (before any client connects)."""
    amap = getattr(options, "map", None)
    return ModbusService(door, options,
                         load_map(amap, plc.mem.areas) if amap is not None else None)
