"""The panel's websocket protocol: every message type, both directions, as
data, and the validation of what a browser sends.

A message is one JSON object with a ``type``; a client message may carry
an ``id`` (a number or short text) that the server echoes in an ``error``
answering it.  :data:`CLIENT` lists what the page may send and the fields
of each type; :func:`parse` turns a websocket text frame into a checked
dict or raises :class:`ProtocolError` (a :class:`~plcrt.errors.PlcError`)
with a message the page shows.  :data:`SERVER` lists what the server
sends; ``docs/panel.md`` explains both tables and the tests check that it
names every type.

This module only checks shapes (types, ranges, lengths); whether an
address exists or a value fits is the PLC's business (``set`` and
``force`` go through the same code as ``plcrt run --set``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

from ..errors import PlcConfigError
from ..net.jsonmsg import finite, load, nesting

#: the longest text field a client may send (an address, a condition ...)
MAX_TEXT = 200
#: the largest websocket text message read (bytes)
MAX_MESSAGE = 16384
#: the most signals in one trend
MAX_TREND = 8
#: the most networks one ``view`` may name
MAX_VIEW = 1000
#: the most scans one ``step`` may ask for
MAX_STEP = 1_000_000
#: the deepest nesting of arrays and objects in a message (a message needs 2)
MAX_DEPTH = 8
#: the most rows of the watch table (shared by every page)
MAX_WATCH = 100


class ProtocolError(PlcConfigError):
    """A client message that is not one of :data:`CLIENT` as described."""


@dataclass(frozen=True)
class Field:
    """One field of a message: its kind and limits."""

    kind: str                       #: "int", "num", "str", "enum", "strs"
    required: bool = True
    choices: tuple[str, ...] = ()   #: for "enum"
    lo: float = -math.inf           #: for "int" / "num"
    hi: float = math.inf
    doc: str = ""


#: client -> server: type -> (fields, what it does)
CLIENT: dict[str, tuple[dict[str, Field], str]] = {
    "run": ({}, "run continuously at the current speed"),
    "stop": ({}, "stop after the scan in progress"),
    "step": ({"scans": Field("int", False, lo=1, hi=MAX_STEP, doc="scans to run, default 1")},
             "run N scans, then stop"),
    "until": ({"cond": Field("str", doc="a test-harness condition: Q0.0, not M0.1, VW100 >= 5"),
               "timeout": Field("num", False, lo=0.001, hi=86400.0,
                                doc="simulated seconds, default 10")},
              "run until the condition holds (or the timeout passes), then stop"),
    "speed": ({"mode": Field("enum", choices=("realtime", "factor", "max")),
               "factor": Field("num", False, lo=0.01, hi=10000.0,
                               doc="with mode factor: simulated seconds per wall second")},
              "real time, x N, or as fast as possible"),
    "reset": ({}, "power-up reset: the state right after loading; breakpoints, watches, "
                  "trends and forces stay"),
    "set": ({"addr": Field("str", doc="address or symbol, VD4:REAL for a real"),
             "value": Field("str", doc="as --set: 12, -3, 16#FF, 2#1010, 1.5")},
            "write a value once (an input keeps it: a switch left on)"),
    "force": ({"addr": Field("str"), "value": Field("str")},
              "force a value until unforce (as Micro/WIN's status chart)"),
    "unforce": ({"addr": Field("str", False, doc="omitted: release every force")},
                "release one force or all"),
    "watch": ({"spec": Field("str", doc="address or symbol"),
               "format": Field("enum", False, choices=("auto", "bit", "int", "dint", "real",
                                                       "hex"))},
              "add a row to the watch table"),
    "unwatch": ({"spec": Field("str")}, "remove a row of the watch table"),
    "break": ({"network": Field("str", doc="OB1/3, SBR0/1 or 3")},
              "stop the run at the start of that network"),
    "unbreak": ({"network": Field("str")}, "remove a breakpoint"),
    "continue": ({}, "leave a breakpoint: the paused scan goes on, and the run with it"),
    "trend": ({"signals": Field("strs", hi=MAX_TREND, doc=f"at most {MAX_TREND} addresses or "
                                                          f"device signals (axis0.0.position)")},
              "record these signals once per scan (an empty list stops the trend)"),
    "history": ({}, "send the whole trend buffer again (after skipped frames)"),
    "view": ({"block": Field("str", doc="OB1, SBR0, INT0"),
              "networks": Field("strs", False, hi=MAX_VIEW,
                                doc="the networks on screen (OB1/3 ...); omitted: all of "
                                    "the block")},
             "which networks this client shows (frames carry their status only)"),
    "lesson": ({"id": Field("str", doc="a lesson folder name of the course")},
               "load that lesson's program (every client gets a new hello)"),
    "check": ({}, "run the current lesson's tests ('check my program')"),
    "machine": ({"machine": Field("str", doc="a machine's name in the plant"),
                 "action": Field("enum", choices=("press", "hold", "release", "fault_on",
                                                  "fault_off")),
                 "name": Field("str", doc="a button of the machine (press, hold, release) "
                                          "or one of its faults (fault_on, fault_off)")},
                "press (for 0.3 s), hold or release a machine's button; switch a fault"),
}

#: server -> client: type -> what it carries
SERVER: dict[str, str] = {
    "hello": "the program: blocks with their networks (SVG or STL), symbols, inputs and "
             "outputs, axes and drives with their plant marks, lessons, the current lesson, "
             "the machines with their buttons and faults",
    "frame": "the newest state: time, scans, run state, speed, per-network status of the "
             "viewed blocks, inputs, outputs, watch table, forces, breakpoints, axes, drives, "
             "new trend samples, each machine's state",
    "trend": "the whole trend buffer (answer to history, or after trend)",
    "error": "a request that failed: message, and the request's id and type",
    "notice": "something the user should read: a breakpoint reached, a condition met, "
              "a fault",
    "check": "the result of check: each test with its outcome, and the pytest output",
    "diagnostics": "the program's warnings at load and while running, and a fault, as the "
                   "CLI prints them, each with its network (the whole list, again when it grows)",
}


def parse(text: str | bytes) -> dict[str, Any]:
    """A checked client message from a websocket text frame.

    Raises:
        ProtocolError: not JSON, not an object, an unknown type, a missing,
            unknown or badly typed field, or a value out of range.
    """
    msg = load(text, max_bytes=MAX_MESSAGE, max_depth=MAX_DEPTH, error=ProtocolError)
    return validate(msg)


def validate(msg: Any) -> dict[str, Any]:
    """Check a decoded client message against :data:`CLIENT`; returns a new
    dict with defaults filled in (``id`` kept when valid)."""
    if not isinstance(msg, dict):
        raise ProtocolError("a message must be a JSON object")
    kind = msg.get("type")
    if not isinstance(kind, str) or kind not in CLIENT:
        shown = kind if isinstance(kind, str) else type(kind).__name__
        raise ProtocolError(f"unknown message type '{_short(str(shown))}'")
    fields, _ = CLIENT[kind]
    out: dict[str, Any] = {"type": kind}
    if "id" in msg:
        mid = msg["id"]
        if isinstance(mid, bool) or not isinstance(mid, (int, str)) or \
                (isinstance(mid, str) and len(mid) > 40):
            raise ProtocolError("id must be a number or a short text")
        out["id"] = mid
    extra = set(msg) - set(fields) - {"type", "id"}
    if extra:
        raise ProtocolError(f"{kind}: unknown field '{_short(sorted(extra)[0])}'")
    for name, f in fields.items():
        if name not in msg or msg[name] is None:
            if f.required:
                raise ProtocolError(f"{kind}: missing field '{name}'")
            continue
        out[name] = _check(kind, name, f, msg[name])
    return out


def _check(kind: str, name: str, f: Field, v: Any) -> Any:
    where = f"{kind}.{name}"
    if f.kind in ("int", "num"):
        ok = isinstance(v, int) if f.kind == "int" else isinstance(v, (int, float))
        if isinstance(v, bool) or not ok or (isinstance(v, float) and not math.isfinite(v)):
            raise ProtocolError(f"{where} must be {'a whole' if f.kind == 'int' else 'a'} "
                                f"number")
        if not f.lo <= v <= f.hi:
            raise ProtocolError(f"{where} must be between {f.lo:g} and {f.hi:g}")
        return v
    if f.kind == "strs":
        if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
            raise ProtocolError(f"{where} must be a list of texts")
        if len(v) > f.hi:
            raise ProtocolError(f"{where}: at most {f.hi:g} items")
        return [_text(where, x) for x in v]
    if not isinstance(v, str):
        raise ProtocolError(f"{where} must be a text")
    v = _text(where, v)
    if f.kind == "enum" and v not in f.choices:
        raise ProtocolError(f"{where} must be one of {', '.join(f.choices)}")
    return v


def _text(where: str, v: str) -> str:
    v = v.strip()
    if not v:
        raise ProtocolError(f"{where} must not be empty")
    if len(v) > MAX_TEXT:
        raise ProtocolError(f"{where} is too long (at most {MAX_TEXT} characters)")
    return v


def _short(text: str) -> str:
    from ..safetext import excerpt, printable
    return printable(excerpt(text))


def dumps(msg: dict[str, Any]) -> str:
    """A server message as JSON text (NaN and infinities as text, so the
    browser's JSON.parse takes them)."""
    return json.dumps(msg, separators=(",", ":"), default=_default, allow_nan=False)


def _default(o: Any) -> Any:
    if hasattr(o, "to_dict"):
        return o.to_dict()
    if isinstance(o, (set, frozenset, tuple)):
        return list(o)
    raise TypeError(f"not JSON: {type(o).__name__}")


__all__ = ["CLIENT", "Field", "MAX_DEPTH", "MAX_MESSAGE", "MAX_WATCH", "ProtocolError",
           "SERVER", "dumps", "finite", "nesting", "parse", "validate"]
