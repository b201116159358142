"""The CAN PDOs of a simulated drive: communication parameters, mapping and
the SYNC-driven cycle (CiA 301 §7.2.2, §7.2.5, §7.5.2.35–38).

What it is: :class:`CanPdos`, the process-data side of the CANopen port.  Each
PDO is a :class:`Channel` with its communication record (1400h+n / 1800h+n:
COB-ID with the "not valid" bit 31 and "no RTR" bit 30, transmission type,
inhibit time, event timer) and its mapping record (1600h+n / 1A00h+n), held by
a :class:`~.pdo.PdoConfig` with CAN's limits (8 entries, 8 bytes).  The drive
transmits and receives according to the mapping and the communication
parameters as they are *now*:

* transmission types 1–240: a TPDO is sampled and sent at every n-th SYNC; an
  RPDO received is buffered and acts at the next SYNC;
* 0 (acyclic synchronous): a TPDO is sent at a SYNC when its data changed
  since it was last sent; an RPDO acts at the next SYNC;
* 254/255 (event-driven): a TPDO is sent when its data changed and the
  inhibit time (100 µs units) has passed since the last one, and when the
  event timer (ms) runs out; an RPDO acts at once.  Events are looked for at
  every drive cycle, so a timer takes effect at the first cycle at or after
  it expires;
* 241–251 are reserved and 252/253 need remote frames: refused with SDO
  abort 0x06090030 (the port answers no RTR; bit 30 reads 1).

Remapping follows CiA 301 §7.5.2.36/38: the PDO is made invalid (bit 31 of
:01), sub 0 of the map is set to 0, the entries written, sub 0 set to their
number, the PDO made valid again.  A mapping write while the PDO is valid is
refused with 0x06010000 (unsupported access), an entry written while sub 0 is
not 0 also (``PdoConfig``'s CiA 301 code), an object that does not exist with
0x06020000, one that cannot be mapped with 0x06040041, more than 8 entries or
8 bytes with 0x06040042, a wrong length with 0x06040043; mapping is written in
NMT PRE-OPERATIONAL only (0x08000022 otherwise; the model's dictionary marks
mapping objects ``when = "preop"``).  The COB-ID (bits 0–29) of a valid PDO
cannot change (0x06090030), nor can a TPDO's inhibit time; a 29-bit COB-ID
(bit 29) and the CAN-IDs CiA 301 §7.3.5 restricts are refused (0x06090030).

What it is not: no CAN access (the port sends and subscribes), no NMT (the
port tells :meth:`CanPdos.operational`), no canopen import.
"""

from __future__ import annotations

import struct
from operator import itemgetter
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

from .drive_io import OWN_KEYS
from .od import SdoAbort
from .pdo import MapEntry, MapLayout, PdoConfig, pack, unpack

__all__ = ["Channel", "CanPdos", "NOT_VALID", "NO_RTR", "Frame", "SYNCED"]

NOT_VALID = 1 << 31          # CiA 301 §7.5.2.35 Table 56: bit 31 valid (0) / not valid (1)
NO_RTR = 1 << 30             # bit 30: RTR allowed (0) / not allowed (1)
FRAME_29 = 1 << 29           # bit 29: 11-bit (0) / 29-bit (1) CAN-ID
#: CiA 301 §7.3.5 Table 38: CAN-IDs no PDO may use.
RESTRICTED = ((0x000, 0x000), (0x001, 0x07F), (0x101, 0x180), (0x581, 0x5FF),
              (0x601, 0x67F), (0x6E0, 0x6FF), (0x701, 0x77F), (0x780, 0x7FF))

Frame = tuple[int, bytes]    # (CAN-ID, data)
#: The synchronous transmission types (CiA 301 §7.5.2.35 Table 57).
SYNCED = range(0, 241)
_COM_BITS = {0: 8, 1: 32, 2: 8, 3: 16, 5: 16}   # CiA 301 §7.5.2.35/37 (sub 4 reserved)
_FMT = {(8, False): "B", (8, True): "b", (16, False): "H", (16, True): "h",
        (32, False): "I", (32, True): "i"}


