"""What every server of a served PLC is told: where it listens, how many
clients it takes, how long an idle client may stay, and what a client may
write.

- ``[HOST:]PORT`` (:func:`parse_listen`): loopback unless a host is given;
  a host that is not loopback is allowed, and :func:`exposed` says so, so
  that the command line warns.
- a write allow-list of S7-200 address ranges (:func:`parse_ranges`:
  ``"VB0-VB99,Q0.0-Q1.7,M0-M3,T0-T31"``), checked per request by
  :class:`WriteGuard`; ``read_only`` refuses every write.

What it is: plain data and its parsing, shared by the S7 server, the
Modbus server and the lockstep server.  What it is not: any protocol, nor
the listening itself (:mod:`plcrt.net.tcp`).
"""

from __future__ import annotations

import ipaddress
import re
from dataclasses import dataclass, field

from ..errors import PlcConfigError
from ..safetext import excerpt, shown_value

__all__ = ["AddressRange", "Listen", "ServerOptions", "WriteGuard", "exposed",
           "parse_listen", "parse_ranges"]

#: most ranges an allow-list holds
MAX_RANGES = 256
#: longest allow-list text read
MAX_RANGES_TEXT = 8192

#: the areas an allow-list names, by their S7-200 letter; T and C count
#: timers and counters, every other area bytes
AREAS = ("V", "I", "Q", "M", "SM", "AI", "AQ", "T", "C", "S")


@dataclass(frozen=True)
class Listen:
    """Where a server listens (port 0: any free port)."""

    host: str = "127.0.0.1"
    port: int = 0

    def __str__(self) -> str:
        return f"[{self.host}]:{self.port}" if ":" in self.host else f"{self.host}:{self.port}"


def parse_listen(spec: object, *, what: str = "server") -> Listen:
    """``PORT``, ``HOST:PORT``, ``[V6HOST]:PORT`` or an int port.

    Raises:
        PlcConfigError: not one of those, or a port outside 0..65535.
    """
    if isinstance(spec, Listen):
        return spec
    if isinstance(spec, bool):
        raise PlcConfigError(f"{what}: a port is a number, not {shown_value(spec)}")
    if isinstance(spec, int):
        if not 0 <= spec <= 65535:
            raise PlcConfigError(f"{what}: port {shown_value(spec)} is outside 0..65535")
        host, port_text = "127.0.0.1", "%d" % spec
    elif isinstance(spec, str) and len(spec) <= 300:
        text = spec.strip()
        m = re.fullmatch(r"(?:\[([0-9A-Fa-f:.]+)\]:|([^:\[\]\s]+):)?(\d{1,5})", text)
        if m is None:
            raise PlcConfigError(f"{what}: expected [HOST:]PORT, not {excerpt(text)}")
        host = m.group(1) or m.group(2) or "127.0.0.1"
        port_text = m.group(3)
    else:
        raise PlcConfigError(f"{what}: expected [HOST:]PORT, not {shown_value(spec)}")
    port = int(port_text)
    if not 0 <= port <= 65535:
        raise PlcConfigError(f"{what}: port {port} is outside 0..65535")
    return Listen(host, port)


def exposed(host: str) -> bool:
    """Whether ``host`` is reachable from other machines (not loopback)."""
    if host in ("localhost", "localhost.localdomain"):
        return False
    try:
        return not ipaddress.ip_address(host).is_loopback
    except ValueError:
        return True


@dataclass(frozen=True)
class AddressRange:
    """``first`` .. ``last`` (inclusive) of an area: bytes, or timer /
    counter numbers for T and C."""

    area: str
    first: int
    last: int

    def covers(self, area: str, start: int, length: int) -> bool:
        return area == self.area and self.first <= start and start + length - 1 <= self.last


_ADDR = re.compile(r"(SM|AI|AQ|V|I|Q|M|S|T|C)(B|W|D|IW|QW)?(\d{1,6})(?:\.([0-7]))?",
                   re.IGNORECASE)


def _one(text: str, end: bool) -> tuple[str, int]:
    m = _ADDR.fullmatch(text.strip())
    if m is None:
        raise PlcConfigError(f"write allow-list: {excerpt(text)} is not an S7-200 address "
                             f"(VB0, Q0.0, MW10, AIW0, T37 ...)")
    area, size, num = m.group(1).upper(), (m.group(2) or "").upper(), int(m.group(3))
    if area in ("T", "C"):
        if size or m.group(4):
            raise PlcConfigError(f"write allow-list: {excerpt(text)}: timers and counters "
                                 f"are named by number (T37, C0)")
        return area, num
    width = {"W": 2, "IW": 2, "QW": 2, "D": 4}.get(size, 1)
    return area, num + (width - 1 if end else 0)


def parse_ranges(text: str) -> tuple[AddressRange, ...]:
    """An allow-list: ranges ``FIRST-LAST`` or single addresses, joined by
    commas.  ``VB0-VB99``, ``Q0.0-Q1.7`` (whole bytes: a bit range allows
    its bytes), ``MW10`` (two bytes), ``T0-T31``.

    Raises:
        PlcConfigError: a bad address, a range whose ends are in different
            areas or backwards, or more than :data:`MAX_RANGES` ranges.
    """
    if not isinstance(text, str) or len(text) > MAX_RANGES_TEXT:
        raise PlcConfigError(f"write allow-list: a text of at most {MAX_RANGES_TEXT} "
                             f"characters, not {shown_value(text)}")
    parts = [p for p in text.split(",") if p.strip()]
    if len(parts) > MAX_RANGES:
        raise PlcConfigError(f"write allow-list: at most {MAX_RANGES} ranges")
    out = []
    for part in parts:
        lo, _, hi = part.partition("-")
        a1, first = _one(lo, False)
        a2, last = _one(hi or lo, True)
        if a1 != a2:
            raise PlcConfigError(f"write allow-list: {excerpt(part)} spans two areas")
        if last < first:
            raise PlcConfigError(f"write allow-list: {excerpt(part)} ends before it starts")
        out.append(AddressRange(a1, first, last))
    return tuple(out)


@dataclass(frozen=True)
class WriteGuard:
    """Which writes a server accepts: none (``read_only``), those inside
    ``allow`` (when given), else all."""

    read_only: bool = False
    allow: tuple[AddressRange, ...] | None = None

    def allows(self, area: str, start: int, length: int) -> bool:
        """Whether a write of ``length`` units at ``start`` of ``area``
        (S7-200 letters, see :data:`AREAS`) is allowed."""
        if self.read_only:
            return False
        if self.allow is None:
            return True
        return any(r.covers(area, start, length) for r in self.allow)


@dataclass(frozen=True)
class ServerOptions:
    """One server's listening address and limits.

    ``max_connections``: clients served at once; one more is accepted and
    closed at once (the CPU refuses a connection beyond its resources the
    same way).  ``idle_timeout``: seconds a client may stay silent before
    its connection is closed (0: never).
    """

    listen: Listen = field(default_factory=Listen)
    max_connections: int = 8
    idle_timeout: float = 60.0
    guard: WriteGuard = field(default_factory=WriteGuard)

    def __post_init__(self) -> None:
        if isinstance(self.max_connections, bool) or not isinstance(self.max_connections, int) \
                or not 1 <= self.max_connections <= 1024:
            raise PlcConfigError(f"max_connections is 1..1024, not "
                                 f"{shown_value(self.max_connections)}")
        t = self.idle_timeout
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not 0 <= t <= 86400:
            raise PlcConfigError(f"idle_timeout is 0..86400 s, not {shown_value(t)}")
