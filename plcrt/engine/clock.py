"""The CPU's simulated real-time clock and its SMART extras (TODR, TODW,
TODRX, TODWX; the station settings of DLED, GPA and SPA).

What it is: the state a forked PLC copies (:meth:`plcrt.Plc.fork` deep-
copies :class:`Clock` and :class:`Station`) and the BCD buffer formats of
the clock instructions (S7-200 System Manual, "Clock instructions": byte 0
year 00..99, 1 month, 2 day, 3 hour, 4 minute, 5 second, 6 always 0, 7 day
of week 1..7 with 1 = Sunday and 0 = day of week disabled; S7-200 SMART
System Manual, "Read/set real-time clock extended": bytes 8..18 the
daylight-saving mode and its rule).

What it is not: no wall clock.  The clock starts at a fixed date
(:data:`DEFAULT_START`) unless the program is loaded with ``clock=`` (or
``--clock``, or the plant file's ``[cpu] clock``), and it advances with
simulated time only, so runs are deterministic.  With a daylight-saving
mode set by TODWX the reading is ahead by the correction inside the
daylight-saving window (:mod:`plcrt.engine.dst`); the clock keeps standard
time underneath.
"""

from __future__ import annotations

import datetime as _dt
from typing import Any

from ..errors import PlcConfigError
from . import dst as _dst

#: the clock's reading at power-up when no start is given (a Monday)
DEFAULT_START = _dt.datetime(2024, 1, 1, 0, 0, 0)
#: the two BCD year digits cover 2000..2099
FIRST_YEAR, LAST_YEAR = 2000, 2099
_EPOCH = _dt.datetime(FIRST_YEAR, 1, 1)

#: bytes 0..7 of a clock buffer that must hold these BCD values (TODW)
_RANGES = ((0, 0, 99), (1, 1, 12), (2, 1, 31), (3, 0, 23), (4, 0, 59), (5, 0, 59), (7, 0, 7))
#: TODWX byte 8: 0 off, 1-3 and 8 EU (UTC, +1 h, +2 h, -1 h), 16 US,
#: 17 Australia, 18 Tasmania, 19 New Zealand, 255 the rule in bytes 9..18
DST_MODES = frozenset((0x00, 0x01, 0x02, 0x03, 0x08, 0x10, 0x11, 0x12, 0x13, 0xFF))
#: bytes 9..18 of the user rule (mode 16#FF): correction hours and minutes,
#: start month, day, hour, minute, end month, day, hour, minute
_DST_RANGES = ((9, 0, 23), (10, 0, 59), (11, 1, 12), (12, 1, 31), (13, 0, 23), (14, 0, 59),
               (15, 1, 12), (16, 1, 31), (17, 0, 23), (18, 0, 59))


