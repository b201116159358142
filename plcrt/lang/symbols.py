"""Symbol tables: Micro/WIN tab-separated text and Micro/WIN SMART ``.sdf`` CSV.

A symbol table maps names used as operands (``电机启动``, ``Start_PB``) to
addresses (``I0.0``).  This module reads the two export formats into a
:class:`SymbolTable` and knows the built-in S7-200 SMART system symbols
(``Always_On`` = ``SM0.0`` ...).

It is not an address checker: the address text is kept exactly as written
and the compiler decides whether ``VW7`` or ``QX0.0`` is valid.  Nor does it
resolve ``#local`` names, which belong to a block's VAR table.

Lookup rules (see :func:`resolve_symbol`): names are case-sensitive, as in
Micro/WIN; a user symbol hides a system symbol of the same name.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field

from ..errors import Diagnostic, DiagnosticSink, PlcSyntaxError, SourceLoc
from ..safetext import excerpt
from .stlerrors import raise_collected

__all__ = ["SYSTEM_SYMBOLS", "Symbol", "SymbolTable", "parse_symbols",
           "resolve_symbol"]

#: Built-in S7-200 SMART system symbols, name -> address.  Micro/WIN SMART
#: exports use these names as operands without listing them in the user's
#: symbol table, so the compiler must know them.
SYSTEM_SYMBOLS: dict[str, str] = {
    "Always_On": "SM0.0",
    "First_Scan_On": "SM0.1",
    "Retentive_Lost": "SM0.2",
    "RUN_Power_Up": "SM0.3",
    "Clock_60s": "SM0.4",
    "Clock_1s": "SM0.5",
    "Clock_Scan": "SM0.6",
    "RTC_Lost": "SM0.7",
    "Result_0": "SM1.0",
    "Overflow_Illegal": "SM1.1",
    "Neg_Result": "SM1.2",
    "Divide_By_0": "SM1.3",
    "Table_Overflow": "SM1.4",
    "Table_Empty": "SM1.5",
    "Not_BCD": "SM1.6",
    "Not_Hex": "SM1.7",
    "Time_0_Intrvl": "SMB34",
    "Time_1_Intrvl": "SMB35",
    "HSC0_Ctrl": "SMB37",
    "HSC0_CV": "SMD38",
    "HSC0_PV": "SMD42",
    "HSC1_Ctrl": "SMB47",
    "HSC1_CV": "SMD48",
    "HSC1_PV": "SMD52",
    "HSC2_Ctrl": "SMB57",
    "HSC2_CV": "SMD58",
    "HSC2_PV": "SMD62",
    "HSC3_Ctrl": "SMB137",
    "HSC3_CV": "SMD138",
    "HSC3_PV": "SMD142",
    "PLS0_Stat": "SMB66",
    "PLS0_Ctrl": "SMB67",
    "PLS0_Cycle": "SMW68",
    "PWM0_PW": "SMW70",
    "PTO0_PC": "SMD72",
    "PLS1_Stat": "SMB76",
    "PLS1_Ctrl": "SMB77",
    "PLS1_Cycle": "SMW78",
    "PWM1_PW": "SMW80",
    "PTO1_PC": "SMD82",
    "P0_Config": "SMB30",
    "P1_Config": "SMB130",
    "P0_Stat_Rcv": "SMB86",
    "P0_Ctrl_Rcv": "SMB87",
    "P0_Start_Char": "SMB88",
    "P0_End_Char": "SMB89",
    "P0_Idle_Time": "SMW90",
    "P0_Timeout": "SMW92",
    "P0_Max_Char": "SMB94",
    "P1_Stat_Rcv": "SMB186",
    "P1_Ctrl_Rcv": "SMB187",
    "P1_Start_Char": "SMB188",
    "P1_End_Char": "SMB189",
    "P1_Idle_Time": "SMW190",
    "P1_Timeout": "SMW192",
    "P1_Max_Char": "SMB194",
}


@dataclass(frozen=True, slots=True)
class Symbol:
    """One symbol: its name, address text as written, and comment."""

    name: str
    address: str
    comment: str = ""
    #: where it was defined; ``None`` for a built-in system symbol
    loc: SourceLoc | None = None


@dataclass
class SymbolTable:
    """The user's symbols of one file (or several merged by the caller)."""

    entries: dict[str, Symbol] = field(default_factory=dict)
    file: str = "<string>"

    def lookup(self, name: str) -> Symbol | None:
        """The *user* symbol called ``name`` (exact, case-sensitive) or None.

        System symbols are not consulted; use :func:`resolve_symbol` or
        :meth:`with_system` for that.
        """
        return self.entries.get(name)

    def with_system(self) -> SymbolTable:
        """A new table holding the user symbols plus every system symbol
        whose name the user did not define (user symbols take precedence)."""
        merged = {name: Symbol(name, address, "system symbol")
                  for name, address in SYSTEM_SYMBOLS.items()}
        merged.update(self.entries)
        return SymbolTable(entries=merged, file=self.file)

    def __len__(self) -> int:
        return len(self.entries)

    def __contains__(self, name: object) -> bool:
        return name in self.entries