@dataclass(slots=True)
class Channel:
    """One CAN PDO: its communication parameters and where its map is held."""

    number: int
    tx: bool
    com: int
    map: int
    cob_id: int
    trans: int
    inhibit: int = 0          # 100 µs (TPDO)
    event_ms: int = 0
    syncs: int = 0            # SYNCs counted toward the next synchronous TPDO
    sent: Optional[bytes] = None
    sent_at: Optional[int] = None
    pending: Optional[bytes] = None
    codec: tuple = field(default=((), None))

    @property
    def valid(self) -> bool:
        return not self.cob_id & NOT_VALID

    @property
    def can_id(self) -> int:
        return self.cob_id & 0x7FF

    @property
    def name(self) -> str:
        return f"{'T' if self.tx else 'R'}PDO {self.number}"


class CanPdos:
    """The CAN PDOs of *drive* (a :class:`~.drive.Drive`).

    *channels*: ``(number, tx, cob_id, trans, event_ms, entries)`` per PDO;
    the maps are held here with CAN's limits (8 entries, 8 bytes, CiA 301)."""

    def __init__(self, drive: Any,
                 channels: list[tuple[int, bool, int, int, int, tuple[int, ...]]]) -> None:
        self.drive = drive
        rx = tuple(0x1600 + n - 1 for n, tx, *_ in channels if not tx)
        tx_ = tuple(0x1A00 + n - 1 for n, tx, *_ in channels if tx)
        defaults = {(0x1A00 if tx else 0x1600) + n - 1: tuple(entries)
                    for n, tx, _, _, _, entries in channels}
        self.cfg = PdoConfig(drive._lookup, lambda: drive.esm.state, defaults,
                             MapLayout(rx, tx_, False, 8, 8, "CiA 301 §7.5.2.36: a CAN PDO "
                                       "carries at most 8 bytes", 0x06010000,
                                       "CiA 301 §7.5.2.36 step 2"))
        self.channels = [Channel(n, tx, (0x1800 if tx else 0x1400) + n - 1,
                                 (0x1A00 if tx else 0x1600) + n - 1, cob, trans,
                                 event_ms=ev)
                         for n, tx, cob, trans, ev, _ in channels]
        self.by_com = {c.com: c for c in self.channels}
        self.by_map = {c.map: c for c in self.channels}
        self.rx_by_id: dict[int, Channel] = {}
        # perf: the valid channels by role, rebuilt when a COB-ID or a
        # transmission type changes (_index), so a SYNC visits only its own
        self.sync_rx: tuple[Channel, ...] = ()
        self.sync_tx: tuple[Channel, ...] = ()
        self.event_tx: tuple[Channel, ...] = ()
        self.active = False                  # NMT OPERATIONAL
        self._noted: set[str] = set()
        self._index()

    # ---------------------------------------------------------------- objects
    def owns(self, index: int) -> bool:
        return index in self.by_com or index in self.by_map

    def bits(self, index: int, sub: int) -> Optional[int]:
        """The size of PDO object *index*:*sub* in bits (None: no such subindex)."""
        if index in self.by_com:
            return _COM_BITS.get(sub)
        return (8 if sub == 0 else 32) if 0 <= sub <= 8 else None

    def read(self, index: int, sub: int) -> int:
        """The value an SDO upload of a PDO object returns."""
        ch = self.by_com.get(index)
        if ch is None:
            return self.cfg.read(index, sub)
        if sub == 0:
            return 5
        if sub == 1:
            return ch.cob_id | NO_RTR
        return {2: ch.trans, 3: ch.inhibit, 5: ch.event_ms}[sub]

    def write(self, index: int, sub: int, value: int) -> str:
        """One SDO download to a PDO object; returns what it did.

        Raises:
            SdoAbort: the rule broken (see the module docstring)."""
        ch = self.by_com.get(index)
        where = f"{index:04X}h:{sub:02X} := 0x{value:X}"
        if sub == 0 and ch is not None:
            raise SdoAbort(0x06010002, f"{where}: the number of entries of a "
                           "communication record is read-only (CiA 301 §7.5.2.35)")
        if ch is None:
            ch = self.by_map[index]
            if ch.valid:
                raise SdoAbort(0x06010000, f"{where}: {ch.name} exists (its COB-ID "
                               f"{ch.com:04X}h:01 has bit 31 = 0); set bit 31 before "
                               "changing its mapping (CiA 301 §7.5.2.36 step 1)")
            res = self.cfg.write(index, sub, value)
            if not res.ok:
                raise SdoAbort(res.abort, res.explanation.split(": ", 1)[-1])
            ch.codec = ((), None)
            return res.explanation
        if sub == 1:
            return self._write_cob_id(ch, value, where)
        if sub == 2:
            if not (value in SYNCED or value in (254, 255)):
                why = ("needs remote frames (RTR), which the drive does not answer"
                       if value in (252, 253) else "is reserved")
                raise SdoAbort(0x06090030, f"{where}: transmission type {value} {why} "
                               "(CiA 301 §7.5.2.35 Table 57)")
            ch.trans, ch.syncs, ch.pending = value, 0, None
            self._index()
        elif sub == 3:
            if ch.tx and ch.valid:
                raise SdoAbort(0x06090030, f"{where}: the inhibit time of a valid "
                               f"{ch.name} cannot change (CiA 301 §7.5.2.37)")
            ch.inhibit = value
        elif sub == 5:
            ch.event_ms = value
        return f"{where}: {ch.name}"

    def _write_cob_id(self, ch: Channel, value: int, where: str) -> str:
        if value & FRAME_29:
            raise SdoAbort(0x06090030, f"{where}: a 29-bit CAN-ID (bit 29); the drive is a "
                           "CAN 2.0A (11-bit) node (CiA 301 §7.5.2.35)")
        can_id = value & 0x1FFFFFFF
        if ch.valid and not value & NOT_VALID and can_id != ch.can_id:
            raise SdoAbort(0x06090030, f"{where}: the CAN-ID of a valid {ch.name} cannot "
                           "change; set bit 31 first (CiA 301 §7.5.2.35)")
        if not value & NOT_VALID:
            if can_id > 0x7FF or any(lo <= can_id <= hi for lo, hi in RESTRICTED):
                raise SdoAbort(0x06090030, f"{where}: CAN-ID 0x{can_id:X} is restricted "
                               "(CiA 301 §7.3.5)")
            other = next((c for c in self.channels if c is not ch and c.valid
                          and c.tx == ch.tx and c.can_id == can_id), None)
            if other is not None:
                raise SdoAbort(0x06090030, f"{where}: CAN-ID 0x{can_id:X} is {other.name}'s "
                               "(CiA 301 §7.3.5: one producer per CAN-ID)")
        ch.cob_id = (value & ~NO_RTR) & 0xFFFFFFFF
        ch.sent = ch.pending = None
        ch.syncs = 0
        ch.codec = ((), None)
        self._index()
        return f"{where}: {ch.name} {'valid' if ch.valid else 'not valid'}"

    def _index(self) -> None:
        valid = [c for c in self.channels if c.valid]
        self.rx_by_id = {c.can_id: c for c in valid if not c.tx}
        self.sync_rx = tuple(c for c in valid if not c.tx and c.trans in SYNCED)
        self.sync_tx = tuple(c for c in valid if c.tx and c.trans in SYNCED)
        self.event_tx = tuple(c for c in valid if c.tx and c.trans >= 254)

    def entries(self, ch: Channel) -> tuple[MapEntry, ...]:
        cfg = self.cfg
        return tuple(MapEntry.parse(r) for r in cfg.entries[ch.map][:cfg.count[ch.map]])

    # ---------------------------------------------------------------- codecs
    def _codec(self, ch: Channel) -> tuple:
        """(struct or None, keys, entries, size, getter, held getter, held
        picker) for the current map (perf: built once per mapping); *getter*
        takes the values of *keys* from the store's live values as a tuple,
        *held getter* from the held values over them (:meth:`sample`), *held
        picker* from the held values alone (None: a key is not the drive's
        own, or no struct)."""
        if ch.codec[1] is not None:
            return ch.codec[1]          # perf: built once per mapping (write() clears it)
        entries = self.entries(ch)
        signed = self.drive._signed
        fmt, keys, ok = "<", [], True
        for e in entries:
            if e.index == 0:
                if e.bits % 8:
                    ok = False
                fmt += f"{e.bits // 8}x"
                continue
            code = _FMT.get((e.bits, (e.index, e.sub) in signed))
            if code is None:
                ok = False
                break
            fmt += code
            keys.append((e.index, e.sub))
        size = (sum(e.bits for e in entries) + 7) // 8
        keys = tuple(keys)
        own_only = ok and all(k in OWN_KEYS for k in keys)
        codec = (struct.Struct(fmt) if ok else None, keys, entries, size, _getter(keys),
                 _held_getter(keys),
                 _getter(tuple(OWN_KEYS.index(k) for k in keys)) if own_only else None)
        ch.codec = (entries, codec)
        return codec

    def sample(self, ch: Channel, held: Optional[tuple[int, ...]] = None) -> bytes:
        """The TPDO's data now, from the drive's objects; *held*: the
        drive's own objects as :meth:`~.drive_io.ProcessData.publish_deferred`
        holds them (in the order of OWN_KEYS), over the store's values."""
        codec = ch.codec[1] or self._codec(ch)        # perf: the codec at hand
        st, keys, entries, _, get, get_held, _ = codec
        live = self.drive._live            # perf: the store's live dict, no property call
        values = get(live) if held is None else get_held(live, held)
        if st is not None:
            return st.pack(*values)
        return pack(entries, {k: int(v) for k, v in zip(keys, values)})

    def decode(self, ch: Channel, data: bytes) -> dict[tuple[int, int], int]:
        st, keys, entries, size, *_ = ch.codec[1] or self._codec(ch)
        if st is not None:
            return dict(zip(keys, st.unpack_from(data)))
        return unpack(entries, bytes(data[:size]), self.drive._signed)

    # ---------------------------------------------------------------- traffic
    def operational(self, on: bool) -> None:
        """NMT OPERATIONAL entered (True) or left: PDOs act only in
        OPERATIONAL (CiA 301 §7.3.2.2 Table 36); event-driven TPDOs are sent
        once on entering it."""
        self.active = on
        for ch in self.channels:
            ch.sent = ch.sent_at = ch.pending = None
            ch.syncs = 0

    def receive(self, ch: Channel, data: bytes, t: int,
                note: Callable[[str, str], None]) -> Optional[dict[tuple[int, int], int]]:
        """An RPDO's frame: the objects to apply now (event-driven types), or
        None (buffered for the next SYNC, or not processed)."""
        if not self.active:
            self._once(note, "nmt", "CiA 301 §7.3.2.2",
                       f"RPDO ignored ({ch.name}): PDOs act in NMT OPERATIONAL only")
            return None
        size = (ch.codec[1] or self._codec(ch))[3]       # perf: the codec at hand
        if len(data) < size:
            self._once(note, f"short{ch.number}", "CiA 301 §7.2.2.3",
                       f"{ch.name} of {len(data)} bytes not processed: its mapping needs "
                       f"{size}")
            return None
        if ch.trans in SYNCED:
            ch.pending = bytes(data)
            return None
        return self.decode(ch, data)

    def on_sync(self, t: int, held: Optional[tuple[int, ...]] = None
                ) -> tuple[list[Frame], dict[tuple[int, int], int]]:
        """A SYNC: the synchronous TPDOs sampled now (*held*: as for
        :meth:`sample`), and the objects of the RPDOs buffered since the
        last SYNC (CiA 301 §7.2.2.2)."""
        frames: list[Frame] = []
        values: dict[tuple[int, int], int] = {}
        if not self.active:
            return frames, values
        for ch in self.sync_rx:
            pending = ch.pending
            if pending is not None:
                ch.pending = None
                codec = ch.codec[1] or self._codec(ch)
                st = codec[0]
                if st is not None:
                    # perf: decode() inline: the pairs go into values, no dict between
                    values.update(zip(codec[1], st.unpack_from(pending)))
                else:
                    values.update(self.decode(ch, pending))
        for ch in self.sync_tx:
            if ch.trans == 0:
                data = self.sample(ch, held)
                if data != ch.sent:
                    frames.append(self._sent(ch, data, t))
                continue
            ch.syncs += 1
            if ch.syncs >= ch.trans:
                ch.syncs = 0
                codec = ch.codec[1] or self._codec(ch)
                pick = codec[6]
                if pick is not None and held is not None:
                    # perf: sample() inline for a map of the drive's own
                    # objects: packed straight from the held values
                    data = codec[0].pack(*pick(held))
                else:
                    data = self.sample(ch, held)
                ch.sent, ch.sent_at = data, t           # perf: _sent inline
                frames.append((ch.cob_id & 0x7FF, data))
        return frames, values

    def events(self, t: int) -> list[Frame]:
        """The event-driven TPDOs due at drive time *t*: data changed and the
        inhibit time passed, or the event timer ran out (CiA 301 §7.5.2.37)."""
        frames: list[Frame] = []
        if not self.active:
            return frames
        for ch in self.event_tx:
            last = ch.sent_at
            if last is not None and ch.event_ms and t - last >= ch.event_ms * 1000:
                frames.append(self._sent(ch, self.sample(ch), t))
                continue
            data = self.sample(ch)
            if data != ch.sent and (last is None or t - last >= ch.inhibit * 100):
                frames.append(self._sent(ch, data, t))
        return frames

    def next_due(self, t: int) -> Optional[int]:
        """When the next event-timer TPDO falls due after *t* (None: none)."""
        due = [c.sent_at + c.event_ms * 1000 for c in self.event_tx
               if c.event_ms and c.sent_at is not None]
        return min(due) if due else None

    @staticmethod
    def _sent(ch: Channel, data: bytes, t: int) -> Frame:
        ch.sent, ch.sent_at = data, t
        return ch.can_id, data

    def _once(self, note: Callable[[str, str], None], key: str, section: str,
              text: str) -> None:
        if key not in self._noted:
            self._noted.add(key)
            note(section, text)


def _getter(keys: tuple) -> Callable[[Any], tuple]:
    """A function of a mapping that gives the values of *keys* as a tuple."""
    if len(keys) > 1:
        return itemgetter(*keys)              # perf: one C call for the image's values
    if keys:
        one = keys[0]
        return lambda live: (live[one],)
    return lambda live: ()


def _held_getter(keys: tuple) -> Callable[[Any, tuple], tuple]:
    """A function of (a mapping, the drive's held own objects in the order
    of OWN_KEYS) that gives the values of *keys* as a tuple, an own object
    from the held values, any other from the mapping."""
    # perf: the values picked by position from one tuple, no dict built
    extra = tuple(k for k in keys if k not in OWN_KEYS)
    at = [OWN_KEYS.index(k) if k in OWN_KEYS else len(OWN_KEYS) + extra.index(k)
          for k in keys]
    pick = itemgetter(*at) if len(at) > 1 else (
        (lambda values, one=at[0]: (values[one],)) if at else (lambda values: ()))
    if not extra:
        return lambda live, held: pick(held)
    get_extra = _getter(extra)
    return lambda live, held: pick(held + get_extra(live))
