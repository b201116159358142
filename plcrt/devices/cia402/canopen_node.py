"""A simulated CiA 402 drive on a CANopen bus.

What it is: :class:`CanopenDrive`, which puts a :class:`~.drive.Drive` on a
connected ``canopen.Network`` (python-can's ``virtual`` bus, or ``vcan``) so
that any CANopen master -- canopen's own ``RemoteNode`` / ``BaseNode402`` --
drives it with SDOs, PDOs, SYNC, NMT, heartbeat and EMCY; or on plcrt's
in-process bus (:mod:`.can_bus`).

* SDO: the drive answers every request itself (:class:`~.sdo_server.SdoServer`
  over :meth:`Drive.sdo_read` / :meth:`Drive.sdo_write` and the CAN objects of
  the port): a subindex an object lacks is 0x06090011, an object the drive
  lacks 0x06020000, a block transfer 0x05040001.  canopen's ``LocalNode`` keeps
  only NMT and the heartbeat.  plcrt's :class:`~.od.SdoAbort` keeps its code and
  its explanation goes to the ``plcrt.cia402.canopen`` logger (INFO); any other
  exception is logged with its traceback and aborts 0x08000000.
* PDOs (:mod:`.can_pdo`): the drive sends and receives its PDOs itself, by
  their present mapping and communication parameters; a master remaps them
  with SDO (canopen's ``pdo.save()``).  The CAN view (:func:`can_view`) gives
  one TPDO (6041h, 6064h, 6061h; event-driven, event timer 2 ms) and one RPDO
  (6040h, 607Ah, 6060h; event-driven) at numbers the model's own mapping
  objects leave free, plus 1005h (COB-ID SYNC) and 1006h (communication cycle
  period).  A master sees them with ``object_dictionary(model, node_id)``.
* SYNC: synchronous TPDOs are sampled and synchronous RPDOs take effect at each
  SYNC; with ``clock="sync"`` each SYNC is also one bus cycle of the drive, of
  1006h µs (the drive's own bus period while 1006h = 0), so CSP interpolates
  over the real bus cycle.  HCFA §7.4.3 (200 µs–10 ms) bounds 1006h.
* NMT: PRE-OPERATIONAL, OPERATIONAL and STOPPED map onto the drive's EtherCAT
  communication state (PRE-OP, OP, SAFE-OP, digest §7.1); PDOs act in
  OPERATIONAL only, EMCY is sent in PRE-OPERATIONAL and OPERATIONAL (CiA 301
  §7.3.2.2 Table 36).  Heartbeat producer 1017h (50 ms in the CAN view).
* EMCY (:mod:`.emcy`): on a fault the CiA 301/402 code of 603Fh with 1001h;
  on the reset, 0000h.  A master sees them in ``node.emcy``.
* The bus: a 29-bit frame whose identifier is one the drive listens on is not
  a CANopen message for it (CiA 301 uses 11-bit identifiers): the port drops it
  before canopen's dispatch, which does not look at the frame format.
* Time: ``clock="wall"`` (default) -- a background thread runs one bus cycle
  per bus period (1C32h:02, 1 ms); ``"manual"`` -- time moves only by
  :meth:`CanopenDrive.advance`; ``"step"`` -- each SDO read of 6041h first runs
  one bus cycle; ``"sync"`` -- each SYNC received runs one bus cycle.
* Caveat 6 (``homing()`` judges 6041h at once): the drive publishes 6041h
  inside the SDO write of 6040h.  Caveat 1 (``setup_402_state_machine`` on a
  fresh node): the node boots to PRE-OPERATIONAL, sends its boot-up message and
  its heartbeat, so a master learns the state within one heartbeat.

What it is not: no remote frames (RTR), no SDO block transfer, no SYNC
producer.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any, Literal, Optional

import can
import canopen
from canopen.nmt import NmtSlave
from canopen.objectdictionary import ODVariable

from ...engine.values import Duration, duration_us, shown_value, step_count
from ...errors import PlcConfigError
from .can_pdo import SYNCED, CanPdos, Channel
from .can_view import SYNC_ID, can_view, pdo_slots, view_channels
from .canopen_od import object_dictionary
from .drive import Drive
from .emcy import emcy_code, emcy_frame
from .esm import EsmState
from .od import SdoAbort
from .plant import DrivePlant
from .sdo_server import SdoServer
from .sync import can_cycle_problem

__all__ = ["CanopenDrive", "Clock", "can_view", "pdo_slots"]

log = logging.getLogger("plcrt.cia402.canopen")

Clock = Literal["wall", "manual", "step", "sync"]
CLOCKS = ("wall", "manual", "step", "sync")

#: NMT state code (CiA 301 §7.2.8.3.2.1) -> the drive's communication state.
#: Decision (docs/cia402.md "A real CANopen master"): PRE-OPERATIONAL has
#: the mailbox only (PRE-OP), OPERATIONAL has outputs (OP), STOPPED keeps
#: inputs without outputs (SAFE-OP), so the drive leaves OPERATION ENABLED.
_NMT_TO_ESM = {127: (EsmState.PREOP,), 5: (EsmState.SAFEOP, EsmState.OP),
               4: (EsmState.SAFEOP,)}


class _Nmt(NmtSlave):
    """canopen's NMT slave that tells the drive port of each state change."""

    def __init__(self, node_id: int, local_node: Any, port: "CanopenDrive") -> None:
        super().__init__(node_id, local_node)
        self._port = port

    def on_command(self, can_id: int, data: bytes, timestamp: float) -> None:
        super().on_command(can_id, data, timestamp)
        self._port._nmt_changed(self._state)

    def send_command(self, code: int) -> None:
        super().send_command(code)
        self._port._nmt_changed(self._state)


