"""The panel's STL editor on the server: the program's text, its check while
typing, the download to the running PLC and the save to its file.

The page edits the text of the program file (``lesson.awl`` of a lesson,
else the first program of ``plcrt serve``); the other files (symbols, data
block, plant, library programs) are loaded as the command line names them.
Four things are done with a text, each through HTTP at ``/editor/...``
(:mod:`plcrt.web.editroutes`):

* *check*: loaded as ``plcrt check`` loads it (nothing runs), the
  diagnostics come back with their lines and columns;
* *download*: loaded for running (a text with an error is never applied)
  and put in place of the running program the way Micro/WIN downloads
  (:func:`download`): in STOP from power-up; in RUN with the memory of the
  running program, when both programs keep all their state in memory;
* *save*: written to the program file, in its own encoding and line ends,
  only when the file on disk is still the one the page loaded;
* *source*: the file's text and a stamp that changes when the file does.

What it is: loading texts and moving the PLC's memory.  What it is not:
HTTP, origins and sizes (:mod:`plcrt.web.editroutes`), the runner thread
(:mod:`plcrt.web.session`).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..engine.runtime import Plc
from ..errors import Diagnostic, PlcConfigError, PlcError, capped
from ..isa.registry import REGISTRY
from ..lang import ir
from ..lang.encoding import read_decoded
from ..memory.image import Snapshot
from ..safetext import printable

#: the largest program text the editor takes (characters)
MAX_TEXT = 1_000_000
#: diagnostics sent back for one text
MAX_DIAGNOSTICS = 200
#: seconds a download in RUN waits for the scan boundary it swaps at
SWAP_TIMEOUT = 5.0

#: instructions whose state is not all in the memory image (attached
#: interrupts, high-speed counters, pulse outputs, ports and network jobs):
#: a program using one cannot take over a running one's state (a download
#: in RUN), only start from power-up (a download in STOP)
HIDDEN_STATE = frozenset({"ATCH", "DTCH", "ENI", "DISI", "CEVNT", "HDEF", "HSC", "PLS",
                          "XMT", "RCV", "NETR", "NETW", "GET", "PUT"})
#: areas a download in RUN does not carry over: the special memory is the
#: CPU's (SMB0 and the first-scan bit are set by the scan, not the program)
NOT_CARRIED = frozenset({"SM"})


@dataclass(frozen=True)
class ProgramSource:
    """The program file the editor edits and how a text of it is loaded.

    Args:
        path: the file the editor edits and saves.
        others: the other program files loaded with it (libraries), as
            they are on disk.
        options: the keyword arguments of :func:`plcrt.load` (symbols,
            data, plant, cpu, scan_ms, backend ...), as ``plcrt serve``'s
            options give them.
    """

    path: Path
    others: tuple[Path, ...] = ()
    options: Mapping[str, Any] = field(default_factory=dict)

    def load(self, text: str, *, check: bool = False) -> Plc:
        """The program with ``text`` in place of the file's.  ``check``:
        as ``plcrt check`` loads (a library without OB1 passes, the Python
        code generator: nothing is run); else for running.

        Raises:
            PlcError: the program does not load (with locations).
        """
        from .. import load
        opts = dict(self.options)
        opts.pop("encoding", None)   # the text is decoded already
        if check:
            opts.update(library=True, backend="python", instrument=False)
        return load([text, *self.others], **opts)

    def read(self) -> tuple[str, str]:
        """The file's text and stamp.

        Raises:
            PlcConfigError: the file cannot be read.
        """
        try:
            decoded = read_decoded(self.path, self.options.get("encoding"),
                                   max_bytes=4 * MAX_TEXT)
        except OSError as e:
            raise PlcConfigError(f"{self.path.name}: cannot be read: {e.strerror}") from None
        return decoded.text, self.stamp()

    def stamp(self) -> str:
        """Changes when the file does (modification time and size)."""
        try:
            st = self.path.stat()
        except OSError:
            return "missing"
        return f"{st.st_mtime_ns}-{st.st_size}"

    def writable(self) -> bool:
        return os.access(self.path, os.W_OK) and os.access(self.path.parent, os.W_OK)


#: the source of the current lesson's program (the argument: the lesson or
#: None); None: nothing to edit
SourceOf = Callable[[Any], "ProgramSource | None"]


def check_text(source: ProgramSource, text: str) -> dict[str, Any]:
    """``plcrt check`` of ``text``: ``ok`` (no error) and the diagnostics,
    each ``line`` and ``column`` in the text (null for one in another
    file), ``severity``, ``message`` and ``where`` (block and network),
    errors kept first when there are more than :data:`MAX_DIAGNOSTICS`."""
    check_size(text)
    try:
        diags = list(source.load(text, check=True).diagnostics)
        ok = True
    except PlcError as e:
        diags = list(e.diagnostics) or [Diagnostic("error", e.message, None)]
        ok = False
    return {"ok": ok, **diagnostics(diags)}


def diagnostics(diags: list[Diagnostic]) -> dict[str, Any]:
    """Diagnostics for the page: errors first, at most
    :data:`MAX_DIAGNOSTICS`, every text made printable."""
    shown, more = capped(diags, MAX_DIAGNOSTICS, ordered=True)
    items = []
    for d in shown:
        loc = d.loc
        mine = loc is not None and loc.file == "<string>"
        where = ""
        if loc is not None and loc.block:
            where = loc.block + (f" network {loc.network}" if loc.network else "")
        message = d.message if mine or loc is None else \
            f"{Path(loc.file).name}:{loc.line}: {d.message}"
        items.append({"severity": d.severity if d.severity in ("error", "warning") else "note",
                      "line": loc.line if mine and loc is not None else None,
                      "column": loc.column if mine and loc is not None else None,
                      "message": printable(message), "where": printable(where)})
    return {"diagnostics": items, "more": more}


def check_size(text: str) -> None:
    if not isinstance(text, str):
        raise PlcConfigError("the program text must be a text")
    if len(text) > MAX_TEXT:
        raise PlcConfigError(f"the program text is {len(text)} characters long; the editor "
                             f"takes at most {MAX_TEXT}")


def words() -> dict[str, Any]:
    """What completion and hover help know of the instructions: each
    mnemonic with its family, summary and operands (the registry's)."""
    return {"instructions": [
        {"m": s.mnemonic, "family": s.family, "summary": s.summary,
         "operands": [r.value for r in s.roles] + (["..."] if s.variadic else [])}
        for s in sorted(REGISTRY.values(), key=lambda s: s.mnemonic)]}


# ----------------------------------------------------------------------
# Download
# ----------------------------------------------------------------------
def run_obstacle(old: Plc, new: Plc) -> str | None:
    """Why ``new`` cannot take over the running ``old``'s state (a
    download in RUN), or None.  The memory image (I, Q, V, M, S, T, C, AI,
    AQ, AC, HC, L) moves; what lives outside it does not: devices of the
    plant, attached interrupts, counters, pulse outputs, ports, library
    blocks, a timing off-delay timer."""
    for which, plc in (("running", old), ("new", new)):
        if plc.devices:
            return f"the plant has devices ({_names(plc)}) whose state lives outside the " \
                   f"memory image"
        used = _mnemonics(plc.program)
        hidden = sorted(used & HIDDEN_STATE)
        if hidden:
            return f"the {which} program uses {', '.join(hidden)}, whose state lives outside " \
                   f"the memory image"
        lib = _library_calls(plc.program)
        if lib:
            return f"the {which} program calls the library block {lib}, whose state lives " \
                   f"outside the memory image"
    if {k: len(v) for k, v in old.mem.areas.items()} != \
            {k: len(v) for k, v in new.mem.areas.items()}:
        return "the two programs run on CPUs with different memory sizes"
    t = old.timers
    for n, kind in enumerate(t.kind):
        if kind == "TOF" and t.running[n]:
            return f"the off-delay timer T{n} is timing"
    return None


def carry(old: Plc, new: Plc) -> None:
    """Give ``new`` the memory of ``old`` (checked by :func:`run_obstacle`),
    in ``old``'s thread at a scan boundary: every area but the special
    memory, the counters' input edges, and the scan count (so that the next
    scan is not a first scan: SM0.1 stays off, as a program changed in RUN
    does not start again).  Timers go on from their current values."""
    snap = old.mem.snapshot()
    new.mem.restore(Snapshot({k: v for k, v in snap.areas.items() if k not in NOT_CARRIED}))
    new.counters.prev_up[:] = old.counters.prev_up
    new.counters.prev_dn[:] = old.counters.prev_dn
    new.scans = old.scans
    for key, value in old.forces.items():
        new.force(key, value)


def _names(plc: Plc) -> str:
    return ", ".join(sorted({type(d).__name__ for d in plc.devices}))


def _mnemonics(prog: ir.Program) -> set[str]:
    return {i.mnemonic for p in prog.pous for n in p.networks for i in n.insns}


def _library_calls(prog: ir.Program) -> str | None:
    own = {p.name.upper() for p in prog.pous} | {p.ident.upper() for p in prog.pous}
    for p in prog.pous:
        for n in p.networks:
            for i in n.insns:
                if i.mnemonic == "CALL" and i.operands and \
                        i.operands[0].text.upper() not in own:
                    return printable(i.operands[0].text)
    return None


# ----------------------------------------------------------------------
# Save
# ----------------------------------------------------------------------
def save(source: ProgramSource, text: str, stamp: str | None) -> str:
    """Write ``text`` to the program file, in the file's encoding and line
    ends, atomically (a temporary file replaced); returns the new stamp.

    Raises:
        PlcConfigError: the file changed on disk since ``stamp`` (the page
            must load it first), it is read-only, or the text has a
            character its encoding cannot hold.
    """
    check_size(text)
    path = source.path
    if stamp is not None and stamp != source.stamp():
        raise PlcConfigError(f"{path.name} changed on disk since the editor loaded it: "
                             f"load it again (or keep your text and save after that)")
    if path.exists() and not source.writable():
        raise PlcConfigError(f"{path.name} is read-only: nothing was saved. Copy the lesson "
                             f"folder to a folder of yours and serve the copy")
    encoding, newline = "utf-8", "\r\n"
    if path.exists():
        raw = path.read_bytes()[:4 * MAX_TEXT]
        decoded = read_decoded(path, source.options.get("encoding"), max_bytes=4 * MAX_TEXT)
        # an ASCII file says nothing of its code page: UTF-8, which reads back the same
        encoding = "utf-8" if decoded.encoding == "ascii" else decoded.encoding
        newline = "\r\n" if b"\r\n" in raw or not raw else "\n"
    body = text.replace("\r\n", "\n").replace("\r", "\n").replace("\n", newline)
    try:
        data = body.encode(encoding)
    except UnicodeEncodeError as e:
        bad = printable(body[e.start:e.end])
        raise PlcConfigError(f"{path.name} is {encoding.upper()}: it cannot hold '{bad}'; "
                             f"nothing was saved") from None
    fd, tmp = tempfile.mkstemp(prefix=".plcrt-", suffix=".awl", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        if path.exists():
            os.chmod(tmp, path.stat().st_mode & 0o777)
        os.replace(tmp, path)
    except OSError as e:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise PlcConfigError(f"{path.name}: cannot be written: {e.strerror}") from None
    return source.stamp()


__all__ = ["HIDDEN_STATE", "MAX_TEXT", "ProgramSource", "SourceOf", "carry", "check_size",
           "check_text", "diagnostics", "run_obstacle", "save", "words"]
