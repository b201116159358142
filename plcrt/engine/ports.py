"""The CPU's communication ports 0 and 1 in freeport mode: XMT and RCV.

What it is: :class:`Port`, one RS-485 port as an event source of the scan's
time line (:class:`plcrt.engine.events.Scheduler`; its timed items are an
:class:`plcrt.engine.serial.Inbox`).  S7-200 System Manual, "Communications
instructions" (Transmit, Receive) and "Freeport mode":

* SMB30 / SMB130 select the protocol, baud rate, data bits and parity; they
  are read when XMT or RCV executes and when a character arrives.  Freeport
  needs protocol 01 and the CPU in RUN (plcrt runs code only in RUN); in
  PPI mode XMT and RCV do nothing and give ENO 0.
* ``XMT TBL, PORT``: TBL holds a count byte and the characters (count 0
  sends a break of 16 bit times).  SM4.5 / SM4.6 are the transmitters'
  idle bits; the transmit-complete event 9 / 26 occurs when the last stop
  bit ends.  The port is half duplex: XMT while a receive runs, or RCV
  while a transmission runs, is the manual's error 0009 / 000B.
* ``RCV TBL, PORT``: the receive message function, set up by SMB87..SMB94 /
  SMB187..SMB194 (control byte ``en sc ec il c/m tmr bk 0``, start and end
  character, idle-line time SMW90, timer SMW92, maximum count SMB94); it
  ends for the reason SMB86 / SMB186 records (``n r e 0 0 t c p``) with
  the message-complete event 23 / 24.
* every character received in freeport mode gives the receive-character
  event 8 / 25 with the character in SMB2 and its parity error in SM3.0.

What is at the other end is a *peer*: a scripted device
(:mod:`plcrt.devices.portdev`) or a linked CPU's port (:mod:`.link`); with
none, what is sent is reported as unanswered.  NETR/NETW jobs live in
:mod:`.netjobs` and use this port's inbox.  What it is not: no PPI slave
protocol (a port in PPI mode ignores freeport characters).
"""

from __future__ import annotations

from typing import Any, Callable, Optional

from .serial import Framing, Inbox, framing_of, table_at

__all__ = ["Port", "make_ports", "PORTS_OF", "STATUS"]

#: SM layout per port: (SMB30-style control, receive status, receive control,
#: receive-character event, transmit-complete event, message event, SMB4 idle bit)
_LAYOUT = {0: (30, 86, 87, 8, 9, 23, 0x20), 1: (130, 186, 187, 25, 26, 24, 0x40)}
#: CPU model -> its ports (CPU 221, 222 and 224 have one, 224XP and 226 two)
from ..memory.hardware import PORTS_OF  # noqa: E402
#: SMB86 status bits: why the receive ended
STATUS = {"user": 0x80, "parameter": 0x40, "end": 0x20, "timer": 0x04, "count": 0x02,
          "parity": 0x01}
#: the first unanswered transmissions reported one by one (then one summary)
REPORTED = 20


class _Receive:
    """One receive message function in progress."""

    __slots__ = ("buf", "off", "max", "start", "end", "idle_us", "brk", "timeout_us",
                 "message_timer", "phase", "idle_ref", "count", "gen")

    def __init__(self) -> None:
        self.count = 0
        self.gen = 0