class _Frames(can.Listener):
    """The network's dispatcher behind a filter: 29-bit frames whose
    identifier a drive port listens on are dropped (canopen dispatches by
    identifier alone).  One per network, shared by its drive ports."""

    def __init__(self, inner: Any) -> None:
        self.inner = inner
        self.ports: list["CanopenDrive"] = []

    @property
    def passes_base_frames_to(self) -> Any:
        """The listener an 11-bit frame goes to unchanged (can_bus.py's
        LocalNetwork hands such frames to the network itself)."""
        return self.inner

    def on_message_received(self, msg: can.Message) -> None:
        if msg.is_extended_id:
            for port in self.ports:
                if msg.arbitration_id in port._ids:
                    port._once("ext", "CiA 301 §7.2.1", f"29-bit frame 0x{msg.arbitration_id:X}"
                               " dropped: the node uses 11-bit identifiers")
                    return
        self.inner.on_message_received(msg)

    def stop(self) -> None:
        self.inner.stop()


class CanopenDrive:
    """A :class:`Drive` of *model* as node *node_id* on *network*.

    Attributes: ``drive`` (the model), ``node`` (the ``canopen.LocalNode``:
    NMT and heartbeat), ``pdos`` (:class:`~.can_pdo.CanPdos`), ``clock``.
    Use :func:`plcrt.cia402.attach` rather than this class."""

    def __init__(self, network: Any, node_id: int, model: str = "hcfa-am0520b",
                 plant: Optional[DrivePlant] = None, *, clock: Clock = "wall",
                 od: Any = None) -> None:
        if not isinstance(clock, str) or clock not in CLOCKS:
            raise PlcConfigError(f"cia402.attach: clock={shown_value(clock)}; expected one of "
                                 + ", ".join(CLOCKS))
        if not isinstance(node_id, int) or isinstance(node_id, bool) or not 1 <= node_id <= 127:
            raise PlcConfigError(f"cia402.attach: node id {shown_value(node_id)} is not a "
                                 f"CANopen node id "
                                 "(1..127, CiA 301 §7.5.2.4)")
        if not isinstance(network, canopen.Network):
            raise PlcConfigError(f"cia402.attach: {type(network).__name__} is not a "
                                 "canopen.Network")
        if network.bus is None:
            raise PlcConfigError("cia402.attach: the canopen.Network is not connected "
                                 "(call network.connect(interface='virtual', channel=...) first)")
        if plant is not None and not isinstance(plant, DrivePlant):
            raise PlcConfigError(f"cia402.attach: plant= is a DrivePlant or None, got "
                                 f"{type(plant).__name__}")
        if od is not None and not isinstance(od, canopen.ObjectDictionary):
            raise PlcConfigError(f"cia402.attach: od= is a canopen.ObjectDictionary or None, "
                                 f"got {type(od).__name__}")
        if node_id in network:
            raise PlcConfigError(f"cia402.attach: node {node_id} is already on the network")
        self.clock: Clock = clock
        self.drive = Drive(model, plant=plant, node_id=node_id)
        self.period_us = self.drive.bus_period_us()
        self._lock = self.drive.store.lock
        self._t0 = time.monotonic()
        codod = od if od is not None else object_dictionary(model)
        self.tpdo_no, self.rpdo_no = pdo_slots(codod)
        can_view(codod, node_id)
        self.codod = codod
        self.pdos = CanPdos(self.drive, view_channels(codod, self.tpdo_no, self.rpdo_no))
        self.node = canopen.LocalNode(node_id, codod)
        self.node._write_callbacks.clear()          # canopen's own 1017h hook belongs to .nmt
        self.node.nmt = _Nmt(node_id, self.node, self)
        self.node.add_write_callback(self.node.nmt.on_write)
        self.network = network
        self._noted: set[str] = set()
        self._emcy_code = 0                         # 603Fh as last sent in an EMCY
        self._cycle_us = 0                          # 1006h
        self.sdo = SdoServer(self._sdo_read, self._sdo_write,
                             lambda e: log.info("node %d: %s", node_id, e))
        network.create_node(self.node)
        network.unsubscribe(0x600 + node_id, self.node.sdo.on_request)
        self._sync_id = SYNC_ID
        self._subs: list[tuple[int, Any]] = []
        self._subscribe()
        frames = next((f for f in network.notifier.listeners if isinstance(f, _Frames)), None)
        if frames is None:
            listeners = network.notifier.listeners
            k = next(i for i, f in enumerate(listeners)
                     if isinstance(f, canopen.network.MessageListener))
            frames = listeners[k] = _Frames(listeners[k])
        frames.ports.append(self)
        self._frames = frames
        self.drive.request_esm(EsmState.PREOP)
        self.node.nmt.send_command(0x81)            # reset: boot-up message
        self.node.nmt.send_command(0x80)            # to PRE-OPERATIONAL, heartbeat per 1017h
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None
        if clock == "wall":
            self._thread = threading.Thread(target=self._run, daemon=True,
                                            name=f"plcrt-cia402-node{node_id}")
            self._thread.start()

    # ---------------------------------------------------------------- bus
    def _subscribe(self) -> None:
        """Listen on the SDO, SYNC and valid RPDO identifiers (again after a
        COB-ID changed)."""
        for can_id, cb in self._subs:
            self.network.unsubscribe(can_id, cb)
        node = self.drive.node_id
        self._subs = [(0x600 + node, self._on_sdo), (self._sync_id, self._on_sync)]
        self._subs += [(can_id, self._on_rpdo) for can_id in self.pdos.rx_by_id]
        for can_id, cb in self._subs:
            self.network.subscribe(can_id, cb)
        self._ids = frozenset(c for c, _ in self._subs) | {0}

    def _send(self, can_id: int, data: bytes) -> None:
        try:
            self.network.send_message(can_id, data)
        except Exception:                          # the bus went away: the drive goes on
            self._once(f"send{can_id}", "CiA 301", f"frame 0x{can_id:X} not sent")

    def _once(self, key: str, section: str, text: str) -> None:
        if key not in self._noted:
            self._noted.add(key)
            self.drive.note(self.drive.now, section, text, "CAN")

    # ---------------------------------------------------------------- time
    def advance(self, seconds: Duration) -> None:
        """Run the drive *seconds* further (a duration: ``0.5``, ``"200ms"``),
        one bus cycle at a time (``clock="manual"``, ``"step"`` or ``"sync"``;
        in wall-clock mode time follows the wall clock and this raises).

        Raises:
            PlcConfigError: wall-clock mode, not a duration, a negative one,
                or more than :data:`~plcrt.engine.values.MAX_STEPS` bus
                cycles in one call.
        """
        if self.clock == "wall":
            raise PlcConfigError("cia402: advance() needs clock='manual', 'step' or 'sync'; "
                                 "this drive follows the wall clock")
        what = "cia402: advance()"
        if isinstance(seconds, (int, float)) and not isinstance(seconds, bool) and seconds < 0:
            raise PlcConfigError(f"{what}: {shown_value(seconds)} s cannot go back in time")
        span = duration_us(seconds, what)
        step_count(span, self.period_us, seconds, what, "bus cycle")
        with self._lock:
            end = self.drive.now + span
            while self.drive.now < end:
                self._cycle(min(end, self._next_boundary()))

    def _next_boundary(self) -> int:
        p = self.period_us
        return (self.drive.now // p + 1) * p

    def _cycle(self, t: int) -> None:
        """One bus cycle of the drive at *t* (the lock held), then the
        event-driven TPDOs and the EMCY it brings."""
        self.drive.tick(t)
        self._after()

    def _after(self) -> None:
        for can_id, data in self.pdos.events(self.drive.now):
            self._send(can_id, data)
        self._check_emcy()

    def _catch_up(self) -> None:
        """Wall clock: run the bus cycles up to the present."""
        t = int((time.monotonic() - self._t0) * 1e6)
        while self._next_boundary() <= t:
            self._cycle(self._next_boundary())

    def _run(self) -> None:
        period = self.period_us / 1e6
        while not self._stop.wait(period):
            try:
                with self._lock:
                    self._catch_up()
            except Exception:                        # keep the bus alive, say why
                log.exception("node %d: drive cycle failed", self.drive.node_id)
                return

    def close(self) -> None:
        """Stop the clock thread and the heartbeat; take the node off the network."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
        self.node.nmt.stop_heartbeat()
        for can_id, cb in self._subs:
            self.network.unsubscribe(can_id, cb)
        self._subs = []
        if self in self._frames.ports:
            self._frames.ports.remove(self)
        if self.node.id in self.network:
            # canopen's remove_network unsubscribes the LocalNode's SDO server
            self.network.subscribe(self.node.sdo.rx_cobid, self.node.sdo.on_request)
            del self.network[self.node.id]

    # ---------------------------------------------------------------- SDO server
    def _on_sdo(self, can_id: int, data: bytes, timestamp: float) -> None:
        node = self.drive.node_id
        if self.node.nmt.state == "STOPPED":     # CiA 301 §7.3.2.2 Table 36: no SDO
            self._once("sdo-stopped", "CiA 301 §7.3.2.2", "SDO request not answered in NMT "
                       "STOPPED")
            return
        with self._lock:
            if self.clock == "wall":
                self._catch_up()
            try:
                answer = self.sdo.request(bytes(data))
            except Exception:
                log.exception("node %d: SDO request failed", node)
                answer = self.sdo.abort(0x08000000)
            if answer is None and len(data) != 8:
                self._once("sdo-dlc", "CiA 301 §7.2.4.3",
                           f"SDO request of {len(data)} bytes not answered: SDO frames "
                           "have 8 data bytes")
            self._after()
        if answer is not None:
            self._send(0x580 + node, answer)

    def _port_object(self, index: int, sub: int) -> Any:
        """The CAN view's variable of a port object (1005h, 1006h, 1017h)."""
        obj = self.codod.get(index) if index in self.codod else None
        if obj is None:
            raise SdoAbort(0x06020000, f"{index:04X}h is not in the drive's object "
                           f"dictionary ({self.drive.od.info.get('layout', '')})")
        if not isinstance(obj, ODVariable) or sub != 0:
            raise SdoAbort(0x06090011, f"{index:04X}h has no subindex {sub:02X}h")
        return obj

    def _sdo_read(self, index: int, sub: int) -> bytes:
        drive = self.drive
        if drive.od.find(index, 0) is not None:
            if self.clock == "step" and index == 0x6041:
                self._cycle(self._next_boundary())
            return drive.sdo_read(index, sub)
        if self.pdos.owns(index):
            bits = self.pdos.bits(index, sub)
            if bits is None:
                raise SdoAbort(0x06090011, f"{index:04X}h has no subindex {sub:02X}h "
                               "(CiA 301 §7.5.2.35–38)")
            return self.pdos.read(index, sub).to_bytes(bits // 8, "little")
        self._port_object(index, sub)
        return self.node.get_data(index, sub, check_readable=True)

    def _sdo_write(self, index: int, sub: int, data: bytes) -> None:
        drive = self.drive
        if drive.od.find(index, 0) is not None:
            drive.sdo_write(index, sub, data)
            return
        if self.pdos.owns(index):
            bits = self.pdos.bits(index, sub)
            if bits is None:
                raise SdoAbort(0x06090011, f"{index:04X}h has no subindex {sub:02X}h "
                               "(CiA 301 §7.5.2.35–38)")
            if len(data) != bits // 8:
                raise SdoAbort(0x06070010, f"{index:04X}h:{sub:02X} takes {bits // 8} bytes, "
                               f"got {len(data)}")
            text = self.pdos.write(index, sub, int.from_bytes(data, "little"))
            log.info("node %d: %s", drive.node_id, text)
            if index in self.pdos.by_com and sub == 1:
                self._subscribe()
            return
        obj = self._port_object(index, sub)
        if len(data) * 8 != len(obj):
            raise SdoAbort(0x06070010, f"{index:04X}h takes {len(obj) // 8} bytes, "
                           f"got {len(data)}")
        value = int.from_bytes(data, "little")
        if index == 0x1005:
            self._write_sync_id(value)
        elif index == 0x1006:
            self._check_cycle(value)
        self.node.set_data(index, sub, data, check_writable=True)
        if index == 0x1006:
            self._cycle_us = value              # perf: read at every SYNC

    def _write_sync_id(self, value: int) -> None:
        if value & (1 << 30) or value & (1 << 29) or value & 0x7FF == 0:
            raise SdoAbort(0x06090030, f"1005h := 0x{value:08X}: the drive is a SYNC consumer "
                           "with an 11-bit COB-ID (CiA 301 §7.5.2.5: bit 30 = producer, "
                           "bit 29 = 29-bit)")
        self._sync_id = value & 0x7FF
        self._subscribe()

    def _check_cycle(self, us: int) -> None:
        why = can_cycle_problem(self.drive.model, us)
        if why is not None:
            raise SdoAbort(0x06090030, why)

    def _sync_period_us(self) -> int:
        """The bus cycle a SYNC stands for: 1006h, or the drive's bus period."""
        return self._cycle_us or self.period_us

    # ---------------------------------------------------------------- PDOs, SYNC
    def _on_sync(self, can_id: int, data: bytes, timestamp: float) -> None:
        """A SYNC (CiA 301 §7.2.5): sample the synchronous TPDOs, then apply
        the synchronous RPDOs in a bus cycle of the drive."""
        if len(data) > 1:
            self._once("sync-dlc", "CiA 301 §7.2.5.3", f"SYNC of {len(data)} bytes ignored")
            return
        frames: list = []
        try:
            with self._lock:
                drive, pdos, clock = self.drive, self.pdos, self.clock
                if clock == "sync":
                    t = drive.now + (self._cycle_us or self.period_us)   # perf: _sync_period_us
                    # perf: the objects at the SYNC held for its TPDOs, not
                    # written: exchange() below writes the cycle's (the
                    # lock is held: the drive's _locked forms)
                    drive.hold_locked(t)
                elif clock == "wall":
                    self._catch_up()
                t = drive.now
                frames, values = pdos.on_sync(t, drive.deferred)
                if values or clock == "sync":
                    if (0x6060, 0) in values:
                        values = self._rx_values(values)
                    drive.exchange_locked(t, values, True)   # decoded by the RPDOs' maps
                if pdos.event_tx:                  # perf: no event-driven TPDO, no search
                    frames += pdos.events(t)
                if drive.sm.error_code != self._emcy_code:   # perf: _check_emcy's test
                    self._check_emcy()
        except Exception:
            log.exception("node %d: SYNC failed", self.drive.node_id)
            self.drive.flush()
        send = self.network.send_message
        for can_id, data in frames:
            try:
                send(can_id, data)                 # perf: _send inline
            except Exception:                      # the bus went away: the drive goes on
                self._once(f"send{can_id}", "CiA 301", f"frame 0x{can_id:X} not sent")

    @staticmethod
    def _rx_values(values: dict) -> dict:
        # digest §7.2 caveat 5: 6060h = 0 in an RPDO keeps the mode
        if values.get((0x6060, 0), 1) == 0:
            del values[(0x6060, 0)]
        return values

    def _on_rpdo(self, can_id: int, data: bytes, timestamp: float) -> None:
        """An RPDO: buffered for the next SYNC (synchronous types) or written
        to the drive at once, 6040h last (event-driven types)."""
        pdos = self.pdos
        ch: Optional[Channel] = pdos.rx_by_id.get(can_id)
        if ch is None:
            return
        try:
            with self._lock:
                if self.clock == "wall":
                    self._catch_up()
                codec = ch.codec[1]
                if (pdos.active and codec is not None and ch.trans in SYNCED
                        and len(data) >= codec[3]):
                    ch.pending = bytes(data)     # perf: receive() of a synchronous RPDO
                    return
                values = pdos.receive(ch, bytes(data), self.drive.now, self._note)
                if values is None:
                    return
                values = self._rx_values(values)
                for (index, sub), value in sorted(values.items(), key=lambda v: v[0][0] == 0x6040):
                    if index != 0x6040 and self.drive.store.get(index, sub) == value:
                        continue
                    self.drive.write(index, sub, value)
                self._after()
        except SdoAbort as e:
            log.info("node %d: %s: %s", self.drive.node_id, ch.name, e)
            self.drive.note(self.drive.now, "CiA 301 §7.2.2", f"{ch.name} refused: {e}", "CAN")
        except Exception:
            log.exception("node %d: %s failed", self.drive.node_id, ch.name)

    def _note(self, section: str, text: str) -> None:
        self.drive.note(self.drive.now, section, text, "CAN")

    # ---------------------------------------------------------------- EMCY
    def _check_emcy(self) -> None:
        code = self.drive.sm.error_code
        if code != self._emcy_code:
            self._emcy_code = code
            if self.node.nmt.state in ("PRE-OPERATIONAL", "OPERATIONAL"):
                self._send_emcy(code)

    def _send_emcy(self, code: int) -> None:
        """One emergency message (CiA 301 §7.2.7.3.1): the code of 603Fh
        (:func:`~.emcy.emcy_code`), 1001h, 603Fh."""
        sm = self.drive.sm
        self._send(0x80 + self.drive.node_id, emcy_frame(code, sm.error_register))
        self.drive.note(self.drive.now, "CiA 301 §7.2.7",
                        f"EMCY 0x{emcy_code(code):04X} sent (603Fh = {code}, 1001h = "
                        f"0x{sm.error_register:02X})", "EMCY")

    # ---------------------------------------------------------------- NMT
    def _nmt_changed(self, state: int) -> None:
        with self._lock:
            self.pdos.operational(state == 5)
            steps = _NMT_TO_ESM.get(state, ())
            for target in steps:
                if self.drive.esm.state is target:
                    continue
                res = self.drive.request_esm(target)
                if not res.accepted:
                    log.warning("node %d: NMT state %d: %s", self.drive.node_id, state,
                                res.explanation)
                    break
            if state == 5:
                self._after()
