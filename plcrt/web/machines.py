"""The plant's machines as the panel shows them: what a page may draw of
their ``state()`` and what it may do to them (press, hold, release a
button; switch a fault).

A machine's state (docs/machines.md) is already numbers, booleans and
short names, but the page draws whatever arrives, so it passes through
:func:`clean` on the way out: only finite numbers, booleans, ``None`` and
names of :data:`NAME` survive, lists are cut at :data:`MAX_ITEMS` items and
dicts at :data:`MAX_KEYS` keys, nesting at :data:`MAX_NEST`; anything else
becomes ``None``.  The page therefore never receives text it did not
expect, even from a plant file with odd machine names.

This module is not the machines' model (``plcrt.devices.machines``) and
does not draw them (``static/machines.js`` does, from the frame).
"""

from __future__ import annotations

import math
import re
from typing import Any

from ..engine.runtime import Plc
from ..errors import PlcConfigError

#: the names a state may carry: signals, faults, kinds, bins, notes' keys
NAME = re.compile(r"[A-Za-z0-9_:.+\- ]{1,64}\Z")
#: the most items of a list in a machine's state (parts on a belt ...)
MAX_ITEMS = 64
#: the most keys of a dict in a machine's state (signals, faults ...)
MAX_KEYS = 128
#: the deepest nesting of lists and dicts kept
MAX_NEST = 4
#: the most machines a frame carries
MAX_MACHINES = 16

#: the actions of the ``machine`` message and the Machine method each calls
ACTIONS = ("press", "hold", "release", "fault_on", "fault_off")


def clean(v: Any, depth: int = 0) -> Any:
    """*v* with only what a page may draw (see the module's docstring)."""
    if v is None or isinstance(v, bool):
        return v
    if isinstance(v, int):
        return v if abs(v) < 2 ** 53 else None
    if isinstance(v, float):
        return v if math.isfinite(v) else None
    if isinstance(v, str):
        return v if NAME.match(v) else None
    if depth >= MAX_NEST:
        return None
    if isinstance(v, (list, tuple)):
        return [clean(x, depth + 1) for x in list(v)[:MAX_ITEMS]]
    if isinstance(v, dict):
        out = {}
        for k, x in list(v.items())[:MAX_KEYS]:
            if isinstance(k, str) and NAME.match(k):
                out[k] = clean(x, depth + 1)
        return out
    return None


def machine_info(plc: Plc) -> list[dict[str, Any]]:
    """For the ``hello``: each machine's name, kind, buttons and faults."""
    out = []
    for m in plc.machines()[:MAX_MACHINES]:
        info = clean({"name": m.name, "kind": m.kind, "buttons": m.buttons(),
                      "faults": m.faults()})
        if info.get("name") and info.get("kind"):
            info["faults"] = [f for f in info["faults"] if f]
            info["buttons"] = [b for b in info["buttons"] if b]
            out.append(info)
    return out


def machine_states(plc: Plc) -> list[dict[str, Any]]:
    """For each frame: every machine's ``state()``, cleaned."""
    return [clean(m.state()) for m in plc.machines()[:MAX_MACHINES]]


def apply(plc: Plc, msg: dict[str, Any]) -> None:
    """Apply a checked ``machine`` message (:mod:`plcrt.web.protocol`).

    Raises:
        PlcConfigError: no such machine (or button, fault: the machine's
            own errors, which are PlcErrors too).
    """
    found = {m.name: m for m in plc.machines()}
    m = found.get(msg["machine"])
    if m is None:
        raise PlcConfigError("no such machine in the plant")
    action, name = msg["action"], msg["name"]
    if action == "press":
        m.press(name)
    elif action in ("hold", "release"):
        getattr(m, action)(name)
    else:
        m.fault(name, action == "fault_on")


__all__ = ["ACTIONS", "MAX_ITEMS", "MAX_KEYS", "MAX_MACHINES", "MAX_NEST", "NAME", "apply",
           "clean", "machine_info", "machine_states"]
