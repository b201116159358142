"""Write the blocks of a project as the STL export Micro/WIN writes.

The text is what ``File > Export`` of Micro/WIN produces for a program
block (``ORGANIZATION_BLOCK MAIN:OB1``, ``TITLE=``, the local variable
table, ``Network n // title``, comment lines, one statement a line, the
mnemonic padded to seven columns), so it is both the ``.awl`` that
``plcrt export`` writes and the text :mod:`plcrt.lang` parses when a
project is loaded: a project and its export become the same IR.

Strings are kept one character a byte (Latin-1) until the whole text is
written; the caller decodes it once with plcrt's code-page detection.
It reads nothing; :mod:`.program` does.
"""

from __future__ import annotations

import re

from .program import Block, Net

__all__ = ["blocks_text"]

_CONTROL = re.compile(r"[\x00-\x1f\x7f]")
_HEADS = {"OB": ("ORGANIZATION_BLOCK", "END_ORGANIZATION_BLOCK"),
          "SBR": ("SUBROUTINE_BLOCK", "END_SUBROUTINE_BLOCK"),
          "INT": ("INTERRUPT_BLOCK", "END_INTERRUPT_BLOCK")}
_SECTIONS = (("IN", "VAR_INPUT"), ("IN_OUT", "VAR_IN_OUT"), ("OUT", "VAR_OUTPUT"),
             ("TEMP", "VAR"))


def _one_line(text: str) -> str:
    """``text`` on one line: a name or title read from a project file
    cannot start a line of its own (no statement is injected through it)."""
    return _CONTROL.sub(" ", text).strip()


def _comment_lines(text: str) -> list[str]:
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    return ["// " + _one_line(line) if _one_line(line) else "//" for line in lines]


def _statement(mnemonic: str, operands: tuple[str, ...]) -> str:
    if not operands:
        return mnemonic
    return f"{mnemonic:<6} {', '.join(_one_line(o) for o in operands)}"


def kept_networks(block: Block) -> list[Net]:
    """The networks an export lists: trailing empty networks (no
    statement, title or comment; the editor keeps a page of them) are left
    out, at least one network is kept."""
    nets = list(block.networks)
    while len(nets) > 1 and not (nets[-1].statements or nets[-1].title or nets[-1].comment):
        nets.pop()
    return nets


def block_text(block: Block) -> list[str]:
    head, tail = _HEADS[block.kind]
    name = _one_line(block.name) or block.ident
    lines = [f"{head} {name}:{block.ident}", f"TITLE={_one_line(block.comment)}"]
    if block.remarks.strip():
        lines.extend(_comment_lines(block.remarks))
    for section, keyword in _SECTIONS:
        rows = [v for v in block.variables if v[0] == section]
        if rows or (block.kind == "SBR" and block.variables):
            lines.append(keyword)
            for _, vname, vtype, comment in rows:
                note = f"\t// {_one_line(comment)}" if comment.strip() else ""
                lines.append(f"{_one_line(vname)}:{vtype};{note}")
            lines.append("END_VAR")
    lines.append("BEGIN")
    # a block with a password is exported as Micro/WIN exports it: its
    # interface and one empty network (docs/project-files.md)
    nets = [Net("", "", "LAD")] if block.protected else kept_networks(block)
    for number, net in enumerate(nets, 1):
        title = _one_line(net.title)
        lines.append(f"Network {number} // {title}" if title else f"Network {number} ")
        if net.comment.strip():
            lines.extend(_comment_lines(net.comment))
        lines.extend(_statement(m, ops) for m, ops in net.statements)
    lines.append(tail)
    return lines


def blocks_text(blocks: list[Block]) -> str:
    """The export of ``blocks`` (MAIN first, then subroutines, then
    interrupt routines, as Micro/WIN orders them), CR LF line ends."""
    order = {"OB": 0, "SBR": 1, "INT": 2}
    ordered = sorted(blocks, key=lambda b: (order[b.kind], b.number))
    lines = [line for b in ordered for line in block_text(b)]
    return "\r\n".join(lines) + "\r\n"
