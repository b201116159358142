"""The panel's watch table, and writing and forcing values.

A row reads one address, symbol or device signal in a format (auto, bit,
INT, DINT, REAL, hex), resolved once (:func:`plcrt.testing.harness.reader`)
and bound again when the session moves to another build of the program.
The table holds at most :data:`~plcrt.web.protocol.MAX_WATCH` rows: every
row is read and sent to every page in every frame.  ``set`` and ``force``
read ``addr``/``value`` as one ``plcrt run --set ADDR=VALUE`` and go
through its code, so they accept and refuse what it does.

What it is: the rows and how each is read and shown.  What it is not: when
rows are read (the session's frames, :mod:`plcrt.web.session`) or how a
value is formatted (:func:`plcrt.web.present.format_value`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..term.options import SetItem, apply_sets, parse_sets
from ..engine.access import force_covers
from ..engine.runtime import Plc
from ..errors import PlcConfigError, PlcError
from ..safetext import printable
from ..testing.harness import reader
from ..trace.recorder import is_device_signal
from .present import format_value
from .protocol import MAX_WATCH


@dataclass
class Watch:
    """One row of the watch table."""
    spec: str
    format: str
    read: Callable[[], Any]
    width: int              #: bytes, 0 for a bit


class WatchTable:
    """The rows every page shares, in the order they were added."""

    def __init__(self) -> None:
        self.rows: list[Watch] = []

    def add(self, plc: Plc, spec: str, fmt: str) -> None:
        """Watch ``spec`` in ``fmt`` (a row already there is kept)."""
        if any(w.spec == spec and w.format == fmt for w in self.rows):
            return
        if len(self.rows) >= MAX_WATCH:
            # every row is read and sent to every page in every frame
            raise PlcConfigError(f"the watch table is full ({MAX_WATCH} rows at most): "
                                 f"remove a row first")
        read, width = watch_reader(plc, spec, fmt)
        self.rows.append(Watch(spec, fmt, read, width))

    def remove(self, spec: str) -> None:
        """Every row of ``spec`` goes, in any format."""
        self.rows = [w for w in self.rows if w.spec != spec]

    def rebind(self, plc: Plc) -> None:
        """Read the rows from ``plc`` (another build of the same program)."""
        for w in self.rows:
            w.read, w.width = watch_reader(plc, w.spec, w.format)

    def row(self, plc: Plc, w: Watch) -> dict[str, Any]:
        """A row as a frame carries it: its value now and whether a force
        overlaps it (forcing Q0.0 marks QB0 too)."""
        try:
            v = w.read()
            text = format_value(v, w.format, w.width)
        except PlcError as e:
            text = f"error: {e.message}"
        return {"spec": w.spec, "format": w.format, "value": text,
                "forced": force_covers(plc, w.spec)}


def watch_reader(plc: Plc, spec: str, fmt: str) -> tuple[Callable[[], Any], int]:
    """How a row of ``spec`` in ``fmt`` is read, and its width in bytes (0:
    a bit); a format that does not fit the address is refused."""
    if is_device_signal(spec):
        if fmt not in ("auto", "int", "real"):
            raise PlcConfigError(f"{spec} is a device signal: watch it as auto")
        return reader(plc, spec), 4
    base = spec.split(":")[0].strip()
    _, _, width, _, _ = plc.locate(spec)
    if fmt == "real":
        if width != 4:
            raise PlcConfigError(f"{spec}: REAL needs a double word (VD, MD, ...)")
        return reader(plc, base + ":REAL"), 4
    if fmt == "bit":
        try:
            return reader(plc, base + ":BIT"), 0
        except PlcError:
            if width != 0:
                raise PlcConfigError(f"{spec} is not a bit") from None
            return reader(plc, base), 0
    need = {"int": 2, "dint": 4}.get(fmt)
    if need is not None and width != need:
        raise PlcConfigError(f"{spec}: {fmt.upper()} needs a "
                             f"{'word' if need == 2 else 'double word'}")
    return reader(plc, spec), width


def set_items(msg: dict[str, Any]) -> list[SetItem]:
    """``addr``/``value`` read as one ``--set ADDR=VALUE``."""
    try:
        return parse_sets([f"{msg['addr']}={msg['value']}"])
    except PlcConfigError as e:
        raise PlcConfigError(e.message.removeprefix("--")) from None


def write(plc: Plc, msg: dict[str, Any]) -> None:
    """The ``set`` message: write once, as ``plcrt run --set``."""
    apply_sets(plc, set_items(msg))


def force(plc: Plc, msg: dict[str, Any]) -> None:
    """The ``force`` message: hold the value until it is unforced."""
    (item,) = set_items(msg)
    try:
        plc.force(item.addr, item.value)
    except PlcError as e:
        raise PlcConfigError(f"force {printable(item.item)}: {e.message}") from None
