"""Several plcrt CPUs on one wire: ports linked port to port, and GET/PUT
between CPUs by their IP addresses, run together in lockstep.

What it is: :class:`Network`, a co-simulation of several :class:`Plc`
objects.  ``plcrt.link(plc_a, 0, plc_b, 0)`` makes one and links port 0 of
A to port 0 of B (RS-485: what one sends, the other receives);
``Network(plc_a, plc_b)`` reaches the CPUs' Ethernet interfaces by the IP
addresses of their plant files (``[ethernet] ip``).  ``net.run(seconds)``
runs them all.

How the bytes arrive at their exact µs on both sides: every CPU's time line
is run in windows of at most :data:`plcrt.engine.serial.MIN_CHAR_US` µs
(78 µs, the shortest character any port can send), all CPUs one window
after the other.  Whatever a CPU sends at a time s in a window arrives at
the other end no earlier than one character later, after the end of the
window, which the receiver has not yet run: the character, an answer to
NETR/NETW or GET/PUT, is put into the receiver's time line before its time
comes.  (A plant's Ethernet latency below 79 µs makes the windows one µs
shorter than it.)  A scan is cut into windows only here (the main program runs at the
scan's start as always); a CPU that is not linked runs its scans whole.

What it is not: no collisions on the wire (two ports that send at once
each receive the other's characters), no more than two ports on one wire.
"""

from __future__ import annotations

from typing import Any, Optional

from ..errors import PlcConfigError
from .serial import MIN_CHAR_US
from .values import Duration, duration_us, shown_value, step_count

__all__ = ["Network", "link"]


class _LinkEnd:
    """The far end of a linked port, as its peer."""

    def __init__(self, other: Any) -> None:
        self.other = other                   #: the other CPU's Port

    def transmit(self, port: Any, t: int, fr: Any, data: bytes) -> None:
        self.other.receive(t, fr, data, link=True)

    def station(self, address: int) -> Optional[Any]:
        """The port answering PPI station *address* on this wire."""
        return self.other if self.other.address == address else None


