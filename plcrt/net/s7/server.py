"""The S7 server: a running PLC answers S7 clients (HMIs, SCADA, client
libraries) as an S7-200 SMART CPU does, on ISO-on-TCP.

One connection: a COTP CR (its called TSAP's type — PG, HMI/OP or basic —
counts against that type's limit; beyond it the request is refused with
a COTP DR), then S7 PDUs: setup communication (the PDU size is the
smaller of the asked one and the identity's), read var and write var
(up to 20 items), PLC stop (0x29) and the PI service ``P_PROGRAM``
(0x28, start) wired to :meth:`plcrt.engine.scan.ScanLoop.set_mode`, and
the SZL reads of user data group 4.  Reads and writes run as door jobs
(:mod:`plcrt.net.door`), so a read sees one scan boundary's image and a
write lands at the next boundary; nothing here touches the PLC.

A frame that is not ISO-on-TCP or S7 closes its connection; a malformed
parameter section is answered with the S7 header error 0x8500; an item
the CPU does not have gets its return code (:mod:`.areas`).

What it is: the connection's life and the dispatch of requests.  What it
is not: the frames (:mod:`.iso`, :mod:`.pdu`), the areas and the SZL
(:mod:`.areas`, :mod:`.szl`), the TCP plumbing (:mod:`plcrt.net.tcp`).
"""

from __future__ import annotations

import asyncio
import struct
from collections import Counter
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field
from typing import Any

from ...errors import PlcConfigError
from ..door import DoorBusy, DoorClosed, ScanDoor
from ..options import ServerOptions
from ..tcp import ClosedByPeer, TcpService
from .areas import RC, Loc, check_write, locate, read_job, reply_item, write_job
from .iso import DR, DT, MAX_TPDU_CODE, FrameError, build_cc, build_dr, build_dt, \
    connection_type, parse_cotp, parse_tpkt_header
from .pdu import ERR, FN, USERDATA, Header, ack, parse_header, parse_items, \
    parse_write_data, userdata_answer
from .szl import S7Identity, szl_answer

__all__ = ["S7Options", "S7Server", "make_s7"]

#: longest S7 PDU reassembled from COTP DT segments
MAX_PDU = 1024
#: smallest PDU size negotiated (a client asking less gets this)
MIN_PDU = 64
#: COTP DR reason for a refused connection: congestion at connect time
REFUSED = 0x81
#: seconds an answer may take to leave before the connection is given up
SEND_TIMEOUT = 10.0


@dataclass(frozen=True)
class S7Options(ServerOptions):
    """:class:`~plcrt.net.options.ServerOptions` and the identity the S7
    server answers with (its SZL, PDU size and connection resources)."""

    identity: S7Identity = field(default_factory=S7Identity)


class _Refuse(Exception):
    """A request answered with an S7 header error word."""

    def __init__(self, error: int) -> None:
        super().__init__(error)
        self.error = error


@dataclass
class _Conn:
    pdu: int
    tpdu: int = 0x7FFF       # the S7 PDU size the TPDU size allows
    pending: bytes = b""      # the rest of an SZL answer longer than a PDU
    seq: int = 0


Handler = Callable[["S7Server", _Conn, Header], Awaitable[bytes]]


