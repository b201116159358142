"""``plcrt debug``: an interactive, scriptable debugger for a loaded PLC.

:mod:`plcrt.debug.session` is the command interpreter (the input loop,
breakpoints on networks and the paused mode inside a scan) over
:mod:`plcrt.debug.state`, the state a session keeps and the operations the
commands use; :mod:`plcrt.debug.commands` holds the commands (scan, run,
break, watch, set, force, show, axes, ...) in a table of
:class:`plcrt.debug.base.Command` entries, and :mod:`plcrt.debug.panels`
the tables and the ladder view with live values they print; :mod:`plcrt.debug.complete`
is Tab completion at the prompt; :mod:`plcrt.debug.cli` is the
``plcrt debug`` subcommand that wires a session to a terminal, a script file
or a pipe.

This package does not run PLC code itself: every scan is
:meth:`plcrt.Plc.scan`, and breakpoints are the probes an instrumented
program (``plcrt.load(..., instrument=True)``) carries anyway.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .session import COMMANDS, CommandError, Session

__all__ = ["COMMANDS", "CommandError", "Session"]


def __getattr__(name: str) -> Any:
    # perf: `plcrt --help` imports plcrt.debug.cli to register the
    # subcommand; the interpreter is only needed when a session starts
    if name in __all__:
        from . import session
        return getattr(session, name)
    raise AttributeError(f"module 'plcrt.debug' has no attribute {name!r}")
