"""``plcrt dump``: the generated Python of a program, annotated for reading.

Each network's code gets a banner with its block, network and title,
and each instruction marker of the generated code gets the STL line it
came from.  This module only formats text for people; nothing here is
executed or fed back to the compiler.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

from .engine.runtime import Plc
from .errors import PlcError
from .safetext import printable

# The marker before each instruction's code (:func:`_with_markers`).
_INSN_COMMENT_RE = re.compile(r"^(\s*)# \[(\d+)\] line (\d+)\s*$")
_PIECE_DEF_RE = re.compile(r"^def n_([A-Z]+\d+)_(\d+)")
#: a function holding several consecutive networks of a block
_GROUP_DEF_RE = re.compile(r"^def g_([A-Z]+\d+)_")
_RUNNER_RE = re.compile(r"^(?:def |_pieces_|_costs_)?pou_([A-Z]+\d+)")



def render_dump(plc: Plc) -> str:
    """The generated source, annotated for reading.

    Before each network's code a banner names the block, network and
    title; each ``# [id] line n`` marker gains the STL text of line ``n``.
    The result is meant for people: the STL text is inserted into comments
    only, and nothing of it is executed.
    """
    texts = _source_lines(plc)
    titles = {(p.ident, n.number): n.title for p in plc.program.pous for n in p.networks}
    names = {p.ident: p.name for p in plc.program.pous}
    locs = plc.unit.locs
    lines = _with_markers(plc)
    files = sorted({str(f) for f in texts})
    out = [f"# plcrt dump of {', '.join(files) or plc.program.file}",
           "# Generated Python, for reading only: each '# [id] line n:' comment",
           "# shows the STL instruction whose code follows it.", ""]
    out += _backend_lines(plc)
    last_runner = None
    in_group = False
    shown: tuple[str, int] | None = None      # the network of the last banner

    def banner(block: str, net: int) -> None:
        title = titles.get((block, net), "")
        out.append(printable(f"# ==== {block} network {net}"
                             + (f": {title}" if title else "") + " ===="))

    for i, line in enumerate(lines):
        piece = _PIECE_DEF_RE.match(line)
        if piece:
            block, net = _piece_origin(lines, i, locs) or (piece.group(1), int(piece.group(2)))
            banner(block, net)
            shown, in_group = (block, net), False
            last_runner = None
        elif _GROUP_DEF_RE.match(line):
            # several networks in one function: a banner before it for the
            # first, and where each of the others begins
            in_group, shown = True, _piece_origin(lines, i, locs)
            if shown is not None:
                banner(*shown)
            last_runner = None
        runner = _RUNNER_RE.match(line)
        if runner and runner.group(1) != last_runner:
            last_runner = runner.group(1)
            name = names.get(last_runner, "")
            label = f" ({name})" if name and name != last_runner else ""
            out.append(printable(f"# ==== {last_runner}{label}: runs its networks in order ===="))
        m = _INSN_COMMENT_RE.match(line)
        if m:
            insn_id = int(m.group(2))
            loc = locs[insn_id] if insn_id < len(locs) else None
            if in_group and loc is not None and loc.block and loc.network is not None \
                    and (loc.block, loc.network) != shown:
                shown = (loc.block, loc.network)
                banner(loc.block, loc.network)
            lineno = loc.line if loc else int(m.group(3))
            stl = _stl_line(texts, loc.file if loc else None, lineno)
            # program text goes into a comment only, with control characters
            # escaped (a CR or an escape sequence must not reach the output)
            line = f"{m.group(1)}# [{insn_id}] line {lineno}: {printable(stl)}"
        out.append(line)
    return "\n".join(out).rstrip("\n") + "\n"


def _with_markers(plc: Plc) -> list[str]:
    """The generated module's lines with the marker ``# [id] line n``
    before the code of each instruction (the module itself has none: the
    compiler records where each instruction's code starts)."""
    table = plc.line_locs
    starts, indents = table.starts, table.indents
    locs = plc.unit.locs
    out: list[str] = []
    k, n = 0, len(starts)
    for number, line in enumerate(plc.source.splitlines(), 1):
        while k < n and starts[k] <= number:
            out.append("    " * indents[k] + f"# [{k}] line {int(locs[k].line)}")
            k += 1
        out.append(line)
    out += ["    " * indents[i] + f"# [{i}] line {int(locs[i].line)}" for i in range(k, n)]
    return out


def _piece_origin(lines: list[str], start: int, locs: Sequence[Any]) -> tuple[str, int] | None:
    """Block and network of the function starting at ``lines[start]``, from
    its first instruction marker (exact even when names change)."""
    for line in lines[start + 1:]:
        if line and not line.startswith((" ", "\t")):
            return None  # next top-level statement: a function without instructions
        m = _INSN_COMMENT_RE.match(line)
        if m:
            insn_id = int(m.group(2))
            if insn_id < len(locs) and locs[insn_id].block and locs[insn_id].network is not None:
                return locs[insn_id].block, locs[insn_id].network
            return None
    return None


def _source_lines(plc: Plc) -> dict[str, list[str]]:
    """Program text per file, split into lines the way the parser counts them
    (CRLF and a lone CR each end one line)."""
    from .lang import read_source

    files = {p.loc.file for p in plc.program.pous}
    texts: dict[str, list[str]] = {}
    for f in files:
        try:
            # the encoding the program was loaded with, not a new guess
            text = read_source(f, plc.program.encoding or None)
        except PlcError:
            # A file that vanished since loading: fall back to the text kept
            # in the program, which is right for the first file at least.
            text = plc.program.source if f == plc.program.file else ""
        texts[f] = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    return texts


def _stl_line(texts: dict[str, list[str]], file: str | None, lineno: int) -> str:
    lines = texts.get(file or "") or next(iter(texts.values()), [])
    if 1 <= lineno <= len(lines):
        return lines[lineno - 1].strip()
    return "?"


__all__ = ["render_dump"]


def _backend_lines(plc: Plc) -> list[str]:
    """With the native backend: how many pieces are machine code (the
    ``_nsegK()`` calls of the block runners) and why the others are not."""
    info = plc.backend
    if info["name"] != "native":
        return []
    if "pieces" not in info:
        return ["# native backend: every piece runs as Python (an instrumented program)", ""]
    out = [f"# native backend: {info['pieces']} pieces run as machine code in "
           f"{info['segments']} segments (_nsegK() in the block runners); "
           f"{len(info['python'])} as the Python below"]
    for block, net, why in info["python"][:50]:
        out.append(printable(f"#   {block} network {net}: {why}"))
    if len(info["python"]) > 50:
        out.append(f"#   ... and {len(info['python']) - 50} more")
    return out + [""]
