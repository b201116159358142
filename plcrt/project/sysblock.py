"""The system block of a Micro/WIN V4 or Micro/WIN SMART V2 project.

The system block is the CPU's configuration as Micro/WIN downloads it:
retentive ranges, the ports' station addresses and baud rates, input
filters and pulse catch, the outputs' state in STOP, passwords; a SMART
CPU's start-up mode, its type and firmware, its IP settings.  It lies in
the stream before the program block, after the preamble and four time
stamps (a flag byte and four more time stamps follow it).

:func:`read_system_block` finds it, reads it field by field with every
fixed byte checked, and returns a :class:`SystemBlock`: the settings plcrt
simulates (:class:`plcrt.memory.system.SystemSettings`: retentive ranges,
start-up mode, port addresses) and the ones it reports.  Where the block
is not found (another version of Micro/WIN, a layout not described), it
returns None and a one-line note: the project loads with the defaults.  A
block that is found but holds a value this reader does not know, or does
not end where it must, is refused with :class:`PlcConfigError` naming the
file, the section and the byte offset (docs/project-files.md, "System
block").

It reads the bytes; the engine applies the settings
(:mod:`plcrt.engine.power`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import cast

from ..errors import PlcConfigError
from ..memory.system import RetentiveRange, SystemSettings
from .stream import Cursor, binary_error

__all__ = ["SystemBlock", "read_system_block", "read_v3_system_block", "V4_SIZE"]

SECTION = "system block"
#: the fixed size of a Micro/WIN V4 system block (version 0x010e)
V4_SIZE = 0x4C2
#: between the system block's end and the program block: a flag byte and
#: four time stamps of 16 bytes (Windows SYSTEMTIME)
_GAP = 1 + 4 * 16
#: a SMART system block's start: its version, then nulls (44; 35 in V1)
_SMART_START = re.compile(rb"(?:\x0f\x06|\x13\x06|\x15\x06)\x00{44}|\x0f\x03\x00{35}")

#: six retentive ranges (four zero bytes, a data width, an area code, the
#: offset and the count), as a V3 project holds them
_V3_RANGES = re.compile(rb"(?:\x00{4}[\x02\x04\x08]\x00{3}[\x10\x20\x40\x80]\x00{3}.{8}){6}",
                        re.S)
#: area code of a retentive range -> (area, data widths it is stored with)
_AREAS = {0x10: ("V", (2,)), 0x20: ("M", (2,)), 0x40: ("T", (4, 8)), 0x80: ("C", (4, 8))}
#: SMART start-up mode byte -> mode
_STARTUP = {0: "STOP", 1: "RUN", 2: "LAST"}
#: baud rate codes: SMART (RS485 port 0), V4 (ports 0 and 1; only 9.6 and
#: 187.5 kbaud are described)
_SMART_BAUD = {1: 9600, 2: 19200, 4: 187500}
_V4_BAUD = {0: 9600, 4: 187500}
#: SMART CPU type bytes: series, then I/O size
_SERIES = {0x00: "ST{}", 0x01: "SR{}", 0x20: "ST{}", 0x80: "CR{}", 0x81: "CR{}s"}
_IO = {0x02: "20", 0x03: "30", 0x04: "40", 0x06: "60"}
#: SMART input filter codes (bits 0-5 of an input's byte) -> time in its unit
_FILTER = {2: "0.2", 3: "0.4", 4: "0.8", 5: "1.6", 6: "3.2", 7: "6.4", 9: "12.8", 14: "none"}
#: V4 input filter code (per group of four inputs): the default is the only
#: code seen and described with its time
_V4_FILTER = {6: "6.4 ms"}
#: SMART password field sizes (salt and hash) by system block version
_SMART_PASSWORD = {0x060F: 22, 0x0613: 34, 0x0615: 34, 0x030F: 4}
#: the most inputs a CPU's input configuration may list
_MAX_INPUTS = 64


@dataclass
class SystemBlock:
    """A system block, read."""

    #: its version (0x010e: Micro/WIN V4; 0x060f: SMART V2; 0: Micro/WIN
    #: V3, of which only the retentive ranges are read)
    version: int
    #: its offset in the decompressed project
    offset: int
    #: what plcrt simulates: retentive ranges, start-up mode, port addresses
    settings: SystemSettings
    #: port -> baud rate (bits/s, or "code N" where the code is not described)
    baud: dict[int, int | str] = field(default_factory=dict)
    #: the CPU type (SMART: "CPU ST40") and its firmware, "" where not held
    cpu: str = ""
    firmware: str = ""
    #: input filters: per input (SMART) or per group of four (V4), as text
    filters: list[str] = field(default_factory=list)
    #: the inputs with pulse catch (bit numbers: I0.0 = 0)
    pulse_catch: list[int] = field(default_factory=list)

    def lines(self) -> list[str]:
        """The settings as short lines (``plcrt export`` notes, ``read_project``)."""
        s = self.settings
        out = [f"retentive ranges: {', '.join(map(str, s.ranges)) or 'none'}"
               if s.ranges is not None else "retentive ranges: not held"]
        if s.startup:
            out.append(f"start-up mode: {s.startup}")
        for port, address in sorted(s.addresses.items()):
            out.append(f"port {port}: station address {address}, baud rate "
                       f"{self.baud.get(port, '?')}")
        if self.cpu:
            out.append(f"CPU: {self.cpu}" + (f" firmware {self.firmware}" if self.firmware
                                             else ""))
        if self.pulse_catch:
            out.append("pulse catch: " + ", ".join(f"I{b // 8}.{b % 8}"
                                                    for b in self.pulse_catch))
        return out


def read_system_block(stream: bytes, file: str, fmt: str, program_start: int
                      ) -> tuple[SystemBlock | None, str]:
    """The system block of a project whose program block starts at
    ``program_start`` (``fmt`` as :class:`~.container.Container` names it),
    or (None, a note) where it is not where this reader looks for it."""
    if fmt == "Micro/WIN V4":
        start = program_start - _GAP - V4_SIZE
        if start < 0 or stream[start:start + 2] != b"\x0e\x01":
            return None, _not_found("a Micro/WIN V4 system block (version 0x010e)")
        block = _read_v4(Cursor(stream, file, SECTION, start))
    elif fmt.startswith("Micro/WIN SMART"):
        match = _SMART_START.search(stream, 0, program_start)
        if match is None:
            return None, _not_found("a Micro/WIN SMART system block (version 0x060f)")
        block = _read_smart(Cursor(stream, file, SECTION, match.start()), program_start)
    else:
        return None, _not_found(f"a {fmt} system block")
    return block, ""


def read_v3_system_block(stream: bytes, file: str, program_start: int
                         ) -> tuple[SystemBlock | None, str]:
    """The retentive ranges of a Micro/WIN V3 project (its system block's
    other fields are not decoded): six ranges laid out as V4's, found
    before the program block by their form."""
    match = _V3_RANGES.search(stream, 0, program_start)
    if match is None:
        return None, _not_found("the retentive ranges of a Micro/WIN V3 system block")
    c = Cursor(stream, file, SECTION, match.start())
    return SystemBlock(0, match.start(), SystemSettings(
        _ranges(c), source=f"the system block of {file}")), ""


def _not_found(what: str) -> str:
    return (f"the system block was not read ({what} was not found before the program "
            "block): the defaults apply (retentive ranges, start-up in RUN)")


def _refuse(c: Cursor, at: int, message: str) -> PlcConfigError:
    return cast(PlcConfigError, binary_error(c.file, SECTION, at, message, PlcConfigError))


def _expect(c: Cursor, value: int, width: int, what: str) -> None:
    at = c.pos
    got = {1: c.u1, 2: c.u2, 4: c.u4}[width]()
    if got != value:
        raise _refuse(c, at, f"{what}: expected 0x{value:x}, found 0x{got:x} (a system "
                      "block of a layout this reader does not know)")


def _ranges(c: Cursor) -> tuple[RetentiveRange, ...]:
    """The six retentive ranges (empty ones left out)."""
    out = []
    for n in range(6):
        at = c.pos
        _expect(c, 0, 4, f"retentive range {n}")
        width, code, start, count = c.u4(), c.u4(), c.u4(), c.u4()
        area = _AREAS.get(code)
        if area is None or width not in area[1]:
            raise _refuse(c, at, f"retentive range {n}: memory area 0x{code:x} with data "
                          f"width {width} is not one this reader knows")
        if start > 0xFFFF or count > 0x10000:
            raise _refuse(c, at, f"retentive range {n}: offset {start} and count {count} "
                          "lie outside any CPU's memory")
        if count:
            out.append(RetentiveRange(area[0], start, count))
    return tuple(out)


def _address(c: Cursor, port: int) -> int:
    at = c.pos
    address = c.u4()
    if address > 126:
        raise _refuse(c, at, f"port {port}: station address {address} is outside 0..126")
    return address


def _bauds(baud: dict[int, int | str]) -> dict[int, int]:
    """The baud rates that were decoded."""
    return {port: rate for port, rate in baud.items() if isinstance(rate, int)}


def _read_v4(c: Cursor) -> SystemBlock:
    """Micro/WIN V4 (version 0x010e): a fixed layout."""
    start = c.pos
    _expect(c, 0x010E, 2, "version")
    c.skip(8 + 6)            # the CPU password (encoded) and its privilege level
    c.skip(4 + 128 * 4)      # the outputs' state in STOP: freeze, Q0.0..Q15.7
    _expect(c, 1, 1, "marker before the retentive ranges")
    ranges = _ranges(c)
    _expect(c, 1, 1, "marker before the ports")
    addresses: dict[int, int] = {}
    baud: dict[int, int | str] = {}
    for port in (0, 1):      # address, highest address, baud, retries, gap factor
        addresses[port] = _address(c, port)
        c.skip(4)
        code = c.u4()
        baud[port] = _V4_BAUD.get(code, f"code {code}")
        c.skip(8)
    _expect(c, 1, 1, "marker before the input filters")
    filters = []
    for group in range(6):   # one filter per group of four inputs from I0.0
        code = c.u4()
        filters.append(f"I{group // 2}.{group % 2 * 4}-I{group // 2}.{group % 2 * 4 + 3}: "
                       + _V4_FILTER.get(code, f"code {code}"))
    _expect(c, 2, 1, "marker before the analog input filters")
    c.skip(32 * 4 + 8)       # AIW0..AIW62 filtered, samples, deadband
    _expect(c, 1, 1, "marker before pulse catch")
    catch = []
    for bit in range(24):    # I0.0 .. I2.7
        at = c.pos
        flag = c.u4()
        if flag > 1:
            raise _refuse(c, at, f"pulse catch of I{bit // 8}.{bit % 8}: {flag} is not 0 or 1")
        if flag:
            catch.append(bit)
    # the rest: expansion modules' configuration, background time, the
    # analog outputs in STOP, the LEDs, edit in RUN (read and ignored)
    c.skip(1 + 7 * 16 + 1 + 4 + 1 + 4 + 32 * 4 + 1 + 8 + 1)
    c.skip(4)
    return SystemBlock(0x010E, start, SystemSettings(ranges, None, addresses, _bauds(baud),
                                                      f"the system block of {c.file}"),
                       baud, filters=filters, pulse_catch=catch)


def _read_smart(c: Cursor, program_start: int) -> SystemBlock:
    """Micro/WIN SMART (0x060f V2, 0x0613 V3.0/V3.1, 0x0615 V3.2, 0x030f V1): the fields up to
    the digital inputs' configuration (what follows, signal boards,
    expansion modules and motion axes, is not read)."""
    start = c.pos
    version = c.u2()
    c.skip(35 if version == 0x030F else 44)
    c.skip(c.u1())           # a version text, usually empty
    _expect(c, 1, 1, "marker before the RS485 port")
    _expect(c, 2, 1, "RS485 port record")
    address = _address(c, 0)
    code = c.u4()
    baud: dict[int, int | str] = {0: _SMART_BAUD.get(code, f"code {code}")}
    c.skip(8)
    _expect(c, 1, 1, "marker before the retentive ranges")
    ranges = _ranges(c)
    at = c.pos
    block_version = c.u1()
    expected = {0x060F: 5, 0x0613: 6, 0x0615: 6, 0x030F: 3}[version]
    if block_version != expected:
        raise _refuse(c, at, f"security record version {block_version}, not the "
                      f"{expected} of a system block of version 0x{version:04x}")
    c.skip(4 + 4 + _SMART_PASSWORD[version])   # privileges, port security, password
    _expect(c, 1, 1, "marker before the background time")
    c.skip(4)
    _expect(c, 1, 1, "marker before the start-up mode")
    c.skip(1)
    at = c.pos
    startup = _STARTUP.get(c.u1())
    if startup is None:
        raise _refuse(c, at, f"start-up mode {c.data[at]} is not STOP (0), RUN (1) or "
                      "LAST (2)")
    _expect(c, 0, 2, "after the start-up mode")
    c.skip(8)                # allow missing hardware, allow configuration errors
    _expect(c, 3, 1, "marker before the IP settings")
    c.skip(80 + 16)          # fixed IP, address, mask, gateway, station name
    block = SystemBlock(version, start, SystemSettings(
        ranges, startup, {0: address}, _bauds(baud), f"the system block of {c.file}"), baud)
    if block_version != 3:
        _smart_cpu(c, block)
    if c.pos > program_start:
        raise _refuse(c, start, "the system block runs into the program block")
    return block


def _smart_cpu(c: Cursor, block: SystemBlock) -> None:
    """The CPU's type, firmware and digital inputs (SMART V2 and V3)."""
    _expect(c, 0, 1, "CPU configuration record")
    c.skip(12)               # restrict communication writes to a V range
    block.cpu = "CPU " + _cpu_type(c)
    _expect(c, 0x8000, 2, "after the CPU type")
    sub = c.u1()
    _expect(c, 1, 2, "CPU record")
    c.skip(10 + 4 + 16)
    if "CPU " + _cpu_type(c) != block.cpu:
        raise _refuse(c, c.pos - 2, "the CPU type is given twice, differently")
    _expect(c, 0x8000, 2, "after the CPU type")
    _expect(c, 1, 4, "CPU record")
    _expect(c, 0, 4, "CPU record")
    text = c.take(c.u1())
    block.firmware = text.rstrip(b"\0").decode("ascii", "replace")
    if not block.firmware.isprintable():
        raise _refuse(c, c.pos - len(text), "the firmware version is not text")
    if sub == 7:
        c.skip(24)
    _expect(c, 0x0101, 2, "end of the CPU record")
    _expect(c, 0, 4, "end of the CPU record")
    _expect(c, 2, 1, "digital inputs record")
    count = c.count(4, _MAX_INPUTS, "number of digital inputs")
    for bit in range(count):
        c.skip(1)
        at = c.pos
        flags = c.u1()
        unit = "us" if flags & 0x80 else "ms"
        time = _FILTER.get(flags & 0x3F)
        if time is None:
            raise _refuse(c, at, f"input filter code {flags & 0x3f} of I{bit // 8}.{bit % 8} "
                          "is not one this reader knows")
        block.filters.append(f"I{bit // 8}.{bit % 8}: " + (time if time == "none"
                                                          else f"{time} {unit}"))
        if flags & 0x40:
            block.pulse_catch.append(bit)


def _cpu_type(c: Cursor) -> str:
    at = c.pos
    series, io = c.u1(), c.u1()
    if series not in _SERIES or io not in _IO:
        raise _refuse(c, at, f"CPU type 0x{series:02x} 0x{io:02x} is not one this reader "
                      "knows")
    return _SERIES[series].format("32" if series == 0x20 else _IO[io])
