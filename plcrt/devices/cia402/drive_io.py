"""The process data of a simulated CiA 402 drive: images in and out.

What it is: :class:`ProcessData`, the part of :class:`~.drive.Drive` that
exchanges process data with a master in each bus cycle: :meth:`cycle` (an
RxPDO image in, the TxPDO image out, through struct codecs built once per
mapping), :meth:`exchange` (the same by object, the PLC coupler's path),
the received objects applied in OP (:meth:`_apply_rx`, :meth:`_apply_values`),
and the drive's own objects written back to the store (:meth:`publish`).  The objects' keys and
the constants the drive shares with it are defined here.

What it is not: the cycle's stages (:meth:`Drive._step`: advance, the held
controlword, the mode's cycle), the steady CSP cycle written out
(:mod:`.drive_csp`) or the mapping rules (:mod:`.pdo`).  It is a
base class of :class:`~.drive.Drive` and works on a drive's attributes.
"""

from __future__ import annotations

import struct
from dataclasses import fields
from operator import itemgetter
from typing import Any, Callable, Iterable, Optional

from ..motion import US
from .esm import EsmState
from .modes import CyclicPosition
from .pdo import pack, unpack
from .plant import DrivePlant
from .statemachine import State
from .store import key

__all__ = ["ProcessData", "CW", "I32_HIGH", "I32_LOW", "MISSING", "MOTION_KEYS", "OE", "OUTPUTS",
           "OWN_KEYS", "STATE_KEYS"]

#: The drive's own objects, written by :meth:`ProcessData.publish`.
#: 6063h (position actual internal value) reads as 6064h: neither model has a
#: factor group (6091h/6092h), so one increment is one count; 606Bh (velocity
#: demand) is the speed of the demand 6062h (docs/decisions.md).
OUTPUTS = (0x6041, 0x6061, 0x6062, 0x6064, 0x606C, 0x603F, 0x1001, 0x60F4, 0x60FD,
           0x6063, 0x606B)
_OUTPUT_KEYS = tuple(key(i, 0) for i in OUTPUTS)
MOTION_KEYS = _K6062, _K6064, _K606C, _K60F4, _K6063, _K606B = tuple(
    key(i, 0) for i in (0x6062, 0x6064, 0x606C, 0x60F4, 0x6063, 0x606B))
STATE_KEYS = _K6041, _K6061, _K603F, _K1001, _K60FD = tuple(
    key(i, 0) for i in (0x6041, 0x6061, 0x603F, 0x1001, 0x60FD))
#: The order of the values :meth:`ProcessData.publish_deferred` holds.
OWN_KEYS = MOTION_KEYS + STATE_KEYS
#: Objects whose write the drive's hook acts on whatever the mode (6040h
#: controlword, 6060h mode, 605Ah/6084h/6085h read by the state machine).
_HOOK_INDEXES = frozenset({0x6040, 0x6060, 0x605A, 0x6084, 0x6085})
CW = key(0x6040, 0)
# perf: enum members as module constants (a class attribute of an Enum costs
# ten times a global on Python 3.11, EnumType.__getattr__)
OE = State.OPERATION_ENABLED
_ESM_OP = EsmState.OP
MISSING = object()
_K60B8 = key(0x60B8, 0)       # touch probe function
_B10, _B12 = 0x400, 0x1000     # 6041h: target reached, set-point followed (HCFA §7.5.1)
I32_LOW, I32_HIGH = -0x80000000, 0x7FFFFFFF    # the range of an I32 object
_B8, _B13 = 0x100, 0x2000      # 6041h: limit stop, following error (CyclicPosition.bits)
# perf: a DrivePlant with these fields only reads 60FDh from its switches
# (plant.py as written with this module); other fields turn the shortcut off
_PLAIN_PLANT = {f.name for f in fields(DrivePlant)} == {
    "neg_limit", "pos_limit", "home_switch", "index_period", "index_phase",
    "neg_stop", "pos_stop", "probe", "probe2"}


def _picker(at: list) -> Callable[[object], tuple]:
    """itemgetter(*at), giving a tuple also for one or no item."""
    if len(at) > 1:
        return itemgetter(*at)
    if at:
        return lambda values, one=at[0]: (values[one],)
    return lambda values: ()


class DriveFields:
    """The attributes of a :class:`~.drive.Drive` its process-data and CSP
    mixins read (set by ``Drive.__init__``; the mixins also call the
    drive's methods)."""

    now: int
    controlword: int
    mode_number: int
    engines: dict[int, Any]
    axis: Any
    sm: Any
    esm: Any
    pdo: Any
    plant: DrivePlant
    store: Any
    stops: Any
    probe: Any
    _live: dict[tuple[int, int], Any]
    deferred: Optional[tuple[int, ...]]
    _held_state: Optional[tuple[int, ...]]
    _fit: bool
    _out: dict[tuple[int, int], int]


