"""What the debugger prints besides short answers: the status line, the
watch table, the ``status`` and ``axes`` tables, and a network drawn in
ladder (or listed as STL when the ladder view is not available).

These are plain functions from values to lines of text (or, for a drawn
network, to the output stream), shared by the session
(:mod:`plcrt.debug.session`) and its commands (:mod:`plcrt.debug.commands`).

This module is not the ladder renderer (that is :mod:`plcrt.view`, imported
only when a network is drawn) and keeps no session state: which addresses
are watched, what is forced and where a scan is paused are the session's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, TextIO

from ..engine.runtime import Plc
from ..engine.values import json_number
from ..lang import ir
from ..safetext import printable


def fmt(value: int | float) -> str:
    """A value as the debugger shows it."""
    # REALs are single precision: seven significant digits say all there is;
    # NaN and the infinities are spelled as `set` takes them
    if isinstance(value, float):
        return f"{value:.7g}" if math.isfinite(value) else str(json_number(value))
    return str(value)


def ms(us: int) -> str:
    """Microseconds as milliseconds, without trailing zeros."""
    return f"{us / 1000:g}"


def sim_time(plc: Plc) -> str:
    """The simulated time in seconds, as precise as the scan time needs."""
    us = plc.now_us
    # three decimals (ms) suffice unless the scan time has a fraction of a ms
    return f"{us / 1e6:.3f}" if plc.scan_us % 1000 == 0 else f"{us / 1e6:.6f}"


def mode(plc: Plc) -> str:
    """RUN, STOP, or STOP (fault)."""
    if plc.mode == "RUN":
        return "RUN"
    return "STOP (fault)" if plc.fault is not None else "STOP"


def status_line(plc: Plc) -> str:
    """The line printed after every command that runs scans (with ``DLED
    on`` while the program lights the SMART's diagnostic LED)."""
    led = "  DLED on" if plc.station.led else ""
    return f"t={sim_time(plc)} s  scan {plc.scans}  {mode(plc)}{led}"


def watch_table(rows: Sequence[tuple[str, str, bool]]) -> list[str]:
    """(address, formatted value, forced?) rows under an aligned heading."""
    aw = max(len("address"), *(len(r[0]) for r in rows))
    vw = max(len("value"), *(len(r[1]) for r in rows))
    lines = [f"{'address':<{aw}}  {'value':>{vw}}"]
    for spec, value, forced in rows:
        lines.append(f"{spec:<{aw}}  {value:>{vw}}" + ("  forced" if forced else ""))
    return lines


def key_values(rows: Sequence[tuple[str, str]]) -> list[str]:
    """``name  value`` lines with the names padded to one width."""
    w = max(len(k) for k, _ in rows)
    return [f"{k:<{w}}  {v}" for k, v in rows]


def axes_table(axes: Sequence[dict[str, Any]]) -> list[str]:
    """The EM253 axes (entries of :meth:`plcrt.Plc.axes`, at least one):
    numbers right-aligned, the status left-aligned with its notes."""
    from ..term.tables import axis_rows, table_lines
    head = ("slot", "axis", "position", "mechanical", "speed Hz", "status")
    return table_lines(head, axis_rows(axes), {len(head) - 1})


def drives_table(drives: Sequence[Any]) -> list[str]:
    """The bus drives (entries of :meth:`plcrt.Plc.drives`, at least one):
    numbers right-aligned, model and state left-aligned, the statusword in
    hex and decoded."""
    from ..term.tables import DRIVE_COLUMNS, drive_rows, table_lines
    return table_lines(DRIVE_COLUMNS, drive_rows(drives), {2, 3, len(DRIVE_COLUMNS) - 1})


def block_heading(pou: ir.Pou) -> str:
    """``OB1 (MAIN)  title``: the line above a block's networks."""
    name = f" ({pou.name})" if pou.name and pou.name != pou.ident else ""
    return f"{pou.ident}{name}" + (f"  {pou.title}" if pou.title else "")


def load_view() -> Any:
    """``(ladder_text, render_network, PlcStatus)`` of :mod:`plcrt.view`, or
    False when it is not there (or broken): the debugger then shows STL."""
    try:
        # the package exports PlcStatus wherever the view keeps it
        from ..view import PlcStatus
        from ..view.render import ladder_text, render_network
        return (ladder_text, render_network, PlcStatus)
    except Exception:  # noqa: BLE001 - any import problem means: no ladder view
        return False


def draw_network(out: TextIO, plc: Plc, pou: ir.Pou, network: ir.Network, *,
                 view: Any, color: bool) -> None:
    """Write one network to ``out``: in ladder with the values of this
    moment (in the middle of a scan while paused) when ``view`` is what
    :func:`load_view` returned, as STL when it is False or drawing fails."""
    if view:
        ladder_text, render_network, plc_status = view
        try:
            status = plc_status(plc)
            program = plc.program   # names the pins of CALL boxes
            if color:
                from rich.console import Console
                console = Console(file=out, force_terminal=True, highlight=False,
                                  soft_wrap=True)
                console.print(render_network(pou, network, status=status, styled=True,
                                             program=program))
            else:
                text = ladder_text(pou, network, status=status, program=program)
                out.write(text.rstrip("\n") + "\n")
            return
        except Exception as e:  # noqa: BLE001 - a drawing problem must not end the session
            out.write(printable(f"(the ladder view failed: {type(e).__name__}: {e}; "
                                f"showing STL)") + "\n")
    # program text: control characters are written as escapes
    out.write(printable(f"Network {network.number}" + (f"  {network.title}" if network.title
                                                       else "")) + "\n")
    for insn in network.insns:
        ops = ", ".join(o.text for o in insn.operands)
        out.write(printable(f"{insn.mnemonic:<7}{ops}".rstrip()) + "\n")


__all__ = ["axes_table", "block_heading", "drives_table", "draw_network", "fmt", "key_values", "load_view",
           "mode", "ms", "sim_time", "status_line", "watch_table"]
