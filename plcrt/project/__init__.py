"""Micro/WIN V3 and V4 (``.mwp``) and Micro/WIN SMART V2 and V3 (``.smart``,
``.smartV3``) project files.

A front end beside :mod:`plcrt.lang`: it reads a project file (container,
bounded decompression, system block, program block, symbol tables, data
block) and hands :mod:`plcrt.lang` the STL export text of its program, so
a project loads into the same :class:`~plcrt.lang.ir.Program` its ``.awl`` export does.
Importing :mod:`.frontend` registers the reader in
:data:`plcrt.lang.sources.PROJECT_READERS` (:mod:`plcrt.loader` does), so
``plcrt.load("x.mwp")`` and the command line read project files.

Submodules: :mod:`.stream` (the bounded cursor), :mod:`.container`
(header, password, zlib), :mod:`.program` (blocks, networks, statements),
:mod:`.tables` (symbol tables), :mod:`.datapage` (data block),
:mod:`.wizards` (the wizard configurations and their plant tables), :mod:`.codes`
(the code tables), :mod:`.sysblock` (the system block), :mod:`.r03`, :mod:`.r03codes` and :mod:`.r03tables`
(Micro/WIN V3 projects: blocks and cells, compiled code, symbol table),
:mod:`.smartv3` and :mod:`.smartv3pou` (SMART V3 projects: the encrypted
zip, its blocks, symbol tables and data pages),
:mod:`.awl` (the export text), :mod:`.reader` (the
sections in order), :mod:`.frontend` (what ``load`` calls), :mod:`.cli`
(``plcrt export``).  The package imports them when a name below is first
used, so importing :mod:`plcrt.project.cli` for ``plcrt --help`` stays
cheap.  docs/project-files.md says what is read and what is not.
"""

from __future__ import annotations

from typing import Any

__all__ = ["PROJECT_SUFFIXES", "Project", "load_project", "read_project",
           "read_project_file"]

_WHERE = {"PROJECT_SUFFIXES": "reader", "Project": "reader", "read_project": "reader",
          "read_project_file": "reader", "load_project": "frontend"}


def __getattr__(name: str) -> Any:
    # perf: imported on first use (PEP 562), not by ``plcrt --help``
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'plcrt.project' has no attribute {name!r}")
    from importlib import import_module
    return getattr(import_module(f"{__name__}.{module}"), name)
