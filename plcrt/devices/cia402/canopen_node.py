"""A simulated CiA 402 drive on a CANopen bus, as a ``canopen.LocalNode``.

What it is: :class:`CanopenDrive`, which puts a :class:`~.drive.Drive` on a
connected ``canopen.Network`` (python-can's ``virtual`` bus, or ``vcan``) so
that any CANopen master -- canopen's own ``RemoteNode`` / ``BaseNode402`` --
drives it with SDOs, NMT and heartbeat.  It is the only module of the drive
that imports ``canopen``.

* SDO server: the LocalNode's read and write callbacks delegate to
  :meth:`Drive.sdo_read` / :meth:`Drive.sdo_write`; plcrt's
  :class:`~.od.SdoAbort` becomes ``canopen.SdoAbortedError`` with the same
  code, and the explanation (object, value, manual section) goes to the
  ``plcrt.cia402.canopen`` logger.  No other exception leaves a callback
  (canopen would abort 0x08000000 without a word, digest §7.2 caveat 9): one
  is logged with its traceback and aborts 0x08000000.
* NMT: PRE-OPERATIONAL, OPERATIONAL and STOPPED map onto the drive's
  EtherCAT communication state (PRE-OP, OP, SAFE-OP): the HCFA drive's CoE
  dictionary is the same CiA 301/402 dictionary seen over CAN (digest §7.1).
* Heartbeat producer 1017h (added to the CAN view where the model lacks it).
* Time: ``clock="wall"`` (default) -- a background thread runs one bus cycle
  of the drive per bus period (1C32h:02, 1 ms), so a master with real
  timeouts works; ``clock="manual"`` -- time moves only by
  :meth:`CanopenDrive.advance`; ``clock="step"`` -- each SDO read of the
  statusword 6041h first runs one bus cycle (deterministic, and a master
  that polls 6041h sees the drive move).
* Caveat 6 (``homing()`` judges 6041h at once): the drive publishes 6041h
  inside the SDO write of 6040h, so the statusword the master reads next is
  already the one of the new controlword.  Caveat 1 (``setup_402_state_machine``
  on a fresh node): the node boots to PRE-OPERATIONAL, sends its boot-up
  message when attached and its heartbeat every 50 ms (1017h default of the
  CAN view), so a master's NMT learns the state within one heartbeat
  (``nmt.wait_for_heartbeat()``).
* PDOs (caveats 2-5): the CAN view (:func:`can_view`) adds one cyclic TPDO
  (6041h, 6064h, 6061h; every 2 ms in OPERATIONAL, filled from the drive)
  and one RPDO (6040h, 607Ah; routed to the drive, 6040h last, in
  OPERATIONAL only), at numbers the model's EtherCAT mapping objects leave
  free.  A master sees them with ``object_dictionary(model, node_id)``.

* EMCY (CiA 301 §7.2.7): when 603Fh changes, the node sends an emergency
  message on 080h + node id: the error code and the error register 1001h
  (the manufacturer-specific bytes are 0: HCFA's alarm number is the 603Fh
  value itself, §4.7); a fault reset sends the code 0000h (error reset).
  A master sees them in ``node.emcy`` (``active``, ``log``, ``wait()``).

What it is not: no SYNC, no remapping of the CAN view's PDOs.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any, Literal, Optional

import canopen
from canopen.nmt import NmtSlave
from canopen.objectdictionary import ODRecord, ODVariable, datatypes

from ...engine.values import Duration, duration_us, shown_value, step_count
from ...errors import PlcConfigError
from .canopen_od import object_dictionary
from .drive import Drive
from .esm import EsmState
from .od import SdoAbort
from .plant import DrivePlant

__all__ = ["CanopenDrive", "Clock", "can_view", "pdo_slots"]

log = logging.getLogger("plcrt.cia402.canopen")

Clock = Literal["wall", "manual", "step"]
CLOCKS = ("wall", "manual", "step")

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


class CanopenDrive:
    """A :class:`Drive` of *model* as node *node_id* on *network*.

    Attributes: ``drive`` (the model), ``node`` (the ``canopen.LocalNode``),
    ``clock``.  Use :func:`plcrt.cia402.attach` rather than this class."""

    def __init__(self, network: Any, node_id: int, model: str = "hcfa-am0520b",
                 plant: Optional[DrivePlant] = None, *, clock: Clock = "wall",
                 od: Any = None) -> None:
        if clock not in CLOCKS:
            raise PlcConfigError(f"cia402.attach: clock={clock!r}; expected one of "
                                 + ", ".join(CLOCKS))
        if not isinstance(node_id, int) or isinstance(node_id, bool) or not 1 <= node_id <= 127:
            raise PlcConfigError(f"cia402.attach: node id {node_id!r} is not a CANopen node id "
                                 "(1..127, CiA 301 §7.5.2.4)")
        if not isinstance(network, canopen.Network):
            raise PlcConfigError(f"cia402.attach: {type(network).__name__} is not a "
                                 "canopen.Network")
        if network.bus is None:
            raise PlcConfigError("cia402.attach: the canopen.Network is not connected "
                                 "(call network.connect(interface='virtual', channel=...) first)")
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
        self.node = canopen.LocalNode(node_id, codod)
        self.node._write_callbacks.clear()          # canopen's own 1017h hook belongs to .nmt
        self.node.nmt = _Nmt(node_id, self.node, self)
        self.node.add_write_callback(self._on_write)
        self.node.add_write_callback(self.node.nmt.on_write)
        self.node.add_read_callback(self._on_read)
        self.network = network
        network.create_node(self.node)
        self.node.tpdo.read(from_od=True)
        self.node.rpdo.read(from_od=True)
        self._rpdo_noted = False
        self._emcy_code = 0                         # 603Fh as last sent in an EMCY
        self.node.rpdo[self.rpdo_no].add_callback(self._on_rpdo)
        self.drive.request_esm(EsmState.PREOP)
        self.node.nmt.send_command(0x81)            # reset: boot-up message
        self.node.nmt.send_command(0x80)            # to PRE-OPERATIONAL, heartbeat per 1017h
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None
        if clock == "wall":
            self._thread = threading.Thread(target=self._run, daemon=True,
                                            name=f"plcrt-cia402-node{node_id}")
            self._thread.start()

    # ---------------------------------------------------------------- time
    def advance(self, seconds: Duration) -> None:
        """Run the drive *seconds* further (a duration: ``0.5``, ``"200ms"``),
        one bus cycle at a time (``clock="manual"`` or ``"step"``; in
        wall-clock mode time follows the wall clock and this raises).

        Raises:
            PlcConfigError: wall-clock mode, not a duration, a negative one,
                or more than :data:`~plcrt.engine.values.MAX_STEPS` bus
                cycles in one call.
        """
        if self.clock == "wall":
            raise PlcConfigError("cia402: advance() needs clock='manual' or 'step'; "
                                 "this drive follows the wall clock")
        what = "cia402: advance()"
        if isinstance(seconds, (int, float)) and not isinstance(seconds, bool) and seconds < 0:
            raise PlcConfigError(f"{what}: {shown_value(seconds)} s cannot go back in time")
        span = duration_us(seconds, what)
        step_count(span, self.period_us, seconds, what, "bus cycle")
        with self._lock:
            end = self.drive.now + span
            while self.drive.now < end:
                self.drive.tick(min(end, self._next_boundary()))
            self._fill_tpdo()

    def _next_boundary(self) -> int:
        p = self.period_us
        return (self.drive.now // p + 1) * p

    def _sync(self) -> None:
        """Wall clock: run the bus cycles up to the present."""
        t = int((time.monotonic() - self._t0) * 1e6)
        with self._lock:
            while self._next_boundary() <= t:
                self.drive.tick(self._next_boundary())
            self._fill_tpdo()

    def _run(self) -> None:
        period = self.period_us / 1e6
        while not self._stop.wait(period):
            try:
                self._sync()
            except Exception:                        # keep the bus alive, say why
                log.exception("node %d: drive cycle failed", self.drive.node_id)
                return

    def close(self) -> None:
        """Stop the clock thread and the heartbeat; take the node off the network."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
        self.node.nmt.stop_heartbeat()
        self.node.tpdo[self.tpdo_no].stop()
        if self.node.id in self.network:
            del self.network[self.node.id]

    # ---------------------------------------------------------------- SDO server
    def _abort(self, e: Exception, what: str, index: int, sub: int) -> Exception:
        """The SDO abort a callback raises for *e*: plcrt's own abort code, or
        0x08000000 for anything else (logged with its traceback), so that no
        exception escapes into canopen's server (digest §7.2, caveat 9)."""
        if isinstance(e, SdoAbort):
            log.info("node %d: %s", self.drive.node_id, e)
            return canopen.SdoAbortedError(e.code)
        log.error("node %d: SDO %s %04Xh:%02X failed", self.drive.node_id, what, index, sub,
                  exc_info=e)
        return canopen.SdoAbortedError(0x08000000)

    def _owns(self, index: int, sub: int) -> bool:
        return self.drive.od.find(index, sub) is not None

    def _on_read(self, index: int, subindex: int, od: Any, **_: Any) -> Any:
        if not self._owns(index, subindex):
            return None                             # the CAN view (1017h): LocalNode's store
        try:
            with self._lock:
                if self.clock == "wall":
                    self._sync()
                elif self.clock == "step" and index == 0x6041:
                    self.drive.tick(self._next_boundary())
                data = self.drive.sdo_read(index, subindex)
                self._check_emcy()
            return od.decode_raw(data)
        except Exception as e:
            raise self._abort(e, "read", index, subindex) from None

    def _on_write(self, index: int, subindex: int, od: Any, data: bytes, **_: Any) -> None:
        if not self._owns(index, subindex):
            return
        try:
            with self._lock:
                if self.clock == "wall":
                    self._sync()
                self.drive.sdo_write(index, subindex, bytes(data))
                self._fill_tpdo()
        except Exception as e:
            raise self._abort(e, "write", index, subindex) from None

    # ---------------------------------------------------------------- PDOs
    def _fill_tpdo(self) -> None:
        """Copy the drive's objects into the TPDO (canopen does not, caveat 3)
        and send an EMCY if 603Fh changed."""
        self._check_emcy()
        tpdo = self.node.tpdo[self.tpdo_no]
        for var in tpdo:
            var.raw = int(self.drive.store.get(var.index, var.subindex))
        tpdo.update()

    def _check_emcy(self) -> None:
        code = self.drive.sm.error_code
        if code != self._emcy_code:
            self._emcy_code = code
            self._send_emcy(code)

    def _send_emcy(self, code: int) -> None:
        """One emergency message (CiA 301 §7.2.7.3.1): 603Fh and 1001h."""
        sm = self.drive.sm
        try:
            self.node.emcy.send(code, sm.error_register & 0xFF)
        except Exception:                    # the bus went away: the drive goes on
            log.exception("node %d: EMCY 0x%04X not sent", self.drive.node_id, code)
        else:
            self.drive.note(self.drive.now, "CiA 301 §7.2.7",
                            f"EMCY 0x{code:04X} sent (1001h = 0x{sm.error_register:02X})",
                            "EMCY")

    def _on_rpdo(self, rpdo: Any) -> None:
        """An RPDO reached the node: write its objects to the drive, 6040h
        last (canopen does not, caveat 3).  PDOs act in OPERATIONAL only."""
        try:
            with self._lock:
                if self.node.nmt.state != "OPERATIONAL":
                    if not self._rpdo_noted:
                        self._rpdo_noted = True
                        self.drive.note(self.drive.now, "CiA 301 §7.3.2.2",
                                        f"RPDO ignored in NMT {self.node.nmt.state}", "NMT")
                    return
                if self.clock == "wall":
                    self._sync()
                values = [(v.index, v.subindex, int(v.raw)) for v in rpdo]
                for index, sub, value in sorted(values, key=lambda v: v[0] == 0x6040):
                    if index != 0x6040 and int(self.drive.store.get(index, sub)) == value:
                        continue
                    self.drive.write(index, sub, value)
                self._fill_tpdo()
        except SdoAbort as e:
            log.warning("node %d: RPDO %d: %s", self.drive.node_id, self.rpdo_no, e)
        except Exception:
            log.exception("node %d: RPDO %d failed", self.drive.node_id, self.rpdo_no)

    # ---------------------------------------------------------------- NMT
    def _nmt_changed(self, state: int) -> None:
        tpdo = self.node.tpdo[self.tpdo_no]
        if state == 5 and tpdo._task is None:
            self._fill_tpdo()
            tpdo.start(TPDO_PERIOD_MS / 1000)
        elif state != 5 and tpdo._task is not None:
            tpdo.stop()
        steps = _NMT_TO_ESM.get(state)
        if steps is None:
            return
        with self._lock:
            for target in steps:
                if self.drive.esm.state is target:
                    continue
                res = self.drive.request_esm(target)
                if not res.accepted:
                    log.warning("node %d: NMT state %d: %s", self.drive.node_id, state,
                                res.explanation)
                    return