def bcd(value: int) -> int:
    """Two BCD digits of 0..99."""
    return (value // 10) << 4 | value % 10


def from_bcd(byte: int) -> int | None:
    """The value of two BCD digits, ``None`` for a digit above 9."""
    hi, lo = byte >> 4, byte & 15
    return None if hi > 9 or lo > 9 else hi * 10 + lo


def _valid(buf: bytes, ranges: tuple[tuple[int, int, int], ...]) -> bool:
    for i, lo, hi in ranges:
        v = from_bcd(buf[i])
        if v is None or not lo <= v <= hi:
            return False
    return True


def start_time(value: Any, what: str = "clock") -> _dt.datetime:
    """The clock's start from ``load(clock=...)``, ``--clock`` or the plant
    file: a :class:`datetime.datetime`, an ISO text ``2026-12-02T08:00:00``
    (``T`` or a space; seconds optional), ``"now"`` for the host's local
    time, or ``None`` for :data:`DEFAULT_START`.

    Raises:
        PlcConfigError: not one of these, or a year outside 2000..2099.
    """
    if value is None:
        return DEFAULT_START
    if isinstance(value, str):
        text = value.strip()
        if text.lower() == "now":
            t = _dt.datetime.now().replace(microsecond=0)
        else:
            try:
                t = _dt.datetime.fromisoformat(text)
            except ValueError:
                raise PlcConfigError(f"{what} must be a date and time like "
                                     f"2026-12-02T08:00:00 (or 'now'), got {value[:40]!r}") from None
    elif isinstance(value, _dt.datetime):
        t = value
    elif isinstance(value, _dt.date):
        t = _dt.datetime(value.year, value.month, value.day)
    else:
        raise PlcConfigError(f"{what} must be a datetime or a text like 2026-12-02T08:00:00, "
                             f"got {type(value).__name__}")
    if t.tzinfo is not None:
        t = t.replace(tzinfo=None)   # the S7-200 clock has no time zone: keep the wall reading
    if not FIRST_YEAR <= t.year <= LAST_YEAR:
        raise PlcConfigError(f"{what}: the S7-200 clock keeps two year digits, so the year "
                             f"must be {FIRST_YEAR}..{LAST_YEAR}, got {t.year}")
    return t.replace(microsecond=0)


class Clock:
    """The real-time clock: a calendar reading that advances with the
    simulated time of ``owner`` (its ``_irq_t``, the instant the running
    code executes at, in µs)."""

    def __init__(self, start: _dt.datetime, owner: Any) -> None:
        self.owner = owner
        self.base_s = int((start - _EPOCH).total_seconds())   #: standard time at set_us
        self.set_us = 0                 #: simulated time of the last set
        self.dow_shift = 0              #: TODW's day of week minus the calendar's (mod 7)
        self.dow_off = False            #: day of week written as 0 (disabled)
        self.dst = bytes(11)            #: TODWX bytes 8..18 as written

    def seconds(self, t_us: int | None = None) -> int:
        """Seconds since 2000-01-01 00:00:00 of the clock's standard time."""
        if t_us is None:
            t_us = self.owner._irq_t
        return self.base_s + (t_us - self.set_us) // 1_000_000

    def now(self, t_us: int | None = None) -> _dt.datetime:
        """The clock's reading at simulated time *t_us* (default: the time
        the running code executes at, what a TODR reads), wrapping from 2099
        to 2000 as the two year digits do."""
        s = self.seconds(t_us) % _CENTURY_S
        standard = _EPOCH + _dt.timedelta(seconds=s)
        if not self.dst[0]:
            return standard
        return standard + _dst.offset(standard, self.dst[0], self.dst[1:])

    def day_of_week(self, t: _dt.datetime) -> int:
        """1 = Sunday .. 7 = Saturday, shifted as TODW wrote it; 0 when disabled."""
        if self.dow_off:
            return 0
        return (t.isoweekday() % 7 + self.dow_shift) % 7 + 1

    # -- the instructions ------------------------------------------------
    def read(self, buf: bytearray, off: int) -> None:
        """TODR: the 8-byte BCD reading at ``buf[off:off + 8]``."""
        t = self.now()
        buf[off:off + 8] = bytes((bcd(t.year % 100), bcd(t.month), bcd(t.day), bcd(t.hour),
                                  bcd(t.minute), bcd(t.second), 0, self.day_of_week(t)))

    def write(self, buf: bytearray, off: int) -> bool:
        """TODW: set the clock from ``buf[off:off + 8]``; False (clock
        unchanged) for a non-BCD digit or a field out of its range (error
        0007, TOD data error).  A day the month lacks (February 30) is
        accepted, as the manual says the CPU does not check it; the calendar
        carries it into the next month."""
        data = bytes(buf[off:off + 8])
        if not _valid(data, _RANGES):
            return False
        year, month, day, hour, minute, second = (from_bcd(b) for b in data[:6])
        t = (_dt.datetime(FIRST_YEAR + year, month, 1, hour, minute, second)
             + _dt.timedelta(days=day - 1))
        standard = t
        if self.dst[0]:
            # the time written is the clock's reading: inside the daylight-
            # saving window it is ahead of standard time by the correction
            w = _dst.window(self.dst[0], self.dst[1:], t.year)
            if w is not None and _dst.offset(t - w[2], self.dst[0], self.dst[1:]):
                standard = t - w[2]
        self.base_s = int((standard - _EPOCH).total_seconds()) % _CENTURY_S
        self.set_us = self.owner._irq_t
        dow = from_bcd(data[7])
        self.dow_off = dow == 0
        if dow:
            # the CPU keeps the day of week it was given, right or wrong,
            # and counts it on at midnight (System Manual, TODW)
            self.dow_shift = (dow - 1 - t.isoweekday() % 7) % 7
        return True

    def read_ext(self, buf: bytearray, off: int) -> None:
        """TODRX: the reading, then the daylight-saving bytes 8..18."""
        self.read(buf, off)
        buf[off + 8:off + 19] = self.dst

    def write_ext(self, buf: bytearray, off: int) -> bool:
        """TODWX: bytes 0..7 as TODW (the time under the new daylight-saving
        setting), byte 8 one of :data:`DST_MODES`, and for the user rule
        (16#FF) bytes 9..18 valid BCD in their ranges; False (nothing
        changed) otherwise."""
        data = bytes(buf[off:off + 19])
        if data[8] not in DST_MODES or (data[8] == 0xFF and not _valid(data, _DST_RANGES)):
            return False
        old, self.dst = self.dst, data[8:19]
        if not self.write(data, 0):
            self.dst = old
            return False
        return True


_CENTURY_S = int((_dt.datetime(LAST_YEAR + 1, 1, 1) - _EPOCH).total_seconds())

#: GPA/SPA ports and station addresses (S7-200 System Manual, "Get Port
#: Address and Set Port Address": PPI station addresses 0..126)
from ..memory.hardware import PORTS  # noqa: E402
ADDRESS_RANGE = range(0, 127)
DEFAULT_ADDRESS = 2   #: Micro/WIN's default CPU station address


class Station:
    """The CPU's own simulated settings that the program can change: the
    diagnostic LED (DLED) and the port station addresses (GPA, SPA)."""

    def __init__(self) -> None:
        self.led = False                                   #: DLED: on (yellow) or off
        self.addresses = {p: DEFAULT_ADDRESS for p in PORTS}  #: port -> station address

    def dled(self, value: int) -> None:
        """DLED IN: the LED is off for IN = 0 and on for any other value."""
        self.led = value != 0

    def get_address(self, port: int) -> int:
        return self.addresses[port]

    def set_address(self, port: int, address: int) -> bool:
        """SPA: False (address unchanged) for an address outside 0..126."""
        if address not in ADDRESS_RANGE:
            return False
        self.addresses[port] = address
        return True


__all__ = ["ADDRESS_RANGE", "Clock", "DEFAULT_ADDRESS", "DEFAULT_START", "DST_MODES", "PORTS",
           "Station", "bcd", "from_bcd", "start_time"]