class Port(Inbox):
    """Port *number* of one CPU.

    *irq* is the CPU's interrupt system (its events are posted there),
    *warn(message, key)* reports once, *touch()* tells the scheduler that
    the next event moved."""

    def __init__(self, number: int, areas: dict[str, bytearray], irq: Any,
                 warn: Callable[[str, str], None], touch: Callable[[Any], None]) -> None:
        super().__init__(touch)
        self.number = number
        self.areas, self.sm = areas, areas["SM"]
        self.irq, self.post, self.warn = irq, irq.post, warn
        (self.control, self.status, self.rcontrol, self.ev_char, self.ev_xmt, self.ev_msg,
         self.idle_bit) = _LAYOUT[number]
        self.peer: Any = None              #: scripted device or linked port
        self.tx_end: Optional[int] = None  #: when the running transmission ends
        self.rx: Optional[_Receive] = None
        self.sent = 0                      #: characters sent
        self.received = 0                  #: characters received in freeport mode
        self.unanswered: list[tuple[int, bytes]] = []   #: (time, bytes) nobody answered
        self.unanswered_count = 0
        #: PPI: this CPU's station address and the PPI baud rate (plant)
        self.address = 2
        self.ppi_baud = 9600
        self.jobs: list[Any] = []          #: NETR/NETW jobs in progress
        #: a library that took the port (the Modbus master or slave): it
        #: gets the characters received, and sends with :meth:`send`
        self.owner: Any = None
        self.sm[4] |= self.idle_bit        # SM4.5 / SM4.6: the transmitter is idle

    # ------------------------------------------------------------ set-up
    def framing(self) -> Framing:
        """What SMB30 / SMB130 select now."""
        return framing_of(self.sm[self.control])

    def table(self, ptr: int) -> Optional[tuple[bytearray, int]]:
        """The buffer and offset a TBL pointer names, or None."""
        return table_at(self.areas, ptr)

    def _refuse(self, what: str, t: int, fr: Framing) -> bool:
        self.warn(f"{what} on port {self.number} at {t / 1e6:.6f} s: SMB{self.control} selects "
                  f"{fr.protocol} mode, not freeport (01): nothing is done, ENO = 0 (System "
                  f"Manual, XMT/RCV)", f"port-ppi-{self.number}-{what}")
        return False

    def _busy(self, what: str, t: int) -> bool:
        # System Manual, XMT/RCV: error 0009 (port 0) / 000B (port 1),
        # simultaneous XMT/RCV; a run-time programming error (SM4.3).  The
        # port is half duplex: one transmission or one receive at a time.
        self.sm[4] |= 0x08
        code = "0009" if self.number == 0 else "000B"
        running = "a transmission" if self.tx_end is not None else "a receive (RCV)"
        self.warn(f"{what} on port {self.number} at {t / 1e6:.6f} s while {running} is still "
                  f"running: error {code} (simultaneous XMT/RCV; the port is half duplex), "
                  f"nothing is done, ENO = 0, SM4.3 set", f"port-busy-{self.number}-{what}")
        return False

    def _bad_table(self, what: str, ptr: int, why: str) -> bool:
        self.warn(f"{what} on port {self.number}: the table at pointer 16#{ptr:08X} {why}; "
                  f"nothing is done, ENO = 0", f"port-table-{self.number}-{what}")
        return False

    # ------------------------------------------------------------ XMT
    def xmt(self, t: int, ptr: int) -> bool:
        """XMT at *t* of the table *ptr* points to; the ENO."""
        fr = self.framing()
        if fr.protocol != "freeport":
            return self._refuse("XMT", t, fr)
        if self.tx_end is not None or self.rx is not None:
            return self._busy("XMT", t)
        at = self.table(ptr)
        if at is None:
            return self._bad_table("XMT", ptr, "is not in I, Q, M, S, SM or V")
        buf, off = at
        n = buf[off]
        if off + 1 + n > len(buf):
            return self._bad_table("XMT", ptr, f"holds {n} characters past the end of its area")
        data = bytes(fr.mask(b) for b in buf[off + 1:off + 1 + n])
        self._send(t, fr, data, True)
        return True

    def send(self, t: int, data: bytes) -> int:
        """A library's transmission (the Modbus master's XMT): *data* from
        *t* in the port's framing, without the program's transmit-complete
        event (the library's own routine takes it); the end µs."""
        return self._send(t, self.framing(), bytes(self.framing().mask(b) for b in data),
                          False)

    def _send(self, t: int, fr: Framing, data: bytes, event: bool) -> int:
        n = len(data)
        # count 0: a break, the line held low for 16 bit times (System Manual, XMT)
        end = fr.end(t, n) if n else fr.end(t, 0, bits=16)
        self.tx_end = end
        self.sent += n
        self.sm[4] &= ~self.idle_bit & 0xFF
        self.push(end, self._xmt_done, event)
        if self.peer is not None:
            self.peer.transmit(self, t, fr, data)
        elif n:
            self.no_answer(fr.end(t, n), data, "no device is at the port")
        return end

    def _xmt_done(self, t: int, event: bool = True) -> None:
        self.tx_end = None
        self.sm[4] |= self.idle_bit
        if event:
            self.post(self.ev_xmt, t)

    def no_answer(self, t: int, data: bytes, why: str) -> None:
        """Bytes sent at the port that nobody answered (diagnostics)."""
        self.unanswered_count += 1
        if len(self.unanswered) < 1000:
            self.unanswered.append((t, data))
        k = self.unanswered_count
        if k <= REPORTED:
            self.warn(f"port {self.number}: {len(data)} byte(s) {data.hex(' ').upper()} sent "
                      f"until {t / 1e6:.6f} s went unanswered ({why})",
                      f"port-unanswered-{self.number}-{k}")
        elif k == REPORTED + 1:
            self.warn(f"port {self.number}: more unanswered transmissions follow; they are "
                      f"not listed (Port.unanswered holds the first 1000)",
                      f"port-unanswered-{self.number}-more")

    # ------------------------------------------------------------ the line in
    def receive(self, t0: int, fr: Framing, data: bytes, bad: frozenset[int] = frozenset(),
                link: bool = False) -> None:
        """Characters sent to this port from *t0* in framing *fr* (the
        characters at positions *bad* with a parity error): each arrives
        when its stop bit ends.  Empty *data* is a break."""
        if not data:
            self.push(fr.end(t0, 0, bits=16), self._break, link=link)
            return
        for k, byte in enumerate(data):
            self.push(fr.end(t0, k + 1), self._char, byte, fr, k in bad, fr.end(t0, k),
                      link=link)

    def _char(self, t: int, byte: int, fr: Framing, bad: bool, t_start: int) -> None:
        mine = self.framing()
        if mine.protocol != "freeport":
            return                  # a PPI port: not a freeport character
        # a sender with another speed or format garbles every character
        err = (fr.baud, fr.data_bits, fr.parity) != (mine.baud, mine.data_bits, mine.parity)
        if err:
            self.warn(f"port {self.number}: characters arrive as {fr.describe()}, the port is "
                      f"set to {mine.describe()}: they are received with an error (SM3.0)",
                      f"port-framing-{self.number}")
        err = err or (bad and mine.parity != "none")
        byte = mine.mask(byte)
        self.received += 1
        if self.owner is not None:
            self.owner.char(t, byte, err)     # the library's receive, not the program's
            return
        sm = self.sm
        # System Manual, "Receive character interrupt": SMB2 and SM3.0
        sm[2] = byte
        sm[3] = sm[3] & 0xFE | err
        self.post(self.ev_char, t)
        if self.rx is not None:
            self._rx_char(t, t_start, byte, err)

    def _break(self, t: int) -> None:
        rx = self.rx
        if rx is None or self.framing().protocol != "freeport":
            return
        if rx.brk and rx.phase in ("break", "start", "first"):
            rx.phase = "start" if rx.start is not None else "first"
        elif rx.phase == "idle":
            rx.idle_ref = t              # a break is activity: the idle time starts again

    # ------------------------------------------------------------ RCV
    def rcv(self, t: int, ptr: int) -> bool:
        """RCV at *t* into the buffer *ptr* points to; the ENO."""
        fr = self.framing()
        if fr.protocol != "freeport":
            return self._refuse("RCV", t, fr)
        sm = self.sm
        ctrl = sm[self.rcontrol]
        if not ctrl & 0x80:
            # en = 0: a running receive ends by user disable (SMB86.7)
            if self.rx is not None:
                self._end(t, STATUS["user"])
            return True
        if self.rx is not None or self.tx_end is not None:
            return self._busy("RCV", t)
        at = self.table(ptr)
        if at is None:
            return self._bad_table("RCV", ptr, "is not in I, Q, M, S, SM or V")
        base = self.rcontrol
        rx = _Receive()
        rx.buf, rx.off = at
        rx.max = sm[base + 7]
        il, sc, ec = ctrl & 0x10, ctrl & 0x40, ctrl & 0x20
        rx.brk = bool(ctrl & 0x02)
        idle_ms = sm[base + 3] << 8 | sm[base + 4]
        timer_ms = sm[base + 5] << 8 | sm[base + 6]
        rx.start = sm[base + 1] if sc else None
        rx.end = sm[base + 2] if ec else None
        rx.idle_us = idle_ms * 1000 if il else 0
        rx.timeout_us = timer_ms * 1000 if ctrl & 0x04 else 0
        rx.message_timer = bool(ctrl & 0x08)
        why = self._check(rx, il, ctrl & 0x04, timer_ms)
        sm[self.status] = 0
        if why:
            # "Receive parameter error sets SM86.6"; the function ends at once
            self.warn(f"RCV on port {self.number} at {t / 1e6:.6f} s: {why}; the receive ends "
                      f"with SMB{self.status}.6 set (parameter error), ENO = 0",
                      f"port-rcv-param-{self.number}")
            sm[self.status] = STATUS["parameter"]
            self._post_now(self.ev_msg, t)
            return False
        rx.idle_ref = t
        any_char = il and not idle_ms and not sc and not rx.brk
        if rx.brk:
            rx.phase = "break"
        elif rx.idle_us:
            rx.phase = "idle"
        elif sc:
            rx.phase = "start"
        else:
            rx.phase = "first"
        self.rx = rx
        rx.buf[rx.off] = 0
        if any_char and rx.timeout_us and rx.message_timer:
            # "any character": the message timer runs from the RCV, so that a
            # missing answer ends the receive (System Manual, RCV); the
            # inter-character timer starts with the first character
            self._arm(t)
        return True

    def _check(self, rx: _Receive, il: int, tmr: int, timer_ms: int) -> str:
        """What is wrong with the receive set-up ('' when nothing)."""
        if rx.max == 0:
            return f"the maximum character count SMB{self.rcontrol + 7} is 0 (1..255)"
        if rx.off + 1 + rx.max > len(rx.buf):
            return (f"a buffer of {rx.max} characters (SMB{self.rcontrol + 7}) runs past the "
                    f"end of its area")
        if not (il or rx.start is not None or rx.brk):
            return "no start condition (idle line, start character or break) is enabled"
        if il and rx.brk:
            return "idle line and break are both enabled as the start condition"
        if tmr and timer_ms == 0:
            return f"the timer is enabled with SMW{self.rcontrol + 5} = 0 ms"
        return ""

    def _arm(self, t: int) -> None:
        rx = self.rx
        rx.gen += 1
        self.push(t + rx.timeout_us, self._timeout, rx, rx.gen)

    def _timeout(self, t: int, rx: _Receive, gen: int) -> None:
        if rx is self.rx and gen == rx.gen:
            self._end(t, STATUS["timer"])

    def _rx_char(self, t: int, t_start: int, byte: int, err: bool) -> None:
        rx = self.rx
        phase = rx.phase
        if phase == "break":
            return
        if phase == "idle":
            if t_start - rx.idle_ref < rx.idle_us:
                rx.idle_ref = t                  # the line was busy: wait again
                return
            phase = "start" if rx.start is not None else "first"
        if phase == "start":
            if byte != rx.start:
                # the character after the idle line or break must be the start character
                rx.idle_ref = t
                rx.phase = "idle" if rx.idle_us else ("break" if rx.brk else "start")
                return
        if phase != "msg":
            rx.phase = "msg"
            if rx.timeout_us and rx.message_timer and rx.gen == 0:
                self._arm(t)                     # the message timer starts
        rx.buf[rx.off + 1 + rx.count] = byte
        rx.count += 1
        rx.buf[rx.off] = rx.count
        if err:
            self._end(t, STATUS["parity"])
        elif rx.end is not None and byte == rx.end and rx.count > (rx.start is not None):
            self._end(t, STATUS["end"])
        elif rx.count >= rx.max:
            self._end(t, STATUS["count"])
        elif rx.timeout_us and not rx.message_timer:
            self._arm(t)                         # inter-character timer restarts

    def _end(self, t: int, status: int) -> None:
        self.sm[self.status] = status
        self.rx = None
        self._post_now(self.ev_msg, t)

    def _post_now(self, event: int, t: int) -> None:
        """Post *event* at *t*, the time of the running code or event: an
        instruction of the main program gets its routine run at this
        instant, after the main program (an empty item at *t* makes the time
        line stop there); in a routine or an event the interrupt system runs
        it at this instant anyway."""
        self.post(event, t)
        if not self.irq.running:
            self.push(t, _nothing)

    # ------------------------------------------------------------ state
    def state(self) -> dict[str, Any]:
        fr = self.framing()
        return {"port": self.number, "mode": fr.protocol, "baud": fr.baud,
                "bits_per_char": fr.bits, "transmitting": self.tx_end is not None,
                "receiving": self.rx is not None, "sent": self.sent,
                "received": self.received, "unanswered": self.unanswered_count}


def _nothing(t: int) -> None:
    """An instant on the time line (see Port._post_now)."""


def make_ports(plc: Any, plant: Any) -> list[Port]:
    """The ports of *plc*'s CPU, with what the plant puts at their other end."""
    n = PORTS_OF.get(plc.model.name, 2)
    ports = [Port(k, plc.mem.areas, plc.interrupts, plc._irq_warn, plc._wake)
             for k in range(n)]
    cfgs = getattr(plant, "ports", None) or {}
    for k, cfg in cfgs.items():
        if k >= n:
            from ..errors import PlcConfigError
            raise PlcConfigError(f"{cfg.where}: the {plc.model.name} has port 0 only")
        ports[k].address, ports[k].ppi_baud = cfg.address, cfg.ppi_baud
    return ports
