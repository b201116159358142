"""The wizard configurations of a project file, and what plcrt runs of them.

Micro/WIN keeps what its wizards were told (speeds and ramps of a pulse
output, a PID loop's gains, a counter's mode) in sections after the CPU
name; the code a wizard generates lives in the program block, its tables in
the data block.  This module reads those sections and maps each
configuration onto what plcrt simulates:

* Micro/WIN V4 (``.mwp``): a count and that many records, each its wizard
  (a 16-bit id), the version 5, three names (the configuration, its data
  page and its symbol table), the V byte where its memory starts and two
  time stamps, then the wizard's own fields.  The Position Control wizard
  of the built-in outputs (id 0x84) becomes the plant's ``[pto.N]``.
* Micro/WIN SMART V2 (``.smart``): after the project's name, the motion
  axes, the PID loops, the high-speed counters and the PWM outputs, one
  list each, in that order.  A PWM output becomes the plant's ``[pwm.N]``.

The result (:class:`Wizards`) holds each configuration read, the plant
tables (``{"pto": {"0": {...}}}``, as a plant file writes them) and one
note per setting that is not mapped (docs/project-files.md, "Wizards").
Every read is bounded by :class:`~.stream.Cursor`; a section that is not
laid out as described stops the reading with a note naming the section and
the byte offset (the program does not depend on it).

It does not run anything: :mod:`plcrt.loader` puts the tables into the
plant, :mod:`plcrt.devices.ptowizard` runs the blocks.
"""

from __future__ import annotations

import math
import re
import struct
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from ..errors import PlcError
from .stream import Cursor

__all__ = ["Wizard", "Wizards", "read_wizards", "plant_toml", "WIZARD_NAMES"]

SECTION = "wizard configuration"
#: Micro/WIN V4 wizard ids (the public format description names them)
WIZARD_NAMES = {
    0x01: "Text Display", 0x02: "PID", 0x08: "NETR/NETW", 0x10: "Position Control (EM253)",
    0x20: "Modem (EM241)", 0x40: "AS-i (CP243-2)", 0x80: "Ethernet (CP243-1)",
    0x81: "Internet (CP243-1 IT)", 0x84: "Position Control (PTO)",
}
#: what plcrt does instead of a wizard it does not map (one phrase each)
_NOT_MAPPED = {
    0x02: "the loop table's initial values are the data page's rows (the data block) and "
          "plcrt emulates the PID instruction (docs/pid.md), not the wizard's subroutines",
    0x10: "the module's configuration block is the data page's rows (the data block); plcrt "
          "simulates another positioning module (docs/em253.md), not the EM253's POSx_ "
          "subroutines",
}
MAX_CONFIGS = 64
MAX_LIST = 32          #: axes, loops, counters, PWM outputs of one SMART list
MAX_FEATURES = 4096    #: the CPU's feature bytes (212 in the projects seen)
MAX_STEPS = 64
#: the bounds of the plant file's [pto.N] (docs/pto-wizard.md, "Configuration")
PTO_HZ = (16, 100_000)
PTO_RAMP_MS = 32_000
#: a V4 record's header: the wizard id, version 5
_V4_RECORD = re.compile(rb"[\x01\x02\x08\x10\x20\x40\x80\x81\x84]\x00\x05")
_PULSE_OUTPUT = re.compile(r"^(PTO|PWM)([01])_[A-Z]+$")
_TIME_BASES = {0: "us", 1: "ms"}


@dataclass
class Wizard:
    """One configuration a wizard stored: its kind and the fields read."""

    kind: str
    name: str
    #: the byte offset of the record in the decompressed project
    offset: int
    fields: dict[str, Any] = field(default_factory=dict)


