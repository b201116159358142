"""Which block a scan runs as the main program: OB1, or the block a user
chose with ``entry=`` (``plcrt run --entry SBR0``).

A Micro/WIN export of a subroutine library has no OB1; to run one of its
subroutines on its own, the program is compiled as a library and the chosen
block takes OB1's place: each scan runs it once, with the main program's
local memory (L).  Its parameters and temporaries are the L addresses its
declaration gives them (``LB0``, ``LD4``...): zero at power-up, written by
nobody but the block itself, ``--set`` / ``plc.write`` and forces, and kept
from one scan to the next (docs/decisions.md).

This module only resolves and checks the choice (and lists the blocks for
the compiler's "no OB1" error); the engine calls the block's compiled
function where it would call OB1's.
"""

from __future__ import annotations

from typing import Any

from ..errors import PlcConfigError
from ..safetext import excerpt, shown_value

#: blocks a scan can run as its main program (an interrupt routine runs on
#: its event, so it is not one)
ENTRY_KINDS = ("OB", "SBR")

#: at most this many blocks are named in a message
_LISTED = 12


def check_entry(entry: Any) -> None:
    """Refuse an ``entry`` that is not a block name.

    Raises:
        PlcConfigError: not a non-empty string of at most 64 characters.
    """
    if not isinstance(entry, str) or not entry.strip() or len(entry) > 64:
        raise PlcConfigError(f"entry must name a block (OB1, SBR0 or a subroutine's name), "
                             f"got {shown_value(entry)}")


def block_list(pous: Any) -> str:
    """``SBR0 (SCALE), SBR1, ...`` for messages: the blocks that can run as
    the main program, at most :data:`_LISTED` of them."""
    names = [p.ident + (f" ({excerpt(p.name)})" if p.name and p.name.upper() != p.ident else "")
             for p in pous if p.kind in ENTRY_KINDS]
    more = len(names) - _LISTED
    return ", ".join(names[:_LISTED]) + (f" and {more} more" if more > 0 else "") or "none"


def main_block(unit: Any, entry: str) -> str:
    """The identifier (``SBR0``) of the block ``entry`` names, by number or
    by its symbolic name, case-insensitively.

    Raises:
        PlcConfigError: no such block, or an interrupt routine; the message
            lists the blocks that can run.
    """
    info = unit.callee(entry)
    pous = [i.pou for i in unit.pous.values()]
    if info is None:
        raise PlcConfigError(f"entry {excerpt(entry)!r}: the program has no such block; the "
                             f"blocks that can run as the main program: {block_list(pous)}")
    if info.pou.kind not in ENTRY_KINDS:
        raise PlcConfigError(f"entry {excerpt(entry)!r}: {info.pou.ident} is an interrupt "
                             f"routine, which runs on its event; the blocks that can run as the "
                             f"main program: {block_list(pous)}")
    return info.pou.ident


__all__ = ["ENTRY_KINDS", "block_list", "check_entry", "main_block"]
