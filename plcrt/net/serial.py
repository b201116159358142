"""A CPU port on a pseudo-terminal: the program's own freeport protocol or
Modbus RTU slave (MBUS_INIT / MBUS_SLAVE) talks to a real serial program
(pymodbus's serial client, mbpoll, a terminal) through ``/dev/pts/N``.

``plcrt.serve(plc, serial={0: "pty"})`` opens a pseudo-terminal per port
(``os.openpty``), puts it in raw mode and makes it the port's peer (the
place a plant device takes, :class:`plcrt.devices.peer.PortPeer`); the
slave side's path is ``serving.addresses["serial0"][0]`` (and
:func:`pty_path`).  Then:

- what the CPU sends (XMT, the Modbus library's answers) leaves the port
  character by character at the port's baud rate in simulated time: each
  character is written to the pseudo-terminal when the time line reaches
  its stop bit (:meth:`plcrt.engine.ports.Port.send`'s timing), so in real
  time a 9-character answer at 9600 baud takes its 9.4 ms;
- what the far end writes is read by the servers' loop and handed to the
  port at the next scan boundary (a door job): the characters arrive one
  after the other from that instant (never overlapping the previous ones)
  at the baud rate and character size the far end set on the
  pseudo-terminal (as pyserial and mbpoll set them with ``termios``), so a
  master at another rate than the port's SMB30 / SMB130 is received with
  errors as on a real line, and so is a request sent before the program's
  MBUS_INIT put the port in freeport.  A Linux pseudo-terminal keeps no
  parity (pyserial cannot even set it there), so the characters carry the
  port's own parity: set the master to parity none;
- the scan never waits: a far end that does not read loses what its
  buffer cannot take (``stats["dropped_out"]``), a flood of input beyond
  the door's bound is dropped (``stats["dropped_in"]``).

What it is not: the PPI protocol (a port in PPI mode ignores freeport
characters in plcrt, docs/ports.md), a break (count 0 XMT) on the line, or
the modem lines.  A port that the plant file already gives a device is
refused.
"""

from __future__ import annotations

import asyncio
import os
import termios
import tty
from collections import Counter
from collections.abc import Mapping
from typing import Any

from ..engine.runtime import Plc
from ..engine.serial import BAUDS, Framing
from ..errors import PlcConfigError
from ..safetext import shown_value
from .door import DoorBusy, DoorClosed, ScanDoor

__all__ = ["PtyBridge", "pty_path", "pty_services"]

#: bytes read from the pseudo-terminal at once
READ_CHUNK = 4096
#: termios speed constant -> bits per second (the rates a port can run at)
_SPEEDS = {getattr(termios, f"B{b}"): b for b in BAUDS if hasattr(termios, f"B{b}")}


def line_framing(fd: int, port: Framing) -> Framing:
    """The framing of the characters the far end writes on the terminal
    ``fd``: its output speed and character size, the ``port``'s parity (a
    pseudo-terminal keeps none); ``port`` itself for a rate no port can
    run at."""
    try:
        _, _, cflag, _, _, ospeed, _ = termios.tcgetattr(fd)
    except (termios.error, OSError):
        return port
    baud = _SPEEDS.get(ospeed)
    if baud is None:
        return port
    bits = 7 if cflag & termios.CSIZE == termios.CS7 else 8
    return Framing(baud, bits, port.parity, "freeport")


class _PtyPeer:
    """The port's peer: characters the CPU sends go to the pseudo-terminal
    at their stop bits' simulated times."""

    def __init__(self, bridge: "PtyBridge") -> None:
        self.bridge = bridge
        self.port: Any = None

    def attach(self, port: Any) -> None:
        self.port = port
        port.peer = self

    def station(self, address: int) -> None:
        """Not a PPI station."""
        return None

    def transmit(self, port: Any, t: int, fr: Any, data: bytes) -> None:
        for k, byte in enumerate(data):
            port.push(fr.end(t, k + 1), self._out, byte)

    def _out(self, t: int, byte: int) -> None:
        self.bridge.write(bytes((byte,)))

    def __deepcopy__(self, memo: dict) -> None:
        # a fork or snapshot of the PLC is not attached to the terminal
        return None