#: The CAN view's PDO contents (CiA 301 §7.5.2.35-38): one TPDO and one RPDO.
TPDO_OBJECTS = ((0x6041, 0, 16), (0x6064, 0, 32), (0x6061, 0, 8))
RPDO_OBJECTS = ((0x6040, 0, 16), (0x607A, 0, 32))
#: 1017h default of the CAN view: a master's NMT learns PRE-OPERATIONAL from
#: the heartbeat, which caveat 1's guard in setup_402_state_machine needs.
HEARTBEAT_MS = 50
TPDO_PERIOD_MS = 2          # digest §7.2 caveat 4: a cyclic TPDO keeps BaseNode402 happy


def pdo_slots(od: Any) -> tuple[int, int]:
    """The CAN view's (TPDO, RPDO) numbers: the first whose communication
    and mapping objects the model's dictionary lacks (HCFA: TPDO 3, RPDO 5;
    the EtherCAT mapping objects 1600h-1603h, 1A00h-1A01h stay the drive's)."""
    def free(com: int, map_: int) -> int:
        return next(n for n in range(512) if com + n not in od and map_ + n not in od)
    return free(0x1800, 0x1A00) + 1, free(0x1400, 0x1600) + 1


def _var(name: str, index: int, sub: int, dtype: int, default: int, access: str = "rw") -> Any:
    var = ODVariable(name, index, sub)
    var.data_type = dtype
    var.access_type = access
    var.default = default
    var.description = "CiA 301 (CAN view of the drive)"
    return var