class ProcessData(DriveFields):
    """The process data of a :class:`~.drive.Drive` (see the module docstring)."""

    _motion_i32: bool
    _own: frozenset[tuple[int, int]]
    _signed: frozenset[tuple[int, int]]

    def cycle(self, t_us: int, rx: Optional[bytes] = None) -> bytes:
        """One bus cycle at *t_us*: advance, apply the RxPDO image *rx* (in
        OP; objects before 6040h), evaluate the held controlword, run the
        mode's cycle, and return the TxPDO image."""
        with self.store.lock:
            if rx is None or not self._csp_fast(t_us, rx, None):
                self._step(t_us, rx, None)
            tx = self.pdo.active_tx
            entries, codec = self._tx_codec
            if entries is not tx:
                codec = self._tx_fast_codec(tx)     # perf: once per mapping
                self._tx_codec = (tx, codec)
            if codec is not None:
                st, pick, more = codec
                if pick is not None:
                    motion, state = self._published
                    return st.pack(*pick(motion + state + (more(self._live) if more else ())))
                args: list[int] = []
                for run, src in more:
                    args += run(src)
                return st.pack(*args)
            get, out = self.store.get, self._out
            values = {(e.index, e.sub): out.get((e.index, e.sub)) if (e.index, e.sub) in out
                      else int(get(e.index, e.sub)) for e in tx if e.index}
            return pack(tx, values)

    def exchange(self, t_us: int, values: dict[tuple[int, int], int],
                 decoded: bool = False) -> None:
        """One bus cycle at *t_us* whose received process data are given
        by object, ``{(index, sub): value}``, instead of as a packed RxPDO
        image: the path of a master module that owns its mapping (the PLC
        coupler).  The objects act as from an RxPDO (in OP only, objects
        before 6040h); the caller reads what it transmits from
        :attr:`store`.  *decoded*: the values were unpacked from a PDO at
        each object's own width and signedness, so they fit their types.
        After :meth:`~.drive.Drive.publish_deferred` (a SYNC), the values it
        holds are written first unless the fast CSP cycle writes its own."""
        with self.store.lock:
            self.exchange_locked(t_us, values, decoded)

    def exchange_locked(self, t_us: int, values: dict[tuple[int, int], int],
                        decoded: bool = False) -> None:
        """:meth:`exchange` for a caller that holds the store's lock (a
        CANopen port at a SYNC; perf: no second acquisition of the lock)."""
        self._fit = decoded
        if self.deferred is not None:
            # perf: the values held at the SYNC stay unwritten when the
            # fast cycle writes its own and reads none of them
            if values.keys().isdisjoint(self._own):
                if self._csp_fast(t_us, None, values):
                    self.deferred = None
                    return
                self.flush()
                self._step(t_us, None, values)
                return
            self.flush()
        if not self._csp_fast(t_us, None, values):
            self._step(t_us, None, values)   # the same cycle as cycle()

    def _codec(self, entries: tuple) -> Optional[tuple[struct.Struct, list[tuple[int, int]]]]:
        """A struct for a byte-aligned image (the same bytes as pdo.pack /
        pdo.unpack, which serve every other mapping)."""
        hit = self._codecs.get(id(entries))
        if hit is not None and hit[0] is entries:
            return hit[1]
        fmt, keys = "<", []
        for e in entries:
            if e.bits not in (8, 16, 32):
                self._codecs[id(entries)] = (entries, None)
                return None
            if e.index == 0:
                fmt += "x" * (e.bits // 8)
                continue
            code = {8: "b", 16: "h", 32: "i"}[e.bits]
            fmt += code if (e.index, e.sub) in self._signed else code.upper()
            keys.append(key(e.index, e.sub))
        codec = (struct.Struct(fmt), keys)
        self._codecs[id(entries)] = (entries, codec)
        return codec

    def _tx_fast_codec(self, entries: tuple) -> Optional[tuple]:
        """For a byte-aligned TxPDO map: (struct, pick, getter).  When the
        model has all the drive's own objects, *pick* takes the image's
        values by position from the motion and state groups publish wrote
        last followed by *getter* (store values) of the other objects;
        otherwise *pick* is None and *getter* lists runs of (getter, source):
        the drive's own outputs (:attr:`_out`) or the store's values."""
        found = self._codec(entries)
        if found is None:
            return None
        st, keys = found
        if len(self._own) == len(OUTPUTS):
            # perf: the own objects from the values publish wrote last (the
            # motion and state groups, kept equal to _out), the others from
            # the store: one tuple, picked by position without hashing keys
            own = MOTION_KEYS + STATE_KEYS
            extra = [k for k in keys if k not in own]
            at = [own.index(k) if k in own else len(own) + extra.index(k) for k in keys]
            pick = _picker(at)
            get_extra = None if not extra else _picker(extra)
            return st, pick, get_extra
        runs: list[tuple[list[tuple[int, int]], dict]] = []
        for key in found[1]:
            src = self._out if key in self._own else self._live
            if runs and runs[-1][1] is src:
                runs[-1][0].append(key)
            else:
                runs.append(([key], src))
        return st, None, [(_picker(keys), src) for keys, src in runs]

    def _rx_fast_codec(self, entries: tuple) -> Optional[tuple]:
        """For a byte-aligned RxPDO map without repeated objects: (image
        size, a struct of the objects other than 6040h, their keys, a struct
        of 6040h or None, its byte offset).  The first struct skips 6040h's
        bytes, so the objects come out without building a dict."""
        fmt, keys, cw, offset = "<", [], None, 0
        for e in entries:
            if e.bits not in (8, 16, 32):
                return None
            k, size = key(e.index, e.sub), e.bits // 8
            code = {8: "b", 16: "h", 32: "i"}[e.bits]
            code = code if k in self._signed else code.upper()
            if e.index == 0:
                fmt += "x" * size
            elif k == CW:
                if cw is not None:
                    return None
                fmt += "x" * size
                cw = (struct.Struct("<" + code), offset)
            else:
                if k in keys:
                    return None
                fmt += code
                keys.append(k)
            offset += size
        return (offset, struct.Struct(fmt), tuple(keys), *(cw or (None, 0)))

    def _apply_rx(self, t_us: int, rx: bytes) -> None:
        rx_map = self.pdo.active_rx
        entries, codec = self._rx_codec
        if entries is not rx_map:
            codec = self._rx_fast_codec(rx_map)     # perf: once per mapping
            self._rx_codec = (rx_map, codec)
        if codec is not None and len(rx) == codec[0]:
            _, objects, keys, cw_st, at = codec
            self._apply_values(t_us, None if cw_st is None else cw_st.unpack_from(rx, at)[0],
                               zip(keys, objects.unpack(rx)), True)
            return
        values = unpack(rx_map, rx, self._signed)
        cw = values.pop(CW, None)
        self._apply_values(t_us, cw, values.items(), True)

    def _apply_values(self, t_us: int, cw: Optional[int],
                      items: Iterable[tuple[tuple[int, int], int]], known: bool) -> None:
        """Apply received objects *items*, then the controlword *cw* (None:
        not received).  *known*: the values come from an image, unpacked at
        each object's own width and signedness."""
        if self.esm.state is not _ESM_OP:          # perf: esm.outputs (OP only)
            if not self._rx_noted:
                self._rx_noted = True
                self.note(t_us, "HCFA §6.5", f"RxPDO ignored in {self.esm.state.name}: "
                          "outputs act in OP only", "drive")
            return
        live, store = self._live, self.store
        for key, v in items:                        # objects first, then 6040h
            if live.get(key, MISSING) == v:
                continue        # perf: an unchanged object: no store write, no hook
            if key[0] in _HOOK_INDEXES or not (
                    # perf: no Write and no hook dispatch for a value nobody
                    # acts on: the drive's own hook is the only one and does
                    # nothing with this object now (outside OPERATION
                    # ENABLED, or a mode without parameter(); inside a
                    # cycle, which publishes once at its end)
                    store.hooked == self._only_hook
                    and (self.sm.state is not OE
                         or not self.engines[self.mode_number].takes_parameters)):
                store.set(key[0], key[1], v, source="pdo")
            elif known:
                store.set_known(key, v)
            else:
                store.set(key[0], key[1], v)
        if cw is not None and cw != self.controlword:
            store.set(0x6040, 0, cw, source="pdo")

    # ---------------------------------------------------------------- outputs
    def publish(self) -> None:
        """Write the drive's own objects for the present time."""
        self._publish_values(*self._outputs())

    def _outputs(self) -> tuple[tuple[int, int, int, int, int, int],
                                tuple[int, int, int, int, int]]:
        """The drive's own objects for the present time: (motion, state) as
        :meth:`_publish_values` takes them.  Sets the statusword's mode
        bits and updates the touch probe."""
        t = self.now
        ax, sm = self.axis, self.sm
        line, plant = ax._line, self.plant
        if (line is not None and sm.state is OE and self.mode_number == 8 and self.stops is None
                and plant.pos_limit is None and plant.neg_limit is None and ax.bounds is None):
            csp = self.engines[8]
            if csp.__class__ is CyclicPosition:
                # perf: the CSP line written out: CyclicPosition.bits with no
                # limit switch, Axis.moving, mechanical and velocity on a line
                t1 = line.t1
                # perf: set_mode_bits of bits that are mode bits (8, 10-15)
                sm._mode_bits = ((_B8 if csp.limit_stop else 0) | _B12 | (0 if t < t1 else _B10)
                                 | (_B13 if csp._fe_since is not None else 0))
                if t >= t1:
                    mech, vel = line.x1, 0
                else:
                    t0 = line.t0
                    span, den = line.x1 - line.x0, t1 - t0
                    mech = line.x0 + span * ((t0 if t < t0 else t) - t0) // den
                    if t < t0:
                        vel = 0
                    else:
                        num = span * US
                        vel = num // den if num >= 0 else -(-num // den)
                pos = mech + ax.shift
                if self.probe.function or self._live.get(_K60B8):
                    self._probe_update(t, mech)            # touch probe armed (drive_service.py)
                inputs = 0 if _PLAIN_PLANT and plant.__class__ is DrivePlant \
                    and plant.home_switch is None else plant.inputs(mech)
                return ((csp.demand, pos, vel, csp.following_error, pos, vel),
                        (sm.statusword, 8, sm.error_code, sm.error_register, inputs))
        if sm.state is OE:
            bits = self.engines[self.mode_number].bits(t)    # perf: self.mode, inline
            if bits is not None:
                sm.set_mode_bits(bits)
        mech = ax.mechanical(t)
        pos = mech + ax.shift                      # axis.position(t)
        if self.probe.function or self._live.get(_K60B8):
            self._probe_update(t, mech)            # touch probe armed (drive_service.py)
        if self.mode_number == 8:
            csp = self.engines[8]
            assert isinstance(csp, CyclicPosition)
            fe = csp.following_error
            demand = csp.demand if sm.state is OE else pos
        else:
            fe, demand = 0, pos
        if self.stops is not None and self.mode_number != 8:
            demand = ax.demand_position(t)      # past a mechanical end (stops.py)
            fe = demand - pos
        vel = ax.velocity(t)
        return ((demand, pos, vel, fe, pos,
                 vel if self.stops is None else int(ax.demand(t)[1])),
                (sm.statusword, self.mode_number, sm.error_code, sm.error_register,
                 self.plant.inputs(mech)))

    def _publish_values(self, motion: tuple[int, int, int, int],
                        state: tuple[int, int, int, int, int]) -> None:
        """Write the drive's own objects: *motion* = 6062h, 6064h, 606Ch,
        60F4h, 6063h, 606Bh and *state* = 6041h, 6061h, 603Fh, 1001h, 60FDh."""
        # perf: two groups, each written only when one of its values changed
        # (the motion values change every cycle of a move, the state values
        # seldom); a group is written whole, unchanged values as they are
        last_motion, last_state = self._published
        new_motion, new_state = motion != last_motion, state != last_state
        if not (new_motion or new_state):
            return
        store, out = self.store, self._out
        if len(self._own) == len(OUTPUTS) \
                and (not new_motion or (
                    # perf: six I32 objects of the type's range: min and max tell
                    I32_LOW <= min(motion) and max(motion) <= I32_HIGH if self._motion_i32
                    else store.fits_group(MOTION_KEYS, motion))) \
                and (not new_state or store.fits_group(STATE_KEYS, state)):
            # perf: each group's dict is kept and refilled, then merged whole
            if new_motion:
                group = self._motion_out
                (group[_K6062], group[_K6064], group[_K606C], group[_K60F4], group[_K6063],
                 group[_K606B]) = motion
                store.set_status_group(group)
                out.update(group)
            if new_state:
                group = self._state_out
                group[_K6041], group[_K6061], group[_K603F], group[_K1001], group[_K60FD] = state
                store.set_status_group(group)
                out.update(group)
        else:
            # each changed value in the order of OUTPUTS, up to one out of range
            values = (state[0], state[1], motion[0], motion[1], motion[2], state[2], state[3],
                      motion[3], state[4], motion[4], motion[5])
            own = self._own
            changed = {key: v for key, v in zip(_OUTPUT_KEYS, values)
                       if out.get(key) != v and key in own}
            if changed:
                store.set_status(changed)
                out.update(changed)
        self._published = (motion, state)
