"""The PLC side of the bus drives: a fieldbus master module in an expansion
slot whose process data and SDO mailbox sit in V memory.

What it is: :class:`FieldbusModule`, the device a plant file's
``[module.N] kind = "FIELDBUS"`` creates.  Like a communication module of an
S7-200 (the CPU reaches it through memory, never through instructions), it
exchanges a fixed set of objects with each of its CiA 402 drives at every bus
cycle and serves one SDO request at a time per drive.  Each drive has an
80-byte image in V memory, in the S7-200's byte order (most significant byte
first, so ``MOVW``/``MOVD`` read and write the objects directly):

====== ====== ======== ===========================================
offset type   object   meaning
====== ====== ======== ===========================================
**written by the program, sent to the drive every bus cycle**
0      WORD   6040h    controlword
2      BYTE   6060h    modes of operation (signed)
3      BYTE   6098h    homing method (signed)
4      DINT   607Ah    target position
8      DINT   60FFh    target velocity
12     DWORD  6081h    profile velocity
16     DWORD  6083h    profile acceleration
20     DWORD  6084h    profile deceleration
24     WORD            SDO request: object index
26     BYTE            SDO request: subindex
27     BYTE            SDO control: bit 0 REQ (a 0→1 edge starts it), bit 1 write
28     DINT            SDO request: value to write
**written by the module after every scan**
32     WORD   6041h    statusword
34     BYTE   6061h    modes of operation display (signed)
35     BYTE            module status: bit 0 online (process data valid),
                       bit 1 SDO busy, bit 2 SDO done, bit 3 SDO error
36     DINT   6064h    position actual value
40     DINT   606Ch    velocity actual value
44     WORD   603Fh    error code
46     WORD            bus cycle counter: +1 at every bus cycle, wraps
48     DINT   60F4h    following error actual value
52     DWORD  60FDh    digital inputs (bit 0 NLS, 1 PLS, 2 home switch)
56     DINT            SDO response: the value read
60     DWORD           SDO response: the abort code (0: none)
**the program's own (the module never touches them)**
64..79                 16 bytes for the program: the STL library
                       (``library/cia402/drive_lib.awl``) keeps its
                       edge flags and steps here
====== ====== ======== ===========================================

Timing: the output half is sampled once, after the program's scan; the
drives are cycled at every multiple of the bus cycle up to the next scan's
start with those values (the profile 6081h/6083h/6084h first, then 6098h,
6060h, the targets, and 6040h last); the input half then holds the drive's
objects after the last of those cycles.  The bus cycle counter (offset 46) tells a
program whether a bus cycle has passed since it wrote a command: with a
scan shorter than the bus cycle, the input half of the next scan may still
be the one from before the command.  An SDO request seen after a scan is served at the
second bus cycle after it (``SDO_CYCLES``); busy, then done or error, show in
the module status; done and error stay until the program drops REQ.

At start-up the module brings every drive to OP (EtherCAT INIT → PRE-OP →
SAFE-OP → OP; NMT start for a CANopen model) and writes the plant file's
``params`` by SDO in PRE-OP, as a master's start-up list does.  Everything a
drive refuses or reports (refused controlwords, faults, SDO aborts, homing
failures) reaches :attr:`plcrt.Plc.diagnostics` with its explanation.

With ``layout = "mapping"`` on a drive, its image follows the drive's PDO
mapping instead (the one in force, 1C12h/1C13h-assigned on the HCFA drive,
every map with entries on the Kinco drive, as the plant's ``params`` left it
at start-up): offsets 0..31 hold the RxPDO image, 32..63 the TxPDO image,
each object in mapping order and in the S7-200's byte order; offset 64 is the
module status byte, 66 the bus cycle counter (WORD); there is no SDO mailbox.
A mapping whose image is over 32 bytes, or with an object that is not a whole
number of bytes, is a start-up error.  The drive runs its own images
(:meth:`~.drive.Drive.cycle`); a mapping changed later is followed at the next
bus cycle.

What it is not: no bus timing below the bus cycle, no PDO mapping of its
own in the fixed layout (the module exchanges objects, see
:meth:`~.drive.Drive.exchange`; the set above fits the PDOs of both models),
no second SDO in flight per drive.
"""

