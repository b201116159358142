"""The live values of one drive's object dictionary, and SDO access to them.

:class:`Store` keeps a typed value per entry of an
:class:`~plcrt.devices.cia402.od.ObjectDictionary`, encodes and decodes the
little-endian CoE bytes, and applies every SDO rule the data can decide:
access, length, range, the ESM state (PDO mapping only in PRE-OP), the
"stopped only" parameters, the PDO mapping procedure (HCFA §6.7.4) and the
parameters that act only after a power cycle (HCFA §5.1 "再次通电").

It does not implement drive behaviour.  The drive's state machine and modes
subscribe with :meth:`Store.on_check` (called before a master's write is
stored; raising :class:`~plcrt.devices.cia402.od.SdoAbort` refuses it) and
:meth:`Store.on_write` (called after it is stored), and update the values
they produce with :meth:`Store.set`.
"""

from __future__ import annotations

import copy
import struct
import threading
from dataclasses import dataclass
from typing import Callable

from ...errors import PlcConfigError
from .od import DTYPES, ESM_STATES, Entry, ObjectDictionary, SdoAbort, is_assign, is_map, obj

Value = int | str

#: perf: one tuple object per (index, sub), shared by every store and by the
#: drive's constants: a dict finds a key by identity, without comparing tuples
_KEYS: dict[tuple[int, int], tuple[int, int]] = {}


def key(index: int, sub: int) -> tuple[int, int]:
    """The shared ``(index, sub)`` tuple the stores' value dicts hold."""
    k = (index, sub)
    return _KEYS.setdefault(k, k)


@dataclass(frozen=True, slots=True)
class Write:
    """A value written by a master (SDO or PDO), as the hooks see it."""

    entry: Entry
    value: Value
    old: Value  #: the value an SDO upload returned before the write
    pending: bool  #: a "power-up" parameter: stored, not yet active
    source: str  #: "sdo" or "pdo"


@dataclass(frozen=True, slots=True)
class StoreEvent:
    """Something the store did on its own account (for the drive's log)."""

    kind: str  #: "pending" (power-up parameter written) or "applied" (power cycle)
    index: int
    sub: int
    value: Value
    text: str


Hook = Callable[[Write], None]

#: struct codes of the CoE integer types (their ranges are the types' ranges)
_STRUCT_CODES = {"I8": "b", "U8": "B", "I16": "h", "U16": "H", "I32": "i", "U32": "I",
                 "I64": "q", "U64": "Q"}


