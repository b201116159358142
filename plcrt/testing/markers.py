"""The ``plc`` marker's and ``plc_factory``'s arguments, checked.

What it is: the list of options a marker takes (:data:`OPTIONS`), the
marker's help line, and :func:`_make_spec`, which checks the arguments of
``@pytest.mark.plc(...)`` or of a ``plc_factory(...)`` call and resolves
the files they name (relative to the test's directory, then the rootdir)
into a :class:`_Spec`; a wrong argument is a :class:`PlcUsageError` whose
message says what to change.  What it is not: loading anything (the
plugin builds harnesses from a spec, :mod:`plcrt.testing.plugin`), nor the
command-line options (:mod:`plcrt.testing.options`).  Like the plugin it
imports the engine only when an argument needs its checks.
"""

from __future__ import annotations

import difflib
import hashlib
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..safetext import excerpt

#: keyword arguments of the marker and of ``plc_factory``
OPTIONS = ("symbols", "data", "plant", "scan_ms", "cpu", "watch", "history", "max_time",
           "encoding", "clock")

MARKER_HELP = (
    "plc(program, *, symbols=None, data=None, plant=None, scan_ms=None, cpu=None, "
    "watch=(), history=None, max_time=None, encoding=None, clock=None): the S7-200 STL "
    "program "
    "(a .awl path or a list of them, relative to the test file or the rootdir) that the "
    "`plc` fixture loads"
)


class PlcUsageError(Exception):
    """A wrong marker or factory argument; the message says what to change."""


@dataclass
class _Spec:
    """Validated arguments of one harness to build."""

    program: tuple[Path, ...] | str     #: resolved files, or STL text
    label: str                          #: the program as the test named it
    key: str                            #: coverage key (rootdir-relative paths)
    symbols: Any = None
    data: Any = None
    plant: Any = None
    scan_ms: float | None = None
    cpu: str | None = None
    watch: tuple[str, ...] = ()
    history: int | None = None
    max_time: float | None = None
    encoding: str | None = None         #: codec name, None to detect
    clock: Any = None                   #: the real-time clock's start (load's clock=)


def _is_pathlike(x: Any) -> bool:
    return isinstance(x, (str, os.PathLike))


def _shown(value: Any) -> str:
    # perf: the engine's values module only when a message needs it
    from ..engine.values import shown_value
    return shown_value(value)


def _scan_us(scan_ms: Any, what: str, error: type[Exception]) -> None:
    """The scan time checked as :func:`plcrt.load` checks it, the message
    naming the option (the engine is imported only when one is given)."""
    from ..engine.values import scan_time_us
    from ..errors import PlcConfigError
    try:
        scan_time_us(scan_ms, what)
    except PlcConfigError as e:
        raise error(e.message) from None


def _resolve(value: Any, what: str, bases: list[Path]) -> Path:
    """A file named relative to the test's directory first, then the rootdir."""
    from ..errors import PlcConfigError
    from ..paths import check_path
    try:
        p = check_path(value, f"{what}=")
    except PlcConfigError as e:
        raise PlcUsageError(e.message) from None
    candidates = [p] if p.is_absolute() else [b / p for b in bases]
    for c in candidates:
        try:
            if c.is_file():
                return c.resolve()
        except OSError as e:
            # a name the file system cannot look up (too long, a bad mount)
            raise PlcUsageError(f"{what} file {excerpt(os.fspath(value))!r}: "
                                f"{e.strerror or e}") from None
    looked = ", ".join(str(c) for c in candidates)
    raise PlcUsageError(f"{what} file {os.fspath(value)!r} not found (looked for {looked})")


def _file_or_text(value: Any, what: str, bases: list[Path]) -> Any:
    """Strings with a newline are the file's text, as in Harness.load."""
    if value is None or (isinstance(value, str) and "\n" in value):
        return value
    if not _is_pathlike(value):
        raise PlcUsageError(f"{what}= must be a file path, got {type(value).__name__} "
                            f"{_shown(value)}")
    return _resolve(value, what, bases)