from __future__ import annotations

import struct
from typing import Any, Optional

from ...engine.device import AxisState, DriveState
from ...errors import PlcConfigError, PlcError
from .drive import Drive
from .esm import EsmState
from .od import DTYPES, SdoAbort
from .pdo import pack
from .plant import DrivePlant

__all__ = ["FieldbusModule", "IMAGE_BYTES", "OUT_LAYOUT", "IN_LAYOUT", "SDO_CYCLES"]

IMAGE_BYTES = 80
SDO_CYCLES = 2        #: bus cycles from a request seen to its answer

#: the output half: (offset, object or None, struct code); objects in order
OUT_LAYOUT: tuple[tuple[int, Optional[int], str], ...] = (
    (0, 0x6040, "H"), (2, 0x6060, "b"), (3, 0x6098, "b"), (4, 0x607A, "i"),
    (8, 0x60FF, "i"), (12, 0x6081, "I"), (16, 0x6083, "I"), (20, 0x6084, "I"),
    (24, None, "H"), (26, None, "B"), (27, None, "B"), (28, None, "i"),
)
#: the input half
IN_LAYOUT: tuple[tuple[int, Optional[int], str], ...] = (
    (32, 0x6041, "H"), (34, 0x6061, "b"), (35, None, "B"), (36, 0x6064, "i"),
    (40, 0x606C, "i"), (44, 0x603F, "H"), (46, None, "H"), (48, 0x60F4, "i"),
    (52, 0x60FD, "I"), (56, None, "i"), (60, None, "I"),
)
_OUT = struct.Struct(">" + "".join(c for _, _, c in OUT_LAYOUT))
_IN = struct.Struct(">" + "".join(c for _, _, c in IN_LAYOUT))
_RX_OBJECTS = tuple(i for _, i, _ in OUT_LAYOUT if i is not None)
#: the order in which a bus cycle applies the received objects (6040h comes
#: last in any case): the profile first, then the mode and the targets, so
#: that a PV start or a set-point written in the same scan as its ramps
#: runs on those ramps, not on the ones before
_APPLY_ORDER = (0x6081, 0x6083, 0x6084, 0x6098, 0x6060, 0x607A, 0x60FF, 0x6040)
assert sorted(_APPLY_ORDER) == sorted(_RX_OBJECTS)
_TX_OBJECTS = tuple(i for _, i, _ in IN_LAYOUT if i is not None)
assert _OUT.size == 32 and _IN.size == 32

ONLINE, BUSY, DONE, ERROR = 0x01, 0x02, 0x04, 0x08
REQ, WRITE = 0x01, 0x02
#: SDO abort code of a value the mailbox's DINT cannot carry (CiA 301:
#: "data type does not match, length of service parameter does not match")
ABORT_LENGTH = 0x06070010
#: the object types the mailbox's DINT carries (their ranges: od.DTYPES)
_MAILBOX_TYPES = frozenset({"I8", "U8", "I16", "U16", "I32", "U32"})


class _Port:
    """One drive on the module: its image address and mailbox state."""

    def __init__(self, node: int, drive: Drive, image: int, layout: str = "fixed") -> None:
        self.node = node
        self.mapped = layout == "mapping"
        self.codec: tuple = ()                #: mapping layout: (rx, tx, (be, le) x 2)
        self.tx_image = b""                   #: mapping layout: the last TxPDO image
        self.drive = drive
        self.image = image
        self.req = False                      #: REQ as the module last saw it
        self.flags = 0                        #: BUSY / DONE / ERROR
        self.shown = False                    #: DONE / ERROR written to V at least once
        self.request: Optional[tuple[int, int, bool, int, int]] = None  # idx, sub, write, value, due
        self.data = 0
        self.abort = 0
        self.seen = 0                         #: drive log entries reported so far
        self.rx_keys = tuple((i, 0) for i in _APPLY_ORDER if drive.od.find(i, 0) is not None)
        self.tx = tuple((i, drive.od.find(i, 0) is not None) for i in _TX_OBJECTS)


