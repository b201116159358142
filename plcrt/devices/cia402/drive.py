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
from dataclasses import dataclass, fields
from operator import itemgetter
from typing import Callable, Iterable, Optional

from ...errors import PlcError
from ..motion import US
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
from .store import Store, Write, key

__all__ = ["Drive", "DriveEvent"]

_OUTPUTS = (0x6041, 0x6061, 0x6062, 0x6064, 0x606C, 0x603F, 0x1001, 0x60F4, 0x60FD)
_OUTPUT_KEYS = tuple(key(i, 0) for i in _OUTPUTS)
_MOTION_KEYS = _K6062, _K6064, _K606C, _K60F4 = tuple(
    key(i, 0) for i in (0x6062, 0x6064, 0x606C, 0x60F4))
_STATE_KEYS = _K6041, _K6061, _K603F, _K1001, _K60FD = tuple(
    key(i, 0) for i in (0x6041, 0x6061, 0x603F, 0x1001, 0x60FD))
#: Values of objects a model's dictionary lacks: the Kinco note gives no 6080h
#: (no speed limit then) and no P03.07 (no homing time limit).
_ABSENT = {(0x6080, 0): 0xFFFFFFFF, (0x2003, 7): 0, (0x6099, 5): 0, (0x6099, 6): 0,
           (0x6099, 4): 0, (0x60F9, 10): 0}
_MAX_EVENTS = 100_000  # per advance: a homing plan that never moves on is an error
#: Objects whose write the drive's hook acts on whatever the mode (6040h
#: controlword, 6060h mode, 605Ah/6084h/6085h read by the state machine).
_HOOK_INDEXES = frozenset({0x6040, 0x6060, 0x605A, 0x6084, 0x6085})
_CW = key(0x6040, 0)
# perf: enum members as module constants (a class attribute of an Enum costs
# ten times a global on Python 3.11, EnumType.__getattr__)
_OE = State.OPERATION_ENABLED
_ESM_OP = EsmState.OP
_MISSING = object()
#: Objects the CSP cycle reads besides 607Ah (HCFA §7.5.1): a received one
#: that changes takes the general cycle.
_CSP_READS = frozenset({(0x6065, 0), (0x6066, 0), (0x6080, 0), (0x1C32, 2)})
_K6065, _K607A, _K6080 = key(0x6065, 0), key(0x607A, 0), key(0x6080, 0)
_B10, _B12 = 0x400, 0x1000     # 6041h: target reached, set-point followed (HCFA §7.5.1)
# perf: a DrivePlant with these fields only reads 60FDh from its switches
# (plant.py as written with this module); other fields turn the shortcut off
_PLAIN_PLANT = {f.name for f in fields(DrivePlant)} == {
    "neg_limit", "pos_limit", "home_switch", "index_period", "index_phase",
    "neg_stop", "pos_stop"}


#: compiled struct codecs cannot be copied: a fork of a drive starts these
#: caches afresh (they are rebuilt on first use)
_FRESH: dict[str, Callable[[], object]] = {
    "_codecs": dict, "_rx_codec": lambda: ((), None), "_csp_codec": lambda: ((), None),
    "_tx_codec": lambda: ((), None)}


