"""CiA 402 object dictionaries as data, and the live values with SDO rules.

An object dictionary is one TOML file per drive model under
``library/cia402/`` (``hcfa-am0520b.toml``, ``kinco-servo.toml``): a
``[model]`` table and a ``[dictionary]`` table whose ``entries`` array holds with one inline table per
(index, subindex), each row citing the manual section it comes from.
:class:`ObjectDictionary` loads and checks such a file (a malformed row is a
:class:`~plcrt.errors.PlcConfigError` naming the file, the line and the
entry); :class:`~.store.Store` (in :mod:`.store`, which builds on this
module) holds the values a drive has and answers SDO uploads and downloads
with the abort codes of ETG.1000.6 / CiA 301 (digest §6.3).

This module knows nothing of drive behaviour: the CiA 402 state machine, the
modes and the EtherCAT state machine subscribe to writes through
:meth:`~.store.Store.on_check` (may refuse) and :meth:`~.store.Store.on_write`
(is told).  The canopen ``ObjectDictionary``/EDS view of the same data is in
:mod:`.canopen_od` (public as :mod:`plcrt.cia402`).
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator

from ...blocks.interface import library_dirs as block_dirs
from ...errors import PlcConfigError, PlcError, SourceLoc
from ...safetext import printable

#: dtype -> (bits, minimum, maximum); the CoE basic data types (ETG.1000.6).
DTYPES: dict[str, tuple[int, int, int]] = {
    "BOOL": (1, 0, 1),
    "I8": (8, -(1 << 7), (1 << 7) - 1),
    "U8": (8, 0, (1 << 8) - 1),
    "I16": (16, -(1 << 15), (1 << 15) - 1),
    "U16": (16, 0, (1 << 16) - 1),
    "I32": (32, -(1 << 31), (1 << 31) - 1),
    "U32": (32, 0, (1 << 32) - 1),
    "I64": (64, -(1 << 63), (1 << 63) - 1),
    "U64": (64, 0, (1 << 64) - 1),
    "STR": (0, 0, 0),
}
ACCESS = ("ro", "rw", "wo", "const")
PDO = ("rx", "tx", "")
EFFECT = ("now", "power-up")
#: "stopped": not while the drive moves (HCFA "停机设定"); "preop": only in
#: the ESM state PRE-OP (PDO mapping and assignment, ETG.1000.6).
WHEN = ("any", "stopped", "preop")
ESM_STATES = ("INIT", "PREOP", "SAFEOP", "OP")

#: SDO abort codes (digest §6.3: ETG.1000.6 Table 41 and CiA 301).
ABORT_CODES: dict[int, str] = {
    0x06010000: "unsupported access to an object",
    0x06010001: "attempt to read a write-only object",
    0x06010002: "attempt to write a read-only object",
    0x06010003: "subindex 0 must be 0 to write this subindex",
    0x06020000: "object does not exist in the object dictionary",
    0x06040041: "object cannot be mapped to the PDO",
    0x06040042: "mapped objects would exceed the PDO length",
    0x06040043: "general parameter incompatibility",
    0x06070010: "data type does not match, length of service parameter does not match",
    0x06070012: "data type does not match, length of service parameter too long",
    0x06070013: "data type does not match, length of service parameter too short",
    0x06090011: "subindex does not exist",
    0x06090030: "value range of parameter exceeded",
    0x06090031: "value of parameter written too high",
    0x06090032: "value of parameter written too low",
    0x08000000: "general error",
    0x08000022: "data cannot be transferred or stored because of the present device state",
}

_MODEL_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")

#: Dictionaries already read, by (path, mtime, size); they are not changed after loading.
_LOADED: dict[tuple[str, int, int], "ObjectDictionary"] = {}

_KEYS_REQUIRED = ("index", "sub", "name", "type", "access", "default", "source")
_KEYS_OPTIONAL = ("pdo", "min", "max", "unit", "effect", "when", "values")


def library_dirs() -> list[Path]:
    """Folders searched for ``<model>.toml``: ``cia402/`` under each plcrt
    library folder (``$PLCRT_LIBRARY_PATH``, then the project's ``library/``)."""
    return [d / "cia402" for d in block_dirs()]


def is_map(index: int) -> bool:
    """RxPDO (1600h–17FFh) or TxPDO (1A00h–1BFFh) mapping object (CiA 301)."""
    return 0x1600 <= index <= 0x17FF or 0x1A00 <= index <= 0x1BFF


def is_assign(index: int) -> bool:
    """Sync-manager PDO assignment 1C12h (outputs) / 1C13h (inputs), ETG.1000.6."""
    return index in (0x1C12, 0x1C13)


def obj(index: int, sub: int) -> str:
    """The usual way of naming an entry: ``6083h:00``."""
    return f"{index:04X}h:{sub:02X}"


@dataclass(frozen=True, slots=True)
class Entry:
    """One row of an object dictionary: a (index, subindex) and its rules."""

    index: int
    sub: int
    name: str
    dtype: str  #: one of :data:`DTYPES`
    access: str  #: "ro", "rw", "wo" or "const"
    pdo: str  #: "rx", "tx" or "" (not mappable)
    min: int | None
    max: int | None
    default: int | str
    unit: str
    effect: str  #: "now" or "power-up" (HCFA 立即生效 / 再次通电)
    when: str  #: "any", "stopped" (HCFA 停机设定) or "preop"
    source: str  #: manual section(s) the row comes from
    values: tuple[int, ...] | None = None  #: the only values accepted, if set

    @property
    def bits(self) -> int:
        """Size in bits as a PDO mapping entry gives it (BOOL is 1 bit)."""
        if self.dtype == "STR":
            return 8 * len(str(self.default).encode("latin-1"))
        return DTYPES[self.dtype][0]

    @property
    def size(self) -> int:
        """Size in bytes of the value in an SDO transfer."""
        return (self.bits + 7) // 8

    @property
    def low(self) -> int:
        """Lowest value accepted (the row's ``min`` or the type's)."""
        return DTYPES[self.dtype][1] if self.min is None else self.min

    @property
    def high(self) -> int:
        """Highest value accepted (the row's ``max`` or the type's)."""
        return DTYPES[self.dtype][2] if self.max is None else self.max

    @property
    def label(self) -> str:
        """``6083h:00 (Profile acceleration)``."""
        return f"{obj(self.index, self.sub)} ({self.name})"

    def encode(self, value: int | str) -> bytes:
        """The little-endian CoE bytes of ``value``."""
        if self.dtype == "STR":
            return str(value).encode("latin-1")
        signed = self.dtype.startswith("I")
        try:
            return int(value).to_bytes(self.size, "little", signed=signed)
        except OverflowError:
            bits, low, high = DTYPES[self.dtype]
            # CiA 301: a value the type cannot hold cannot be sent with the object's length
            raise SdoAbort(0x06070010, f"{self.label} is {self.dtype} ({low}..{high}): "
                                       f"{value} does not fit it") from None

    def decode(self, data: bytes) -> int | str:
        """The value of little-endian CoE bytes (length already checked)."""
        if self.dtype == "STR":
            return bytes(data).decode("latin-1")
        return int.from_bytes(data, "little", signed=self.dtype.startswith("I"))


class SdoAbort(PlcError):
    """An SDO transfer refused with a CoE/CANopen abort code.

    ``code`` is the 32-bit abort code; ``explanation`` names the object, the
    value and the manual section.
    """

    def __init__(self, code: int, explanation: str) -> None:
        self.code = code
        self.explanation = explanation
        meaning = ABORT_CODES.get(code, "abort")
        super().__init__(f"SDO abort 0x{code:08X} ({meaning}): {explanation}")


class ObjectDictionary:
    """The entries of one drive model, read from its TOML file."""

    def __init__(self, model: str, info: dict[str, Any], entries: list[Entry],
                 path: Path | None = None) -> None:
        self.model = model
        self.info = info  #: the file's ``[model]`` table
        self.path = path
        self._entries = {(e.index, e.sub): e for e in sorted(entries, key=lambda e: (e.index, e.sub))}
        self._subs: dict[int, list[Entry]] = {}
        for e in self._entries.values():
            self._subs.setdefault(e.index, []).append(e)

    # -- loading -----------------------------------------------------------
    @staticmethod
    def models() -> list[str]:
        """Names of the drive models found in the library folders."""
        names = {p.stem for d in library_dirs() if d.is_dir() for p in d.glob("*.toml")}
        return sorted(names)

    @classmethod
    def load(cls, model: str) -> ObjectDictionary:
        """Load a model by name (``"hcfa-am0520b"``, ``"kinco-servo"``).

        Raises:
            PlcConfigError: unknown model (naming the known ones), or a
                malformed file (naming the file, line and entry).
        """
        # (a name longer than any file name is no model either)
        named = isinstance(model, str) and len(model) <= 64 and _MODEL_NAME.fullmatch(model)
        for d in library_dirs() if named else ():
            path = d / f"{model}.toml"
            if path.is_file():
                stat = path.stat()
                key = (str(path.resolve()), stat.st_mtime_ns, stat.st_size)
                if key not in _LOADED:
                    _LOADED[key] = cls.from_file(path)
                return _LOADED[key]
        known = ", ".join(cls.models()) or "none"
        shown = printable(model)[:40] if isinstance(model, str) else type(model).__name__
        raise PlcConfigError(f"unknown CiA 402 drive model {shown!r}; known models: {known}")

    @classmethod
    def from_file(cls, path: str | Path) -> ObjectDictionary:
        """Load and check one object dictionary file."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
            data = tomllib.loads(text)
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
            raise PlcConfigError(f"cannot read object dictionary: {e}",
                                 SourceLoc(str(path), 1, 1)) from None
        info = data.get("model")
        if not isinstance(info, dict) or not isinstance(info.get("name"), str):
            raise PlcConfigError("missing [model] table with a name",
                                 SourceLoc(str(path), 1, 1))
        table = data.get("dictionary")
        rows = table.get("entries") if isinstance(table, dict) else None
        if not isinstance(rows, list) or not rows:
            raise PlcConfigError("missing [dictionary] table with an 'entries' array",
                                 SourceLoc(str(path), 1, 1))
        lines = [n for n, line in enumerate(text.splitlines(), 1) if line.lstrip().startswith("{")]
        entries: list[Entry] = []
        seen: set[tuple[int, int]] = set()
        for i, row in enumerate(rows):
            line = lines[i] if len(lines) == len(rows) else 1
            loc = SourceLoc(str(path), line, 1)
            entry = _entry(row, i, loc)
            if (entry.index, entry.sub) in seen:
                raise PlcConfigError(f"entry #{i + 1} {entry.label}: duplicate entry", loc)
            seen.add((entry.index, entry.sub))
            entries.append(entry)
        od = cls(info["name"], info, entries, path)
        od._check_structure(lines if len(lines) == len(rows) else None, rows)
        return od

    def _check_structure(self, lines: list[int] | None, rows: list[Any]) -> None:
        """Whole-file rules: records have a U8 subindex 0; default PDO maps
        name existing, mappable objects of the right size and fit the PDO."""
        def fail(e: Entry, msg: str) -> None:
            where = {(r.get("index"), r.get("sub")): n for r, n in zip(rows, lines or [])}
            line = where.get((e.index, e.sub), 1)
            raise PlcConfigError(f"{e.label}: {msg}",
                                 SourceLoc(str(self.path), line, 1))
        for index, subs in self._subs.items():
            if len(subs) > 1 or subs[0].sub != 0:
                head = self._entries.get((index, 0))
                if head is None or head.dtype != "U8":
                    fail(subs[-1], f"object {index:04X}h has subindexes but no U8 subindex 0")
        for e in self:
            if is_map(e.index) and e.sub > 0 and e.default:
                try:
                    self.check_mapping(e, int(e.default))
                except SdoAbort as abort:
                    fail(e, f"default mapping is invalid: {abort.explanation}")
            if is_map(e.index) and e.sub == 0:
                try:
                    self.check_map_length(e.index, int(e.default), self.default_of)
                except SdoAbort as abort:
                    fail(e, f"default mapping is invalid: {abort.explanation}")

    # -- lookup ------------------------------------------------------------
    def entry(self, index: int, sub: int) -> Entry:
        """The entry at (index, sub).

        Raises:
            SdoAbort: 0x06020000 no such object, 0x06090011 no such subindex.
        """
        e = self._entries.get((index, sub))
        if e is not None:
            return e
        layout = self.info.get("layout", "")
        if index not in self._subs:
            raise SdoAbort(0x06020000, f"object {index:04X}h does not exist in the {self.model} "
                                       f"object dictionary ({layout})")
        have = ", ".join(f"{s.sub:02X}" for s in self._subs[index])
        raise SdoAbort(0x06090011, f"{index:04X}h has no subindex {sub:02X} "
                                   f"(it has {have}; {self._subs[index][0].source})")

    def find(self, index: int, sub: int) -> Entry | None:
        """The entry at (index, sub), or None."""
        return self._entries.get((index, sub))

    def subs(self, index: int) -> list[Entry]:
        """All entries of one object, by subindex (empty if none)."""
        return list(self._subs.get(index, ()))

    def indexes(self) -> list[int]:
        """The object indexes, ascending."""
        return list(self._subs)

    def __iter__(self) -> Iterator[Entry]:
        return iter(self._entries.values())

    def __len__(self) -> int:
        return len(self._entries)

    def __contains__(self, key: object) -> bool:
        return key in self._entries

    def default_of(self, index: int, sub: int) -> int | str:
        return self._entries[(index, sub)].default

    # -- PDO mapping rules (HCFA §6.7.2; ETG.1000.6) -------------------------
    @property
    def pdo_max_entries(self) -> int:
        return int(self.info.get("pdo_max_entries", 8))

    @property
    def pdo_max_bytes(self) -> int:
        return int(self.info.get("pdo_max_bytes", 32))

    def check_mapping(self, entry: Entry, value: int) -> Entry | None:
        """Check one mapping entry ``index<<16 | sub<<8 | bits`` written to
        ``entry`` (a 16xxh/1Axxh subindex > 0); returns the mapped entry
        (None for an empty entry 0)."""
        if value == 0:
            return None
        index, sub, bits = value >> 16, (value >> 8) & 0xFF, value & 0xFF
        target = self._entries.get((index, sub))
        where = f"{entry.label} := 0x{value:08X}"
        if target is None:
            raise SdoAbort(0x06020000, f"{where}: {obj(index, sub)} does not exist in the "
                                       f"{self.model} object dictionary ({entry.source})")
        direction = "rx" if entry.index < 0x1A00 else "tx"
        if target.pdo != direction:
            kind = "not mappable" if not target.pdo else f"mappable only to a {target.pdo.upper()}PDO"
            raise SdoAbort(0x06040041, f"{where}: {target.label} is {kind} "
                                       f"({target.source})")
        if bits != target.bits:
            raise SdoAbort(0x06040043, f"{where}: {target.label} is {target.bits} bits, "
                                       f"the entry says {bits} ({entry.source})")
        return target

    def check_map_length(self, index: int, count: int,
                         value_of: Callable[[int, int], int | str]) -> None:
        """Check that ``count`` entries of map ``index`` fit one PDO."""
        head = self._entries[(index, 0)]
        limit = self.pdo_max_entries
        if count > limit:
            raise SdoAbort(0x06040042, f"{head.label} := {count}: a PDO holds at most {limit} "
                                       f"objects ({self.info.get('pdo_source', head.source)})")
        total = 0
        for k in range(1, count + 1):
            sub = self._entries.get((index, k))
            raw = int(value_of(index, k)) if sub is not None else 0
            if raw == 0:
                raise SdoAbort(0x06040041, f"{head.label} := {count}: entry "
                                           f"{obj(index, k)} is empty ({head.source})")
            total += raw & 0xFF
        if total > 8 * self.pdo_max_bytes:
            raise SdoAbort(0x06040042, f"{head.label} := {count}: the entries take {total} bits, "
                                       f"a PDO holds at most {self.pdo_max_bytes} bytes "
                                       f"({self.info.get('pdo_source', head.source)})")


def _entry(row: Any, i: int, loc: SourceLoc) -> Entry:
    """Check one TOML row and make its :class:`Entry`."""
    name = row.get("name", f"entry #{i + 1}") if isinstance(row, dict) else f"entry #{i + 1}"
    where = f"entry #{i + 1}"

    def bad(msg: str) -> PlcConfigError:
        label = name
        if isinstance(row, dict) and isinstance(row.get("index"), int) and isinstance(row.get("sub"), int):
            label = f"{obj(row['index'], row['sub'])} ({name})"
        return PlcConfigError(f"{where} {label}: {msg}", loc)

    if not isinstance(row, dict):
        raise bad("an entry is an inline table { index = …, sub = …, … }")
    for key in _KEYS_REQUIRED:
        if key not in row:
            raise bad(f"missing key {key!r}")
    for key in row:
        if key not in _KEYS_REQUIRED + _KEYS_OPTIONAL:
            raise bad(f"unknown key {key!r} (keys: {', '.join(_KEYS_REQUIRED + _KEYS_OPTIONAL)})")
    for key in ("index", "sub"):
        if not isinstance(row[key], int) or isinstance(row[key], bool):
            raise bad(f"{key} must be an integer")
    if not 0 <= row["index"] <= 0xFFFF or not 0 <= row["sub"] <= 0xFF:
        raise bad("index must be 0..0xFFFF and sub 0..0xFF")
    choices = {"type": tuple(DTYPES), "access": ACCESS, "pdo": PDO, "effect": EFFECT, "when": WHEN}
    for key, allowed in choices.items():
        if key in row and row[key] not in allowed:
            raise bad(f"{key} = {row[key]!r}; expected one of {', '.join(map(repr, allowed))}")
    for key in ("name", "source", "unit"):
        if key in row and not isinstance(row[key], str):
            raise bad(f"{key} must be a string")
    dtype = row["type"]
    lo, hi = DTYPES[dtype][1:]
    default = row["default"]
    values = row.get("values")
    if dtype == "STR":
        if not isinstance(default, str):
            raise bad("a STR entry needs a string default")
        if "min" in row or "max" in row or values is not None:
            raise bad("a STR entry has no min, max or values")
    else:
        for key in ("min", "max", "default"):
            v = row.get(key)
            if v is None:
                continue
            if not isinstance(v, int) or isinstance(v, bool):
                raise bad(f"{key} must be an integer")
            if not lo <= v <= hi:
                raise bad(f"{key} = {v} is outside the range of {dtype} ({lo}..{hi})")
        low, high = row.get("min", lo), row.get("max", hi)
        if low > high:
            raise bad(f"min {low} is above max {high}")
        if not low <= default <= high:
            raise bad(f"default {default} is outside {low}..{high}")
        if values is not None:
            if (not isinstance(values, list) or not values
                    or not all(isinstance(v, int) and low <= v <= high for v in values)):
                raise bad(f"values must be a list of integers within {low}..{high}")
            if default not in values:
                raise bad(f"default {default} is not one of the values {values}")
    return Entry(index=row["index"], sub=row["sub"], name=row["name"], dtype=dtype,
                 access=row["access"], pdo=row.get("pdo", ""), min=row.get("min"),
                 max=row.get("max"), default=default, unit=row.get("unit", ""),
                 effect=row.get("effect", "now"), when=row.get("when", "any"),
                 source=row["source"], values=tuple(values) if values is not None else None)


__all__ = ["ABORT_CODES", "DTYPES", "Entry", "ObjectDictionary", "SdoAbort", "is_assign",
           "is_map", "obj"]