def can_view(od: Any, node_id: int) -> None:
    """Add the CAN objects a CANopen master expects where the model lacks
    them: 1017h producer heartbeat time (CiA 301 §7.5.2.32), one TPDO
    (:data:`TPDO_OBJECTS`, COB-ID 180h+id, cyclic) and one RPDO
    (:data:`RPDO_OBJECTS`, COB-ID 200h+id) at the slots of :func:`pdo_slots`."""
    if 0x1017 not in od:
        var = _var("Producer heartbeat time", 0x1017, 0, datatypes.UNSIGNED16,
                   HEARTBEAT_MS)
        var.unit = "ms"
        od.add_object(var)
    tpdo, rpdo = pdo_slots(od)
    for com, map_, cob, trans, objects, what in (
            (0x1800 + tpdo - 1, 0x1A00 + tpdo - 1, 0x180 + node_id, 0xFE, TPDO_OBJECTS,
             f"TPDO {tpdo}"),
            (0x1400 + rpdo - 1, 0x1600 + rpdo - 1, 0x200 + node_id, 0xFE, RPDO_OBJECTS,
             f"RPDO {rpdo}")):
        rec = ODRecord(f"{what} communication parameter", com)
        rec.add_member(_var("Highest sub-index supported", com, 0, datatypes.UNSIGNED8, 5, "ro"))
        rec.add_member(_var("COB-ID", com, 1, datatypes.UNSIGNED32, cob))
        rec.add_member(_var("Transmission type", com, 2, datatypes.UNSIGNED8, trans))
        rec.add_member(_var("Inhibit time", com, 3, datatypes.UNSIGNED16, 0))
        rec.add_member(_var("Event timer", com, 5, datatypes.UNSIGNED16,
                            TPDO_PERIOD_MS if com >= 0x1800 else 0))
        od.add_object(rec)
        rec = ODRecord(f"{what} mapping parameter", map_)
        rec.add_member(_var("Number of mapped objects", map_, 0, datatypes.UNSIGNED8,
                            len(objects)))
        for k, (index, sub, bits) in enumerate(objects, 1):
            rec.add_member(_var(f"Mapped object {k}", map_, k, datatypes.UNSIGNED32,
                                index << 16 | sub << 8 | bits))
        od.add_object(rec)