@dataclass
class Wizards:
    """The wizard configurations of a project and what they map onto."""

    configs: list[Wizard] = field(default_factory=list)
    #: plant tables, as a plant file holds them: {"pto": {"0": {...}}}
    plant: dict[str, dict[str, dict[str, Any]]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def read_wizards(c: Cursor, smart: bool, blocks: Mapping[str, bool] | None = None
                 ) -> Wizards:
    """The wizard sections after the data block (the cursor stands on the
    CPU section that follows it); ``blocks`` maps the program's block names
    to whether each is protected (the notes say where a wizard's code is)."""
    out = Wizards()
    c.section = SECTION
    try:
        _cpu_section(c)
        if smart:
            _smart(c, out)
        else:
            _v4(c, out)
    except PlcError as e:
        out.notes.append(f"the wizard configurations are not read: {e.message}")
        return out
    _map(out, dict(blocks or {}))
    return out


def _cpu_section(c: Cursor) -> None:
    c.u1()
    c.text()                                   # the CPU's name (the reader has it)
    c.u1()
    c.text()                                   # its version
    c.skip(c.count(2, MAX_FEATURES, "length of the CPU's features"))
    c.u1()


def _f8(c: Cursor) -> float:
    return float(struct.unpack("<d", c.take(8))[0])


# -- Micro/WIN V4 -------------------------------------------------------------

def _v4(c: Cursor, out: Wizards) -> None:
    count = c.count(4, MAX_CONFIGS, "number of wizard configurations")
    c.expect(0, 1, "wizard configurations")
    start = c.pos
    for i in range(count):
        at = c.pos if i == 0 else _next_v4_record(c, start)
        if at < 0:
            out.notes.append(f"{count - i} of the {count} wizard configurations are not "
                             "found (the record before them is not fully described)")
            return
        c.pos = at
        w, start = _v4_record(c)
        out.configs.append(w)
        try:
            _V4_FIELDS.get(w.fields["id"], _no_fields)(c, w.fields)
        except PlcError as e:
            out.notes.append(f"the fields of the {w.kind} wizard's configuration '{w.name}' "
                             f"are not read: {e.message}")


def _next_v4_record(c: Cursor, start: int) -> int:
    """The next record's offset, searched from the end of the header before
    it: a record is found by its header (the fields of a PTO record are not
    all described, so where it ends is not known)."""
    for match in _V4_RECORD.finditer(c.data, start):
        probe = Cursor(c.data, c.file, SECTION, match.start())
        try:
            _v4_header(probe)
        except PlcError:
            continue
        return match.start()
    return -1


def _v4_header(c: Cursor) -> tuple[int, str, str, int]:
    ident = c.u2()
    c.expect(5, 1, "wizard record version")
    name = c.text()
    page = c.text()
    c.text()                                   # its symbol table's name
    c.expect(2, 2, "wizard memory address")
    c.expect(0x1002, 2, "wizard memory address (a VB address)")
    c.expect(0, 2, "wizard memory address")
    c.expect(0, 1, "wizard memory address")
    memory = c.u4()
    c.skip(32)                                 # two time stamps
    return ident, name, page, memory


def _v4_record(c: Cursor) -> tuple[Wizard, int]:
    """The record's header as a :class:`Wizard`, and where its fields start."""
    at = c.pos
    ident, name, page, memory = _v4_header(c)
    kind = WIZARD_NAMES.get(ident, f"0x{ident:x}")
    return Wizard(kind, name, at, {"id": ident, "data page": page,
                                   "memory": f"VB{memory}"}), c.pos


def _no_fields(c: Cursor, f: dict[str, Any]) -> None:
    """A wizard plcrt does not simulate: its fields are not read."""


def _v4_pid(c: Cursor, f: dict[str, Any]) -> None:
    """The PID wizard's loop: its number, ranges and subroutines."""
    c.expect(2, 1, "PID record")
    f["loop"] = c.count(4, 7, "PID loop number")
    c.expect(1, 1, "PID record")
    f["sp_high"], f["sp_low"], f["sample_s"] = c.f4(), c.f4(), c.f4()
    c.skip(20 + 4)
    f["pv_low"], f["pv_high"] = struct.unpack("<ii", c.take(8))
    c.skip(8 + 5 + 5 + 1 + 2 + 1)
    f["subroutines"] = [c.text(1), c.text(1)]       # INIT, the loops' interrupt routine


def _v4_position(c: Cursor, f: dict[str, Any]) -> None:
    """The EM253 Position Control wizard: the module and its subroutines."""
    c.skip(1)
    f["module"] = c.u1()
    c.skip(2 + 1 + 4 + 2)
    f["pulses_per_rev"] = c.u4()
    f["unit"] = c.text()
    c.skip(4)
    f["ss_speed"], f["max_speed"] = _f8(c), _f8(c)
    c.skip(16)
    f["accel_ms"], f["decel_ms"] = c.u4(), c.u4()
    c.skip(4)
    c.expect(1, 1, "position record")
    f["subroutines"] = [c.text() for _ in range(11)]


def _v4_pto(c: Cursor, f: dict[str, Any]) -> None:
    """The Position Control wizard of a built-in output (the documented
    head of its record: speeds, ramps, the names of its subroutines)."""
    c.skip(12)
    f["max_speed"], f["min_speed"], f["ss_speed"] = _f8(c), _f8(c), _f8(c)
    c.skip(8)
    f["accel_ms"], f["decel_ms"] = c.u4(), c.u4()
    c.skip(5)
    f["subroutines"] = [c.text() for _ in range(5)]   # CTRL, MAN, RUN, LDPOS, ADV


#: the fields read of each V4 wizard's record (its id -> reader)
_V4_FIELDS = {0x02: _v4_pid, 0x10: _v4_position, 0x84: _v4_pto}


# -- Micro/WIN SMART V2 --------------------------------------------------------

def _smart(c: Cursor, out: Wizards) -> None:
    c.u1()                                     # the project's name and a digest
    c.text()
    c.skip(2 + 1 + 4 + 16 + 1 + 4)
    _motion(c, out)
    _pid(c, out)
    _hsc(c, out)
    _pwm(c, out)


def _motion(c: Cursor, out: Wizards) -> None:
    at = c.pos
    version = c.u1()
    if version not in (1, 3):                  # 3: SMART V2, 1: V1 (fixed records)
        raise c.error(f"motion list version {version} is not one this reader knows", at)
    if version == 3:
        c.skip(8)
    for _ in range(c.count(4, MAX_LIST, "number of motion axes")):
        at = c.pos
        if version != 3:
            c.skip(562)                        # SMART V1: a fixed record
            continue
        c.expect(0x0104, 2, "motion axis")
        c.skip(8)
        wide = c.u1() == 2                     # double-precision speeds
        c.skip(4)
        unit = c.text()
        c.skip(4 + 8 + 6 * (25 if wide else 21) + 17 + 2)
        speeds = [_f8(c) for _ in range(3)]
        c.skip(1 + 16 + 1 + 8 + 1 + 4 + 1 + 8 + 14 + 8 + 12 + 2 + 12)
        for _ in range(c.count(4, MAX_STEPS, "number of motion profiles")):
            c.expect(2, 1, "motion profile")
            steps = c.count(4, MAX_STEPS, "number of profile steps")
            c.skip(25 * steps)
            if steps:
                c.text()
                c.text()
                c.skip(16)
        c.skip(1)
        axis = c.u4()
        c.skip(18 * 4)
        memory = c.u4()
        name = c.text()
        c.skip(8 + 28 * 11)
        out.configs.append(Wizard("Motion axis", name or f"Axis{axis}", at, {
            "axis": axis, "unit": unit, "max_speed": speeds[0], "memory": f"VB{memory}"}))


def _pid(c: Cursor, out: Wizards) -> None:
    c.expect(1, 1, "PID list")
    for _ in range(c.count(4, MAX_LIST, "number of PID loops")):
        at = c.pos
        version = c.u1()
        c.skip(14 * 11 + 1)
        gain, ts, ti, td = (c.f4() for _ in range(4))
        c.skip(1 + 8 + 8 + 4 + 1 + 8 + 12 + 4 + 1 + 12 + 8 + 1)
        sub = c.text()                         # the loop's subroutine
        c.skip(4 + 1 + 4)
        enabled = c.u4()
        c.skip(4)
        memory = c.u4()
        name = c.text()
        if version == 1:
            c.text()
        out.configs.append(Wizard("PID", name or sub, at, {
            "enabled": enabled, "subroutine": sub, "gain": gain, "sample_s": ts, "integral_min": ti,
            "derivative_min": td, "memory": f"VB{memory}"}))
    c.text()                                   # the loops' interrupt routine
    c.skip(6 + 1 + 4)
    version = c.u1()
    c.skip(6 + (24 if version >= 8 else 20 if version == 7 else 0))


def _hsc(c: Cursor, out: Wizards) -> None:
    version = c.u1()
    if version >= 2:
        c.skip(4)
    for _ in range(c.count(4, MAX_LIST, "number of high-speed counters")):
        at = c.pos
        c.skip(1)
        c.expect(1, 1, "high-speed counter")
        mode = c.u4()
        c.skip(1)
        init = c.text()
        c.skip(2 + 4 + 4 + 7 + 4 + 4 + 9 + 4 + 8 + 1)
        for _ in range(3):                     # reset, direction, CV = PV routines
            c.skip(4)
            c.text()
        for _ in range(c.count(4, MAX_STEPS, "number of counter steps")):
            c.expect(1, 1, "counter step")
            c.skip(4)
            c.text()
            c.skip(24)
        enabled, index = c.u4(), c.u4()
        name = c.text(1)
        out.configs.append(Wizard("HSC", name or init, at, {
            "enabled": enabled, "counter": index, "mode": mode, "subroutine": init}))


def _pwm(c: Cursor, out: Wizards) -> None:
    c.expect(1, 1, "PWM list")
    for _ in range(c.count(4, MAX_LIST, "number of PWM outputs")):
        at = c.pos
        c.expect(1, 1, "PWM output")
        enabled, index = c.u4(), c.u4()
        name = c.text()
        base = c.u4()
        c.skip(4 * 11)
        out.configs.append(Wizard("PWM", name, at, {
            "enabled": enabled, "output": index, "time_base": base}))


# -- what plcrt runs of them --------------------------------------------------

def _map(out: Wizards, blocks: dict[str, bool]) -> None:
    """Each configuration onto a plant table, or a note naming it."""
    for w in out.configs:
        f = w.fields
        where = f"the {w.kind} wizard's configuration '{w.name}'"
        if "id" in f:                          # a Micro/WIN V4 record
            if f["id"] == 0x84 and "subroutines" in f:
                _map_pto(w, where, out)
            elif f["id"] != 0x84:
                why = _NOT_MAPPED.get(f["id"], "plcrt does not simulate it")
                code = _code(f.get("subroutines", ())[:1], blocks)
                out.notes.append(f"{where} (data page '{f['data page']}', memory from "
                                 f"{f['memory']}) is not mapped: {why}{code}")
        elif w.kind == "PWM":
            if f["enabled"]:
                _map_pwm(w, where, out)
        elif w.kind == "Motion axis":
            # every SMART project holds the axes: those its program uses are named
            if any(b.startswith(f"AXIS{f['axis']}_") for b in blocks):
                out.notes.append(f"{where} is not mapped: plcrt does not emulate the SMART "
                                 f"motion wizard's AXIS{f['axis']}_ blocks")
        elif f["enabled"]:                     # a SMART PID loop or counter
            code = _code((f["subroutine"],), blocks)
            out.notes.append(f"{where} is not mapped: {_SMART_NOTES[w.kind]}{code}")


#: what the SMART wizards' configurations are to plcrt
_SMART_NOTES = {
    "PID": "plcrt emulates the PID instruction (docs/pid.md), not the wizard's subroutine",
    "HSC": "the counter is what the wizard's subroutine sets up (HDEF, HSC; docs/events.md)",
}


def _code(names: Any, blocks: dict[str, bool]) -> str:
    """Where the wizard's (first) subroutine is: the configuration is a
    record of what that code does when the program block holds it readable."""
    for name in names:
        if name not in blocks:
            return f"; its subroutine {name} is not in the program block"
        if blocks[name]:
            return f"; its subroutine {name} is protected and does not run"
        return f"; its subroutine {name} is in the program block and runs"
    return ""


def _map_pwm(w: Wizard, where: str, out: Wizards) -> None:
    f = w.fields
    base = _TIME_BASES.get(f["time_base"])
    if f["output"] not in (0, 1):
        out.notes.append(f"{where}: PWM{f['output']} is not mapped (plcrt emulates "
                         "PWM0_RUN and PWM1_RUN, Q0.0 and Q0.1)")
    elif base is None:
        out.notes.append(f"{where}: time base {f['time_base']} is not one plcrt knows "
                         "(0 microseconds, 1 milliseconds): not mapped")
    elif _free(out, str(f["output"]), where):
        out.plant.setdefault("pwm", {})[str(f["output"])] = {"time_base": base}


def _free(out: Wizards, output: str, where: str) -> bool:
    """Whether no configuration before this one gave the output a table."""
    if any(output in out.plant.get(kind, {}) for kind in ("pto", "pwm")):
        out.notes.append(f"{where}: Q0.{output} is configured by a wizard before it: not "
                         "mapped")
        return False
    return True


def _map_pto(w: Wizard, where: str, out: Wizards) -> None:
    f = w.fields
    subs = f["subroutines"]
    m = _PULSE_OUTPUT.match(subs[0]) if subs else None
    if m is None or m[1] != "PTO":
        out.notes.append(f"{where}: its subroutine '{subs[0]}' is not PTO0_CTRL or "
                         "PTO1_CTRL, which plcrt emulates: not mapped")
        return
    output = m[2]
    table: dict[str, Any] = {}
    for key in ("max_speed", "ss_speed"):
        v = f[key]
        if not (math.isfinite(v) and v == int(v) and PTO_HZ[0] <= v <= PTO_HZ[1]):
            out.notes.append(f"{where}: {key} {v!r} is not a whole number of pulses/s in "
                             f"{PTO_HZ[0]}..{PTO_HZ[1]}: not mapped")
            return
        table[key] = int(v)
    if table["ss_speed"] > table["max_speed"]:
        out.notes.append(f"{where}: ss_speed {table['ss_speed']} is above max_speed "
                         f"{table['max_speed']}: not mapped")
        return
    for key in ("accel_ms", "decel_ms"):
        if f[key] > PTO_RAMP_MS:
            out.notes.append(f"{where}: {key} {f[key]} is above {PTO_RAMP_MS} ms: not mapped")
            return
        table[key] = f[key]
    if _free(out, output, where):
        out.plant.setdefault("pto", {})[output] = table
        out.notes.append(f"{where} gives [pto.{output}] (speeds and ramps); its profiles and "
                         f"counter option (in data page '{f['data page']}' and the record's "
                         "undescribed part) are not read: give them in a plant file's "
                         f"[pto.{output}]")


def plant_toml(plant: dict[str, dict[str, dict[str, Any]]]) -> str:
    """The plant tables as a plant file writes them (``[pto.0]``, ...)."""
    tables = []
    for kind in sorted(plant):
        for output in sorted(plant[kind]):
            rows = [f"[{kind}.{output}]"]
            for key, value in plant[kind][output].items():
                rows.append(f"{key} = " + (f'"{value}"' if isinstance(value, str) else str(value)))
            tables.append("".join(row + "\n" for row in rows))
    return "\n".join(tables)
