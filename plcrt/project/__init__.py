"""Micro/WIN V4 (``.mwp``) and Micro/WIN SMART V2 (``.smart``) project files.

A front end beside :mod:`plcrt.lang`: it reads a project file (container,
bounded decompression, program block) and hands :mod:`plcrt.lang` the STL
export text of its program, so a project loads into the same
:class:`~plcrt.lang.ir.Program` its ``.awl`` export does.  Importing the
package registers :func:`load_project` in
:data:`plcrt.lang.sources.PROJECT_READERS`, so ``plcrt.load("x.mwp")``
and the command line read project files (:mod:`plcrt.loader` imports it).

Submodules: :mod:`.stream` (the bounded cursor), :mod:`.container`
(header, password, zlib), :mod:`.program` (blocks, networks, statements),
:mod:`.codes` (the code tables), :mod:`.awl` (the export text),
:mod:`.reader` (the sections in order).  docs/project-files.md says what
is read and what is not.
"""

from __future__ import annotations

from typing import Any

from ..lang import ir
from ..lang.sources import PROJECT_READERS
from ..lang.codepage import string_codepage
from ..lang.datablock import parse_datablock
from ..lang.stl import parse_program
from ..lang.symbols import parse_symbols
from .reader import PROJECT_SUFFIXES, Project, read_project, read_project_file

__all__ = ["PROJECT_SUFFIXES", "Project", "load_project", "read_project",
           "read_project_file"]


def load_project(path: str, limit: int) -> tuple[ir.Program, Any, Any]:
    """(program, symbols, data block) of the project file ``path``; the
    program's :attr:`~plcrt.lang.ir.Program.source` is its STL export."""
    project = read_project_file(path, limit)
    program = parse_program(project.awl, path)
    program = ir.Program(program.pous, program.file, program.source, project.encoding)
    symbols = parse_symbols(project.symbols, path) if project.symbols else None
    data = None
    if project.data.strip():
        data = parse_datablock(project.data, path, codepage=string_codepage(project.encoding))
    return program, symbols, data


for _suffix in PROJECT_SUFFIXES:
    PROJECT_READERS[_suffix] = load_project
