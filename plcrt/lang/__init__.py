"""The plcrt front end: program, symbol table and data block text to data.

``parse_program`` reads Micro/WIN STL export text into the IR of
:mod:`plcrt.lang.ir`; ``read_source`` decodes such files from disk in the
encoding :mod:`plcrt.lang.encoding` detects; ``parse_symbols`` and ``parse_datablock`` read the symbol
table and data block files that travel with a program.

Nothing here checks what instructions mean or whether addresses exist; that
is the compiler's job.
"""

from __future__ import annotations

from .datablock import DataBlock, DataEntry, parse_datablock
from .stl import parse_program, read_source
from .symbols import (
    SYSTEM_SYMBOLS,
    Symbol,
    SymbolTable,
    parse_symbols,
    resolve_symbol,
)

__all__ = [
    "SYSTEM_SYMBOLS",
    "DataBlock",
    "DataEntry",
    "Symbol",
    "SymbolTable",
    "parse_datablock",
    "parse_program",
    "parse_symbols",
    "read_source",
    "resolve_symbol",
]