class FieldbusModule:
    """Device: a fieldbus master module in slot ``cfg.slot`` with CiA 402 drives."""

    def __init__(self, plc: Any, cfg: Any) -> None:
        self.plc = plc
        self.slot = cfg.slot
        self.cycle_us = cfg.cycle_us
        model = plc.model
        if self.slot >= model.max_modules:
            raise PlcConfigError(f"{cfg.where}: the {model.name} takes {model.max_modules} "
                                 f"expansion module(s); a module in slot {self.slot} is not possible")
        self.cycles = 0                        #: bus cycles so far, modulo 2**16
        self.ports: dict[int, _Port] = {}
        for node, dc in sorted(cfg.drives.items()):
            if dc.image + IMAGE_BYTES > model.v_bytes:
                raise PlcConfigError(
                    f"{dc.where}.image: VB{dc.image}..VB{dc.image + IMAGE_BYTES - 1} is beyond "
                    f"the {model.name}'s V memory (VB0..VB{model.v_bytes - 1})")
            self.ports[node] = port = _Port(node, self._drive(dc), dc.image, dc.layout)
            port.seen = len(port.drive.log)      # the start-up itself is no news
            if port.mapped:
                _follow(port, dc.where)
                d = port.drive
                port.tx_image = pack(d.pdo.active_tx, {(e.index, e.sub): int(
                    d.store.get(e.index, e.sub)) for e in d.pdo.active_tx if e.index})
        self._write_inputs()

    def _drive(self, dc: Any) -> Drive:
        try:
            plant = DrivePlant(**dc.plant)
        except TypeError as e:
            raise PlcConfigError(f"{dc.where}: {e}") from None
        except PlcError as e:
            raise PlcConfigError(f"{dc.where}: {e.message}") from None
        try:
            drive = Drive(dc.model, plant=plant, node_id=dc.node)
        except PlcError as e:
            raise PlcConfigError(f"{dc.where}.model: {e.message}") from None
        drive.request_esm(EsmState.PREOP)
        for index, sub, value, where in dc.params:
            if dc.layout == "fixed" and sub == 0 and index in _RX_OBJECTS:
                off = next(o for o, i, _ in OUT_LAYOUT if i == index)
                raise PlcConfigError(f"{where}: {index:04X}h is in the module's process image "
                                     f"(VB{dc.image + off}, offset {off}): the program sets it "
                                     f"every bus cycle, a start-up value would be overwritten")
            try:
                drive.write(index, sub, value)
            except SdoAbort as e:
                raise PlcConfigError(f"{where}: the drive refuses {index:04X}h:{sub:02X} = "
                                     f"{value}: {e.message}") from None
        if drive.store.pending:
            # start-up values of parameters that act after power-up (HCFA §5.1):
            # the drive is switched on with them, as after a real power cycle
            drive.power_cycle()
            drive.request_esm(EsmState.PREOP)
        for state in (EsmState.SAFEOP, EsmState.OP):
            res = drive.request_esm(state)
            if drive.esm.state is not state:
                raise PlcConfigError(f"{dc.where}: the drive does not reach "
                                     f"{state.name}: {res.explanation}")
        return drive

    # ------------------------------------------------------------------ scan
    def step(self, plc: Any, t_from: int, t_to: int) -> None:
        v = plc.mem.areas["V"]
        period = self.cycle_us
        first = (t_from // period + 1) * period
        for port in self.ports.values():
            if port.mapped:
                self._step_mapped(port, v, first, t_to)
                continue
            out = _OUT.unpack_from(v, port.image)
            values = self._rx(port, out)
            self._mailbox(port, out, t_from)
            drive = port.drive
            req = port.request
            for t in range(first, t_to + 1, period):
                drive.exchange(t, values)
                if req is not None and t >= req[4]:
                    self._serve(port, t)
                    req = None
            self._report(port)
        self.cycles = (self.cycles + len(range(first, t_to + 1, period))) & 0xFFFF
        self._write_inputs()

    def _step_mapped(self, port: _Port, v: bytearray, first: int, t_to: int) -> None:
        """The bus cycles of a drive whose image is its PDO mapping."""
        drive = port.drive
        for t in range(first, t_to + 1, self.cycle_us):
            _follow(port, f"fieldbus slot {self.slot} node {port.node}")
            rx_be, rx_le = port.codec[2]
            port.tx_image = drive.cycle(t, rx_le.pack(*rx_be.unpack_from(v, port.image)))
        self._report(port)

    @staticmethod
    def _rx(port: _Port, out: tuple) -> dict[tuple[int, int], int]:
        values = dict(zip(((i, 0) for i in _RX_OBJECTS), out))
        return {k: values[k] for k in port.rx_keys}

    def _mailbox(self, port: _Port, out: tuple, t: int) -> None:
        index, sub, control, value = out[8], out[9], out[10], out[11]
        req = bool(control & REQ)
        if port.flags & (DONE | ERROR) and port.shown and not req:
            port.flags &= ~(DONE | ERROR)
        if req and not port.req:
            if port.flags & BUSY:
                self.plc.warn(f"fieldbus slot {self.slot} node {port.node}: SDO REQ rose while "
                              f"the request before is busy; the new request is ignored",
                              None, f"sdo-busy-{self.slot}-{port.node}-{t}")
            else:
                due = (t // self.cycle_us + SDO_CYCLES) * self.cycle_us
                port.request = (index, sub, bool(control & WRITE), value, due)
                port.flags = BUSY
                port.shown = False
        port.req = req

    def _serve(self, port: _Port, t: int) -> None:
        assert port.request is not None
        index, sub, write, value, _ = port.request
        port.request = None
        drive = port.drive
        what = f"{'write' if write else 'read'} {index:04X}h:{sub:02X}"
        try:
            entry = drive.od.entry(index, sub)
            bounds = DTYPES[entry.dtype][1:] if entry.dtype in _MAILBOX_TYPES else None
            if write:
                if entry.dtype == "U32" and value < 0:
                    value += 2**32            # a DWORD above 2**31 reads as a negative DINT
                if bounds is None or not bounds[0] <= value <= bounds[1]:
                    raise SdoAbort(ABORT_LENGTH, f"{entry.label} is {entry.dtype}: the value "
                                   f"{value} does not fit it (the module sends the object's "
                                   f"own length)")
                drive.write(index, sub, value)
                port.data = 0
            else:
                got = drive.read(index, sub)
                if not isinstance(got, int) or bounds is None:
                    raise SdoAbort(ABORT_LENGTH, f"{entry.label} is {entry.dtype}: it does not "
                                   f"fit the mailbox's DINT")
                port.data = got - 2**32 if got >= 2**31 else got
            port.abort = 0
            port.flags = DONE
        except SdoAbort as e:
            port.abort = e.code
            port.flags = ERROR
            self.plc.warn(f"fieldbus slot {self.slot} node {port.node}: SDO {what} at "
                          f"{t / 1e6:.6f} s aborted: {e.message}",
                          None, f"sdo-{self.slot}-{port.node}-{t}")

    def _report(self, port: _Port) -> None:
        """Mirror what the drive refused or reported into the PLC's diagnostics."""
        log = port.drive.log
        for k in range(port.seen, len(log)):
            ev = log[k]
            if ev.source == "state machine" and ("no transition" not in ev.text
                                                 and "transition 13 " not in ev.text):
                continue              # transitions that were asked for are no news
            self.plc.warn(f"fieldbus slot {self.slot} node {port.node}: {ev}", None,
                          f"drive-{self.slot}-{port.node}-{k}")
        port.seen = len(log)

    def _write_inputs(self) -> None:
        v = self.plc.mem.areas["V"]
        for port in self.ports.values():
            if port.mapped:
                tx_be, tx_le = port.codec[3]
                if len(port.tx_image) == tx_le.size:
                    tx_be.pack_into(v, port.image + 32, *tx_le.unpack(port.tx_image))
                v[port.image + 64] = ONLINE if port.drive.esm.state is EsmState.OP else 0
                struct.pack_into(">H", v, port.image + 66, self.cycles)
                continue
            get = port.drive.store.get
            vals = [int(get(i, 0)) if present else 0 for i, present in port.tx]
            status = port.flags | (ONLINE if port.drive.esm.state is EsmState.OP else 0)
            if port.flags & (DONE | ERROR):
                port.shown = True
            # 6041h, 6061h, status, 6064h, 606Ch, 603Fh, cycles, 60F4h, 60FDh, data, abort
            _IN.pack_into(v, port.image + 32, vals[0], vals[1], status, vals[2], vals[3],
                          vals[4], self.cycles, vals[5], vals[6], port.data, port.abort)

    # ------------------------------------------------------------------ state
    def snapshot(self, t: int) -> list[AxisState]:
        """No EM253 axes on this module (see :meth:`drive_states`)."""
        return []

    def drive_states(self, t: int) -> list[DriveState]:
        """The state of every drive after the last bus cycle."""
        return [self.drive_state(node) for node in self.ports]

    def drive_state(self, node: int) -> DriveState:
        """The state of the drive at *node* after the last bus cycle."""
        d = self.ports[node].drive
        get = d.store.get
        return DriveState(
            slot=self.slot, node=node, model=d.model, state=str(d.sm.state),
            statusword=d.statusword, controlword=d.controlword, mode=d.mode_number,
            position=int(get(0x6064)), velocity=int(get(0x606C)),
            following_error=int(get(0x60F4)), error_code=int(get(0x603F)),
            online=d.esm.state is EsmState.OP)

    def drive(self, node: int) -> Drive:
        """The simulated drive at bus address *node*."""
        return self.ports[node].drive


#: struct codes of a mapped object by (bits, signed)
_CODES = {(8, False): "B", (8, True): "b", (16, False): "H", (16, True): "h",
          (32, False): "I", (32, True): "i", (64, False): "Q", (64, True): "q"}


def _follow(port: _Port, where: str) -> None:
    """Build the port's image codecs for the drive's mapping in force (again
    only when it changed): each image as S7 (big-endian per object) and CoE
    (little-endian) structs of the same objects."""
    pdo = port.drive.pdo
    if port.codec and port.codec[0] is pdo.active_rx and port.codec[1] is pdo.active_tx:
        return          # perf: the same mapping as the last cycle
    signed = port.drive._signed
    pairs = []
    for entries, what in ((pdo.active_rx, "RxPDO"), (pdo.active_tx, "TxPDO")):
        codes = ""
        for e in entries:
            code = f"{e.bits // 8}x" if e.index == 0 and e.bits % 8 == 0 else \
                _CODES.get((e.bits, (e.index, e.sub) in signed), "") if e.index else ""
            if not code:
                raise PlcConfigError(f"{where}: layout = \"mapping\": {what} entry {e} is not "
                                     "a whole number of bytes the image can hold")
            codes += code
        be, le = struct.Struct(">" + codes), struct.Struct("<" + codes)
        if be.size > 32:
            raise PlcConfigError(f"{where}: layout = \"mapping\": the {what} image is "
                                 f"{be.size} bytes; the image holds 32")
        pairs.append((be, le))
    port.codec = (pdo.active_rx, pdo.active_tx, *pairs)
