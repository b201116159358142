"""Conditions of the test harness: ``"Q0.0"``, ``"not M0.1"``,
``"VW100 >= 25"``, ``"axis0.0.position > 10"``, or a function; and how
failure messages name them.

What it is: the parser of condition strings into fast predicates (each
address resolved once), readers of addresses and device signals, and the
text a message shows for a condition (a lambda by its source text).  What
it is not: the loop that scans until a condition holds (that is
:class:`plcrt.testing.harness.Harness`).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol, Union

from ..engine.values import parse_number, shown_value
from ..errors import PlcConfigError
from ..trace.recorder import is_device_signal, parse_signal

if TYPE_CHECKING:
    from ..engine.runtime import Plc

Value = Union[int, float, bool]
#: a condition function takes no argument, or the harness it is checked on
Condition = Union[str, Callable[[], Any], Callable[[Any], Any]]


class HasPlc(Protocol):
    """What a condition is checked on: a harness (or anything with its PLC)."""

    plc: Plc


# ---------------------------------------------------------------------------
# Fast readers
# ---------------------------------------------------------------------------

def reader(plc: Plc, spec: str) -> Callable[[], Value]:
    """A function reading one address (``VW100``, ``VD4:REAL``, ``T37:BIT``,
    symbol names) or one device quantity (``axis0.0.position``,
    ``drive1.statusword``, the signals of ``plcrt trace``) resolved once,
    for per-scan use (see :meth:`Plc.reader`)."""
    if isinstance(spec, str) and is_device_signal(spec):
        return parse_signal(plc, spec).read
    return plc.reader(spec)[1]


_COND_RE = re.compile(r"^\s*(not\s+|!)?\s*([^<>=!]+?)\s*"
                      r"(?:(==|!=|<>|<=|>=|<|>|=)\s*([^\s<>=!]\S*))?\s*$", re.IGNORECASE)
_OPS: dict[str, Callable[[Any, Any], bool]] = {
    "==": lambda a, b: a == b, "=": lambda a, b: a == b, "!=": lambda a, b: a != b,
    "<>": lambda a, b: a != b, "<": lambda a, b: a < b, "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b, ">=": lambda a, b: a >= b,
}


def condition(h: HasPlc, cond: Condition) -> tuple[Callable[[], bool], str]:
    """A no-argument predicate and its description from a condition:
    ``"Q0.0"``, ``"not M0.1"``, ``"VW100 >= 25"``, ``"VD8:REAL > 1.5"``, a
    callable taking no argument, or a callable taking the harness."""
    if callable(cond):
        import inspect
        try:
            takes_arg = len(inspect.signature(cond).parameters) >= 1
        except (TypeError, ValueError):
            takes_arg = False
        name = getattr(cond, "__name__", "")
        if not name or name == "<lambda>":
            name = describe_function(cond)
        if takes_arg:
            return (lambda: bool(cond(h))), name   # type: ignore[call-arg]
        return (lambda: bool(cond())), name        # type: ignore[call-arg]
    if not isinstance(cond, str):
        raise PlcConfigError(f"a condition is a string such as 'Q0.0' or 'VW100 >= 25', or a "
                             f"function; got {type(cond).__name__} {shown_value(cond)}")
    m = _COND_RE.match(cond)
    if m is None:
        raise PlcConfigError(f"cannot read the condition {shown_value(cond)}: write 'ADDR', "
                             f"'not ADDR' "
                             f"or 'ADDR <op> value' with op one of == != < <= > >=")
    neg, addr, op, value = m.groups()
    rd = reader(h.plc, addr)
    if op is None:
        return ((lambda: not rd()) if neg else (lambda: bool(rd()))), str(cond).strip()
    try:
        v = parse_number(value)
    except PlcConfigError:
        raise PlcConfigError(f"condition {shown_value(cond)}: {shown_value(value)} is not a "
                             f"number") from None
    fn = _OPS[op]
    if neg:
        return (lambda: not fn(rd(), v)), str(cond).strip()
    return (lambda: fn(rd(), v)), str(cond).strip()


#: longest condition text a message quotes
SHOWN_CONDITION = 120


def describe_function(fn: Callable[..., Any]) -> str:
    """A condition function as a message shows it: the text of a lambda
    from its source line (``lambda: h["Q0.0"] and h["VW10"] > 5``), else
    "the condition" (no source, e.g. typed at a prompt)."""
    import inspect
    try:
        src = inspect.getsource(fn)
    except (OSError, TypeError):
        return UNNAMED
    start = src.find("lambda")
    if start < 0:
        return UNNAMED
    depth, end = 0, len(src)
    for k in range(start, len(src)):
        ch = src[k]
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
            if depth < 0:     # the bracket that closes the call around the lambda
                end = k
                break
        elif depth == 0 and (ch == "\n" or (ch == "," and ":" in src[start:k])):
            end = k           # the next argument, or the end of the line
            break
    text = " ".join(src[start:end].split())
    return text if len(text) <= SHOWN_CONDITION else text[:SHOWN_CONDITION - 1] + "\u2026"


#: how a message names a condition function whose text is unknown
UNNAMED = "the condition"


def quoted(what: str) -> str:
    """A condition's description in a message: quoted, but for "the condition"."""
    return what if what == UNNAMED else repr(what)


def addresses_of(cond: Condition | None) -> list[str]:
    """The address or signal a comparison such as ``"VW100 >= 25"`` reads
    (none for a bit condition, whose value its failure says, or a function)."""
    if not isinstance(cond, str):
        return []
    m = _COND_RE.match(cond)
    return [m.group(2)] if m is not None and m.group(3) else []


__all__ = ["Condition", "HasPlc", "UNNAMED", "addresses_of", "condition", "describe_function", "quoted",
           "reader"]