class Network:
    """Linked CPUs, run together (see the module docstring)."""

    def __init__(self, *plcs: Any) -> None:
        self.plcs: list[Any] = []
        #: per CPU: the scan in progress (its start time) or None
        self._scan: dict[int, Optional[int]] = {}
        self._pos: dict[int, int] = {}
        for plc in plcs:
            self.add(plc)

    def add(self, plc: Any) -> Network:
        """Take *plc* into the network (at the others' time, between scans)."""
        from .runtime import Plc
        if not isinstance(plc, Plc):
            raise PlcConfigError(f"a network links loaded PLCs (plcrt.load), got "
                                 f"{type(plc).__name__}")
        if any(p is plc for p in self.plcs):
            return self
        if getattr(plc, "network", None) is not None:
            raise PlcConfigError("this PLC is already in another network")
        if self.plcs and plc.now_us != self.plcs[0].now_us:
            raise PlcConfigError(f"a PLC joins a network at the others' time: it is at "
                                 f"{plc.now_us} µs, the network at {self.plcs[0].now_us} µs")
        plc.network = self
        plc.ethernet.network = self
        self.plcs.append(plc)
        self._scan[id(plc)] = None
        self._pos[id(plc)] = plc.now_us
        ip = plc.ethernet.ip
        if ip is not None and sum(p.ethernet.ip == ip for p in self.plcs) > 1:
            raise PlcConfigError(f"two PLCs in one network have the IP address "
                                 f"{'.'.join(map(str, ip))}")
        return self

    def link(self, a: Any, port_a: int, b: Any, port_b: int) -> Network:
        """Wire port *port_a* of *a* to port *port_b* of *b*."""
        pa, pb = self._port(a, port_a), self._port(b, port_b)
        if pa is pb:
            raise PlcConfigError("a port cannot be linked to itself")
        for p in (pa, pb):
            if p.peer is not None:
                raise PlcConfigError(f"port {p.number} already has something at its other "
                                     f"end (a plant device or another link)")
        self.add(a)
        self.add(b)
        pa.peer, pb.peer = _LinkEnd(pb), _LinkEnd(pa)
        return self

    def _port(self, plc: Any, number: Any) -> Any:
        from .runtime import Plc
        if not isinstance(plc, Plc):
            raise PlcConfigError(f"link() takes loaded PLCs and port numbers, got "
                                 f"{type(plc).__name__}")
        if isinstance(number, bool) or not isinstance(number, int) \
                or not 0 <= number < len(plc.ports):
            raise PlcConfigError(f"the {plc.model.name} has port(s) "
                                 f"{', '.join(str(p.number) for p in plc.ports)}, got "
                                 f"{shown_value(number)}")
        return plc.ports[number]

    def ethernet_of(self, ip: bytes) -> Optional[Any]:
        """The Ethernet interface with address *ip* (4 bytes, as a GET/PUT
        table holds it) in this network, or None.

        Raises:
            PlcConfigError: ``ip`` is not 4 bytes.
        """
        if not isinstance(ip, bytes) or len(ip) != 4:
            raise PlcConfigError(f"an IP address is 4 bytes (b'\\xc0\\xa8\\x00\\x01'), got "
                                 f"{type(ip).__name__} {shown_value(ip)}")
        for plc in self.plcs:
            # a CPU in STOP still serves GET/PUT (its server runs)
            if plc.ethernet.ip == ip:
                return plc.ethernet
        return None

    @property
    def time_us(self) -> int:
        """The time every CPU has run to."""
        return min(self._pos.values()) if self._pos else 0

    def run(self, seconds: Duration) -> None:
        """Run every CPU for *seconds* of simulated time (``0.5``, ``"200ms"``).

        Raises:
            PlcConfigError: not a duration, or a span of more than
                :data:`~plcrt.engine.values.MAX_STEPS` windows (below).
        """
        span = duration_us(seconds, "seconds")
        if not self.plcs:
            return
        # a window shorter than the quickest way from one CPU to another
        # (a character: at least 79 µs; Ethernet: the latency), so that what
        # a CPU sends at the window's start arrives after its end
        window = min([MIN_CHAR_US] + [p.ethernet.latency_us - 1 for p in self.plcs])
        step_count(span, window, seconds, "seconds", "synchronisation window")
        end = self.time_us + span
        t = self.time_us
        while t < end:
            t = min(t + window, end)
            for plc in self.plcs:
                self._advance(plc, t)

    def _advance(self, plc: Any, limit: int) -> None:
        """Run *plc* up to *limit*: scan starts at or before it, the time
        line to it."""
        key = id(plc)
        while True:
            start = self._scan[key]
            if plc.mode != "RUN":
                # STOP (a STOP instruction, a fault): its time stands; the
                # others run on, and what reaches it waits in its inbox
                self._scan[key] = None
                self._pos[key] = max(self._pos[key], limit)
                return
            if start is None:
                s = plc.now_us
                if s > limit:
                    self._pos[key] = max(self._pos[key], limit)
                    return
                plc._scan_begin()
                self._scan[key] = start = s
                self._pos[key] = s
            end = start + plc.scan_us
            upto = min(end, limit)
            pos = self._pos[key]
            if upto > pos:
                plc._timeline(pos, upto, pos == start)
                self._pos[key] = upto
            if upto < end:
                return
            plc._scan_end(start)
            self._scan[key] = None


def link(plc_a: Any, port_a: int, plc_b: Any, port_b: int) -> Network:
    """Link port *port_a* of *plc_a* to port *port_b* of *plc_b* (a new
    :class:`Network`, or the one either is in); run them with ``.run()``."""
    net = getattr(plc_a, "network", None) or getattr(plc_b, "network", None) or Network()
    return net.link(plc_a, port_a, plc_b, port_b)