def _display(p: Path, root: Path) -> str:
    try:
        return p.relative_to(root.resolve()).as_posix()
    except ValueError:
        return p.as_posix()


def _make_spec(args: tuple[Any, ...], kwargs: dict[str, Any], bases: list[Path],
               root: Path) -> _Spec:
    """Check the marker's or factory's arguments; raise PlcUsageError."""
    if len(args) != 1:
        raise PlcUsageError(
            f"expected one program (a path, or a list of paths) as the only positional "
            f"argument, got {len(args)} positional argument(s)")
    unknown = [k for k in kwargs if k not in OPTIONS]
    if unknown:
        hints = []
        for k in unknown:
            close = difflib.get_close_matches(k, OPTIONS, n=1)
            hints.append(f"{k!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
        raise PlcUsageError(f"unknown argument(s) {', '.join(hints)}; "
                            f"the options are {', '.join(OPTIONS)}")
    program = args[0]
    if isinstance(program, str) and "\n" in program:
        digest = hashlib.sha1(program.encode("utf-8")).hexdigest()[:10]
        prog: tuple[Path, ...] | str = program
        label, key = "<STL text>", f"<STL text {digest}>"
    else:
        items = list(program) if isinstance(program, (list, tuple)) else [program]
        if not items or not all(_is_pathlike(x) for x in items):
            raise PlcUsageError(f"the program must be a .awl path or a non-empty list of "
                                f"paths, got {_shown(program)}")
        prog = tuple(_resolve(x, "program", bases) for x in items)
        label = " + ".join(os.fspath(x) for x in items)
        key = " + ".join(_display(p, root) for p in prog)
    spec = _Spec(prog, label, key)
    spec.symbols = _file_or_text(kwargs.get("symbols"), "symbols", bases)
    spec.data = _file_or_text(kwargs.get("data"), "data", bases)
    plant = kwargs.get("plant")
    spec.plant = plant if isinstance(plant, dict) else _file_or_text(plant, "plant", bases)
    scan_ms = kwargs.get("scan_ms")
    if scan_ms is not None:
        _scan_us(scan_ms, "scan_ms=", PlcUsageError)
        spec.scan_ms = float(scan_ms)
    cpu = kwargs.get("cpu")
    if cpu is not None and not isinstance(cpu, str):
        raise PlcUsageError(f"cpu= must be a CPU name such as 'CPU224', got {_shown(cpu)}")
    spec.cpu = cpu
    watch = kwargs.get("watch", ())
    if isinstance(watch, str) or not isinstance(watch, (list, tuple)) or \
            not all(isinstance(a, str) for a in watch):
        raise PlcUsageError(f"watch= must be a list of addresses such as ['Q0.0', 'VW100'], "
                            f"got {_shown(watch)}")
    spec.watch = tuple(watch)
    history = kwargs.get("history")
    if history is not None and (isinstance(history, bool) or not isinstance(history, int)
                                or history < 1):
        raise PlcUsageError(f"history= must be a whole number of scans >= 1, got "
                            f"{_shown(history)}")
    spec.history = history
    max_time = kwargs.get("max_time")
    if max_time is not None:
        from ..errors import PlcConfigError
        from .harness import seconds
        try:
            spec.max_time = seconds(max_time)
        except PlcConfigError:
            raise PlcUsageError(f"max_time= must be a duration such as 60, '90s' or '5min', "
                                f"got {_shown(max_time)}") from None
    encoding = kwargs.get("encoding")
    if encoding is not None:
        from ..errors import PlcConfigError
        from ..lang.encoding import resolve_encoding
        try:
            spec.encoding = resolve_encoding(encoding)
        except PlcConfigError as e:
            raise PlcUsageError(e.message) from None
    clock = kwargs.get("clock")
    if clock is not None:
        from ..engine.clock import start_time
        from ..errors import PlcConfigError
        try:
            spec.clock = start_time(clock, "clock=")
        except PlcConfigError as e:
            raise PlcUsageError(e.message) from None
    return spec


__all__ = ["MARKER_HELP", "OPTIONS", "PlcUsageError"]
