"""The ``plcrt export`` command: a project file's STL export, symbol table
and data block, written as Micro/WIN writes them.

::

    plcrt export PROJECT [--awl OUT.awl] [--symbols OUT.txt] [--data OUT.db]
        [--plant OUT.toml] [--max-file-mb MB]

Each file is written in the project's code page with CR LF line ends, so
it can be read, diffed and versioned, and loaded again by ``plcrt``; the
plant tables the project's wizards give (``--plant``) are UTF-8 TOML, as a
plant file is.
Errors (an unreadable project, an output that cannot be written) are
:class:`~plcrt.errors.PlcError` s, reported by :mod:`plcrt.cli`.

Presentation only: the reading is :mod:`plcrt.project.reader`'s.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..errors import PlcConfigError, SourceLoc
from ..paths import check_path
from ..safetext import printable

__all__ = ["register", "cmd_export"]


def register(sub: Any) -> None:
    """Add the ``export`` subcommand to the ``plcrt`` parser."""
    p = sub.add_parser(
        "export", help="write a project file's STL export, symbol table and data block",
        description="Read a Micro/WIN V4 (.mwp) or Micro/WIN SMART V2/V3 (.smart, .smartV3) "
                    "project and "
                    "write its program as an STL export (.awl), its symbol table "
                    "(tab-separated) and its data block, in the project's code page.")
    p.add_argument("project", metavar="PROJECT", help="the project file (.mwp, .smart, .smartV3)")
    p.add_argument("--awl", metavar="F", help="write the program's STL export here")
    p.add_argument("--symbols", metavar="F", help="write the symbol table here")
    p.add_argument("--data", metavar="F", help="write the data block here")
    p.add_argument("--plant", metavar="F", help="write the plant tables the project's wizards "
                   "give ([pto.N], [pwm.N]) here")
    p.add_argument("--max-file-mb", type=float, default=None, metavar="MB",
                   help="largest project file read (default 16)")
    p.set_defaults(func=cmd_export)


def cmd_export(args: argparse.Namespace) -> int:
    """Run ``plcrt export``; returns the exit status (0)."""
    from ..lang.limits import file_limit
    from .reader import read_project_file

    project = read_project_file(check_path(args.project, "the project"),
                                file_limit(args.max_file_mb))
    codec = "cp1252" if project.encoding in ("", "ascii") else project.encoding
    outputs = ((args.awl, project.awl), (args.symbols, project.symbols),
               (args.data, project.data))
    plant = getattr(args, "plant", None)
    if not any(path for path, _ in outputs) and not plant:
        raise PlcConfigError("plcrt export: give at least one of --awl, --symbols, --data, "
                             "--plant")
    for path, text in outputs:
        if path:
            _write(path, text, codec)
    if plant:
        _write(plant, project.plant, "utf-8")
        if not project.plant:
            print(printable(f"{args.project}: note: no wizard configuration gives a plant "
                            "table; the plant file written is empty"), file=sys.stderr)
    for note in project.notes:        # names read from the file: escaped
        print(printable(f"{args.project}: note: {note}"), file=sys.stderr)
    return 0


def _write(path: str, text: str, codec: str) -> None:
    target = check_path(path, "the output file")
    try:
        target.write_bytes(text.encode(codec, "replace"))
    except OSError as e:
        raise PlcConfigError(f"cannot write {target}: {e.strerror or e}",
                             SourceLoc(str(target), 1, 1)) from None