class S7Server(TcpService):
    """S7 on ISO-on-TCP for one served PLC (see the module doc).

    Args:
        door: the PLC's door.
        plc: the PLC, read here only for its static sizes.
        options: address, limits, write guard; an :class:`S7Options` also
            gives the identity.
    """

    name = "S7"

    def __init__(self, door: ScanDoor, plc: Any, options: ServerOptions) -> None:
        super().__init__(door, options)
        self.identity = getattr(options, "identity", None) or S7Identity()
        self.sizes = {k: len(v) for k, v in plc.mem.areas.items()}
        self.sm_readonly = plc.model.sm_readonly
        self.by_type: Counter[str] = Counter()
        self._refs = 0

    # -- the connection --------------------------------------------------
    async def session(self, reader: asyncio.StreamReader,
                      writer: asyncio.StreamWriter) -> None:
        req = parse_cotp(await self._frame(reader, True)).request
        if req is None:
            raise FrameError("a connection starts with a COTP connection request")
        self._refs = self._refs % 0xFFFF + 1
        ctype = connection_type(req.called)
        if self.by_type[ctype] >= self.identity.connections[ctype]:
            self.stats[f"refused_{ctype}"] += 1
            writer.write(build_dr(req, self._refs, REFUSED))
            await self._drain(writer)
            return
        self.by_type[ctype] += 1
        try:
            writer.write(build_cc(req, self._refs))
            await self._drain(writer)
            # an S7 PDU travels in one TPDU: the negotiated TPDU size (its 3
            # header bytes off) bounds the PDU size setup may answer
            tpdu = 1 << min(max(req.tpdu_code, 7), MAX_TPDU_CODE)
            conn = _Conn(min(self.identity.pdu_size, tpdu - 3), tpdu - 3)
            while True:
                pdu = await self._pdu(reader)
                if pdu is None:
                    return
                writer.write(build_dt(await self._answer(conn, pdu)))
                await self._drain(writer)
                self.stats["requests"] += 1
        finally:
            self.by_type[ctype] -= 1

    async def _drain(self, writer: asyncio.StreamWriter) -> None:
        try:
            await asyncio.wait_for(writer.drain(), SEND_TIMEOUT)
        except (asyncio.TimeoutError, ConnectionError):
            raise ClosedByPeer() from None

    async def _frame(self, reader: asyncio.StreamReader, first: bool) -> bytes:
        n = parse_tpkt_header(await self.read_exactly(reader, 4, first))
        return await self.read_exactly(reader, n)

    async def _pdu(self, reader: asyncio.StreamReader) -> bytes | None:
        """One S7 PDU from one or more COTP DTs; None on a COTP DR."""
        parts = b""
        while True:
            tpdu = parse_cotp(await self._frame(reader, not parts))
            if tpdu.code == DR:
                return None
            if tpdu.code != DT:
                raise FrameError("a second COTP connection request")
            parts += tpdu.data
            if len(parts) > MAX_PDU:
                raise FrameError(f"an S7 PDU longer than {MAX_PDU} bytes")
            if tpdu.eot:
                return parts

    async def _answer(self, conn: _Conn, pdu: bytes) -> bytes:
        h = parse_header(pdu)          # not S7 at all: the connection closes
        try:
            if len(pdu) > conn.pdu:
                raise _Refuse(ERR["frame"])
            if h.rosctr == USERDATA:
                return await self._userdata(conn, h)
            handler = _JOBS.get(h.params[0] if h.params else -1)
            if handler is None:
                raise _Refuse(ERR["not_implemented"])
            return await handler(self, conn, h)
        except FrameError:
            self.stats["refused_requests"] += 1
            return _error(h, ERR["frame"])
        except _Refuse as r:
            self.stats["refused_requests"] += 1
            return _error(h, r.error)
        except DoorBusy:
            self.stats["busy"] += 1
            return _error(h, ERR["resources"])
        except DoorClosed:
            raise ClosedByPeer() from None

    # -- jobs ----------------------------------------------------------------
    async def _setup(self, conn: _Conn, h: Header) -> bytes:
        if len(h.params) != 8:
            raise FrameError("setup communication parameters are 8 bytes")
        _, _, amq1, amq2, asked = struct.unpack(">BBHHH", h.params)
        conn.pdu = max(min(asked, self.identity.pdu_size, conn.tpdu), MIN_PDU)
        return ack(h.ref, struct.pack(">BBHHH", FN["setup"], 0, min(amq1, 1) or 1,
                                      min(amq2, 1) or 1, conn.pdu))

    async def _read(self, conn: _Conn, h: Header) -> bytes:
        items = parse_items(h.params)
        locs = [locate(i, self.sizes) for i in items]
        size = 14 + sum(4 + (x.nbytes + 1 & ~1) if isinstance(x, Loc) else 4 for x in locs)
        if size > conn.pdu:
            raise _Refuse(ERR["frame"])       # the answer would not fit the PDU
        good = [x for x in locs if isinstance(x, Loc)]
        data = iter(await self.ask(read_job(good)) if good else ())
        body = bytearray()
        for k, (item, loc) in enumerate(zip(items, locs)):
            one = reply_item(item.tsize, RC["ok"], next(data)) if isinstance(loc, Loc) \
                else reply_item(item.tsize, loc, b"")
            body += one
            if len(one) & 1 and k < len(items) - 1:
                body.append(0)
        self.stats["reads"] += 1
        return ack(h.ref, bytes([FN["read"], len(items)]), bytes(body))

    async def _write(self, conn: _Conn, h: Header) -> bytes:
        items = parse_items(h.params)
        data = parse_write_data(h.data, len(items))
        codes, writes = [], []
        for item, (_, value) in zip(items, data):
            loc = locate(item, self.sizes)
            rc = check_write(loc, value, self.options.guard, self.sm_readonly) \
                if isinstance(loc, Loc) else loc
            codes.append(rc)
            if rc == RC["ok"]:
                writes.append((loc, value))
        if writes:
            await self.ask(write_job(writes))
        self.stats["writes"] += 1
        return ack(h.ref, bytes([FN["write"], len(items)]), bytes(codes))

    async def _mode(self, h: Header, mode: str) -> bytes:
        if self.options.guard.read_only:
            raise _Refuse(ERR["denied"])
        try:
            same = await self.ask(lambda plc: _switch(plc, mode))
        except PlcConfigError:
            raise _Refuse(ERR["state"]) from None
        # 0x07 in the answer: the CPU was in that mode already (snap7's
        # errCliAlreadyRun / errCliAlreadyStop)
        return ack(h.ref, bytes([h.params[0], 0x07 if same else 0x00]))

    async def _pi(self, conn: _Conn, h: Header) -> bytes:
        p = h.params                     # 28 00*6 FD LEN(2) BLOCK NAMELEN NAME
        if len(p) < 11:
            raise FrameError("PI service parameters too short")
        at = 10 + (p[8] << 8 | p[9])
        if at >= len(p) or at + 1 + p[at] != len(p):
            raise FrameError("PI service parameters do not add up")
        if p[at + 1:] != b"P_PROGRAM":
            raise _Refuse(ERR["not_implemented"])
        return await self._mode(h, "RUN")

    async def _stop(self, conn: _Conn, h: Header) -> bytes:
        p = h.params                     # 29 00*5 NAMELEN NAME
        if len(p) < 7 or 7 + p[6] != len(p) or p[7:] != b"P_PROGRAM":
            raise FrameError("PLC stop parameters are not P_PROGRAM")
        return await self._mode(h, "STOP")

    # -- user data: the SZL ----------------------------------------------
    async def _userdata(self, conn: _Conn, h: Header) -> bytes:
        p = h.params
        if len(p) < 8 or p[:3] != b"\x00\x01\x12" or p[3] + 4 != len(p):
            raise FrameError("malformed user-data parameters")
        method, group, sub = p[4], p[5] & 0x0F, p[6]
        if group != 4 or sub != 1:
            return userdata_answer(h.ref, group, sub, b"\x0a\x00\x00\x00",
                                   error=ERR["not_implemented"])
        if method == 0x12:               # the next part of a long answer
            return self._szl_part(conn, h)
        if len(h.data) != 8:
            raise FrameError("an SZL request is an id and an index")
        szl_id, index = struct.unpack_from(">HH", h.data, 4)
        mode = await self.ask(_mode_of) if szl_id in (0x0424, 0x0232) else "RUN"
        body = szl_answer(self.identity, szl_id, index, mode)
        if body is None:
            # Wireshark's s7comm: 0xD401 "invalid SZL id"; data "object
            # does not exist"
            return userdata_answer(h.ref, 4, 1, b"\x0a\x00\x00\x00", error=0xD401)
        conn.pending = body
        conn.seq = conn.seq % 255 + 1
        self.stats["szl"] += 1
        return self._szl_part(conn, h)

    def _szl_part(self, conn: _Conn, h: Header) -> bytes:
        if not conn.pending:
            return userdata_answer(h.ref, 4, 1, b"\x0a\x00\x00\x00", error=0xD401)
        room = conn.pdu - 10 - 12 - 4
        part, conn.pending = conn.pending[:room], conn.pending[room:]
        data = struct.pack(">BBH", 0xFF, 0x09, len(part)) + part
        return userdata_answer(h.ref, 4, 1, data, seq=conn.seq, more=bool(conn.pending))


def _error(h: Header, error: int) -> bytes:
    """A request answered with an error word: a job's answer names the
    function, a user-data answer the group and subfunction asked."""
    p = h.params
    if h.rosctr == USERDATA:
        group, sub = (p[5] & 0x0F, p[6]) if len(p) >= 7 else (0, 0)
        return userdata_answer(h.ref, group, sub, b"\x0a\x00\x00\x00", error=error)
    return ack(h.ref, p[:1] + b"\x00" if p else b"", error=error)


def _switch(plc: Any, mode: str) -> bool:
    """Set the CPU's mode; whether it was in that mode already (a door job)."""
    same = plc.mode == mode
    plc.set_mode(mode)
    return same


def _mode_of(plc: Any) -> str:
    return str(plc.mode)


#: job function -> handler
_JOBS: dict[int, Handler] = {
    FN["setup"]: S7Server._setup,
    FN["read"]: S7Server._read,
    FN["write"]: S7Server._write,
    FN["pi"]: S7Server._pi,
    FN["stop"]: S7Server._stop,
}


def make_s7(door: ScanDoor, plc: Any, options: ServerOptions) -> S7Server:
    """The factory :data:`plcrt.net.host.SERVICES` holds for ``"s7"``."""
    return S7Server(door, plc, options)