def _picker(at: list) -> Callable[[object], tuple]:
    """itemgetter(*at), giving a tuple also for one or no item."""
    if len(at) > 1:
        return itemgetter(*at)
    if at:
        return lambda values, one=at[0]: (values[one],)
    return lambda values: ()


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
        self._live = self.store.live          # perf: the store's values, read directly
        self._rx_codec: tuple = ((), None)    # perf: (active_rx, codec) of the last cycle
        self._csp_codec: tuple = ((), None)   # perf: the same for the CSP fast cycle
        self._tx_codec: tuple = ((), None)    # perf: (active_tx, _tx_fast_codec of it)
        self._published: tuple = (None, None)  # perf: the groups publish wrote last
        self._motion_out = dict.fromkeys(_MOTION_KEYS, 0)   # perf: refilled by publish
        self._state_out = dict.fromkeys(_STATE_KEYS, 0)
        self._hook = self._on_write
        self._only_hook = ((), (self._hook,))
        self._hooked_ok: tuple = ()           # perf: store.hooked when last found == _only_hook
        self.store.on_write(self._hook)
        self._mirror()
        self.publish()

    def __deepcopy__(self, memo: dict) -> "Drive":
        # a fork of a PLC copies its drives; compiled struct codecs are not
        # copyable and are rebuilt on first use, the dictionary is shared
        new = object.__new__(type(self))
        memo[id(self)] = new
        memo.setdefault(id(self.od), self.od)
        for name, value in self.__dict__.items():
            new.__dict__[name] = _FRESH[name]() if name in _FRESH else copy.deepcopy(value, memo)
        return new

    # ---------------------------------------------------------------- helpers
    @property
    def mode(self) -> Mode:
        return self.engines[self.mode_number]

    def param(self, index: int, sub: int = 0) -> int:
        """The active value of an object the drive acts on (an object the
        model lacks reads as its entry in ``_ABSENT``)."""
        v = self._live.get((index, sub), _MISSING)
        if v.__class__ is int:
            return v            # perf: an integer object read without the entry check
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
    def _eventless(self) -> bool:
        """No event can come, whatever the time: no homing (its time limit),
        and the axis at rest, or on a CSP line with no switch to watch and
        no quick stop waiting for its end (:meth:`_next_event` would find none)."""
        legs = self.axis.legs
        return self.mode_number != 6 and self.stops is None and (not legs or (
            not self._qs_wait and legs[-1].__class__ is LinLeg
            and self.plant.pos_limit is None and self.plant.neg_limit is None))

    def _next_event(self, t_to: int) -> Optional[tuple[int, str, object]]:
        if self._eventless():
            return None       # perf: the search below would find nothing
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
        with self.store.lock:          # a canopen port writes from its Notifier thread
            self._advance(t_us)

    def _advance(self, t_us: int) -> None:
        if t_us < self.now:
            raise PlcError(f"drive time cannot go back: now {self.now} µs, asked {t_us} µs")
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

    def tick(self, t_us: int) -> None:
        """One bus cycle at *t_us* without process data (a CANopen port,
        whose PDOs are not the EtherCAT images): advance, evaluate the held
        controlword, run the mode's cycle."""
        with self.store.lock:
            self._step(t_us, None, None)

    def _csp_fast(self, t: int, rx: Optional[bytes],
                  values: Optional[dict[tuple[int, int], int]]) -> bool:
        """The bus cycle of a drive following CSP set-points, written out:
        what :meth:`_step` does (advance, received objects, the mode's
        cycle, publish) when no event can come, no object the drive acts on
        changes (6040h held; no 6060h, 605Ah, 6084h, 6085h, 6065h, 6066h,
        6080h, 1C32h), no switch is configured and the following error lies
        within 6065h.  Returns False, having done nothing, otherwise."""
        # perf: the steady CSP cycle in one function: no stage calls, no
        # Result, no Write, only the values that change written
        sm = self.sm
        if (sm.state is not _OE or self.mode_number != 8 or self._qs_wait or t < self.now
                or self.esm.state is not _ESM_OP):
            return False
        hooked = self.store.hooked
        if hooked is not self._hooked_ok:
            if hooked != self._only_hook:
                return False
            self._hooked_ok = hooked        # perf: the same subscriptions, seen before
        plant = self.plant
        if plant.pos_limit is not None or plant.neg_limit is not None or self.stops is not None:
            return False
        ax = self.axis
        if ax._line is None and ax.legs:
            return False
        csp = self.engines[8]
        if csp.__class__ is not CyclicPosition or csp._last is None:
            return False
        live = self._live
        window, v_max = live.get(_K6065), live.get(_K6080)
        if window.__class__ is not int or v_max.__class__ is not int:
            return False
        mech = ax.mechanical(t)
        pos = mech + ax.shift
        fe = csp.demand - pos
        if fe > window or -fe > window:
            return False
        known = rx is not None
        if known:
            rx_map = self.pdo.active_rx
            codec = self._csp_codec
            if codec[0] is not rx_map:
                codec = self._csp_codec = (rx_map, self._csp_rx_codec(rx_map))
            codec = codec[1]
            if codec is None or len(rx) != codec[0]:
                return False
            _, objects, keys, cw_st, at = codec
            if cw_st is not None and cw_st.unpack_from(rx, at)[0] != self.controlword:
                return False
            changed = []
            for kv in zip(keys, objects.unpack(rx)):
                if live[kv[0]] != kv[1]:
                    changed.append(kv)
        else:
            changed = []
            for kv in values.items():                       # type: ignore[union-attr]
                key, v = kv
                if key == _CW:
                    if v != self.controlword:
                        return False
                    continue
                cur = live.get(key, _MISSING)
                if not cur == v:
                    if cur is _MISSING or key[0] in _HOOK_INDEXES or key in _CSP_READS:
                        return False
                    changed.append(kv)
        # from here on as _step: the time, then the objects (no hook acts on them)
        self.now = t
        store = self.store
        for key, v in changed:
            if known:
                store.set_known(key, v)
            else:
                store.set(key[0], key[1], v)
        # CyclicPosition.cycle with no switch and the following error within 6065h
        csp.following_error = fe
        csp._fe_since = None
        period = t - csp._last
        csp._last = t
        target = live.get(_K607A)
        if target.__class__ is not int:
            target = self.param(0x607A)
        csp.limit_stop = False
        ax.linear(t, t + (period if period > 1 else 1), target, v_max, mech)
        csp.demand = target
        # publish(): CyclicPosition.bits (no limit stop, no following error
        # beyond 6065h); the line, if any, starts at t, so the count there is
        # still mech; moving(t) and velocity(t) of that line written out
        line = ax._line
        if line is None:
            bits, vel = _B12 | _B10, 0
        else:
            num, den = (line.x1 - line.x0) * US, line.t1 - line.t0
            bits, vel = _B12, num // den if num >= 0 else -(-num // den)
        sm.set_mode_bits(bits)
        # a plant without switches gives 60FDh = 0 wherever the axis is
        inputs = 0 if _PLAIN_PLANT and plant.__class__ is DrivePlant \
            and plant.home_switch is None else plant.inputs(mech)
        self._publish_values((target, pos, vel, fe),
                             (sm.statusword, 8, sm.error_code, sm.error_register, inputs))
        return True

    def _csp_rx_codec(self, entries: tuple) -> Optional[tuple]:
        """:meth:`_rx_fast_codec` for :meth:`_csp_fast`: None when the map
        holds an object the drive acts on besides 6040h and 607Ah."""
        codec = self._rx_fast_codec(entries)
        if codec is None or any(k[0] in _HOOK_INDEXES or k in _CSP_READS for k in codec[2]):
            return None
        return codec

    def _step(self, t_us: int, rx: Optional[bytes],
              values: Optional[dict[tuple[int, int], int]]) -> None:
        """One bus cycle (the caller holds the store's lock), the received
        process data as an image *rx* or by object *values*."""
        self._batch = True
        try:
            if t_us >= self.now and self._eventless():
                self.now = t_us   # perf: what _advance does when no event can come
            else:
                self._advance(t_us)   # the lock is held: advance without taking it again
            if rx is not None:
                self._apply_rx(t_us, rx)
            elif values is not None:
                if _CW in values:
                    self._apply_values(t_us, values[_CW],
                                       [kv for kv in values.items() if kv[0] != _CW], False)
                else:
                    self._apply_values(t_us, None, values.items(), False)
            sm = self.sm
            if sm.state is not _OE:
                # in OE a held level can only hold OE: every other level acted when written
                if sm.cycle_acts():
                    self._do(t_us, sm.cycle(t_us / 1e6))
                elif len(sm.log) != self._sm_seen:
                    self._mirror()   # perf: a held level that changes nothing: no Result
            if sm.state is _OE:
                self.engines[self.mode_number].cycle(t_us)   # perf: self.mode, inline
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
        if len(self._own) == len(_OUTPUTS):
            # perf: the own objects from the values publish wrote last (the
            # motion and state groups, kept equal to _out), the others from
            # the store: one tuple, picked by position without hashing keys
            own = _MOTION_KEYS + _STATE_KEYS
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
            elif k == _CW:
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

    def exchange(self, t_us: int, values: dict[tuple[int, int], int]) -> None:
        """One bus cycle at *t_us* whose received process data are given
        by object, ``{(index, sub): value}``, instead of as a packed RxPDO
        image: the path of a master module that owns its mapping (the PLC
        coupler).  The objects act as from an RxPDO (in OP only, objects
        before 6040h); the caller reads what it transmits from
        :attr:`store`."""
        with self.store.lock:
            if not self._csp_fast(t_us, None, values):
                self._step(t_us, None, values)   # the same cycle as cycle()

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
        cw = values.pop(_CW, None)
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
            if live.get(key, _MISSING) == v:
                continue        # perf: an unchanged object: no store write, no hook
            if key[0] in _HOOK_INDEXES or not (
                    # perf: no Write and no hook dispatch for a value nobody
                    # acts on: the drive's own hook is the only one and does
                    # nothing with this object now (outside OPERATION
                    # ENABLED, or a mode without parameter(); inside a
                    # cycle, which publishes once at its end)
                    store.hooked == self._only_hook
                    and (self.sm.state is not _OE
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
        t = self.now
        ax, sm = self.axis, self.sm
        if sm.state is _OE:
            bits = self.engines[self.mode_number].bits(t)    # perf: self.mode, inline
            if bits is not None:
                sm.set_mode_bits(bits)
        mech = ax.mechanical(t)
        pos = mech + ax.shift                      # axis.position(t)
        if self.mode_number == 8:
            csp = self.engines[8]
            assert isinstance(csp, CyclicPosition)
            fe = csp.following_error
            demand = csp.demand if sm.state is _OE else pos
        else:
            fe, demand = 0, pos
        if self.stops is not None and self.mode_number != 8:
            demand = ax.demand_position(t)      # past a mechanical end (stops.py)
            fe = demand - pos
        self._publish_values(
            (demand, pos, ax.velocity(t), fe),
            (sm.statusword, self.mode_number, sm.error_code, sm.error_register,
             self.plant.inputs(mech)))

    def _publish_values(self, motion: tuple[int, int, int, int],
                        state: tuple[int, int, int, int, int]) -> None:
        """Write the drive's own objects: *motion* = 6062h, 6064h, 606Ch,
        60F4h and *state* = 6041h, 6061h, 603Fh, 1001h, 60FDh."""
        # perf: two groups, each written only when one of its values changed
        # (the motion values change every cycle of a move, the state values
        # seldom); a group is written whole, unchanged values as they are
        last_motion, last_state = self._published
        new_motion, new_state = motion != last_motion, state != last_state
        if not (new_motion or new_state):
            return
        store, out = self.store, self._out
        if len(self._own) == len(_OUTPUTS) \
                and (not new_motion or store.fits_group(_MOTION_KEYS, motion)) \
                and (not new_state or store.fits_group(_STATE_KEYS, state)):
            # perf: each group's dict is kept and refilled, then merged whole
            if new_motion:
                group = self._motion_out
                group[_K6062], group[_K6064], group[_K606C], group[_K60F4] = motion
                store.set_status_group(group)
                out.update(group)
            if new_state:
                group = self._state_out
                group[_K6041], group[_K6061], group[_K603F], group[_K1001], group[_K60FD] = state
                store.set_status_group(group)
                out.update(group)
        else:
            # each changed value in the order of _OUTPUTS, up to one out of range
            values = (state[0], state[1], motion[0], motion[1], motion[2], state[2], state[3],
                      motion[3], state[4])
            own = self._own
            changed = {key: v for key, v in zip(_OUTPUT_KEYS, values)
                       if out.get(key) != v and key in own}
            if changed:
                store.set_status(changed)
                out.update(changed)
        self._published = (motion, state)

    @property
    def statusword(self) -> int:
        return self.sm.statusword

    @property
    def position(self) -> int:
        return self.axis.position(self.now)