class PtyBridge:
    """Port ``number`` of ``plc`` on a new pseudo-terminal (see the module
    doc); started and closed on the servers' loop like a TCP service."""

    name = "serial"

    def __init__(self, door: ScanDoor, plc: Plc, number: int) -> None:
        if isinstance(number, bool) or not isinstance(number, int) \
                or not 0 <= number < len(plc.ports):
            raise PlcConfigError(f"serial: the {plc.model.name} has no port "
                                 f"{shown_value(number)} (it has "
                                 f"{', '.join(map(str, range(len(plc.ports))))})")
        if plc.ports[number].peer is not None:
            raise PlcConfigError(f"serial: port {number} has a device of the plant file; "
                                 f"a pseudo-terminal cannot take its place")
        self.door, self.plc, self.number = door, plc, number
        self.stats: Counter[str] = Counter()
        self.path = ""
        self._master = self._slave = -1
        self._peer = _PtyPeer(self)
        self._rx_free = 0                      # µs: the port's line is free from
        self._loop: asyncio.AbstractEventLoop | None = None

    @property
    def connections(self) -> int:
        return 0

    async def start(self) -> tuple[str, int]:
        """Open the pseudo-terminal and attach it; (its path, the port)."""
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)
        os.set_blocking(self._master, False)
        self.path = os.ttyname(self._slave)
        # the runner may not run yet: the attach is the door's first job
        self.door.post(self._attach)
        self._loop = asyncio.get_running_loop()
        self._loop.add_reader(self._master, self._readable)
        return self.path, self.number

    async def close(self) -> None:
        """Detach the port and close the pseudo-terminal."""
        if self._loop is not None and self._master >= 0:
            self._loop.remove_reader(self._master)
        try:
            self.door.post(self._detach)
        except DoorClosed:
            self._detach(self.plc)             # the runner has stopped
        # forgotten before closed: a write racing the close never reaches a
        # file that reuses the descriptor's number
        fds, self._master, self._slave = (self._master, self._slave), -1, -1
        for fd in fds:
            if fd >= 0:
                os.close(fd)

    # -- the PLC's thread ---------------------------------------------------
    def _attach(self, plc: Plc) -> None:
        self._peer.attach(plc.ports[self.number])

    def _detach(self, plc: Plc) -> None:
        port = plc.ports[self.number]
        if port.peer is self._peer:
            port.peer = None

    def _feed(self, plc: Plc, data: bytes) -> None:
        port = plc.ports[self.number]
        fr = line_framing(self._slave, port.framing())
        t0 = max(plc.now_us, self._rx_free)
        port.receive(t0, fr, data)
        self._rx_free = fr.end(t0, len(data))
        self.stats["received"] += len(data)

    def write(self, data: bytes) -> None:
        """Characters for the far end (the PLC's thread; never blocks)."""
        fd = self._master
        if fd < 0:
            return
        try:
            os.write(fd, data)
            self.stats["sent"] += len(data)
        except (BlockingIOError, OSError):
            self.stats["dropped_out"] += len(data)

    # -- the loop's thread ----------------------------------------------------
    def _readable(self) -> None:
        try:
            data = os.read(self._master, READ_CHUNK)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:                       # no far end (EIO): nothing to read
            return
        if not data:
            return
        try:
            self.door.post(lambda plc: self._feed(plc, data))
        except DoorBusy:
            self.stats["dropped_in"] += len(data)
        except DoorClosed:
            pass


def pty_services(door: ScanDoor, plc: Plc, spec: Any) -> dict[str, PtyBridge]:
    """``{"serial0": bridge, ...}`` for ``serve(serial={0: "pty"})``.

    Raises:
        PlcConfigError: not a mapping of port numbers to ``"pty"``, a port
            the CPU lacks or one the plant file has a device at.
    """
    if not isinstance(spec, Mapping) or len(spec) > 2:
        raise PlcConfigError(f"serial: a mapping port -> \"pty\" ({{0: \"pty\"}}), not "
                             f"{shown_value(spec)}")
    out = {}
    for number, kind in spec.items():
        if kind != "pty":
            raise PlcConfigError(f"serial: port {shown_value(number)}: only \"pty\" (a "
                                 f"pseudo-terminal), not {shown_value(kind)}")
        out[f"serial{number}"] = PtyBridge(door, plc, number)
    return out


def pty_path(serving: Any, port: int = 0) -> str:
    """The pseudo-terminal of ``port`` of a running :class:`plcrt.net.Serving`.

    Raises:
        PlcConfigError: that port is not on a pseudo-terminal.
    """
    try:
        return str(serving.addresses[f"serial{port}"][0])
    except (KeyError, TypeError):
        raise PlcConfigError(f"port {shown_value(port)} is not served on a "
                             f"pseudo-terminal") from None
