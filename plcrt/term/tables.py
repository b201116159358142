"""The tables ``plcrt run`` prints after the watch values: the EM253 axes and
bus drives of a ``--plant``, the CPU's pulse outputs, high-speed counters
and communication ports in use (rich tables on a terminal, aligned plain
text otherwise), and their cells for ``--json`` and the debugger.

Presentation only: the values come from :meth:`plcrt.Plc.axes`,
:meth:`plcrt.Plc.drives` and the PLC's pulse, counter and port objects.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from typing import Any


#: columns of the axes table (keys of :meth:`plcrt.Plc.axes` entries)
_AXIS_COLUMNS = ("slot", "axis", "position", "mechanical", "speed", "status")


def axis_rows(axes: Sequence[Mapping[str, Any]]) -> list[list[str]]:
    """Table cells of :meth:`plcrt.Plc.axes` entries (columns ``_AXIS_COLUMNS``)."""
    rows = []
    for a in axes:
        row = [str(a[c]) for c in _AXIS_COLUMNS]
        # SevOn masking and the STF input explain a position that does not
        # move, so they are shown next to the status rather than dropped.
        notes = [n for n, on in (("SevOn", a.get("masked")), ("STF", a.get("stf"))) if on]
        if notes:
            row[-1] += f" ({', '.join(notes)})"
        rows.append(row)
    return rows


#: columns of the drives table (:meth:`plcrt.Plc.drives`)
DRIVE_COLUMNS = ("slot", "node", "model", "mode", "position", "velocity", "statusword", "state")


def drive_rows(drives: Sequence[Any]) -> list[list[str]]:
    """Table cells of :meth:`plcrt.Plc.drives` entries (columns ``DRIVE_COLUMNS``):
    the statusword in hex and decoded (power state, the mode's bits, 603Fh)."""
    rows = []
    for d in drives:
        notes = list(d.flags)
        if d.error_code:
            notes.append(f"603Fh 0x{d.error_code:04X}")
        if not d.online:
            notes.append("offline")
        state = d.state + (f" ({', '.join(notes)})" if notes else "")
        rows.append([str(d.slot), str(d.node), d.model, d.mode_name, str(d.position),
                     str(d.velocity), f"0x{d.statusword:04X}", state])
    return rows


#: columns of the CPU's pulse output and high-speed counter tables
PULSE_COLUMNS = ("output", "mode", "pulses", "state")
HSC_COLUMNS = ("counter", "mode", "CV", "PV", "state")


def pulse_outputs(plc: Any) -> list[dict[str, Any]]:
    """The pulse outputs Q0.0/Q0.1 that PLS or a wizard block used
    (columns ``PULSE_COLUMNS``): mode, pulses sent so far, idle or running."""
    out = []
    now = plc.now_us
    for po in plc.pulse:
        sent = po.pulses_until(now)
        if not po.mode and not sent:
            continue
        out.append({"output": f"Q0.{po.number}", "mode": po.mode or "-", "pulses": sent,
                    "state": "running" if po.running else "idle"})
    return out


#: columns of the communication port table
PORT_COLUMNS = ("port", "mode", "baud", "sent", "received", "unanswered")


def ports_in_use(plc: Any) -> list[dict[str, Any]]:
    """The ports that sent or received characters (plcrt.engine.ports;
    columns ``PORT_COLUMNS``): mode, baud rate, characters sent and
    received, transmissions nobody answered."""
    out = []
    for p in plc.ports:
        st = p.state()
        if st["sent"] or st["received"] or st["unanswered"]:
            out.append({"port": p.number} | {k: st[k] for k in PORT_COLUMNS[1:]})
    return out


def counters_in_use(plc: Any) -> list[dict[str, Any]]:
    """The high-speed counters an HDEF defined (columns ``HSC_COLUMNS``):
    mode, CV, PV, enabled."""
    out = []
    for c in plc.hsc:
        if c.mode is None:
            continue
        c.sync(plc.now_us)
        state = ("counting" if c.enabled else "disabled") + ("" if c.direction > 0 else ", down")
        out.append({"counter": f"HSC{c.number}", "mode": c.mode, "CV": c.cv, "PV": c.pv,
                    "state": state})
    return out


def _cells(columns: Sequence[str], items: list[dict[str, Any]]) -> list[list[str]]:
    """Table cells of *items*, one row each, in *columns* order."""
    return [[str(item[c]) for c in columns] for item in items]


def print_devices(plc: Any) -> None:
    """The plant's EM253 axes and bus drives, then the CPU's pulse outputs,
    high-speed counters and ports in use, after the watch values."""
    axes, drives = plc.axes(), plc.drives()
    if axes:
        _print_table(_AXIS_COLUMNS, axis_rows(axes))
    if drives:
        _print_table(DRIVE_COLUMNS, drive_rows(drives), left=(2, 3))
    pulses, counters, ports = pulse_outputs(plc), counters_in_use(plc), ports_in_use(plc)
    if pulses:
        _print_table(PULSE_COLUMNS, _cells(PULSE_COLUMNS, pulses), left=(0, 1))
    if counters:
        _print_table(HSC_COLUMNS, _cells(HSC_COLUMNS, counters), left=(0,))
    if ports:
        _print_table(PORT_COLUMNS, _cells(PORT_COLUMNS, ports), left=(1,))
    # a plant that only wires the CPU's own inputs has no axes to speak of
    if not axes and not drives and not pulses and not counters and not ports and (
            plc.modules or not (plc.wiring or plc.encoders or plc.devices)):
        print("axes: none configured in the plant")


def _print_table(columns: Sequence[str], rows: list[list[str]],
                 left: Sequence[int] = ()) -> None:
    """A rich table on a terminal, aligned plain text otherwise: numbers
    right-aligned, the last column and those in *left* left-aligned."""
    lefts = {len(columns) - 1, *left}
    if sys.stdout.isatty() and _print_rich_grid(columns, rows, lefts):
        return
    for line in table_lines(columns, rows, lefts):
        print(line)


def table_lines(columns: Sequence[str], rows: Sequence[Sequence[str]],
                lefts: set[int]) -> list[str]:
    """Plain text table lines, the header first: columns two spaces apart,
    those in *lefts* left-aligned, the others (numbers) right-aligned."""
    widths = [max(len(c), *(len(r[i]) for r in rows)) for i, c in enumerate(columns)]

    def line(cells: Sequence[str]) -> str:
        return "  ".join(c.ljust(w) if i in lefts else c.rjust(w)
                         for i, (c, w) in enumerate(zip(cells, widths))).rstrip()

    return [line(columns)] + [line(r) for r in rows]


def _print_rich_grid(columns: Sequence[str], rows: list[list[str]], lefts: set[int]) -> bool:
    try:
        from rich.console import Console
        from rich.table import Table
        from rich.text import Text
    except ImportError:
        return False
    table = Table()
    for i, col in enumerate(columns):
        table.add_column(col, justify="left" if i in lefts else "right")
    for row in rows:
        table.add_row(*(Text(cell) for cell in row))   # plain text, never markup
    Console().print(table)
    return True


__all__ = ["DRIVE_COLUMNS", "HSC_COLUMNS", "PORT_COLUMNS", "PULSE_COLUMNS", "axis_rows",
           "counters_in_use", "drive_rows", "ports_in_use", "print_devices", "pulse_outputs",
           "table_lines"]
