"""Read a program with its symbol table and data block, in one encoding.

:func:`read_program` is what :func:`plcrt.load` and the pytest plugin use to
turn their ``source``, ``symbols`` and ``data`` arguments (paths, text, or
already parsed tables) into parsed objects.  The files among them are decoded
together by :func:`plcrt.lang.encoding.decode_files`, so a symbol name reads
the same in the program and in its table; a syntax error in a file whose
encoding was guessed carries a note saying so.

It does not compile anything; that is :mod:`plcrt.compiler`'s job.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Any, Callable, Sequence

from ..errors import PlcConfigError, PlcError, PlcSyntaxError, SourceLoc
from . import ir
from .codepage import string_codepage
from .datablock import parse_datablock
from .encoding import Decoded, decode_files, encoding_note, resolve_encoding
from .limits import check_text_size, file_limit
from .stl import parse_program
from .symbols import parse_symbols

__all__ = ["PROJECT_READERS", "is_file_arg", "read_program"]

#: front ends for project files, by file name ending (``.mwp``): each takes
#: the path and the size limit and returns (program, symbols or None, data
#: block or None).  :mod:`plcrt.project` fills it when imported (it sits
#: above this package and is imported by :mod:`plcrt.loader`)
PROJECT_READERS: dict[str, Callable[[str, int], tuple[ir.Program, Any, Any]]] = {}


def is_file_arg(x: Any) -> bool:
    """Whether a program, symbol or data argument names a file (a Path, or
    a string without a newline) rather than holding the text itself."""
    return isinstance(x, Path) or (isinstance(x, str) and "\n" not in x and len(x) < 4096)


def read_program(source: str | Path | Sequence[str | Path], symbols: Any = None,
                 data: Any = None, *, encoding: str | None = None,
                 max_bytes: int | None = None, v_bytes: int | None = None
                 ) -> tuple[ir.Program, Any, Any]:
    """(program, symbols, data), parsed.

    ``source`` is a path or program text, or a list of them whose blocks are
    merged (OB1 first, as Micro/WIN keeps OB1 and its subroutines in one
    project).  ``symbols`` and ``data`` are a path, text, an already parsed
    table (returned as it is) or None.  ``encoding`` forces the encoding of
    every file; by default it is detected.  The program's
    :attr:`~plcrt.lang.ir.Program.encoding` is the one its files were
    decoded with.  Files and texts longer than ``max_bytes`` (default: the
    limit of :mod:`plcrt.lang.limits`) are refused; ``v_bytes`` is the V
    memory size the data block is checked against.
    """
    codec = resolve_encoding(encoding)
    limit = file_limit() if max_bytes is None else max_bytes
    items = [source] if isinstance(source, (str, Path)) else list(source)
    if not items:
        raise PlcConfigError("no program given")
    project = _project_reader(items)
    if project is not None:       # a project file: program and its tables
        program, own_symbols, own_data = project(str(items[0]), limit)
        if symbols is None and data is None:
            return program, own_symbols, own_data
        _, symbols, data = read_program(program.source, symbols, data, encoding=encoding,
                                        max_bytes=max_bytes, v_bytes=v_bytes)
        return (program, own_symbols if symbols is None else symbols,
                own_data if data is None else data)
    tables = [x if isinstance(x, (str, Path)) else None for x in (symbols, data)]
    files = [x for x in items + tables if x is not None and is_file_arg(x)]
    for x in items + tables:
        if isinstance(x, str) and not is_file_arg(x):
            check_text_size(x, "<string>", limit)
    decoded = {id(x): d for x, d in zip(files, decode_files(files, codec, limit))}
    programs: list[ir.Program] = []
    failed: list[PlcSyntaxError] = []
    for x in items:               # every file's syntax errors in one report
        try:
            programs.append(_parse(parse_program, x, decoded.get(id(x))))
        except PlcSyntaxError as e:
            failed.append(e)
            if e.partial is not None:
                programs.append(e.partial)
    used = {decoded[id(x)].encoding for x in items if id(x) in decoded}
    program = _merge(programs, used.pop() if len(used) == 1 else "") if programs else None
    if failed:
        if len(failed) == 1:
            raise failed[0]
        err = PlcSyntaxError(failed[0].message, failed[0].loc,
                             [d for e in failed for d in e.diagnostics])
        err.partial = program
        raise err
    assert program is not None
    if tables[0] is not None:
        symbols = _parse(parse_symbols, tables[0], decoded.get(id(tables[0])))
    if tables[1] is not None:
        table = decoded.get(id(tables[1]))
        # its character constants in the code page the file was written in
        codepage = string_codepage(table.encoding if table is not None else program.encoding)
        data = _parse(partial(parse_datablock, v_bytes=v_bytes, codepage=codepage),
                      tables[1], table)
    return program, symbols, data


def _project_reader(items: list[Any]) -> Callable[[str, int], Any] | None:
    """The project-file reader for a single file argument whose name ends
    in a registered ending, else None."""
    readers = [PROJECT_READERS.get(Path(str(x)).suffix.lower()) if is_file_arg(x) else None
               for x in items]
    if len(items) > 1 and any(readers):
        raise PlcConfigError("a project file (.mwp, .smart) holds a whole program: load it "
                             "alone, not together with other program files")
    return readers[0]


def _merge(programs: list[ir.Program], encoding: str) -> ir.Program:
    """One program of the blocks of several files, OB1 first."""
    pous = tuple(p for prog in programs for p in prog.pous)
    if len(programs) > 1:
        pous = tuple(sorted(pous, key=lambda p: p.kind != "OB"))
    return ir.Program(pous, programs[0].file, programs[0].source, encoding)


def _parse(fn: Callable[[str, str], Any], x: Any, decoded: Decoded | None) -> Any:
    """``fn(text, file name)`` for one argument; a parse error of a file
    decoded with a guessed encoding gets a note after its first error."""
    text, name = (decoded.text, str(x)) if decoded is not None else (str(x), "<string>")
    try:
        return fn(text, name)
    except PlcError as e:
        note = encoding_note(decoded, e.loc or SourceLoc(name, 1, 1))
        if note is not None:
            e.diagnostics.append(note)
        raise
