"""A simulated CiA 402 drive in exact, event-driven simulated time.

What it is: :class:`Drive`, which joins the object dictionary values
(:class:`~.store.Store`), the power state machine (:class:`~.statemachine.Drive402`),
the EtherCAT state machine (:class:`~.esm.Esm`), the PDO mapping
(:class:`~.pdo.PdoConfig`), the mode engines (:mod:`.modes`) and the axis
(:class:`~.axis.Axis`, integer counts).  A master's writes (SDO or RxPDO)
reach the drive through the store's write hook; the drive writes back
6041h, 6061h, 6062h, 6064h, 606Ch, 603Fh, 1001h, 60F4h and 60FDh as they
change.  :meth:`Drive.advance` moves time forward to an integer µs: the
events inside (the end of a move, a limit switch, a watched homing position,
the homing time limit, a mechanical end, :mod:`.stops`) happen at their
exact µs, as for the EM253, and the cost does not depend on the speed.
:meth:`Drive.cycle` is one bus cycle: advance, apply the RxPDO image, run
the cycle, return the TxPDO image.

Every refusal and diagnostic goes to :attr:`Drive.log` with its time and the
manual section.

What it is not: no bus.  The canopen port and the PLC coupler call
:meth:`sdo_read`, :meth:`sdo_write` and :meth:`cycle`.
"""

from __future__ import annotations

import copy
import struct
from dataclasses import dataclass
from typing import Callable, Optional

from ...errors import PlcError
from .axis import Axis, LinLeg
from .esm import AlResult, Esm, EsmState
from . import homing_adapter  # noqa: F401  (registers the homing methods)
from .homing_plan import HomingPlan, homing_plans
from .modes import (CyclicPosition, Homing, Mode, NoMode, ProfilePosition, ProfileVelocity,
                    MODE_NAMES)
from .od import ObjectDictionary, SdoAbort
from .pdo import ASSIGN, MapLayout, PdoConfig, pack, unpack
from .plant import DrivePlant
from .statemachine import Command, Drive402, Result, State
from .states import IDLE_STATUSWORD, STATUSWORD
from .stops import HardStops
from .store import Store, Write

__all__ = ["Drive", "DriveEvent"]

_OUTPUTS = (0x6041, 0x6061, 0x6062, 0x6064, 0x606C, 0x603F, 0x1001, 0x60F4, 0x60FD)
#: Values of objects a model's dictionary lacks: the Kinco note gives no 6080h
#: (no speed limit then) and no P03.07 (no homing time limit).
_ABSENT = {(0x6080, 0): 0xFFFFFFFF, (0x2003, 7): 0, (0x6099, 5): 0, (0x6099, 6): 0,
           (0x6099, 4): 0, (0x60F9, 10): 0}
_MAX_EVENTS = 100_000  # per advance: a homing plan that never moves on is an error


@dataclass(frozen=True, slots=True)
class DriveEvent:
    """One entry of the drive's event log."""

    t_us: int
    source: str
    text: str
    section: str

    def __str__(self) -> str:
        return f"t={self.t_us / 1e6:.6f}s [{self.source}] {self.text} ({self.section})"


