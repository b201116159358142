"""Serial framing of the CPU's ports, and the timed inbox every port-like
event source is built on.

What it is:

* :class:`Framing`, what SMB30 (port 0) / SMB130 (port 1) select (S7-200
  System Manual, "Freeport mode", table "SMB30 and SMB130 control
  registers": ``p p d b b b m m``): parity, data bits, baud rate, protocol.
  A character is one start bit, 7 or 8 data bits, a parity bit when parity
  is on, and one stop bit.  A character ending at a time that is not a
  whole µs is delivered at the first whole µs after its stop bit ends
  (docs/decisions.md, "Communication ports").
* :class:`Inbox`, a heap of things due at exact times (a character arriving,
  a reply of a remote station), the part of a port that the scheduler
  (:class:`plcrt.engine.events.Scheduler`) asks and fires.

What it is not: no receive or transmit logic (:mod:`.ports`), no PPI or
Ethernet jobs (:mod:`.netjobs`).
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass
from typing import Any, Callable, Optional

__all__ = ["Framing", "Inbox", "BAUDS", "BAUD_CODE", "PROTOCOLS", "framing_of",
           "MIN_CHAR_US", "table_at"]

#: baud code (bits 4..2 of SMB30/SMB130) -> bits per second (System Manual,
#: "SMB30 and SMB130": 000 = 38400 ... 101 = 1200; 110 = 115200 and
#: 111 = 57600 on CPUs from version 1.2)
BAUDS: tuple[int, ...] = (38400, 19200, 9600, 4800, 2400, 1200, 115200, 57600)
#: bits per second -> baud code (what a library writes into SMB30 / SMB130)
BAUD_CODE: dict[int, int] = {baud: code for code, baud in enumerate(BAUDS)}
#: protocol code (bits 1..0) -> name; 11 is reserved and means PPI slave
PROTOCOLS: tuple[str, ...] = ("PPI slave", "freeport", "PPI master", "PPI slave")
#: the shortest character any port can send (7 data bits, no parity, 115200
#: baud: 9 bits = 78.125 µs), whole µs below it: the longest lockstep window
#: of linked CPUs (plcrt.engine.link)
MIN_CHAR_US = 9 * 1_000_000 // 115200


#: pointer area code (plcrt.compiler.operands.POINTER_AREAS) -> the areas an
#: instruction's table may be in (System Manual, XMT/RCV/NETR/NETW operands)
TABLE_AREAS = {0x01: "I", 0x02: "Q", 0x03: "M", 0x04: "S", 0x05: "SM", 0x08: "V"}


def table_at(areas: dict[str, bytearray], ptr: int,
             size: int = 1) -> Optional[tuple[bytearray, int]]:
    """The buffer and offset of a *size*-byte table *ptr* points to, or None."""
    name = TABLE_AREAS.get(ptr >> 24)
    off = ptr & 0xFFFFFF
    if name is None or off + size > len(areas[name]):
        return None
    return areas[name], off


@dataclass(frozen=True, slots=True)
class Framing:
    """One port's character format and speed."""

    baud: int
    data_bits: int      #: 8 or 7
    parity: str         #: "none", "even" or "odd"
    protocol: str       #: see PROTOCOLS

    @property
    def bits(self) -> int:
        """Bits per character: start, data, parity (if any), stop."""
        return 1 + self.data_bits + (self.parity != "none") + 1

    def end(self, start: int, chars: int, bits: Optional[int] = None) -> int:
        """The whole µs at or after the end of *chars* characters (or of
        *bits* bit times) sent from *start* (exact: no rounding adds up)."""
        n = chars * self.bits if bits is None else bits
        return start + -(-n * 1_000_000 // self.baud)

    def mask(self, byte: int) -> int:
        """The character as sent: 7 data bits drop the top bit."""
        return byte & (0x7F if self.data_bits == 7 else 0xFF)

    def describe(self) -> str:
        return (f"{self.baud} baud, {self.data_bits} data bits, {self.parity} parity, "
                f"{self.bits} bits per character")


def framing_of(control: int) -> Framing:
    """The framing SMB30/SMB130 = *control* selects."""
    pp = control >> 6 & 3
    return Framing(BAUDS[control >> 2 & 7], 7 if control & 0x20 else 8,
                   ("none", "even", "none", "odd")[pp], PROTOCOLS[control & 3])


class Inbox:
    """Things due at exact times, as an event source of the scheduler.

    An item is ``(t, seq, fn, args, link)``: at *t* the scheduler's fire
    calls ``fn(t, *args)``; *seq* keeps the order of items at one instant;
    *link* marks items that came from a linked CPU (a fork drops them).
    *touch(inbox)* tells the owner's scheduler that the next event moved
    (the first time, the inbox joins the scheduler's sources: ``joined``)."""

    #: the next event changes only through push (which touches) or fire
    cacheable = True

    def __init__(self, touch: Callable[[Any], None]) -> None:
        self.touch = touch
        self.items: list[tuple[int, int, Any, tuple, bool]] = []
        self._seq = 0
        self.joined = False       #: in the scheduler's sources

    def push(self, t: int, fn: Callable[..., None], *args: Any, link: bool = False) -> None:
        """Run ``fn(t, *args)`` at *t*."""
        self._seq += 1
        heapq.heappush(self.items, (t, self._seq, fn, args, link))
        self.touch(self)

    def live(self) -> bool:
        return bool(self.items)

    def next_time(self, after: int, until: int) -> Optional[int]:
        if not self.items:
            return None
        te = self.items[0][0]
        return te if after < te <= until else None

    def fire(self, t: int) -> None:
        items = self.items
        while items and items[0][0] <= t:
            _, _, fn, args, _ = heapq.heappop(items)
            fn(t, *args)

    def drop_links(self) -> None:
        """Forget what linked CPUs scheduled here (a fork is not linked)."""
        self.items = [x for x in self.items if not x[4]]
        heapq.heapify(self.items)
