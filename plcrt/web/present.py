"""What the panel shows of a PLC beside the ladder: watch values in their
formats, symbol names with their comments (:mod:`plcrt.view.names`,
re-exported), the input and output bits that become switches and lamps
(and which kind of switch each input is), and the marks of axes and
drives from the plant file.  Pure functions of a loaded PLC: no state, no
threads, no web code (the runner, :mod:`plcrt.web.session`, calls them)."""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from ..engine.runtime import Plc
from ..errors import PlcError
from ..view.names import symbol_names
from .protocol import finite

#: the most inputs and outputs shown as switches and lamps
MAX_IO = 64


def format_value(v: Any, fmt: str, width: int) -> str:
    """A watch value in its format: bits 0/1, INT/DINT signed, REAL to 7
    digits, hex as Micro/WIN writes it (16#00FF)."""
    if isinstance(v, bool):
        v = int(v)
    if isinstance(v, float):
        import math
        return f"{v:.7g}" if math.isfinite(v) else str(finite(v))
    if fmt == "hex":
        digits = max(2, 2 * (width or 1))
        return f"16#{int(v) & ((1 << (4 * digits)) - 1):0{digits}X}"
    return str(v)


def io_bits(plc: Plc) -> tuple[list[str], list[str]]:
    """The input and output bits the program uses (by address or symbol),
    in address order: the switches and lamps of the page."""
    areas = plc.mem.areas
    found: dict[str, set[tuple[int, int]]] = {"I": set(), "Q": set()}
    seen: set[str] = set()
    for p in plc.program.pous:
        for n in p.networks:
            for insn in n.insns:
                for o in insn.operands:
                    t = o.text
                    if t in seen or not t or t[0] in "#*&\"'0123456789+-":
                        continue
                    seen.add(t)
                    try:
                        buf, off, width, bit, _ = plc.locate(t)
                    except PlcError:
                        continue
                    if width == 0:
                        for area in ("I", "Q"):
                            if buf is areas[area]:
                                found[area].add((off, bit))
    ins = [f"I{o}.{b}" for o, b in sorted(found["I"])][:MAX_IO]
    outs = [f"Q{o}.{b}" for o, b in sorted(found["Q"])][:MAX_IO]
    return ins, outs


#: input kinds -> the input's value at rest (a normally-closed contact reads 1
#: while nobody touches it); a switch keeps what a click gives it, a
#: push-button only while it is held
INPUT_KINDS: dict[str, int] = {"switch": 0, "switch_nc": 1, "button": 0, "button_nc": 1}

#: words of a symbol comment -> what they say about the input (first match
#: of each group wins); the symbol's name is not read: "PB" in a name says
#: nothing about the wiring
_COMMENT_WORDS: tuple[tuple[str, re.Pattern[str]], ...] = (
    ("button", re.compile(r"push[- ]?button|\btaster\b|\bmomentary\b", re.I)),
    ("nc", re.compile(r"normally[- ]closed|\bN\.?C\b|\bbreak contact\b|\böffner\b", re.I)),
)

#: the words of a lesson's input table (``panel.md``) -> input kind
KIND_WORDS: dict[str, str] = {
    "switch": "switch", "nc switch": "switch_nc",
    "push-button": "button", "nc push-button": "button_nc",
}


def kind_from_comment(comment: str) -> str:
    """The input kind a symbol's comment describes: ``push button`` makes a
    push-button, ``normally closed`` / ``NC`` one that rests at 1."""
    said = {what for what, pat in _COMMENT_WORDS if pat.search(comment or "")}
    return ("button" if "button" in said else "switch") + ("_nc" if "nc" in said else "")


def input_kinds(plc: Plc, inputs: list[str],
                declared: Mapping[str, str] | None = None) -> dict[str, str]:
    """Each input bit's kind (:data:`INPUT_KINDS`): the lesson's own table
    first (``declared``: address or symbol -> kind), then the comment of
    the input's symbol, else a switch."""
    table = plc.symbols
    entries: dict[str, Any] = dict(getattr(table, "entries", {}) or {})
    by_addr = {_norm(s.address): s for s in entries.values()}
    said: dict[str, str] = {}
    for key, kind in (declared or {}).items():
        s = entries.get(key)
        said[_norm(s.address if s is not None else key)] = kind
    out = {}
    for a in inputs:
        s = by_addr.get(_norm(a))
        out[a] = said.get(_norm(a)) or kind_from_comment(s.comment if s is not None else "")
    return out


def _norm(addr: str) -> str:
    return addr.replace(" ", "").upper()


def plant_of(plc: Plc) -> Any:
    return getattr(plc, "_config", {}).get("plant")


def axis_marks(plc: Plc) -> list[dict[str, Any]]:
    """Each axis's reference switch, limits and Z marks from the plant."""
    plant = plant_of(plc)
    out = []
    for a in plc.axes():
        marks: dict[str, Any] = {"slot": a.slot, "axis": a.axis}
        mod = plant.modules.get(a.slot) if plant is not None else None
        ap = mod.axes.get(a.axis) if mod is not None else None
        if ap is not None:
            marks.update(start=ap.start, rps=list(ap.rps) if ap.rps else None,
                         limit_neg=ap.limit_neg, limit_pos=ap.limit_pos,
                         z_period=ap.z_period, z_offset=ap.z_offset)
        out.append(marks)
    return out


def drive_marks(plc: Plc) -> list[dict[str, Any]]:
    """Each drive's limits, home switch, index pulses and hard stops."""
    plant = plant_of(plc)
    out = []
    for d in plc.drives():
        marks: dict[str, Any] = {"slot": d.slot, "node": d.node, "model": d.model}
        mod = plant.modules.get(d.slot) if plant is not None else None
        cfg = mod.drives.get(d.node) if mod is not None else None
        if cfg is not None:
            for k, v in cfg.plant.items():
                if k in ("neg_limit", "pos_limit", "home_switch", "index_period",
                         "index_phase", "neg_stop", "pos_stop", "start"):
                    marks[k] = list(v) if isinstance(v, tuple) else v
        out.append(marks)
    return out


__all__ = ["INPUT_KINDS", "KIND_WORDS", "MAX_IO", "axis_marks", "drive_marks", "format_value",
           "input_kinds", "io_bits", "kind_from_comment", "plant_of", "symbol_names"]
