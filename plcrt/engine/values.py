"""The values that cross plcrt's public boundary, and the one check of each.

``plcrt.load``'s :class:`~plcrt.engine.Plc`, the test harness, the command
line (``--set``, ``--watch``, ``--seconds``) and the debugger all take
values from a user: a number for an address, a read format (``VD4:REAL``),
a duration, a number of scans, a number written as text.  Each kind has
exactly one table or function here, so every entry point accepts and
refuses the same things with the same words:

* :func:`check_value` -- a Python number for a location of a given width
  (the S7-200 data types: bit; BYTE unsigned; INT/WORD and DINT/DWORD
  either signed or unsigned; REAL in a double word);
* :data:`FORMATS` and :func:`split_format` -- the ``:FORMAT`` suffixes of
  an address;
* :func:`parse_number` -- a number written as text (``12``, ``-3``,
  ``16#FF``, ``2#1010``, ``1.5``, ``2e3``, ``NaN``, ``Infinity``);
* :func:`duration` and :func:`scan_total` -- how long to run;
* :data:`NONFINITE` -- how a non-finite REAL is spelled in text and JSON;
* :func:`source_items`, :func:`check_load_options` and
  :func:`check_parsed_inputs` -- the program, files and options of
  :func:`plcrt.load`.

Every refusal is a :class:`~plcrt.errors.PlcAddressError` (a value for an
address) or :class:`~plcrt.errors.PlcConfigError` (an option) that says
what was expected.  This module does not know where addresses live; the
engine locates them and passes the width.
"""

from __future__ import annotations

import itertools
import math
import numbers
import re
import struct
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any, Union

from ..errors import PlcAddressError, PlcConfigError
from ..paths import check_path
from ..safetext import excerpt, printable, shown_value

Number = Union[int, float]
Duration = Union[int, float, str]

# ---------------------------------------------------------------------------
# Values for addresses
# ---------------------------------------------------------------------------

#: accepted integers by width in bytes (System Manual, "Data types"): a
#: byte is BYTE only, 0..255 -- the S7-200 has no signed byte -- while a
#: word may hold an INT or a WORD and a double word a DINT or a DWORD, so
#: both the signed and the unsigned range are accepted (-1 and 65535 are
#: the same word).
INT_RANGES: dict[int, tuple[int, int]] = {
    1: (0, 0xFF),
    2: (-0x8000, 0xFFFF),
    4: (-0x8000_0000, 0xFFFF_FFFF),
}
_TYPE_NAMES = {1: "a byte (BYTE)", 2: "a word (INT or WORD)", 4: "a double word (DINT or DWORD)"}

_F32 = struct.Struct(">f")
REAL_RANGE = "about -3.4e38 to 3.4e38"


def as_number(address: str, value: Any) -> Number:
    """``value`` as a Python int or float: bools, numpy scalars, Decimal and
    Fraction are taken as the number they are.

    Raises:
        PlcAddressError: ``value`` is not a number.
    """
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, (int, float)):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        try:
            return float(value)
        except OverflowError:   # a Fraction beyond any float: beyond every range
            return math.inf if value > 0 else -math.inf
    if hasattr(value, "item") and getattr(value, "shape", None) == ():
        item = value.item()   # numpy.bool_ and other 0-d numpy values
        if isinstance(item, (int, float)):
            return int(item) if isinstance(item, bool) else item
    raise PlcAddressError(f"{address}: {shown_value(value)} is not a number (expected an int, "
                          f"a float or a bool, got {type(value).__name__})")


def check_value(address: str, width: int, value: Any) -> Number:
    """``value`` checked for a location of ``width`` bytes (0 = a bit): the
    value to store, an int, or a float for a REAL.

    * a bit takes 0 or 1 (False, True);
    * a byte 0..255, a word -32768..65535, a double word
      -2147483648..4294967295 (see :data:`INT_RANGES`);
    * a float goes to a double word as a REAL if single precision can hold
      it: a finite value beyond about 3.4e38 is refused, while NaN and the
      infinities are stored as such (the REAL format has them, and the
      CPU's arithmetic produces them);
    * elsewhere a float must be a whole number (2.0 stores 2).

    Raises:
        PlcAddressError: the value does not fit, saying what does.
    """
    v = as_number(address, value)
    if width == 0:
        if v not in (0, 1):
            raise PlcAddressError(f"{address}: a bit takes 0 or 1, got {shown_value(value)}")
        return 1 if v else 0
    if isinstance(v, float):
        if width == 4:
            try:
                _F32.pack(v)
            except OverflowError:
                raise PlcAddressError(f"{address}: {shown_value(value)} is out of the range of "
                                      f"a REAL ({REAL_RANGE})") from None
            return v
        if not v.is_integer():
            raise PlcAddressError(f"{address}: a real value needs a double word (VD, MD, ...), "
                                  f"got {shown_value(value)}")
        v = int(v)
    lo, hi = INT_RANGES[width]
    if not lo <= v <= hi:
        extra = "; an S7-200 byte is unsigned" if width == 1 and v < 0 else ""
        raise PlcAddressError(f"{address}: {shown_value(value)} does not fit in "
                              f"{_TYPE_NAMES[width]}, which takes {lo} to {hi}{extra}")
    return v