class Store:
    """Values of one drive, initialised from the defaults of ``od``.

    ``length_abort`` selects the codes for a wrong SDO length: ``"exact"``
    gives 0x06070012 (too long) / 0x06070013 (too short) as CoE slaves do;
    ``"generic"`` gives 0x06070010 for both, as canopen's own SDO server does.
    All methods are thread-safe (canopen calls back from its Notifier thread).
    """

    def __init__(self, od: ObjectDictionary, *, length_abort: str = "exact") -> None:
        if length_abort not in ("exact", "generic"):
            raise PlcConfigError(f"length_abort = {length_abort!r}; expected 'exact' or 'generic'")
        self.od = od
        self.length_abort = length_abort
        self._active: dict[tuple[int, int], Value] = {key(e.index, e.sub): e.default for e in od}
        self._pending: dict[tuple[int, int], Value] = {}
        # perf: the hooks as tuples, rebuilt when one (un)subscribes: a write
        # iterates a snapshot without copying a list
        self._check_hooks: tuple[Hook, ...] = ()
        self._write_hooks: tuple[Hook, ...] = ()
        #: The check hooks and the write hooks subscribed now (read only).
        self.hooked: tuple[tuple[Hook, ...], tuple[Hook, ...]] = ((), ())
        self.events: list[StoreEvent] = []
        self.lock = threading.RLock()
        self._bounds: dict[tuple[int, int], tuple[int, int]] = {}
        # perf: (entry, low, high) per key, low None for a string, found once
        self._types: dict[tuple[int, int], tuple[Entry, int | None, int]] = {}
        # perf: a struct per status group, whose packing checks the ranges
        self._groups: dict[tuple[tuple[int, int], ...], struct.Struct | bool] = {}

    @property
    def live(self) -> dict[tuple[int, int], Value]:
        """The active values by (index, sub), the store's own dict (read it,
        never write it): the bus cycle reads many objects without the entry
        check of :meth:`get`."""
        return self._active

    def __deepcopy__(self, memo: dict) -> "Store":
        # a fork of a PLC copies its drives: a lock is not copied, it is made anew
        new = object.__new__(type(self))
        memo[id(self)] = new
        memo.setdefault(id(self.od), self.od)        # the dictionary itself is read-only data
        for key, value in self.__dict__.items():
            if key == "lock":
                new.__dict__[key] = threading.RLock()
            elif key == "_groups":
                new.__dict__[key] = {}          # struct codecs: rebuilt on first use
            else:
                new.__dict__[key] = copy.deepcopy(value, memo)
        return new

    # -- values ------------------------------------------------------------
    def get(self, index: int, sub: int = 0) -> Value:
        """The active value (the one the drive acts on)."""
        self.od.entry(index, sub)
        return self._active[(index, sub)]

    def stored(self, index: int, sub: int = 0) -> Value:
        """The value last written: pending if a power-up parameter waits."""
        self.od.entry(index, sub)
        key = (index, sub)
        return self._pending.get(key, self._active[key])

    @property
    def pending(self) -> dict[tuple[int, int], Value]:
        """Power-up parameters written but not yet active, by (index, sub)."""
        return dict(self._pending)

    def set(self, index: int, sub: int, value: Value, *, source: str = "drive") -> None:
        """Set a value from the drive side (``source="drive"``, no checks of
        access or state, no hooks) or from process data (``source="pdo"``:
        the hooks run as for an SDO write).

        Raises:
            SdoAbort: unknown object or subindex.
            PlcConfigError: the value does not fit the entry's type.
        """
        key = (index, sub)
        known = self._types.get(key)
        if known is None:
            entry = self.od.entry(index, sub)
            lo, hi = (None, 0) if entry.dtype == "STR" else DTYPES[entry.dtype][1:]
            known = self._types[key] = (entry, lo, hi)
        entry, lo, hi = known
        # perf: a plain int in range is the common case; anything else takes
        # the full check (bool and str values, out-of-range numbers)
        if lo is None or value.__class__ is not int or not lo <= value <= hi:
            self._check_type(entry, value)
        with self.lock:
            if source == "drive":
                # perf: no Write is built when no hook will see it
                self._active[key] = value
                if self._pending:
                    self._pending.pop(key, None)
                return
            write = Write(entry, value, self._pending.get(key, self._active[key]), False, source)
            for hook in self._check_hooks:
                hook(write)
            self._active[key] = value
            self._pending.pop(key, None)
            for hook in self._write_hooks:
                hook(write)

    def set_known(self, key: tuple[int, int], value: int) -> None:
        """Set an object's value from the drive side when its type is known
        to fit (an RxPDO field unpacked at the mapped object's own width and
        signedness): no checks, no hooks.  The caller holds :attr:`lock`."""
        # perf: the bus cycle's path for an RxPDO object no hook needs to see
        self._active[key] = value
        if self._pending:
            self._pending.pop(key, None)

    def set_status(self, values: dict[tuple[int, int], int]) -> None:
        """Set the drive's own integer status objects (6041h, 6064h, ...)
        in one step: a range check only, no hooks (the bus-cycle fast path).

        Raises:
            PlcConfigError: a value outside its entry's type range.
        """
        bounds, active, pending = self._bounds, self._active, self._pending
        with self.lock:
            for key, value in values.items():
                try:
                    low, high = bounds[key]
                except KeyError:
                    entry = self.od.entry(*key)
                    low, high = bounds[key] = (entry.low, entry.high)
                if not low <= value <= high:
                    entry = self.od.entry(*key)
                    raise PlcConfigError(f"{entry.label} := {value} does not fit {entry.dtype}")
                active[key] = value
                if pending:
                    pending.pop(key, None)

    def fits_group(self, keys: tuple[tuple[int, int], ...], values: tuple[int, ...]) -> bool:
        """Whether *values* (in the order of the status objects *keys*, a
        constant tuple) all lie in their objects' integer ranges; False too
        when an object is not a plain integer type (then :meth:`set_status`
        decides)."""
        packer = self._groups.get(keys)
        if packer is None:
            entries = [self.od.entry(*k) for k in keys]
            # a struct code only for an object whose range is its type's
            codes = [_STRUCT_CODES.get(e.dtype) if e.dtype in DTYPES
                     and (e.low, e.high) == DTYPES[e.dtype][1:] else None for e in entries]
            packer = self._groups[keys] = \
                struct.Struct("<" + "".join(codes)) if None not in codes else False
        if packer is False:
            return False
        # perf: struct checks every value against its type's range in C
        try:
            packer.pack(*values)
        except struct.error:
            return False
        return True

    def set_status_group(self, values: dict[tuple[int, int], int]) -> None:
        """Set status objects to *values* that :meth:`fits_group` found in
        range (no further check, no hooks)."""
        with self.lock:
            self._active.update(values)
            if self._pending:
                for k in values:
                    self._pending.pop(k, None)

    def power_cycle(self) -> list[StoreEvent]:
        """Make the pending power-up parameters active; returns the events.

        All other values are kept (parameters are persistent; the drive
        model re-initialises its own status objects at power-up)."""
        with self.lock:
            done = []
            for (index, sub), value in sorted(self._pending.items()):
                entry = self.od.entry(index, sub)
                self._active[(index, sub)] = value
                done.append(StoreEvent("applied", index, sub, value,
                                       f"{entry.label} = {value} active after power-up "
                                       f"({entry.source})"))
            self._pending.clear()
            self.events.extend(done)
            return done

    def mapped(self, map_index: int) -> list[Entry]:
        """The objects a PDO mapping object (16xxh/1Axxh) maps now, in order.

        Raises:
            SdoAbort: the object is not a mapping object (0x06020000), or an
                entry within the count is invalid (the mapping codes).
        """
        if not is_map(map_index):
            raise SdoAbort(0x06020000, f"{map_index:04X}h is not a PDO mapping object "
                                       f"(1600h-17FFh, 1A00h-1BFFh)")
        with self.lock:
            count = int(self.get(map_index, 0))
            out = []
            for k in range(1, count + 1):
                target = self.od.check_mapping(self.od.entry(map_index, k),
                                               int(self._active[(map_index, k)]))
                if target is None:
                    raise SdoAbort(0x06040041, f"{obj(map_index, k)} is empty but "
                                               f"{obj(map_index, 0)} counts {count}")
                out.append(target)
            return out

    # -- hooks -------------------------------------------------------------
    def on_check(self, callback: Hook) -> Callable[[], None]:
        """Call ``callback(write)`` before a master's write is stored; it may
        raise :class:`SdoAbort` to refuse it.  Returns an unsubscribe function."""
        with self.lock:
            self._check_hooks = (*self._check_hooks, callback)
            self.hooked = (self._check_hooks, self._write_hooks)
        return lambda: self._unsubscribe("_check_hooks", callback)

    def on_write(self, callback: Hook) -> Callable[[], None]:
        """Call ``callback(write)`` after a master's write is stored.
        Returns an unsubscribe function."""
        with self.lock:
            self._write_hooks = (*self._write_hooks, callback)
            self.hooked = (self._check_hooks, self._write_hooks)
        return lambda: self._unsubscribe("_write_hooks", callback)

    def _unsubscribe(self, which: str, callback: Hook) -> None:
        with self.lock:
            hooks = list(getattr(self, which))
            hooks.remove(callback)          # ValueError when not subscribed, as list.remove
            setattr(self, which, tuple(hooks))
            self.hooked = (self._check_hooks, self._write_hooks)

    # -- SDO ---------------------------------------------------------------
    def sdo_read(self, index: int, sub: int) -> bytes:
        """SDO upload: the stored value's bytes.

        Raises:
            SdoAbort: 0x06020000, 0x06090011, 0x06010001 (write-only).
        """
        entry = self.od.entry(index, sub)
        if entry.access == "wo":
            raise SdoAbort(0x06010001, f"{entry.label} is write-only ({entry.source})")
        with self.lock:
            return entry.encode(self.stored(index, sub))

    def sdo_write(self, index: int, sub: int, data: bytes, *, state: str = "PREOP",
                  moving: bool = False) -> None:
        """SDO download of ``data`` to (index, sub).

        ``state`` is the EtherCAT state (INIT, PREOP, SAFEOP, OP; a CANopen
        node in NMT pre-operational counts as PREOP); ``moving`` says whether
        the drive is moving (for parameters settable only while stopped).

        Raises:
            SdoAbort: with the code of the first rule broken (docs/cia402.md,
                "Object dictionary and SDO").
            PlcConfigError: ``state`` is not an ESM state.
        """
        if state not in ESM_STATES:
            raise PlcConfigError(f"ESM state {state!r}; expected one of {', '.join(ESM_STATES)}")
        entry = self.od.entry(index, sub)
        if entry.access in ("ro", "const"):
            raise SdoAbort(0x06010002, f"{entry.label} is read-only; write of "
                                       f"{bytes(data).hex(' ') or 'no data'} refused ({entry.source})")
        data = bytes(data)
        if entry.dtype != "STR" and len(data) != entry.size:
            code = 0x06070010
            if self.length_abort == "exact":
                code = 0x06070012 if len(data) > entry.size else 0x06070013
            raise SdoAbort(code, f"{entry.label} is {entry.dtype}, {entry.size} byte(s); "
                                 f"{len(data)} byte(s) written ({entry.source})")
        value = entry.decode(data)
        with self.lock:
            self._check_state(entry, value, state, moving)
            self._check_mapping(entry, value)
            self._check_range(entry, value)
            write = Write(entry, value, self.stored(index, sub), entry.effect == "power-up", "sdo")
            for hook in self._check_hooks:
                hook(write)
            key = (index, sub)
            if write.pending and value != self._active[key]:
                self._pending[key] = value
                self.events.append(StoreEvent(
                    "pending", index, sub, value,
                    f"{entry.label} := {value} stored; it acts after the next power-up, "
                    f"until then {self._active[key]} stays active ({entry.source})"))
            else:
                self._pending.pop(key, None)
                self._active[key] = value
            for hook in self._write_hooks:
                hook(write)

    # -- rules -------------------------------------------------------------
    def _check_state(self, entry: Entry, value: Value, state: str, moving: bool) -> None:
        if entry.when == "preop" and state != "PREOP":
            raise SdoAbort(0x08000022, f"{entry.label} := {_show(value)} refused in {state}: "
                                       f"PDO mapping and assignment are written in PRE-OP only "
                                       f"({entry.source})")
        if entry.when == "stopped" and moving:
            raise SdoAbort(0x08000022, f"{entry.label} := {_show(value)} refused while the "
                                       f"drive moves: settable only while stopped ({entry.source})")
        if entry.sub > 0 and (is_map(entry.index) or is_assign(entry.index)):
            count = self._active[(entry.index, 0)]
            if count != 0:
                raise SdoAbort(0x06010003, f"{entry.label} := {_show(value)} refused: "
                                           f"{obj(entry.index, 0)} is {count}, write 0 there "
                                           f"first ({entry.source})")

    def _check_mapping(self, entry: Entry, value: Value) -> None:
        if not is_map(entry.index):
            return
        if entry.sub > 0:
            self.od.check_mapping(entry, int(value))
        else:
            self.od.check_map_length(entry.index, int(value),
                                     lambda i, s: self._active[(i, s)])

    @staticmethod
    def _check_range(entry: Entry, value: Value) -> None:
        if entry.dtype == "STR":
            return
        assert isinstance(value, int)
        if entry.values is not None and value not in entry.values:
            allowed = ", ".join(map(str, entry.values))
            raise SdoAbort(0x06090030, f"{entry.label} := {value} is not one of {allowed} "
                                       f"({entry.source})")
        if value > entry.high:
            raise SdoAbort(0x06090031, f"{entry.label} := {value} is above the maximum "
                                       f"{entry.high}{_unit(entry)} ({entry.source})")
        if value < entry.low:
            raise SdoAbort(0x06090032, f"{entry.label} := {value} is below the minimum "
                                       f"{entry.low}{_unit(entry)} ({entry.source})")

    @staticmethod
    def _check_type(entry: Entry, value: Value) -> None:
        if entry.dtype == "STR":
            ok = isinstance(value, str)
        else:
            lo, hi = DTYPES[entry.dtype][1:]
            ok = isinstance(value, int) and not isinstance(value, bool) and lo <= value <= hi
        if not ok:
            raise PlcConfigError(f"{entry.label}: {value!r} is not a {entry.dtype} value")


def _show(value: Value) -> str:
    return f"0x{value:X}" if isinstance(value, int) and value > 0xFFFF else str(value)


def _unit(entry: Entry) -> str:
    return f" {entry.unit}" if entry.unit else ""
