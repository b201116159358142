"""JSON messages from untrusted clients, bounded before they are parsed:
size in UTF-8 bytes, UTF-8 itself, and the nesting depth of arrays and
objects (Python's decoder recurses once per level).  Shared by the panel's
websocket protocol (:mod:`plcrt.web.protocol`) and the lockstep protocol
(:mod:`plcrt.net.lockstep`).

What it is: reading one message into Python values, and writing one
(NaN and the infinities as text).  What it is not: what a message may say
(each protocol checks its own fields).
"""

from __future__ import annotations

import json
import math
from typing import Any

from ..errors import PlcConfigError

__all__ = ["MessageError", "dumps", "finite", "load", "nesting"]


class MessageError(PlcConfigError):
    """A client message that is not bounded, UTF-8 JSON."""


def load(text: str | bytes, *, max_bytes: int, max_depth: int,
         error: type[PlcConfigError] = MessageError) -> Any:
    """The JSON value of ``text``, checked before it is parsed.

    Raises:
        ``error``: over ``max_bytes`` UTF-8 bytes, not UTF-8, nested deeper
            than ``max_depth``, or not JSON.
    """
    size = len(text.encode("utf-8", "surrogatepass") if isinstance(text, str) else text)
    if size > max_bytes:
        raise error(f"message too long ({size} bytes, at most {max_bytes})")
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError:
            raise error("a message must be UTF-8 JSON text") from None
    # perf: every normal message has fewer brackets than the limit
    if text.count("[") + text.count("{") > max_depth:
        depth = nesting(text)
        if depth > max_depth:
            raise error(f"a message may nest arrays and objects {max_depth} deep at "
                        f"most (this one: {depth})")
    try:
        return json.loads(text)
    except (ValueError, RecursionError):
        # RecursionError cannot happen after nesting(); kept so that no
        # parser limit ever escapes as a traceback
        raise error("a message must be a JSON object") from None


def nesting(text: str) -> int:
    """How deep arrays and objects nest in JSON ``text`` (brackets inside
    strings do not count), found before parsing: Python's JSON decoder
    recurses once per level and fails with RecursionError near 1000.  One
    pass over the text, whatever it holds."""
    depth = deepest = 0
    in_str = escaped = False
    for ch in text:
        if in_str:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_str = False
        elif ch == '"':
            in_str = True
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth -= 1
    return deepest


def finite(v: int | float) -> int | float | str:
    """A value JSON can carry: NaN and the infinities as text."""
    if isinstance(v, float) and not math.isfinite(v):
        return "NaN" if v != v else ("Infinity" if v > 0 else "-Infinity")
    return v


def dumps(msg: Any) -> str:
    """A message as compact JSON text (NaN and infinities must have gone
    through :func:`finite`)."""
    return json.dumps(msg, separators=(",", ":"), allow_nan=False)