# ---------------------------------------------------------------------------
# Read formats
# ---------------------------------------------------------------------------

#: the ``:FORMAT`` suffixes of an address (``VD4:REAL``, ``T37:BIT``) and
#: what each reads; the API's ``read(address, format)``, ``--watch``, the
#: harness, traces and the debugger all use this table
FORMATS: dict[str, str] = {
    "REAL": "a double word as a float (REAL)",
    "BIT": "the bit of a timer or counter (T37:BIT)",
}
#: other spellings accepted for a format
FORMAT_ALIASES: dict[str, str] = {"R": "REAL"}


def check_format(fmt: Any, spec: str, *, suffix: bool = False) -> str:
    """The canonical name of a format (``"REAL"``, ``"BIT"``, or ``""``
    for none), case and blanks ignored; ``suffix`` says it was written
    after the address (``VD4:REAL``), for the message.

    Raises:
        PlcAddressError: an unknown format, naming the accepted ones.
    """
    if fmt is None:
        return ""
    if not isinstance(fmt, str):
        raise PlcAddressError(f"{spec}: a format is a string such as 'REAL', got "
                              f"{type(fmt).__name__} {shown_value(fmt)}")
    name = fmt.strip().upper()
    name = FORMAT_ALIASES.get(name, name)
    if name and name not in FORMATS:
        known = "; ".join(f":{k} reads {v}" for k, v in FORMATS.items())
        shown = printable(fmt.strip())[:40]
        what = f"suffix ':{shown}'" if suffix else f"format {shown!r}"
        raise PlcAddressError(f"{spec}: unknown {what} ({known})")
    return name


def check_address(address: Any) -> str:
    """``address`` as a stripped string.

    Raises:
        PlcAddressError: not a string, or empty.
    """
    if not isinstance(address, str):
        raise PlcAddressError(f"an address is a string such as 'VW100', 'Q0.0' or a symbol "
                              f"name, got {type(address).__name__} {shown_value(address)}")
    text = address.strip()
    if not text:
        raise PlcAddressError("an address is a string such as 'VW100', 'Q0.0' or a symbol "
                              "name, got an empty string")
    if len(text) > MAX_ADDRESS_CHARS:
        # no address or symbol is this long (Micro/WIN symbols have at most
        # 23 characters); quoting it whole would flood the terminal
        raise PlcAddressError(f"{excerpt(text)!r} is {len(text)} characters long: no address "
                              f"or symbol name has more than {MAX_ADDRESS_CHARS}")
    return text


#: longest address spec accepted (a symbol with a format suffix fits easily)
MAX_ADDRESS_CHARS = 256


def split_format(spec: Any, fmt: Any = None) -> tuple[str, str]:
    """``(address, format)`` of ``"VD4:REAL"`` or of ``("VD4", "REAL")``;
    the format is canonical (see :func:`check_format`).

    Raises:
        PlcAddressError: a bad address or format, or a format given twice.
    """
    text = check_address(spec)
    addr, sep, suffix = text.rpartition(":")
    if sep:
        addr = addr.strip()
        if not addr:
            raise PlcAddressError(f"{printable(text)[:60]!r}: an address must come before "
                                  f"':{printable(suffix.strip())[:20]}'")
        name = check_format(suffix, printable(text)[:60], suffix=True)
        if fmt is not None and check_format(fmt, addr) != name:
            raise PlcAddressError(f"{printable(text)[:60]}: the format is given twice "
                                  f"(also as {shown_value(fmt)}); give it once")
        return addr, name
    return text, check_format(fmt, printable(text)[:60])