class Drive:
    """One simulated drive of *model* (``hcfa-am0520b``, ``kinco-servo``).

    *plant*: its switches (none by default); *node_id*: the bus address a
    port gives it; *t_us*: the time it powers up; *homing*: the homing
    methods by 6098h value (default :func:`~.homing_plan.homing_plans`)."""

    def __init__(self, model: str = "hcfa-am0520b", *, plant: Optional[DrivePlant] = None,
                 node_id: int = 1, t_us: int = 0,
                 homing: Optional[dict[int, Callable[[], HomingPlan]]] = None) -> None:
        self.model = model
        self.node_id = node_id
        self.od = ObjectDictionary.load(model)
        self.store = Store(self.od)
        self.plant = plant or DrivePlant()
        self.homing_plans = homing_plans(model) if homing is None else dict(homing)
        self.now = t_us
        self.log: list[DriveEvent] = []
        self.axis = Axis(0)
        self.controlword = int(self.store.get(0x6040))
        self.pdo = PdoConfig(self._lookup, lambda: self.esm.state, self._default_maps(),
                             self._map_layout())
        self.esm = Esm(self.pdo.activate)
        mode = int(self.store.get(0x6060))
        self.sm = Drive402(model, t=t_us / 1e6, mode=mode or None)
        self._sm_seen = 0
        self.engines: dict[int, Mode] = {0: NoMode(self), 1: ProfilePosition(self),
                                         3: ProfileVelocity(self), 6: Homing(self),
                                         8: CyclicPosition(self)}
        self.mode_number = mode
        self._qs_wait = False
        self._out: dict[tuple[int, int], int] = {}
        self._cache_version = -1
        self._cache: dict[tuple, Optional[int]] = {}
        self._signed = frozenset((e.index, e.sub) for e in self.od if e.dtype.startswith("I"))
        self._absent = {k: v for k, v in _ABSENT.items() if self.od.find(*k) is None}
        self._own = frozenset((i, 0) for i in _OUTPUTS if self.od.find(i, 0) is not None)
        self._codecs: dict[int, tuple] = {}   # id(entries) -> (entries, codec)
        self._batch = False
        self._rx_noted = False
        self.stops = HardStops(self) if (self.plant.neg_stop is not None
                                         or self.plant.pos_stop is not None) else None
        self.store.on_write(self._on_write)
        self._mirror()
        self.publish()

    def __deepcopy__(self, memo: dict) -> "Drive":
        # a fork of a PLC copies its drives; compiled struct codecs are not
        # copyable and are rebuilt on first use, the dictionary is shared
        new = object.__new__(type(self))
        memo[id(self)] = new
        memo.setdefault(id(self.od), self.od)
        for key, value in self.__dict__.items():
            new.__dict__[key] = {} if key == "_codecs" else copy.deepcopy(value, memo)
        return new

    # ---------------------------------------------------------------- helpers
    @property
    def mode(self) -> Mode:
        return self.engines[self.mode_number]

    def param(self, index: int, sub: int = 0) -> int:
        """The active value of an object the drive acts on (an object the
        model lacks reads as its entry in ``_ABSENT``)."""
        if (index, sub) in self._absent:
            return self._absent[(index, sub)]
        return int(self.store.get(index, sub))

    def note(self, t: int, section: str, text: str, source: str = "") -> None:
        self.log.append(DriveEvent(t, source or MODE_NAMES.get(self.mode_number, "drive"),
                                   text, section))

    def _map_layout(self) -> MapLayout:
        """This model's mapping objects and limits, from its dictionary: a
        CANopen model (Kinco) has no 1C12h/1C13h and maps of at most 8 bytes."""
        od = self.od
        rx = tuple(i for i in range(0x1600, 0x1800) if od.find(i, 0) is not None)
        tx = tuple(i for i in range(0x1A00, 0x1C00) if od.find(i, 0) is not None)
        return MapLayout(rx, tx, od.find(0x1C12, 0) is not None, od.pdo_max_entries,
                         od.pdo_max_bytes, str(od.info.get("pdo_source", "HCFA §6.7.2")))

    def _default_maps(self) -> dict[int, tuple[int, ...]]:
        """The power-up PDO maps and assignment of this model's object dictionary."""
        out: dict[int, tuple[int, ...]] = {}
        for index in (*range(0x1600, 0x1800), *range(0x1A00, 0x1C00), *ASSIGN):
            if self.od.find(index, 0) is None:
                continue
            count = int(self.store.get(index, 0))
            out[index] = tuple(int(self.store.get(index, k)) for k in range(1, count + 1)
                               if self.od.find(index, k) is not None)
        return out

    def _lookup(self, index: int, sub: int) -> Optional[tuple[int, str]]:
        e = self.od.find(index, sub)
        return None if e is None else (e.bits, e.pdo)

    def bus_period_us(self) -> int:
        """The bus cycle from 1C32h:02 (ns), 1 ms if absent."""
        if self.od.find(0x1C32, 2) is not None:
            return max(1, self.param(0x1C32, 2) // 1000)
        return 1000

    def limit_active(self, t: int) -> bool:
        if self.plant.neg_limit is None and self.plant.pos_limit is None:
            return False
        pos = self.axis.mechanical(t)
        return self.plant.nls(pos) or self.plant.pls(pos)

    def limit_toward(self, t: int, direction: int) -> Optional[str]:
        """The active limit switch in *direction*, if any (not while homing)."""
        if self.mode_number == 6 or (self.plant.neg_limit is None
                                     and self.plant.pos_limit is None):
            return None
        pos = self.axis.mechanical(t)
        if direction > 0 and self.plant.pls(pos):
            return f"the positive limit switch (PLS at {self.plant.pos_limit})"
        if direction < 0 and self.plant.nls(pos):
            return f"the negative limit switch (NLS at {self.plant.neg_limit})"
        return None

    def idle_mode_bits(self) -> int:
        base = STATUSWORD[self.sm.state]
        return IDLE_STATUSWORD.get((self.mode_number, self.sm.state), base) & ~base

    @property
    def moving(self) -> bool:
        return self.axis.moving(self.now)

    # ---------------------------------------------------------------- master side
    def sdo_read(self, index: int, sub: int = 0) -> bytes:
        """SDO upload (the store's rules)."""
        if index in self.pdo.entries:
            return self.od.entry(index, sub).encode(self.pdo.read(index, sub))
        return self.store.sdo_read(index, sub)

    def sdo_write(self, index: int, sub: int, data: bytes) -> None:
        """SDO download at the present time; raises :class:`SdoAbort`.
        Mapping objects follow the dynamic mapping procedure (HCFA §6.7.4)."""
        with self.store.lock:
            self._sdo_write(index, sub, data)

    def _sdo_write(self, index: int, sub: int, data: bytes) -> None:
        state = {EsmState.PREOP: "PREOP", EsmState.SAFEOP: "SAFEOP",
                 EsmState.OP: "OP"}.get(self.esm.state, "INIT")
        if index in self.pdo.entries:
            entry = self.od.entry(index, sub)
            if len(data) != entry.size:
                self.store.sdo_write(index, sub, data, state=state)   # raises the length code
            res = self.pdo.write(index, sub, int(entry.decode(bytes(data))))
            if not res.ok:
                raise SdoAbort(res.abort, res.explanation.split('): ', 1)[-1])
            self.store.set(index, sub, int(entry.decode(bytes(data))))
            return
        self.store.sdo_write(index, sub, data, state=state, moving=self.moving)

    def write(self, index: int, sub: int, value: int) -> None:
        """SDO download of *value* encoded as the object's type."""
        self.sdo_write(index, sub, self.od.entry(index, sub).encode(value))

    def read(self, index: int, sub: int = 0) -> int | str:
        """SDO upload decoded."""
        return self.od.entry(index, sub).decode(self.sdo_read(index, sub))

    def _on_write(self, w: Write) -> None:
        index, sub, value = w.entry.index, w.entry.sub, w.value
        t = self.now
        if index == 0x6040:
            self._controlword(t, int(value))
        elif index == 0x6060:
            self._select_mode(t, int(value))
        else:
            if index == 0x605A:
                self.sm.quick_stop_option = int(value)
            elif index == 0x6084:
                self.sm.dec_6084 = int(value)
            elif index == 0x6085:
                self.sm.dec_6085 = int(value)
            if self.sm.state is State.OPERATION_ENABLED:
                self.mode.parameter(t, index, sub)
        if not self._batch:
            self.publish()        # 6041h is current when an SDO write returns

    def _controlword(self, t: int, cw: int) -> None:
        old, self.controlword = self.controlword, cw
        was_oe = self.sm.state is State.OPERATION_ENABLED
        self._do(t, self.sm.apply_controlword(cw, t / 1e6))
        if was_oe and self.sm.state is State.OPERATION_ENABLED:
            self.mode.controlword(t, old, cw)
        elif not was_oe and self.sm.state is State.OPERATION_ENABLED:
            # the mode's bits 4-8 as written with the enable: the bit 4 edge counts
            self.mode.controlword(t, cw & ~0x10 | old & 0x10, cw)

    def _select_mode(self, t: int, mode: int) -> None:
        if mode == 0 and self.mode_number != 0:
            self.note(t, "HCFA §8.3; digest §7.2 caveat 5",
                      f"6060h := 0 ignored: 6061h stays {self.mode_number} (a master that maps "
                      "6040h and 6060h together sends 0)", "drive")
            return
        if mode == self.mode_number:
            return
        oe = self.sm.state is State.OPERATION_ENABLED
        if oe:
            if self.axis.moving(t):
                self.note(t, "CiA 402 (HCFA silent)",
                          f"6060h changed from {self.mode_number} to {mode} while moving: the "
                          "axis stops at once", "drive")
            self.axis.stop_at_once(t)
            self.mode.disable(t)
        self.mode_number = mode
        self.sm.mode = mode or None
        if oe:
            self.mode.enable(t)

    def request_esm(self, state: EsmState | int, ack: bool = False) -> AlResult:
        """AL Control from the master at the present time (HCFA §6.5): a
        mapping error raises alarm 35; leaving OP disables the drive."""
        res = self.esm.request(state, self.now / 1e6, ack)
        self._esm_result(res)
        return res

    def _esm_result(self, res: AlResult) -> None:
        t = self.now
        if res.explanation:
            self.note(t, "HCFA §6.5", res.explanation, "ESM")
        if res.fault is not None:
            self.fault(t, *res.fault)
        if res.left_op and self.sm.state in (State.OPERATION_ENABLED,
                                             State.QUICK_STOP_ACTIVE):
            self._do(t, self.sm.command(Command.DISABLE_VOLTAGE, t / 1e6,
                                        "the bus left OP (digest §6.1)"))
        self.publish()

    # ---------------------------------------------------------------- state machine
    def _mirror(self) -> None:
        for ev in self.sm.log[self._sm_seen:]:
            self.log.append(DriveEvent(round(ev.t * 1e6), "state machine", str(ev), ev.section))
        self._sm_seen = len(self.sm.log)

    def _do(self, t: int, res: Result) -> None:
        for act in res.actions:
            if act.kind == "power-on":
                self._qs_wait = False
                self.mode.enable(t)
            elif act.kind in ("power-off", "fault-reaction"):
                self._qs_wait = False
                self.axis.stop_at_once(t)
                self.mode.disable(t)
            elif act.kind == "quick-stop":
                plan = act.plan
                self.mode.disable(t)
                if self.sm.state is not State.QUICK_STOP_ACTIVE or self.sm.at_rest_in_quick_stop:
                    self.axis.stop_at_once(t)     # Drive402 already reported the stop
                    continue
                dec = plan.deceleration if plan is not None and plan.deceleration else \
                    self.param(0x6085)
                self.axis.stop(t, dec)
                if self.axis.moving(t):
                    self._qs_wait = True
                else:
                    self._do(t, self.sm.motion_stopped(t / 1e6))
        self._mirror()

    def fault(self, t: int, code: int, alarm: Optional[int], why: str) -> None:
        """Raise a fault (603Fh *code*, alarm number) with its reason."""
        self._do(t, self.sm.raise_fault(code, alarm, why, t / 1e6))

    # ---------------------------------------------------------------- time
    def _next_event(self, t_to: int) -> Optional[tuple[int, str, object]]:
        ax = self.axis
        if ax.version != self._cache_version:
            self._cache_version, self._cache = ax.version, {}
        best: Optional[tuple[int, str, object]] = None

        def offer(te: Optional[int], kind: str, data: object) -> None:
            nonlocal best
            if te is not None and te <= t_to and (best is None or te < best[0]):
                best = (te, kind, data)

        end = ax.end_time()
        if ax.legs and end is not None and (self._qs_wait or not isinstance(ax.legs[-1], LinLeg)):
            # a CSP line needs no end event: its end position holds by itself
            offer(max(end, self.now), "end", None)
        if ax.legs:
            watches: list[tuple[str, int, int, object]] = []
            if self.mode_number == 6:
                hm = self.engines[6]
                assert isinstance(hm, Homing)
                watches = [("watch", w.position, w.direction, w) for w in hm.watches]
            elif self.sm.state in (State.OPERATION_ENABLED, State.QUICK_STOP_ACTIVE):
                if self.plant.pos_limit is not None:
                    watches.append(("limit", self.plant.pos_limit, 1, "PLS"))
                if self.plant.neg_limit is not None:
                    watches.append(("limit", self.plant.neg_limit, -1, "NLS"))
            for kind, level, direction, data in watches:
                key = (kind, level, direction)
                if key not in self._cache:
                    te = ax.first_reach(self.now, level, direction, mechanical=True)
                    self._cache[key] = None if te == self.now else te
                te = self._cache[key]
                if te is not None and te >= self.now:
                    offer(te, kind, data)
        if self.mode_number == 6:
            hm = self.engines[6]
            assert isinstance(hm, Homing)
            if hm.deadline is not None:
                offer(max(hm.deadline, self.now), "timeout", None)
        if self.stops is not None:                     # mechanical ends (stops.py)
            for te, ev in self.stops.events():
                offer(te, "stop", ev)
        return best

    def advance(self, t_us: int) -> None:
        """Move simulated time forward to *t_us* (integer µs), exactly."""
        if t_us < self.now:
            raise PlcError(f"drive time cannot go back: now {self.now} µs, asked {t_us} µs")
        with self.store.lock:          # a canopen port writes from its Notifier thread
            self._advance(t_us)

    def _advance(self, t_us: int) -> None:
        for _ in range(_MAX_EVENTS):
            ev = self._next_event(t_us)
            if ev is None:
                break
            te, kind, data = ev
            self.now = te
            if kind == "end":
                if self._qs_wait:
                    self.axis.settle(te)
                    self._qs_wait = False
                    self._do(te, self.sm.motion_stopped(te / 1e6))
                elif self.stops is None or not self.stops.holds_end(te):
                    self.mode.motion_end(te)
                if self.axis.legs and self.axis.end_time() == te:
                    self.axis.settle(te)
            elif kind == "limit":
                self._cache[("limit", self.plant.pos_limit if data == "PLS"
                             else self.plant.neg_limit, 1 if data == "PLS" else -1)] = None
                switch = "positive limit switch (PLS)" if data == "PLS" \
                    else "negative limit switch (NLS)"
                if self._qs_wait:
                    self.note(te, "HCFA §7.4.2", f"{switch} reached during the quick stop")
                else:
                    self.mode.limit(te, switch)
            elif kind == "watch":
                hm = self.engines[6]
                assert isinstance(hm, Homing)
                self._cache[("watch", data.position, data.direction)] = None  # type: ignore
                hm.watch_hit(te, data)  # type: ignore[arg-type]
            elif kind == "timeout":
                hm = self.engines[6]
                assert isinstance(hm, Homing)
                hm.timeout(te)
            elif kind == "stop":
                assert self.stops is not None
                self.stops.on_event(te, data)  # type: ignore[arg-type]
        else:
            raise PlcError(f"drive: more than {_MAX_EVENTS} events before {t_us} µs "
                           "(a homing plan that does not move on?)")
        self.now = t_us
        if not self._batch:
            self.publish()

    def cycle(self, t_us: int, rx: Optional[bytes] = None) -> bytes:
        """One bus cycle at *t_us*: advance, apply the RxPDO image *rx* (in
        OP; objects before 6040h), evaluate the held controlword, run the
        mode's cycle, and return the TxPDO image."""
        with self.store.lock:
            return self._cycle(t_us, rx)

    def tick(self, t_us: int) -> None:
        """One bus cycle at *t_us* without process data (a CANopen port,
        whose PDOs are not the EtherCAT images): advance, evaluate the held
        controlword, run the mode's cycle."""
        with self.store.lock:
            self._step(t_us, None)

    def _cycle(self, t_us: int, rx: Optional[bytes]) -> bytes:
        self._step(t_us, rx)
        get, out = self.store.get, self._out
        codec = self._codec(self.pdo.active_tx)
        if codec is not None:
            return codec[0].pack(*[out[k] if k in out else int(get(*k)) for k in codec[1]])
        values = {(e.index, e.sub): out.get((e.index, e.sub)) if (e.index, e.sub) in out
                  else int(get(e.index, e.sub)) for e in self.pdo.active_tx if e.index}
        return pack(self.pdo.active_tx, values)

    def _step(self, t_us: int, rx: Optional[bytes]) -> None:
        self._batch = True
        try:
            self.advance(t_us)
            if rx is not None:
                self._apply_rx(t_us, rx)
            if self.sm.state is not State.OPERATION_ENABLED:
                # in OE a held level can only hold OE: every other level acted when written
                self._do(t_us, self.sm.cycle(t_us / 1e6))
            if self.sm.state is State.OPERATION_ENABLED:
                self.mode.cycle(t_us)
        finally:
            self._batch = False
        self.publish()

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
            keys.append((e.index, e.sub))
        codec = (struct.Struct(fmt), keys)
        self._codecs[id(entries)] = (entries, codec)
        return codec

    def exchange(self, t_us: int, values: dict[tuple[int, int], int]) -> None:
        """One bus cycle at *t_us* whose received process data are given
        by object, ``{(index, sub): value}``, instead of as a packed RxPDO
        image: the path of a master module that owns its mapping (the PLC
        coupler).  The objects act as from an RxPDO (in OP only, objects
        before 6040h); the caller reads what it transmits from
        :attr:`store`."""
        with self.store.lock:
            self._batch = True
            try:
                self.advance(t_us)
                self._apply_values(t_us, dict(values))
                if self.sm.state is not State.OPERATION_ENABLED:
                    self._do(t_us, self.sm.cycle(t_us / 1e6))
                if self.sm.state is State.OPERATION_ENABLED:
                    self.mode.cycle(t_us)
            finally:
                self._batch = False
            self.publish()

    def _apply_rx(self, t_us: int, rx: bytes) -> None:
        codec = self._codec(self.pdo.active_rx)
        if codec is not None and len(rx) == codec[0].size:
            values = dict(zip(codec[1], codec[0].unpack(rx)))
        else:
            values = unpack(self.pdo.active_rx, rx, self._signed)
        self._apply_values(t_us, values)

    def _apply_values(self, t_us: int, values: dict[tuple[int, int], int]) -> None:
        if not self.esm.outputs:
            if not self._rx_noted:
                self._rx_noted = True
                self.note(t_us, "HCFA §6.5", f"RxPDO ignored in {self.esm.state.name}: "
                          "outputs act in OP only", "drive")
            return
        cw = values.pop((0x6040, 0), None)
        for key, v in values.items():               # objects first, then 6040h
            if self._stored(key) != v:
                self.store.set(key[0], key[1], v, source="pdo")
        if cw is not None and cw != self.controlword:
            self.store.set(0x6040, 0, cw, source="pdo")

    def _stored(self, key: tuple[int, int]) -> int:
        return int(self.store.get(*key))

    # ---------------------------------------------------------------- outputs
    def publish(self) -> None:
        """Write the drive's own objects for the present time."""
        t = self.now
        if self.sm.state is State.OPERATION_ENABLED:
            bits = self.mode.bits(t)
            if bits is not None:
                self.sm.set_mode_bits(bits)
        pos = self.axis.position(t)
        csp = self.engines[8]
        assert isinstance(csp, CyclicPosition)
        fe = csp.following_error if self.mode_number == 8 else 0
        demand = csp.demand if self.mode_number == 8 and self.sm.state is \
            State.OPERATION_ENABLED else pos
        if self.stops is not None and self.mode_number != 8:
            demand = self.axis.demand_position(t)      # past a mechanical end (stops.py)
            fe = demand - pos
        values = {0x6041: self.sm.statusword, 0x6061: self.mode_number, 0x6062: demand,
                  0x6064: pos, 0x606C: self.axis.velocity(t), 0x603F: self.sm.error_code,
                  0x1001: self.sm.error_register, 0x60F4: fe,
                  0x60FD: self.plant.inputs(self.axis.mechanical(t))}
        out = self._out
        changed = {(i, 0): v for i, v in values.items()
                   if out.get((i, 0)) != v and (i, 0) in self._own}
        if changed:
            self.store.set_status(changed)
            out.update(changed)

    @property
    def statusword(self) -> int:
        return self.sm.statusword

    @property
    def position(self) -> int:
        return self.axis.position(self.now)