def resolve_symbol(table: SymbolTable | None, name: str) -> Symbol | None:
    """Resolve ``name`` as the compiler should: user symbol, else system symbol.

    ``table`` may be None when the program comes without a symbol table; the
    SMART system symbols still resolve then.  Returns None for unknown names.
    """
    if table is not None:
        found = table.lookup(name)
        if found is not None:
            return found
    address = SYSTEM_SYMBOLS.get(name)
    if address is None:
        return None
    return Symbol(name, address, "system symbol")


# --------------------------------------------------------------------------
# Parsing
# --------------------------------------------------------------------------

# Header cells of the first row, lower-cased, in English and Chinese
# (Micro/WIN SMART localises the column titles).
_NAME_HEADERS = {"symbol", "name", "symbol name", "符号", "符号名"}
_ADDRESS_HEADERS = {"address", "地址"}


def parse_symbols(text: str, file: str = "<string>") -> SymbolTable:
    """Parse a symbol table in either export format and return it.

    The format is detected from the first non-blank line: a line starting
    with a double quote (the ``"Symbol","Address","Comment"`` header Micro/WIN
    SMART writes) means CSV; a line with a TAB or ``|`` means the Micro/WIN
    tab-separated form; otherwise commas mean CSV and anything else is read
    as blank-separated ``name address comment``.  Raises
    :class:`PlcSyntaxError` listing every bad row and duplicate name.
    """
    if text.startswith("\ufeff"):
        text = text[1:]
    first = next((line for line in text.splitlines() if line.strip()), "")
    stripped = first.strip()
    if stripped.startswith('"') or (
            "\t" not in first and "|" not in first and "," in first):
        rows = _csv_rows(text, file)
    else:
        rows = _tabbed_rows(text)

    sink = DiagnosticSink()
    table = SymbolTable(file=file)
    header_checked = False
    for line, column, cells in rows:
        loc = SourceLoc(file, line, column)
        if not header_checked:
            header_checked = True
            if (len(cells) >= 2 and cells[0].lower() in _NAME_HEADERS
                    and cells[1].lower() in _ADDRESS_HEADERS):
                continue
        name = cells[0] if cells else ""
        address = cells[1] if len(cells) > 1 else ""
        comment = " ".join(c for c in cells[2:] if c)
        if not name:
            sink.error("symbol row without a name", loc, code="symbol")
            continue
        if not address:
            sink.error(f"symbol {excerpt(name)!r} has no address", loc, code="symbol")
            continue
        previous = table.entries.get(name)
        if previous is not None:
            sink.items.append(Diagnostic(
                "error", f"duplicate symbol {excerpt(name)!r} (first defined at "
                f"{previous.loc})", loc, "symbol"))
            sink.items.append(Diagnostic(
                "note", f"first definition of {excerpt(name)!r}", previous.loc, "symbol"))
            continue
        table.entries[name] = Symbol(name, address, comment, loc)
    raise_collected(sink)
    return table


Row = tuple[int, int, list[str]]


def _csv_rows(text: str, file: str) -> list[Row]:
    """Rows of a CSV export as (line, column of first cell, stripped cells)."""
    rows: list[Row] = []
    lines = text.splitlines()
    reader = csv.reader(io.StringIO(text, newline=""))
    start = 1
    try:
        for cells in reader:
            # reader.line_num is the line the record *ended* on; a quoted
            # comment may span lines, so remember where the record began.
            line = start
            start = reader.line_num + 1
            cells = [c.strip() for c in cells]
            if not any(cells):
                continue
            raw = lines[line - 1] if line - 1 < len(lines) else ""
            column = len(raw) - len(raw.lstrip()) + 1
            rows.append((line, column, cells))
    except csv.Error as exc:
        raise PlcSyntaxError(f"bad CSV symbol table: {exc}",
                             SourceLoc(file, start, 1)) from None
    return rows


def _tabbed_rows(text: str) -> list[Row]:
    """Rows of the Micro/WIN text form as (line, column, stripped cells).

    Micro/WIN 4 copies a symbol table with leading status columns that are
    empty or hold a ``|`` marker; such leading cells are dropped.  A line
    without TAB is split at ``|`` if it has one, else at blanks (name and
    address, the rest is the comment).  ``//`` lines are comments.
    """
    rows: list[Row] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        body = raw.strip()
        if not body or body.startswith("//"):
            continue
        if "\t" in raw:
            parts = raw.split("\t")
        elif "|" in raw:
            parts = raw.split("|")
        else:
            parts = body.split(None, 2)
        # Column of the first real cell, for the location of errors.
        offset = 0
        cells: list[str] = []
        for part in parts:
            cell = part.strip()
            if not cells and cell in ("", "|"):
                offset += len(part) + 1
                continue
            cells.append(cell)
        if not cells:
            continue
        lead = raw[offset:] if offset <= len(raw) else ""
        column = offset + (len(lead) - len(lead.lstrip())) + 1
        rows.append((number, column, cells))
    return rows
