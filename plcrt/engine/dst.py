"""Daylight-saving rules of the S7-200 SMART's clock (TODWX byte 8, the mode,
and bytes 9..18, the user rule).

What it is: pure functions that say, for a reading of the clock in
standard time, whether daylight saving is on and by how much the clock is
ahead.  The modes are those of the SMART System Manual ("Read/set real-time
clock extended"); the dates of the preset regions are their current civil
rules: EU from the last Sunday of March to the last Sunday of October at
01:00 UTC; US from the second Sunday of March 02:00 to the first Sunday of
November 02:00 (daylight time); Australia and Tasmania from the first
Sunday of October 02:00 to the first Sunday of April 03:00 (daylight
time); New Zealand from the last Sunday of September 02:00 to the first
Sunday of April 03:00.  Presets shift by one hour.  The user rule (16#FF)
starts at its start date and time (standard time) and ends at its end date
and time (daylight time), each year, shifted by its correction.

What it is not: the clock's state (:mod:`plcrt.engine.clock`).
"""

from __future__ import annotations

import calendar
import datetime as _dt

_HOUR = _dt.timedelta(hours=1)

#: mode -> ((month, n-th Sunday (-1 last), hour of standard time) at the start,
#:          the same at the end)
PRESETS: dict[int, tuple[tuple[int, int, int], tuple[int, int, int]]] = {
    0x01: ((3, -1, 1), (10, -1, 1)),     # EU, UTC
    0x02: ((3, -1, 2), (10, -1, 2)),     # EU, UTC + 1 h
    0x03: ((3, -1, 3), (10, -1, 3)),     # EU, UTC + 2 h
    0x08: ((3, -1, 0), (10, -1, 0)),     # EU, UTC - 1 h
    0x10: ((3, 2, 2), (11, 1, 1)),       # US
    0x11: ((10, 1, 2), (4, 1, 2)),       # Australia
    0x12: ((10, 1, 2), (4, 1, 2)),       # Australia, Tasmania
    0x13: ((9, -1, 2), (4, 1, 2)),       # New Zealand
}


def _from_bcd(b: int) -> int:
    return (b >> 4) * 10 + (b & 15)


def sunday(year: int, month: int, n: int) -> _dt.date:
    """The n-th Sunday of a month (n = -1: the last)."""
    days = calendar.monthrange(year, month)[1]
    sundays = [d for d in range(1, days + 1) if _dt.date(year, month, d).weekday() == 6]
    return _dt.date(year, month, sundays[n if n < 0 else n - 1])


def window(mode: int, rule: bytes, year: int
           ) -> tuple[_dt.datetime, _dt.datetime, _dt.timedelta] | None:
    """(start, end, correction) of the daylight-saving time of *year*, start
    and end in standard time; None when the mode has none (0, or a rule
    with no correction).  *rule* is TODWX bytes 9..18 (BCD, checked)."""
    if mode in PRESETS:
        (sm, sn, sh), (em, en, eh) = PRESETS[mode]
        start = _dt.datetime.combine(sunday(year, sm, sn), _dt.time(sh))
        end = _dt.datetime.combine(sunday(year, em, en), _dt.time(eh))
        return start, end, _HOUR
    if mode != 0xFF:
        return None
    ch, cm, sm, sd, sh, smin, em, ed, eh, emin = (_from_bcd(b) for b in rule[:10])
    corr = _dt.timedelta(hours=ch, minutes=cm)
    if not corr:
        return None
    # a day the month lacks (February 30) carries into the next month
    start = _dt.datetime(year, sm, 1, sh, smin) + _dt.timedelta(days=sd - 1)
    end = _dt.datetime(year, em, 1, eh, emin) + _dt.timedelta(days=ed - 1) - corr
    return start, end, corr


def offset(standard: _dt.datetime, mode: int, rule: bytes) -> _dt.timedelta:
    """How far the clock is ahead of *standard* time (0 outside daylight
    saving).  A window whose end comes before its start in the year (the
    southern hemisphere) runs over the new year."""
    w = window(mode, rule, standard.year)
    if w is None:
        return _dt.timedelta(0)
    start, end, corr = w
    on = start <= standard < end if start <= end else (standard >= start or standard < end)
    return corr if on else _dt.timedelta(0)


__all__ = ["PRESETS", "offset", "sunday", "window"]
