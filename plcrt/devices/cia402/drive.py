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

The drive is one class in five modules: this one (construction, the
master's SDO side, the write hook, mode selection, the power and EtherCAT
state machines, the stages of a bus cycle), :mod:`.drive_time` (the time
line: events in exact µs, :class:`~.drive_time.Timeline`),
:mod:`.drive_io` (process data in and out, the drive's own objects,
:class:`~.drive_io.ProcessData`), :mod:`.drive_csp` (the steady CSP cycle
and a SYNC's hold written out, :class:`~.drive_csp.CspCycle`) and
:mod:`.drive_service` (the test surface: injected faults, the power cycle,
digital inputs, P18 display values, the touch probe,
:class:`~.drive_service.Service`).

Every refusal and diagnostic goes to :attr:`Drive.log` with its time and the
manual section.

What it is not: no bus.  The canopen port and the PLC coupler call
:meth:`sdo_read`, :meth:`sdo_write` and :meth:`cycle`.
"""

from __future__ import annotations

import copy
from functools import partial
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Optional

from .axis import Axis
from .drive_csp import CspCycle
from .drive_io import (CW, I32_HIGH, I32_LOW, MISSING, MOTION_KEYS, OE, OUTPUTS, STATE_KEYS,
                       ProcessData)
from .drive_service import Service, TouchProbe, cite
from .drive_time import Timeline
from .esm import AlResult, Esm, EsmState
from . import homing_adapter  # noqa: F401  (registers the homing methods)
from .homing_plan import HomingPlan, homing_plans
from .modes import (CyclicPosition, Homing, Mode, NoMode, ProfilePosition, ProfileVelocity,
                    MODE_NAMES)
from .od import ObjectDictionary, SdoAbort
from .pdo import ASSIGN, MapLayout, PdoConfig
from .plant import DrivePlant, plant_of
from .sync import drive_cycle_problem
from .statemachine import Command, Drive402, Result, State
from .states import IDLE_STATUSWORD, STATUSWORD
from .stops import HardStops
from .store import Store, Write

__all__ = ["Drive", "DriveEvent"]

#: Values of objects a model's dictionary lacks: the Kinco note gives no 6080h
#: (no speed limit then), no 60C5h/60C6h (no ramp limit) and no P03.07 (no
#: homing time limit).
_ABSENT = {(0x6080, 0): 0xFFFFFFFF, (0x2003, 7): 0, (0x6099, 5): 0, (0x6099, 6): 0,
           (0x6099, 4): 0, (0x60F9, 10): 0, (0x60C5, 0): 0xFFFFFFFF, (0x60C6, 0): 0xFFFFFFFF}

#: compiled struct codecs cannot be copied: a fork of a drive starts these
#: caches afresh (they are rebuilt on first use)
_FRESH: dict[str, Callable[[], object]] = {
    "_codecs": dict, "_rx_codec": lambda: ((), None), "_csp_codec": lambda: ((), None),
    "_tx_codec": lambda: ((), None)}


@dataclass(frozen=True, slots=True)
class DriveEvent:
    """One entry of the drive's event log."""

    t_us: int
    source: str
    text: str
    section: str

    def __str__(self) -> str:
        return f"t={self.t_us / 1e6:.6f}s [{self.source}] {self.text} ({self.section})"


class Drive(Service, CspCycle, ProcessData, Timeline):
    """One simulated drive of *model* (``hcfa-am0520b``, ``kinco-servo``).

    *plant*: its switches (none by default), a :class:`DrivePlant`, a dict
    or the path of a TOML file (:func:`~.plant.plant_of`); *node_id*: the
    bus address a port gives it; *t_us*: the time it powers up; *homing*: the homing
    methods by 6098h value (default :func:`~.homing_plan.homing_plans`)."""

    def __init__(self, model: str = "hcfa-am0520b", *,
                 plant: DrivePlant | dict[str, Any] | str | Path | None = None,
                 node_id: int = 1, t_us: int = 0,
                 homing: Optional[dict[int, Callable[[], HomingPlan]]] = None) -> None:
        self.model = model
        self.node_id = node_id
        self.od = ObjectDictionary.load(model)
        self.store = Store(self.od)
        self.plant = plant_of(plant)
        #: DI levels set by :meth:`set_input` (DI number -> level), over the plant's
        self.forced_inputs: dict[int, bool] = {}
        self.homing_plans = homing_plans(model) if homing is None else dict(homing)
        self.now = t_us
        self.log: list[DriveEvent] = []
        self.axis = Axis(0)
        self.pdo = PdoConfig(self._lookup, lambda: self.esm.state, self._default_maps(),
                             self._map_layout())
        self._out: dict[tuple[int, int], int] = {}
        self._signed = frozenset((e.index, e.sub) for e in self.od if e.dtype.startswith("I"))
        self._absent = {k: v for k, v in _ABSENT.items() if self.od.find(*k) is None}
        self._own = frozenset((i, 0) for i in OUTPUTS if self.od.find(i, 0) is not None)
        self._codecs: dict[int, tuple] = {}   # id(entries) -> (entries, codec)
        self._batch = False
        self._live = self.store.live          # perf: the store's values, read directly
        self._power_up(t_us)
        self._rx_codec: tuple = ((), None)    # perf: (active_rx, codec) of the last cycle
        self._csp_codec: tuple = ((), None)   # perf: the same for the CSP fast cycle
        self._tx_codec: tuple = ((), None)    # perf: (active_tx, _tx_fast_codec of it)
        self._published: tuple = (None, None)  # perf: the groups publish wrote last
        self.deferred: Optional[tuple[int, ...]] = None   # perf: publish_deferred's values
        self._held_state: Optional[tuple[int, ...]] = None   # perf: a state group in range
        self._fit = False                     # perf: exchange's values fit their types
        # perf: the motion group is six I32 objects of the type's whole range
        # (then its range check is a min and a max)
        self._motion_i32 = all(
            e is not None and e.dtype == "I32" and (e.low, e.high) == (-2**31, 2**31 - 1)
            for e in (self.od.find(*k) for k in MOTION_KEYS))
        # perf: the model has all its own objects and the motion group is I32
        self._plain_motion = self._motion_i32 and len(self._own) == len(OUTPUTS)
        self._motion_out = dict.fromkeys(MOTION_KEYS, 0)   # perf: refilled by publish
        self._state_out = dict.fromkeys(STATE_KEYS, 0)
        self._hook = self._on_write
        self._only_hook = ((), (self._hook,))
        self._hooked_ok: tuple = ()           # perf: store.hooked when last found == _only_hook
        self.store.on_write(self._hook)
        self._mirror()
        self.publish()

    def _power_up(self, t_us: int) -> None:
        """The drive's state at power-up (transitions 0 and 1, ESM INIT, no
        fault, modes idle, the mechanical ends watched afresh): at
        construction and at :meth:`~.drive_service.Service.power_cycle`."""
        self.controlword = int(self.store.get(0x6040))
        self.esm = Esm(self.pdo.activate, check_sync=partial(drive_cycle_problem, self))
        mode = int(self.store.get(0x6060))
        self.sm = Drive402(self.model, t=t_us / 1e6, mode=mode or None)
        self._sm_seen = 0
        self.engines: dict[int, Mode] = {0: NoMode(self), 1: ProfilePosition(self),
                                         3: ProfileVelocity(self), 6: Homing(self),
                                         8: CyclicPosition(self)}
        self.mode_number = mode
        self._qs_wait = False
        self._cache_version = -1
        self._cache: dict[tuple, Optional[int]] = {}
        self._rx_noted = False
        self.stops = HardStops(self) if (self.plant.neg_stop is not None
                                         or self.plant.pos_stop is not None) else None
        self.probe = TouchProbe()

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
        v = self._live.get((index, sub), MISSING)
        if v.__class__ is int:
            return v            # perf: an integer object read without the entry check
        if (index, sub) in self._absent:
            return self._absent[(index, sub)]
        return int(self.store.get(index, sub))

    def note(self, t: int, section: str, text: str, source: str = "") -> None:
        text, section = cite(self.model, text, section)
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
        if self.deferred is not None:
            with self.store.lock:
                self.flush()           # the values held at a SYNC, if a read comes between
        if index in self.pdo.entries:
            return self.od.entry(index, sub).encode(self.pdo.read(index, sub))
        if index == 0x2012:
            with self.store.lock:
                self._display(index, sub)      # P18: computed when read (HCFA §5.1)
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
        if w.pending:
            self._pending_write(w)             # alarm 83 (HCFA §4.7)
        elif index == 0x6040:
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
            # the event without its time and section: the log line prints them once
            what = f"transition {ev.transition}" if ev.transition is not None \
                else "no transition"
            self.note(round(ev.t * 1e6), ev.section,
                      f"#{ev.seq} {what} ({ev.source}): {ev.before} -> {ev.after}, 6041h "
                      f"0x{ev.sw_before:04X} -> 0x{ev.sw_after:04X}"
                      + (f" {ev.note}" if ev.note else ""), "state machine")
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

    def tick(self, t_us: int) -> None:
        """One bus cycle at *t_us* without process data (a CANopen port,
        whose PDOs are not the EtherCAT images): advance, evaluate the held
        controlword, run the mode's cycle."""
        with self.store.lock:
            self._step(t_us, None, None)

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
                if CW in values:
                    self._apply_values(t_us, values[CW],
                                       [kv for kv in values.items() if kv[0] != CW], False)
                else:
                    self._apply_values(t_us, None, values.items(), False)
            sm = self.sm
            if sm.state is not OE:
                # in OE a held level can only hold OE: every other level acted when written
                if sm.cycle_acts():
                    self._do(t_us, sm.cycle(t_us / 1e6))
                elif len(sm.log) != self._sm_seen:
                    self._mirror()   # perf: a held level that changes nothing: no Result
            if sm.state is OE:
                self.engines[self.mode_number].cycle(t_us)   # perf: self.mode, inline
        finally:
            self._batch = False
        self.publish()

    def publish_deferred(self) -> None:
        """:meth:`publish` for a SYNC whose bus cycle follows at once: the
        values are computed now (the statusword's mode bits and the touch
        probe as publish sets them) and held in :attr:`deferred`, in the
        order of OWN_KEYS, for the synchronous TPDOs sampled before the
        cycle; the cycle (:meth:`exchange`) writes its own values, or first
        these (:meth:`flush`) where it takes the general path.  Written at
        once when the model lacks one of its own objects or a value does
        not fit its object (publish's other path)."""
        self._hold(*self._outputs())

    def _hold(self, motion: tuple[int, ...], state: tuple[int, ...]) -> None:
        """Hold *motion* and *state* (:meth:`_outputs`) as :meth:`publish_deferred` does."""
        # perf: the SYNC's two publishes (at the SYNC, after the cycle's
        # set-points) write the store once; a group equal to the one written
        # last was checked when written
        last_motion, last_state = self._published
        store = self.store
        if len(self._own) == len(OUTPUTS) \
                and (motion == last_motion
                     or (I32_LOW <= min(motion) and max(motion) <= I32_HIGH
                         if self._motion_i32 else store.fits_group(MOTION_KEYS, motion))) \
                and (state == last_state or state == self._held_state
                     or store.fits_group(STATE_KEYS, state)):
            self._held_state = state   # perf: found in range: the same state is again
            self.deferred = motion + state
        else:
            self._publish_values(motion, state)

    def flush(self) -> None:
        """Write the values :meth:`publish_deferred` holds, if any."""
        held = self.deferred
        if held is not None:
            self.deferred = None
            self._publish_values(held[:6], held[6:])

    @property
    def statusword(self) -> int:
        return self.sm.statusword

    @property
    def position(self) -> int:
        return self.axis.position(self.now)
