"""What every module of debugger commands shares: :class:`Command`, one
entry of the command table, and :class:`CommandError`.

The table itself is :data:`plcrt.debug.commands.COMMANDS`; the commands are
written in :mod:`plcrt.debug.commands` and, for traces,
:mod:`plcrt.debug.trace_commands`.  Both import these two names from here,
so neither module needs the other at import time.  This module holds no
command and no session state.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .session import Session


class CommandError(Exception):
    """A command that cannot be carried out as written: printed as
    ``error: <message>`` and the session goes on."""


@dataclass(frozen=True)
class Command:
    """One entry of the command table."""

    name: str
    handler: Callable[[Session, list[str]], None]
    usage: str
    summary: str
    details: str = ""
    aliases: tuple[str, ...] = ()
    #: would start scans: refused while paused inside a scan
    runs_scans: bool = False
    #: only makes sense while paused (continue, next, finish)
    paused_only: bool = False


__all__ = ["Command", "CommandError"]