# ---------------------------------------------------------------------------
# Numbers written as text (--set, the debugger, test conditions)
# ---------------------------------------------------------------------------

#: how non-finite REALs are written in text and JSON (JSON has no token for
#: them); :func:`parse_number` reads the same spellings back
NONFINITE: dict[str, float] = {"NaN": math.nan, "Infinity": math.inf,
                               "-Infinity": -math.inf}
_NONFINITE_IN = {k.upper(): v for k, v in NONFINITE.items()}
_NONFINITE_IN.update({"+INFINITY": math.inf, "INF": math.inf, "+INF": math.inf,
                      "-INF": -math.inf})

# After the STL constant forms (16#FF, 2#1010) so a value can be copied
# from a program.  Reals need a dot or an exponent.
_DEC_RE = re.compile(r"[+-]?\d+")
_HEX_RE = re.compile(r"16#([0-9A-Fa-f][0-9A-Fa-f_]*)")
_BIN_RE = re.compile(r"2#([01][01_]*)")
_REAL_RE = re.compile(r"[+-]?(\d+\.\d*|\.\d+|\d+(?=[eE]))([eE][+-]?\d+)?")
#: longer than any value a location holds needs (a REAL's 9 significant
#: digits and an exponent, or a 32-bit binary constant)
MAX_NUMBER_TEXT = 64

NUMBER_FORMS = ("a decimal (12, -3), 16#hex, 2#binary, a real (1.5, 2e3) "
                "or NaN, Infinity, -Infinity")


def parse_number(text: str) -> Number:
    """A number written as text: decimal, ``16#hex``, ``2#binary``, a real
    (``1.5``, ``2e3``) or a non-finite REAL (``NaN``, ``Infinity``,
    ``-Infinity``, also ``inf``).

    Raises:
        PlcConfigError: anything else, a real literal beyond the REAL range
            (``1e999``: it would silently become infinity) or a text too
            long to be a value of any location.
    """
    t = text.strip()
    if len(t) > MAX_NUMBER_TEXT:
        raise PlcConfigError(f"bad value '{printable(t[:20])}...' ({len(t)} characters): "
                             f"too long for a number; use {NUMBER_FORMS}")
    if _DEC_RE.fullmatch(t):
        return int(t)
    m = _HEX_RE.fullmatch(t)
    if m:
        return int(m.group(1).replace("_", ""), 16)
    m = _BIN_RE.fullmatch(t)
    if m:
        return int(m.group(1).replace("_", ""), 2)
    if _REAL_RE.fullmatch(t):
        v = float(t)
        try:
            _F32.pack(v)
        except OverflowError:
            v = math.inf
        if math.isinf(v):
            raise PlcConfigError(f"{t} is out of the range of a REAL ({REAL_RANGE}); "
                                 f"write Infinity or -Infinity for an infinite REAL")
        return v
    special = _NONFINITE_IN.get(t.upper())
    if special is not None:
        return special
    raise PlcConfigError(f"bad value '{printable(t)}': use {NUMBER_FORMS}")


def json_number(value: Number) -> Number | str:
    """A value for strict JSON: non-finite floats as the strings of
    :data:`NONFINITE` (``"NaN"``, ``"Infinity"``, ``"-Infinity"``)."""
    if isinstance(value, float) and not math.isfinite(value):
        return "NaN" if math.isnan(value) else ("Infinity" if value > 0 else "-Infinity")
    return value


# ---------------------------------------------------------------------------
# How long to run
# ---------------------------------------------------------------------------

_UNITS = {"us": 1e-6, "µs": 1e-6, "ms": 1e-3, "s": 1.0, "sec": 1.0, "min": 60.0, "h": 3600.0}
_DURATION_RE = re.compile(r"^\s*([0-9]+(?:\.[0-9]*)?|\.[0-9]+)\s*(us|µs|ms|s|sec|min|h)?\s*$")

#: most scans one call runs (``scan``, ``run``, the harness's waits and
#: stimuli), and most bus cycles one ``advance()`` of the CANopen simulator
#: runs: about an hour of wall time at the fastest (a few µs a scan), 115
#: days of simulated time at the default 10 ms scans.  A span or count
#: beyond it cannot end in any useful time (``run(1e300)``,
#: ``scans=2**70``) and is refused before anything runs
#: (docs/decisions.md, "Values at the public boundary").
MAX_STEPS = 10**9


