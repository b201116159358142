"""The project-file front end as :mod:`plcrt.lang.sources` calls it.

Importing this module registers :func:`load_project` in
:data:`plcrt.lang.sources.PROJECT_READERS` for ``.mwp``, ``.smart`` and
``.smartv3`` (suffixes are compared in lower case), so
``plcrt.load("x.mwp")`` and the command line read project files
(:mod:`plcrt.loader` and ``plcrt show`` import it).  It is kept apart from
the package's ``__init__`` so that ``plcrt --help``, which imports
:mod:`plcrt.project.cli`, loads neither the parser nor lark.
"""

from __future__ import annotations

from typing import Any

from ..lang import ir
from ..lang.codepage import string_codepage
from ..lang.datablock import parse_datablock
from ..lang.sources import PROJECT_READERS
from ..lang.stl import parse_program
from ..lang.symbols import parse_symbols
from .reader import PROJECT_SUFFIXES, read_project_file

__all__ = ["load_project"]


def load_project(path: str, limit: int) -> tuple[ir.Program, Any, Any]:
    """(program, symbols, data block) of the project file ``path``; the
    program's :attr:`~plcrt.lang.ir.Program.source` is its STL export."""
    project = read_project_file(path, limit)
    program = parse_program(project.awl, path)
    program = ir.Program(program.pous, program.file, program.source, project.encoding,
                         project.plant, system=project.system,
                         project_notes=tuple(project.notes), from_project=True)
    symbols = parse_symbols(project.symbols, path) if project.symbols else None
    data = None
    if project.data.strip():
        data = parse_datablock(project.data, path, codepage=string_codepage(project.encoding))
    return program, symbols, data


for _suffix in PROJECT_SUFFIXES:
    PROJECT_READERS[_suffix] = load_project
