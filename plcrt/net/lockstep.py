"""The lockstep protocol: an external simulator or test drives the PLC
step by step over TCP — advance N scans or to a simulated instant, read
the image, write inputs, go on — the way PLCSIM Advanced's single-step
mode serves virtual commissioning.

One JSON object per line each way (UTF-8, ``\\n``-terminated, at most
:data:`MAX_LINE` bytes, nesting at most 4 deep).  A request has an ``op``
and may have an ``id`` (echoed); the answer is ``{"ok": true, ...}`` or
``{"ok": false, "error": "..."}``.  The operations (:data:`OPS`):

========  ==============================================  ==========================
op        fields                                          answer
========  ==============================================  ==========================
hello                                                     cpu, scan_us, speed, now_us
state                                                     mode, now_us, scans, fault
advance   exactly one of scans, seconds, to_us            scans (run), now_us, mode
read      addresses: list of addresses or symbols         values: address -> value
write     values: object address -> number                written: count
mode      mode: "RUN" or "STOP"                           mode
========  ==============================================  ==========================

``advance`` is only for a PLC served with ``speed="lockstep"`` (else the
PLC runs by itself and the answer is an error).  Every request runs at a
scan boundary (:mod:`plcrt.net.door`); a write is in the image before the
next scan, exactly as ``plc.write`` does it (an input holds its value).
Writes obey the server's read-only mode and allow-list.

What it is: the server side, a :class:`plcrt.net.tcp.TcpService`.  What
it is not: the client (:mod:`plcrt.net.client`).
"""

from __future__ import annotations

import asyncio
from typing import Any

from ..engine.runtime import Plc
from ..errors import PlcConfigError, PlcError
from ..safetext import printable
from . import jsonmsg
from .door import ScanDoor
from .options import ServerOptions, WriteGuard
from .runner import advance
from .tcp import ClosedByPeer, TcpService

__all__ = ["LockstepServer", "MAX_ITEMS", "MAX_LINE", "OPS"]

#: the longest request line (bytes, with its newline)
MAX_LINE = 65536
#: the most addresses one read or write names
MAX_ITEMS = 1000
#: the deepest nesting of a request (an object holding a list or object)
MAX_DEPTH = 4

#: op -> (required fields, optional fields)
OPS: dict[str, tuple[frozenset[str], frozenset[str]]] = {
    "hello": (frozenset(), frozenset()),
    "state": (frozenset(), frozenset()),
    "advance": (frozenset(), frozenset({"scans", "seconds", "to_us"})),
    "read": (frozenset({"addresses"}), frozenset()),
    "write": (frozenset({"values"}), frozenset()),
    "mode": (frozenset({"mode"}), frozenset()),
}