def _seconds_shown(d: Any) -> str:
    if isinstance(d, numbers.Integral) and not isinstance(d, bool) and int(d).bit_length() > 200:
        # the order of magnitude, without str() of a huge int (slow, refused
        # above 4300 digits)
        return f"{'-' if d < 0 else ''}about 1e{int(int(d).bit_length() * 0.30103)}"
    return shown_value(d)


def duration(d: Any, what: str = "") -> float:
    """A duration in seconds from ``1.5``, ``"1.5s"``, ``"200ms"``,
    ``"250us"``, ``"2min"``, ``"1h"``.

    ``what`` names the argument in messages.

    Raises:
        PlcConfigError: not a finite, non-negative number of seconds whose
            microseconds a float can count.
    """
    where = f"{what}: " if what else ""
    forms = "write e.g. 2, '1.5s', '200ms', '2min'"
    if isinstance(d, str):
        m = _DURATION_RE.match(d) if len(d) <= MAX_NUMBER_TEXT else None
        if m is None:
            raise PlcConfigError(f"{where}not a duration: {shown_value(d)} ({forms})")
        value = float(m.group(1)) * _UNITS[m.group(2) or "s"]
    elif isinstance(d, numbers.Real) and not isinstance(d, bool):
        try:
            value = float(d)
        except OverflowError:
            # an int (or Fraction) beyond any float: too long if positive,
            # refused as negative below otherwise
            if d > 0:
                raise PlcConfigError(f"{where}a duration of {_seconds_shown(d)} s is too long "
                                     f"to count in microseconds") from None
            value = -math.inf
    else:
        raise PlcConfigError(f"{where}not a duration: {type(d).__name__} {shown_value(d)} "
                             f"(a number of seconds or a string; {forms})")
    if not (math.isfinite(value) and value >= 0):
        raise PlcConfigError(f"{where}a duration must be a non-negative, finite time, "
                             f"got {_seconds_shown(d)}")
    if not math.isfinite(value * 1e6):
        # simulated time is counted in whole microseconds: the count must
        # exist (about 1.8e302 s and more overflow a float)
        raise PlcConfigError(f"{where}a duration of {_seconds_shown(d)} s is too long to "
                             f"count in microseconds")
    return value


def duration_us(d: Any, what: str = "") -> int:
    """:func:`duration` in whole microseconds (the engine's unit of time)."""
    return int(round(duration(d, what) * 1e6))


def scan_number(n: Any, what: str = "the number of scans", bounded: bool = True) -> int:
    """A number of scans: a whole number from 0 to :data:`MAX_STEPS` (any
    size if not ``bounded``; numpy ints too).

    Raises:
        PlcConfigError: a negative, fractional, non-numeric or too large count.
    """
    if isinstance(n, bool) or not isinstance(n, numbers.Integral):
        if isinstance(n, float) and n.is_integer():
            raise PlcConfigError(f"{what} must be an int, got the float {shown_value(n)}; "
                                 f"write {int(n)}")
        raise PlcConfigError(f"{what} must be a whole number (an int), got "
                             f"{type(n).__name__} {shown_value(n)}")
    n = int(n)
    if n < 0:
        raise PlcConfigError(f"{what} must not be negative, got {shown_value(n)}")
    if n > MAX_STEPS and bounded:
        raise PlcConfigError(f"{what} must be at most {MAX_STEPS:_} (one call runs at most "
                             f"that many scans: split a longer run into several calls), "
                             f"got {shown_value(n)}")
    return n


