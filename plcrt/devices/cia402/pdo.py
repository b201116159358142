"""PDO mapping of a CoE drive as data, its rules, and process-data images
(HCFA §6.7.2–§6.7.4; SOES object handlers; ETG.1000.6).

What it is: 32-bit map entries (``index<<16 | sub<<8 | bits``), the capacity
rules (RxPDO maps 1600h–1603h, TxPDO maps 1A00h–1A01h, at most 8 entries and
32 bytes each), the assignment objects 1C12h/1C13h, the HCFA default maps,
:class:`PdoConfig` which follows the dynamic mapping procedure A–H as SDO
writes change the objects and answers each wrong step with its SDO abort code,
and packing of process data images (little-endian, CoE).

What it is not: it holds no object dictionary.  Objects are looked up through
a callable ``lookup(index, sub) -> (bits, "rx" | "tx" | "") | None`` and the
ESM state through ``state() -> EsmState``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Iterable, Mapping

from .esm import EsmState, MappingProblem
from .statemachine import Cia402Error

__all__ = [
    "MapEntry", "RX_MAPS", "TX_MAPS", "MAX_ENTRIES", "MAX_BYTES", "DEFAULT_MAPS",
    "DEFAULT_ASSIGN", "WriteResult", "PdoConfig", "MapLayout", "pack", "unpack", "layout",
    "Lookup",
]

Lookup = Callable[[int, int], "tuple[int, str] | None"]

RX_MAPS = (0x1600, 0x1601, 0x1602, 0x1603)   # HCFA §6.7.2: 4 RxPDOs
TX_MAPS = (0x1A00, 0x1A01)                   # HCFA §6.7.2: 2 TxPDOs
ASSIGN = {0x1C12: RX_MAPS, 0x1C13: TX_MAPS}  # HCFA §6.7.3
MAX_ENTRIES = 8                              # HCFA §6.7.2
MAX_BYTES = 32                               # HCFA §6.7.2

ABORT_TEXT = {
    0x06010000: "unsupported access to an object",
    0x06010003: "subindex 0 must be 0 to write (SOES)",
    0x06020000: "object does not exist in the object dictionary",
    0x06040041: "object cannot be mapped to the PDO",
    0x06040042: "number and length of the objects exceed the PDO length",
    0x06040043: "general parameter incompatibility",
    0x06090011: "subindex does not exist",
    0x06090030: "value range of parameter exceeded",
    0x06090031: "value of parameter written too high",
    0x08000022: "data cannot be transferred or stored because of the present device state",
}


@dataclass(frozen=True, slots=True)
class MapEntry:
    """One mapping entry: object index, subindex, length in bits."""

    index: int
    sub: int
    bits: int

    @classmethod
    def parse(cls, raw: int) -> MapEntry:
        """Split a 32-bit entry ``index<<16 | sub<<8 | bits``."""
        if not 0 <= raw <= 0xFFFFFFFF:
            raise Cia402Error(f"PDO map entry {raw} is not a UDINT (HCFA §6.7.4 step D)")
        return cls(raw >> 16, (raw >> 8) & 0xFF, raw & 0xFF)

    @property
    def raw(self) -> int:
        return self.index << 16 | self.sub << 8 | self.bits

    def __str__(self) -> str:
        return f"{self.index:04X}h:{self.sub:02X} ({self.bits} bits)"


def _e(index: int, sub: int, bits: int) -> int:
    return MapEntry(index, sub, bits).raw


#: HCFA default maps.  The manual gives only the counts (§8.2: 3, 6, 5, 7 / 7, 0);
#: the entries are the digest's reconstruction (§3.4) to be checked against the ESI.
DEFAULT_MAPS: dict[int, tuple[int, ...]] = {
    0x1600: (_e(0x6040, 0, 16), _e(0x607A, 0, 32), _e(0x60B8, 0, 16)),
    0x1601: (_e(0x6040, 0, 16), _e(0x607A, 0, 32), _e(0x6081, 0, 32), _e(0x6083, 0, 32),
             _e(0x6084, 0, 32), _e(0x6060, 0, 8)),
    0x1602: (_e(0x6040, 0, 16), _e(0x60FF, 0, 32), _e(0x6083, 0, 32), _e(0x6084, 0, 32),
             _e(0x6060, 0, 8)),
    0x1603: (_e(0x6040, 0, 16), _e(0x6098, 0, 8), _e(0x6099, 1, 32), _e(0x6099, 2, 32),
             _e(0x609A, 0, 32), _e(0x607C, 0, 32), _e(0x6060, 0, 8)),
    0x1A00: (_e(0x6041, 0, 16), _e(0x603F, 0, 16), _e(0x6064, 0, 32), _e(0x606C, 0, 32),
             _e(0x6061, 0, 8), _e(0x60B9, 0, 16), _e(0x60BA, 0, 32)),
    0x1A01: (),
}
#: Only 1600h and 1A00h are assigned by default (HCFA §8.2: 1C12h = 1600h, 1C13h = 1A00h).
DEFAULT_ASSIGN: dict[int, tuple[int, ...]] = {0x1C12: (0x1600,), 0x1C13: (0x1A00,)}


@dataclass(frozen=True, slots=True)
class MapLayout:
    """A model's mapping objects and their limits (from its object dictionary).

    ``assign``: the model has the EtherCAT assignment objects 1C12h/1C13h
    (HCFA §6.7.3); without them (a CANopen model, CiA 301) every map with
    entries is in use and none is locked by an assignment."""

    rx: tuple[int, ...] = RX_MAPS
    tx: tuple[int, ...] = TX_MAPS
    assign: bool = True
    max_entries: int = MAX_ENTRIES
    max_bytes: int = MAX_BYTES
    source: str = "HCFA §6.7.2"
    #: the abort of an entry written while sub 0 is not 0: CoE's (SOES) by
    #: default; a CAN port's maps use CiA 301's 0x06010000 (unsupported access)
    entry_abort: int = 0x06010003
    entry_rule: str = "HCFA §6.7.4 step C"


@dataclass(frozen=True, slots=True)
class WriteResult:
    """The answer to one SDO write: abort code 0 = done."""

    abort: int
    explanation: str

    @property
    def ok(self) -> bool:
        return self.abort == 0


def layout(entries: Iterable[MapEntry]) -> list[tuple[MapEntry, int]]:
    """Each entry with its bit offset in the image, in mapping order."""
    out, offset = [], 0
    for entry in entries:
        out.append((entry, offset))
        offset += entry.bits
    return out


def pack(entries: Iterable[MapEntry], values: Mapping[tuple[int, int], int]) -> bytes:
    """The process data image of *values* for *entries*, little-endian (CoE).

    Padding entries (index 0) are zero; a missing object is an error; negative
    values are stored in two's complement of the entry's width."""
    image, total = 0, 0
    for entry, offset in layout(entries):
        total = offset + entry.bits
        if entry.index == 0:
            continue
        key = (entry.index, entry.sub)
        if key not in values:
            raise Cia402Error(f"no value for mapped object {entry}")
        v = values[key]
        if not -(1 << (entry.bits - 1)) <= v < (1 << entry.bits):
            raise Cia402Error(f"value {v} does not fit mapped object {entry}")
        image |= (v & ((1 << entry.bits) - 1)) << offset
    return image.to_bytes((total + 7) // 8, "little")


def unpack(entries: Iterable[MapEntry], data: bytes,
           signed: frozenset[tuple[int, int]] = frozenset()) -> dict[tuple[int, int], int]:
    """The values in image *data*; objects in *signed* are read as signed."""
    rows = layout(entries)
    need = (rows[-1][1] + rows[-1][0].bits + 7) // 8 if rows else 0
    if len(data) != need:
        raise Cia402Error(f"process data image of {len(data)} bytes; the mapping needs {need}")
    image, out = int.from_bytes(data, "little"), {}
    for entry, offset in rows:
        if entry.index == 0:
            continue
        v = (image >> offset) & ((1 << entry.bits) - 1)
        if (entry.index, entry.sub) in signed and v >> (entry.bits - 1):
            v -= 1 << entry.bits
        out[(entry.index, entry.sub)] = v
    return out


class PdoConfig:
    """The mapping objects as an SDO writer changes them (HCFA §6.7.4 A–H).

    ``write(index, sub, value)`` applies one SDO download to 1600h–1603h,
    1A00h–1A01h, 1C12h or 1C13h and returns its abort code; :meth:`activate`
    is the ESM's PRE-OP -> SAFE-OP validator (step H): it checks the assignment
    and, when good, makes it the active mapping."""

    def __init__(self, lookup: Lookup, state: Callable[[], EsmState],
                 defaults: dict[int, tuple[int, ...]] | None = None,
                 layout: MapLayout | None = None) -> None:
        """``defaults``: the power-up maps and assignment by object index
        (the model's object dictionary); missing ones are HCFA's.
        ``layout``: the model's mapping objects and limits (HCFA's)."""
        self.lookup = lookup
        self.state = state
        self.layout = L = layout or MapLayout()
        #: assignment object -> the maps it may name (none in a CANopen model)
        self.owners: dict[int, tuple[int, ...]] = {0x1C12: L.rx, 0x1C13: L.tx} \
            if L.assign else {}
        self.entries: dict[int, list[int]] = {}
        self.count: dict[int, int] = {}
        defaults = defaults or {}
        for index in (*L.rx, *L.tx):
            rows = defaults.get(index, DEFAULT_MAPS.get(index, ()) if L.assign else ())
            self.entries[index] = list(rows) + [0] * (L.max_entries - len(rows))
            self.count[index] = len(rows)
        for index, allowed in self.owners.items():
            rows = defaults.get(index, DEFAULT_ASSIGN[index])
            self.entries[index] = list(rows) + [0] * (len(allowed) - len(rows))
            self.count[index] = len(rows)
        self.active_rx: tuple[MapEntry, ...] = self._flatten(0x1C12)
        self.active_tx: tuple[MapEntry, ...] = self._flatten(0x1C13)

    # ---------------------------------------------------------------- SDO side
    def read(self, index: int, sub: int) -> int:
        """The value an SDO upload of *index*:*sub* returns."""
        self._check_object(index, sub)
        return self.count[index] if sub == 0 else self.entries[index][sub - 1]

    def write(self, index: int, sub: int, value: int) -> WriteResult:
        """One SDO download; the abort code names the broken rule."""
        where = f"{index:04X}h:{sub:02X} = {value:#x}"
        bad = self._check_object(index, sub, raise_=False)
        if bad:
            return self._abort(bad, where, "HCFA §6.7.2, §6.7.3")
        limit = 0xFF if sub == 0 else (0xFFFFFFFF if index not in self.owners else 0xFFFF)
        if not 0 <= value <= limit:
            return self._abort(0x06090030, where, f"{index:04X}h:{sub:02X} is a "
                               f"{'USINT' if sub == 0 else 'UDINT' if limit > 0xFFFF else 'UINT'}"
                               " (HCFA §3.1)")
        state = self.state()
        if state is not EsmState.PREOP:
            return self._abort(0x08000022, where, f"PDO mapping is written in PRE-OP only, the "
                               f"ESM is in {state.name} (HCFA §6.7.4 step A)")
        if index in self.owners:
            return self._write_assign(index, sub, value, where)
        return self._write_map(index, sub, value, where)

    def _write_map(self, index: int, sub: int, value: int, where: str) -> WriteResult:
        L = self.layout
        side = "rx" if index in L.rx else "tx"
        owner = 0x1C12 if side == "rx" else 0x1C13
        if L.assign and index in self._assigned(owner):
            return self._abort(0x06010003, where, f"{index:04X}h is assigned in {owner:04X}h "
                               f"(:00 = {self.count[owner]}); clear {owner:04X}:00 first "
                               "(HCFA §6.7.4 step B)")
        if sub == 0:
            if value > L.max_entries:
                return self._abort(0x06040042, where, f"at most {L.max_entries} entries per "
                                   f"PDO ({L.source})")
            rows = [MapEntry.parse(r) for r in self.entries[index][:value]]
            if any(r.raw == 0 for r in rows):
                return self._abort(0x06040043, where, f"entries :01–:{value:02X} are not all "
                                   "written (HCFA §6.7.4 step D before E)")
            if sum(r.bits for r in rows) > L.max_bytes * 8:
                return self._abort(0x06040042, where, f"the entries take "
                                   f"{sum(r.bits for r in rows) // 8} bytes, more than "
                                   f"{L.max_bytes} ({L.source})")
            self.count[index] = value
            step = "step E" if value else "step C: the map is invalid while changed"
            return WriteResult(0, f"{where}: {index:04X}h maps {value} entries ({step})")
        if self.count[index] != 0:
            return self._abort(L.entry_abort, where, f"{index:04X}:00 = {self.count[index]}; "
                               f"set it to 0 before writing entries ({L.entry_rule})")
        if value == 0:
            self.entries[index][sub - 1] = 0
            return WriteResult(0, f"{where}: entry cleared")
        entry = MapEntry.parse(value)
        if entry.index != 0:      # index 0 = padding (a gap of entry.bits)
            found = self.lookup(entry.index, entry.sub)
            if found is None:
                return self._abort(0x06020000, where, f"{entry.index:04X}h:{entry.sub:02X} is "
                                   "not in the object dictionary (HCFA ch. 8)")
            bits, mappable = found
            if mappable != side:
                return self._abort(0x06040041, where, f"{entry.index:04X}h:{entry.sub:02X} is "
                                   f"not {side.upper()}PDO-mappable (mappable: "
                                   f"{mappable or 'no'}; HCFA §7.5, §7.6, §8.3)")
            if entry.bits != bits:
                return self._abort(0x06040043, where, f"{entry.index:04X}h:{entry.sub:02X} is "
                                   f"{bits} bits, the entry says {entry.bits}")
        self.entries[index][sub - 1] = value
        return WriteResult(0, f"{where}: entry {entry} (step D)")

    def _write_assign(self, index: int, sub: int, value: int, where: str) -> WriteResult:
        allowed = self.owners[index]
        if sub == 0:
            if value > len(allowed):
                return self._abort(0x06090031, where, f"{index:04X}h holds at most "
                                   f"{len(allowed)} maps (HCFA §6.7.2)")
            maps = self.entries[index][:value]
            if any(m not in allowed for m in maps):
                return self._abort(0x06040043, where, f"{index:04X}:01–{value:02X} are not all "
                                   "written with map indices (HCFA §6.7.4 step F before G)")
            if len(set(maps)) != len(maps):
                return self._abort(0x06040043, where, "a map is assigned twice")
            self.count[index] = value
            step = "step G" if value else "step B: no map assigned while mapping changes"
            return WriteResult(0, f"{where}: {value} maps assigned ({step})")
        if self.count[index] != 0:
            return self._abort(0x06010003, where, f"{index:04X}:00 = {self.count[index]}; "
                               f"set it to 0 first (HCFA §6.7.4 step B)")
        if value != 0 and value not in allowed:
            return self._abort(0x06090030, where, f"{index:04X}h takes "
                               + "/".join(f"{a:04X}h" for a in allowed) + " (HCFA §6.7.3)")
        self.entries[index][sub - 1] = value
        return WriteResult(0, f"{where}: assignment entry (step F)")

    # ---------------------------------------------------------------- ESM side
    def check(self) -> MappingProblem | None:
        """Whether the assignment and its maps are valid (at PRE-OP -> SAFE-OP)."""
        for owner, side in ((0x1C12, "outputs"), (0x1C13, "inputs")):
            for index in self._assigned(owner):
                rows = [MapEntry.parse(r) for r in self.entries[index][:self.count[index]]]
                if sum(r.bits for r in rows) > self.layout.max_bytes * 8:
                    return MappingProblem(side, f"{index:04X}h exceeds "
                                          f"{self.layout.max_bytes} bytes")
                for r in rows:
                    if r.index == 0:
                        continue
                    found = self.lookup(r.index, r.sub)
                    want = "rx" if owner == 0x1C12 else "tx"
                    if found is None or found != (r.bits, want):
                        return MappingProblem(side, f"{index:04X}h maps {r}, which is not a "
                                              f"{want.upper()}PDO object of that length")
        return None

    def activate(self) -> MappingProblem | None:
        """The ESM validator: check, and if good the mapping takes effect (step H)."""
        problem = self.check()
        if problem is None:
            self.active_rx, self.active_tx = self._flatten(0x1C12), self._flatten(0x1C13)
        return problem

    # ---------------------------------------------------------------- helpers
    def _assigned(self, owner: int) -> list[int]:
        if self.layout.assign:
            return self.entries[owner][:self.count[owner]]
        # CiA 301 (no assignment objects): every map with entries is in use
        maps = self.layout.rx if owner == 0x1C12 else self.layout.tx
        return [m for m in maps if self.count[m]]

    def _flatten(self, owner: int) -> tuple[MapEntry, ...]:
        return tuple(MapEntry.parse(r) for index in self._assigned(owner)
                     for r in self.entries[index][:self.count[index]])

    def _check_object(self, index: int, sub: int, raise_: bool = True) -> int:
        code = 0
        if index not in self.entries:
            code = 0x06020000
        elif not 0 <= sub <= len(self.entries[index]):
            code = 0x06090011
        if code and raise_:
            raise Cia402Error(f"{index:04X}h:{sub:02X}: {ABORT_TEXT[code]}")
        return code

    @staticmethod
    def _abort(code: int, where: str, why: str) -> WriteResult:
        return WriteResult(code, f"SDO abort 0x{code:08X} ({ABORT_TEXT[code]}): {where}: {why}")
