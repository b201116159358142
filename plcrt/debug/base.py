"""The entry type of the debugger's command table: :class:`Command`.

The table itself is :data:`plcrt.debug.commands.COMMANDS`; the commands are
written in :mod:`plcrt.debug.commands` and, for traces,
:mod:`plcrt.debug.trace_commands`.  A handler receives the
:class:`~plcrt.debug.state.SessionState` it acts on, never the interpreter
(:class:`plcrt.debug.session.Session`), so the command modules and the
interpreter import this module and :mod:`plcrt.debug.state`, not each other.
This module holds no command and no session state.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from .state import CommandError, SessionState


@dataclass(frozen=True)
class Command:
    """One entry of the command table."""

    name: str
    handler: Callable[[SessionState, list[str]], None]
    usage: str
    summary: str
    details: str = ""
    aliases: tuple[str, ...] = ()
    #: would start scans: refused while paused inside a scan
    runs_scans: bool = False
    #: only makes sense while paused (continue, next, finish)
    paused_only: bool = False


__all__ = ["Command", "CommandError"]