def step_count(span_us: int, step_us: int, d: Any = None, what: str = "",
               step: str = "scan") -> int:
    """How many steps of ``step_us`` (scans, bus cycles) cover ``span_us``,
    a partial last step counting as one; ``d`` is the duration as the user
    gave it and ``what`` names it, for the message.

    Raises:
        PlcConfigError: more than :data:`MAX_STEPS` steps.
    """
    n = -(-span_us // step_us)
    if n > MAX_STEPS:
        where = f"{what}: " if what else ""
        shown = _seconds_shown(d) if d is not None else f"{span_us / 1e6:g}"
        raise PlcConfigError(
            f"{where}{shown} s at {step_us / 1000:g} ms a {step} is more than "
            f"{MAX_STEPS:_} {step}s, the most one call runs (at this {step} time, "
            f"{MAX_STEPS * step_us / 86_400e6:.3g} days): split a longer run into "
            f"several calls")
    return n


def scan_total(scan_us: int, seconds: Any = None, scans: Any = None,
               what: str = "seconds", bounded: bool = True) -> int:
    """How many scans ``run(seconds=...)`` or ``run(scans=...)`` runs: a
    duration is rounded up to whole scans (a partial last scan is a scan).
    ``bounded=False`` lifts :data:`MAX_STEPS` from a duration, for a run
    that another limit ends (a wall-clock limit).

    Raises:
        PlcConfigError: neither or both given, a bad value, or more than
            :data:`MAX_STEPS` scans.
    """
    if (seconds is None) == (scans is None):
        raise PlcConfigError("give exactly one of seconds (a duration such as 1.5 or '1.5s') "
                             "or scans=")
    if scans is not None:
        return scan_number(scans, "scans", bounded)
    if not bounded:
        return -(-duration_us(seconds, what) // scan_us)
    return step_count(duration_us(seconds, what), scan_us, seconds, what)


# ---------------------------------------------------------------------------
# The scan time
# ---------------------------------------------------------------------------

#: the scan times accepted, in ms: 1 µs to one minute
SCAN_MS_RANGE = (0.001, 60000)


def scan_time_us(scan_ms: Any, what: str = "scan time") -> int:
    """The scan time ``scan_ms`` (milliseconds: ``load(scan_ms=...)``,
    ``--scan-ms``, the pytest marker and ``--plc-scan-ms``) in whole
    microseconds, the unit the engine counts time in.

    Raises:
        PlcConfigError: not a number, outside :data:`SCAN_MS_RANGE`, or not
            a whole number of microseconds (``0.0015`` ms would have to be
            rounded to 1 or 2 µs, and every timer would drift from what
            the test asked for; see docs/decisions.md).
    """
    lo, hi = SCAN_MS_RANGE
    if isinstance(scan_ms, bool) or not isinstance(scan_ms, numbers.Real) \
            or not _fits_float(scan_ms) or not lo <= float(scan_ms) <= hi:
        raise PlcConfigError(f"{what} must be between {lo:g} and {hi:g} ms, got "
                             f"{shown_value(scan_ms)}")
    us = float(scan_ms) * 1000
    whole = round(us)
    # 1e-6 µs: far below any scan time one means, far above the float
    # error of writing one in ms (1.1 ms is 1100.0000000000002 µs)
    if abs(us - whole) > 1e-6:
        raise PlcConfigError(f"{what} must be a whole number of microseconds (the simulated "
                             f"clock counts µs): {shown_value(scan_ms)} ms is {us:.6g} µs; give "
                             f"{max(1, math.floor(us)) / 1000:g} or "
                             f"{math.ceil(us) / 1000:g}")
    return whole


def _fits_float(x: Any) -> bool:
    try:
        return math.isfinite(float(x))
    except (OverflowError, ValueError, TypeError):
        return False


# ---------------------------------------------------------------------------
# The arguments of plcrt.load() and Plc()
# ---------------------------------------------------------------------------

#: the keyword options of load() besides symbols, data, scan_ms and cpu
LOAD_OPTIONS = ("plant", "pace", "watchdog_ms", "instrument", "system_symbols", "library",
                "max_file_mb", "auto_symbols", "clock", "backend", "entry")

#: the code generators a program can be loaded with (plcrt.compiler.native);
#: "auto" is native where llvmlite works, else Python
BACKENDS = ("auto", "python", "native")


def check_backend(backend: Any) -> str:
    """The code generator to load with, ``"python"`` or ``"native"``:
    ``backend``, or when it is None the environment's ``PLCRT_BACKEND`` (a
    test suite pinned to one backend: ``PLCRT_BACKEND=python pytest``), else
    ``"auto"``, which is native where llvmlite imports and works and Python
    otherwise (:func:`plcrt.compiler.native.jit.auto_backend` says so once)."""
    if backend is None:
        import os
        backend = os.environ.get("PLCRT_BACKEND") or "auto"
        if backend not in BACKENDS:
            raise PlcConfigError(f"PLCRT_BACKEND must be one of "
                                 f"{', '.join(BACKENDS)}, got {shown_value(backend)}")
    if not isinstance(backend, str) or backend not in BACKENDS:
        raise PlcConfigError(f"backend must be one of {', '.join(map(repr, BACKENDS))}, "
                             f"got {shown_value(backend)}")
    if backend == "auto":
        from ..compiler.native.jit import auto_backend
        return auto_backend()
    return backend

_SOURCE_FORMS = "a file path (str or pathlib.Path), STL text (a str with a newline)"


#: most files (or texts) one program is merged from: Micro/WIN exports a
#: project as one file, libraries add a few; the bound keeps an endless
#: iterable from being read without end
MAX_SOURCES = 1000


def source_items(sources: Any) -> list[str | Path]:
    """The program sources of load() as a list, each checked.

    ``bytes`` are refused rather than guessed at: a file's path lets plcrt
    read and decode it as Micro/WIN wrote it (see docs/decisions.md).
    """
    if isinstance(sources, (str, Path, bytes, bytearray, Mapping)) \
            or not isinstance(sources, Iterable):
        items = [sources]
    else:
        try:
            # one more than allowed, so that a longer (or endless) iterable
            # is refused without being read to its end
            items = list(itertools.islice(iter(sources), MAX_SOURCES + 1))
        except TypeError:
            # an object that says it is iterable and is not (a 0-d array)
            items = [sources]
        if not items:
            raise PlcConfigError("no program given: the list of program files is empty")
        if len(items) > MAX_SOURCES:
            raise PlcConfigError(f"a program is at most {MAX_SOURCES} files (or texts) "
                                 f"whose blocks are merged; got more")
    for x in items:
        _check_text_or_path(x, "the program", _SOURCE_FORMS + ", or a list of them")
    return items


def _check_text_or_path(x: Any, what: str, forms: str) -> None:
    if isinstance(x, (bytes, bytearray)):
        raise PlcConfigError(f"{what} is {type(x).__name__}; give {forms} -- to load a file "
                             f"pass its path, which plcrt reads and decodes as Micro/WIN "
                             f"wrote it, or decode the bytes to str first")
    if isinstance(x, str) and not x.strip():
        raise PlcConfigError(f"{what} is an empty string; give {forms}")
    if not isinstance(x, (str, Path)):
        raise PlcConfigError(f"{what} must be {forms}; got {_typed(x)}")
    from ..lang.sources import is_file_arg
    if is_file_arg(x):
        check_path(x, f"{what}: the file name")


def check_load_options(*, symbols: Any, data: Any, plant: Any, options: dict[str, Any]) -> None:
    """load()'s file arguments given as text or paths, and its options."""
    unknown = sorted(k for k in options if k not in LOAD_OPTIONS)
    if unknown:
        raise PlcConfigError(f"load() got unknown option(s) {', '.join(map(repr, unknown))}; "
                             f"the options are symbols, data, scan_ms, cpu, encoding, "
                             f"{', '.join(LOAD_OPTIONS)}")
    for what, x in (("symbols", symbols), ("data", data), ("plant", plant)):
        if isinstance(x, (str, bytes, bytearray, Path)):
            _check_text_or_path(x, what, "a file path or the file's text")


def check_parsed_inputs(symbols: Any, data: Any, plant: Any,
                        is_plant: Callable[[Any], bool]) -> None:
    """Plc()'s symbols, data and plant: parsed, or None (*is_plant* tells a
    parsed plant: :attr:`plcrt.parts.Parts.is_plant`)."""
    from ..lang import DataBlock, SymbolTable
    for what, x, ok, forms in (
            ("symbols", symbols, isinstance(symbols, SymbolTable),
             "a symbol table's path or text, or a plcrt.lang.SymbolTable"),
            ("data", data, isinstance(data, DataBlock),
             "a data block's path or text, or a plcrt.lang.DataBlock"),
            ("plant", plant, plant is None or is_plant(plant),
             "a plant file's path or TOML text, a dict, or a plcrt.devices.plant.Plant")):
        if x is not None and not ok:
            raise PlcConfigError(f"{what} must be {forms}; got {_typed(x)}")


def _typed(x: Any) -> str:
    return f"{type(x).__name__} {shown_value(x)[:40]}"


__all__ = ["FORMATS", "FORMAT_ALIASES", "INT_RANGES", "LOAD_OPTIONS", "MAX_STEPS", "NONFINITE",
           "NUMBER_FORMS", "SCAN_MS_RANGE", "as_number", "check_address", "check_format",
           "check_load_options", "check_parsed_inputs", "check_value", "duration",
           "duration_us", "json_number", "parse_number", "scan_number", "scan_time_us",
           "scan_total", "shown_value", "source_items", "split_format", "step_count"]