class LockstepServer(TcpService):
    """The lockstep protocol on a TCP port (see the module doc)."""

    name = "lockstep"

    def __init__(self, door: ScanDoor, plc: Plc, options: ServerOptions) -> None:
        super().__init__(door, options)
        self.cpu = plc.model.name

    async def session(self, reader: asyncio.StreamReader,
                      writer: asyncio.StreamWriter) -> None:
        while True:
            line = await self._line(reader)
            try:
                msg = self._check(line)
                answer = await self._answer(msg)
                answer = {"ok": True, **answer}
            except PlcError as e:
                self.stats["errors"] += 1
                answer = {"ok": False, "error": printable(e.message)}
                msg = None
            rid = _request_id(line) if msg is None else msg.get("id")
            if rid is not None:
                answer["id"] = rid
            self.stats["requests"] += 1
            writer.write(jsonmsg.dumps(answer).encode() + b"\n")
            await writer.drain()

    async def _line(self, reader: asyncio.StreamReader) -> bytes:
        timeout = self.options.idle_timeout or None
        try:
            return await asyncio.wait_for(reader.readuntil(b"\n"), timeout)
        except asyncio.LimitOverrunError:
            # a line longer than the stream's limit: this client is done
            raise PlcConfigError(f"a request line is longer than {MAX_LINE} bytes") from None
        except (asyncio.IncompleteReadError, ConnectionError, asyncio.TimeoutError):
            raise ClosedByPeer() from None

    def _check(self, line: bytes) -> dict[str, Any]:
        msg = jsonmsg.load(line, max_bytes=MAX_LINE, max_depth=MAX_DEPTH)
        if not isinstance(msg, dict) or not isinstance(msg.get("op"), str):
            raise PlcConfigError('a request is a JSON object with an "op"')
        op = msg["op"]
        if op not in OPS:
            raise PlcConfigError(f"no operation {printable(op[:40])!s} (there are: "
                                 f"{', '.join(OPS)})")
        required, optional = OPS[op]
        fields = set(msg) - {"op", "id"}
        if required - fields:
            raise PlcConfigError(f"{op} needs {', '.join(sorted(required - fields))}")
        if fields - required - optional:
            raise PlcConfigError(f"{op} takes no {printable(sorted(fields - required - optional)[0][:40])}")
        if msg.get("id") is not None and not _valid_id(msg["id"]):
            raise PlcConfigError("an id is a whole number or a text of at most 64 characters")
        return msg

    async def _answer(self, msg: dict[str, Any]) -> dict[str, Any]:
        op = msg["op"]
        handler = getattr(self, f"_op_{op}")
        return await handler(msg)

    # -- operations ----------------------------------------------------------
    async def _op_hello(self, msg: dict[str, Any]) -> dict[str, Any]:
        door = self.door
        return await self.ask(lambda plc: {"cpu": self.cpu, "scan_us": plc.scan_us,
                                           "speed": door.speed, "now_us": plc.now_us})

    async def _op_state(self, msg: dict[str, Any]) -> dict[str, Any]:
        return await self.ask(_state)

    async def _op_advance(self, msg: dict[str, Any]) -> dict[str, Any]:
        kw = {k: msg[k] for k in ("scans", "seconds", "to_us") if k in msg}
        door = self.door

        def job(plc: Plc) -> dict[str, Any]:
            if door.speed != "lockstep":   # asked at the boundary: the speed may change
                raise PlcConfigError("advance: the PLC runs by itself; serve it with speed "
                                     "lockstep to step it")
            n = advance(plc, **kw)
            return {"scans": n, "now_us": plc.now_us, "mode": plc.mode}
        return await self.ask(job)

    async def _op_read(self, msg: dict[str, Any]) -> dict[str, Any]:
        addresses = msg["addresses"]
        if not isinstance(addresses, list) or not 0 < len(addresses) <= MAX_ITEMS \
                or not all(isinstance(a, str) and len(a) <= 200 for a in addresses):
            raise PlcConfigError(f"read: addresses is a list of 1 to {MAX_ITEMS} texts")

        def job(plc: Plc) -> dict[str, Any]:
            return {"values": {a: jsonmsg.finite(plc.read(a)) for a in addresses}}
        return await self.ask(job)

    async def _op_write(self, msg: dict[str, Any]) -> dict[str, Any]:
        values = msg["values"]
        if not isinstance(values, dict) or not 0 < len(values) <= MAX_ITEMS or not all(
                len(a) <= 200 and isinstance(v, (int, float)) for a, v in values.items()):
            raise PlcConfigError(f"write: values is an object of 1 to {MAX_ITEMS} "
                                 f"addresses and numbers")
        guard = self.options.guard

        def job(plc: Plc) -> dict[str, Any]:
            for a in values:      # all or nothing: every address is checked first
                _allowed(plc, guard, a)
            for a, v in values.items():
                plc.write(a, v)
            return {"written": len(values)}
        return await self.ask(job)

    async def _op_mode(self, msg: dict[str, Any]) -> dict[str, Any]:
        mode = msg["mode"]
        if self.options.guard.read_only:
            raise PlcConfigError("mode: this server is read-only")

        def job(plc: Plc) -> dict[str, Any]:
            plc.set_mode(mode if isinstance(mode, str) else repr(mode))
            return {"mode": plc.mode}
        return await self.ask(job)


def _state(plc: Plc) -> dict[str, Any]:
    return {"mode": plc.mode, "now_us": plc.now_us, "scans": plc.scans,
            "fault": printable(plc.fault.message) if plc.fault is not None else None}


def _allowed(plc: Plc, guard: WriteGuard, address: str) -> None:
    """Refuse a write the server's guard does not allow."""
    if guard.read_only:
        raise PlcConfigError("write: this server is read-only")
    if guard.allow is None:
        return
    buf, off, width, bit, _kind = plc.locate(address)
    area = next((k for k, b in plc.mem.areas.items() if b is buf), "?")
    unit_off, unit_len = off, max(width, 1)
    if area in ("TV", "CV"):            # a timer's or counter's value: its number
        area, unit_off, unit_len = area[0], off // 2, 1
    elif area in ("TB", "CB"):          # its bit
        area, unit_off, unit_len = area[0], off * 8 + bit, 1
    if not guard.allows(area, unit_off, unit_len):
        raise PlcConfigError(f"write: {printable(address[:40])} is outside this server's "
                             f"write allow-list")


def _request_id(line: bytes) -> Any:
    """The id of a request that failed its checks, if it can be read."""
    try:
        msg = jsonmsg.load(line, max_bytes=MAX_LINE, max_depth=MAX_DEPTH)
    except PlcError:
        return None
    if isinstance(msg, dict) and _valid_id(msg.get("id")):
        return msg["id"]
    return None


def _valid_id(rid: Any) -> bool:
    """A request id the answer may echo: a whole number JSON carries
    exactly, or a text of at most 64 characters."""
    return (isinstance(rid, int) and not isinstance(rid, bool) and abs(rid) < 2 ** 53
            or isinstance(rid, str) and len(rid) <= 64)
