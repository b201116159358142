"""The panel's PLC session: the runner thread, the commands of the pages,
breakpoint pauses and frames.  No web code: the server hands it checked
messages (:mod:`plcrt.web.protocol`) and carries its frames; tests drive
it directly.

One thread touches the PLC: :meth:`PanelSession.start` runs
:meth:`PanelSession.tick` in a loop, and every command a client sends is
queued (:meth:`submit`) and applied between two chunks of scans.  The scan
runs in simulated time; a *frame* (time, scans, run state, the status of
the networks clients look at, inputs and outputs, watch table, forces,
axes, drives and new trend samples) is sampled at the end of a scan at the
display rate (:data:`DISPLAY_HZ`), never per scan, and put into every
client's one-slot :class:`Mailbox`: a slow client skips frames, the scan
never waits for it.

The session composes the parts, each in a module of its own: the run
modes and a chunk of scans (:mod:`plcrt.web.running`), the speed
(:mod:`plcrt.net.pacing`), breakpoints and the builds with and without
probes (:mod:`plcrt.web.builds`), the watch table, set and force
(:mod:`plcrt.web.watch`), the trend (:mod:`plcrt.web.trend`) and the
program as the pages draw it (:mod:`plcrt.web.program`).  What the session
itself does: the clients, the command queue and the thread; what follows
the PLC to another build; the power-up reset; the pause inside a scan.

Breakpoints stop inside a scan, as the debugger's do: ``CoverageMap.
on_break`` is called before a network with a breakpoint.  The handler, in
the runner thread, publishes a frame of that moment and applies commands
until one resumes the scan (``continue``, ``run``, ``step``, ``stop``,
``until`` or ``reset``; the scan in progress always runs to its end
first).

It is not a second engine: scans are :meth:`plcrt.Plc.scan`, conditions
the test harness's, values go through the PLC's address access and
``set``/``force`` through the code of ``plcrt run --set``.
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable
from typing import Any

from ..engine.coverage import NetworkRef
from ..engine.runtime import Plc
from ..errors import PlcConfigError, PlcError
from ..net.door import ScanDoor
from ..net.pacing import CHUNK_S, DISPLAY_HZ, Pacer
from ..safetext import printable
from ..testing.harness import Harness, condition
from .builds import Builds
from .diagnostics import DiagnosticLog
from .machines import apply as machine_apply
from .machines import machine_info, machine_states
from .mailbox import Client, Mailbox
from .present import INPUT_KINDS, input_kinds, io_bits
from .program import ProgramView
from .protocol import finite
from .running import UNTIL_TIMEOUT, RunControl
from .trend import TREND_MAX, Trend
from .watch import Watch, WatchTable, force, write


class PanelSession:
    """The panel's PLC and everything the page can ask of it.

    Args:
        plc: the loaded PLC, best without probes (it may use the native
            backend): the session moves to a build with probes while a
            breakpoint is set and back when the last one is cleared
            (:meth:`plcrt.Plc.recompiled`), so breakpoints cost nothing until
            they are used.  A PLC loaded with ``instrument=True`` keeps its
            probes.
        breakpoints: whether breakpoints may be set (default: yes).
        kinds: the lesson's own input kinds (address or symbol ->
            ``switch``, ``switch_nc``, ``button``, ``button_nc``); the other
            inputs take theirs from their symbol's comment
            (:func:`plcrt.web.present.input_kinds`).  Inputs that rest at 1
            (normally closed) read 1 from power-up on.
        display_hz: frames per wall second.
        clock, sleep: the wall clock (tests pass their own); without a
            ``sleep``, the pacing waits on the door, so a command or a
            network client's request ends the wait.
        door: the scan-boundary door of the network servers
            (:mod:`plcrt.net.door`): this session's thread runs the PLC, so
            it serves the door between chunks (a new one if not given).
    """

    def __init__(self, plc: Plc, *, breakpoints: bool = True,
                 kinds: dict[str, str] | None = None,
                 display_hz: float = DISPLAY_HZ,
                 clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] | None = None,
                 door: ScanDoor | None = None) -> None:
        self.plc = plc
        self.inputs, self.outputs = io_bits(plc)
        self.kinds = self._rest_inputs(kinds)     # before the power-up snapshot
        self.harness = Harness(plc)
        self.display_hz = display_hz
        self.door = door if door is not None else ScanDoor()
        self.clock = clock
        self.sleep: Callable[[float], None] = sleep if sleep is not None else self.door.wait
        self.program = ProgramView(plc)
        self.builds = Builds(plc, breakpoints=breakpoints, blocks=self.program.blocks,
                             on_break=self._on_break)
        self.pacer = Pacer(clock, self.sleep, display_hz, plc.now_us)
        self.control = RunControl(self.pacer, self._notice, self._reset)
        self.watch_table = WatchTable()
        self.trend = Trend()
        self.clients: dict[int, Client] = {}
        self._lock = threading.Lock()
        self._queue: queue.SimpleQueue[tuple[Client | None, dict[str, Any]]] = \
            queue.SimpleQueue()
        self._seq = 0
        self._last_frame = -1e9
        self._dirty = True
        self._closed = False
        self._thread: threading.Thread | None = None
        self._hello: dict[str, Any] | None = None
        #: the error of the last command applied without a client (tests)
        self.last_error: dict[str, Any] | None = None
        #: load-time and run-time diagnostics, for the pages
        self.diagnostics = DiagnosticLog(self.program.blocks, set(self.program.nets))
        self.diagnostics.sync(plc)

    @property
    def state(self) -> str:
        """stopped, running, stepping, until or paused."""
        return self.control.state

    @property
    def breakable(self) -> bool:
        """Whether breakpoints may be set."""
        return self.builds.breakable

    @property
    def watches(self) -> list[Watch]:
        """The rows of the watch table."""
        return self.watch_table.rows

    # ------------------------------------------------------------------
    # Clients
    # ------------------------------------------------------------------
    def connect(self, notify: Callable[[], None] | None = None) -> Client:
        """A new client; its mailbox gets the next frame."""
        c = Client(Mailbox(notify))
        with self._lock:
            self.clients[id(c)] = c
        self._dirty = True
        return c

    def disconnect(self, client: Client) -> None:
        with self._lock:
            self.clients.pop(id(client), None)

    def submit(self, client: Client | None, msg: dict[str, Any]) -> None:
        """Queue a checked message (:func:`plcrt.web.protocol.validate`);
        it is applied in the runner thread between two chunks of scans."""
        self._queue.put((client, msg))
        self.door.wake()

    def _rest_inputs(self, declared: dict[str, str] | None) -> dict[str, str]:
        """Each input's kind; the inputs that rest at 1 (normally closed)
        are written 1, as their wiring gives them at power-up."""
        kinds = input_kinds(self.plc, self.inputs, declared)
        for addr, kind in kinds.items():
            if INPUT_KINDS.get(kind):
                self.plc.write(addr, 1)
        return kinds

    def hello(self) -> dict[str, Any]:
        """What a page needs to draw the program (sent once per connection)."""
        if self._hello is None:
            self._hello = self.program.hello(self.plc, self.inputs, self.outputs, self.kinds,
                                             self.builds.breakable)
        return {**self._hello, "diagnostics": self.diagnostics.shown,
                "machines": machine_info(self.plc)}

    # ------------------------------------------------------------------
    # The runner thread
    # ------------------------------------------------------------------
    def start(self) -> None:
        """Run :meth:`tick` in a thread of its own until :meth:`close`."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._loop, name="plcrt-panel",
                                            daemon=True)
            self._thread.start()

    def close(self) -> None:
        self._closed = True
        self._queue.put((None, {"type": "_wake"}))
        self.door.wake()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5)

    def _loop(self) -> None:
        while not self._closed:
            try:
                self.tick()
            except Exception as e:  # noqa: BLE001 - the runner must go on
                self.control.state = "stopped"
                self._notice("error", f"internal error: {type(e).__name__}: {e}")

    def tick(self, wait: bool = True) -> None:
        """One round: apply queued commands, run a chunk of scans if a run
        is on, publish a frame if one is due.  ``wait``: block up to a
        frame period for a command when nothing runs."""
        control = self.control
        self._drain(block=wait and not control.busy, timeout=1 / self.display_hz)
        if self._closed:
            return
        # at a scan boundary: the network clients' reads and writes
        self.door.serve(self.plc)
        if not self.builds.breaks and control.state != "paused":
            self._use_build(probes=self.builds.home[0])
        if control.busy:
            control.chunk(self.plc, bool(self.builds.breaks))
        self._maybe_frame()

    def _drain(self, block: bool, timeout: float, jobs: bool = True) -> None:
        """Apply the queued commands; ``block``: first wait up to
        ``timeout`` for one (or, with ``jobs``, for a network client's
        request, which :meth:`tick` serves)."""
        if block and self._queue.empty():
            self.door.wait(timeout, jobs=jobs)
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                return
            self._apply(*item)

    # ------------------------------------------------------------------
    # Commands
    # ------------------------------------------------------------------
    def _apply(self, client: Client | None, msg: dict[str, Any]) -> None:
        kind = msg["type"]
        if kind == "_wake":
            return
        try:
            handler = getattr(self, "_do_" + kind, None)
            if handler is None:
                raise PlcConfigError(f"'{kind}' is not handled by the session")
            handler(client, msg)
        except PlcError as e:
            self._reply(client, msg, e.message)
        self._dirty = True

    def apply(self, msg: dict[str, Any], client: Client | None = None) -> None:
        """Apply a checked message now (in the calling thread; for tests and
        for a session without a runner thread)."""
        self._apply(client, msg)

    def _reply(self, client: Client | None, msg: dict[str, Any], message: str) -> None:
        err = {"type": "error", "request": msg.get("type"), "message": printable(message)}
        if "id" in msg:
            err["id"] = msg["id"]
        if client is not None:
            client.mailbox.put(err)
        else:
            self.last_error = err

    def _broadcast(self, message: dict[str, Any]) -> None:
        with self._lock:
            clients = list(self.clients.values())
        for c in clients:
            c.mailbox.put(message)

    def _notice(self, level: str, message: str) -> None:
        self._broadcast({"type": "notice", "level": level, "message": message})

    def _do_run(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.control.run(self.plc)

    def _do_continue(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.control.cont()

    def _do_stop(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.control.stop()

    def _do_step(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.control.step(self.plc, msg.get("scans", 1))

    def _do_until(self, client: Client | None, msg: dict[str, Any]) -> None:
        pred, what = condition(self.harness, msg["cond"])
        self.control.run_until(self.plc, pred, what, msg["cond"],
                               msg.get("timeout", UNTIL_TIMEOUT))

    def _do_speed(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.pacer.set(msg["mode"], msg.get("factor"), self.plc.now_us)

    def _do_reset(self, client: Client | None, msg: dict[str, Any]) -> None:
        if not self.control.reset_later():
            self._reset()

    def _reset(self) -> None:
        """Power-up: the state right after loading.  Forces, breakpoints,
        watches and trend signals stay (as a force stays in the CPU)."""
        plc = self.plc
        forces = dict(plc.forces)
        plc.restore(self.builds.power_up(plc))
        for k, v in forces.items():
            plc.force(k, v)
        self.control.stop_after_scan = False
        self._apply_breaks()
        self.control.halt()
        self.trend.clear(plc)
        if self.trend.signals:   # the pages' trends start again too (their time went back)
            self._broadcast(self.trend.message())
            self.trend.sent = self.trend.count
        self._notice("info", "power-up reset")

    def _do_set(self, client: Client | None, msg: dict[str, Any]) -> None:
        write(self.plc, msg)

    def _do_force(self, client: Client | None, msg: dict[str, Any]) -> None:
        force(self.plc, msg)

    def _do_unforce(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.plc.unforce(msg.get("addr"))

    def _do_machine(self, client: Client | None, msg: dict[str, Any]) -> None:
        machine_apply(self.plc, msg)

    def _do_watch(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.watch_table.add(self.plc, msg["spec"], msg.get("format", "auto"))

    def _do_unwatch(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.watch_table.remove(msg["spec"])

    def _do_break(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.builds.breaks.add(self._network(msg["network"]).index)
        self._apply_breaks()

    def _do_unbreak(self, client: Client | None, msg: dict[str, Any]) -> None:
        if not self.builds.breaks:
            return
        self.builds.breaks.discard(self._network(msg["network"]).index)
        self._apply_breaks()

    def _network(self, text: str) -> NetworkRef:
        """The network ``text`` names, in the build with probes (the
        session moves there first)."""
        self.builds.check()
        self._use_build(probes=True)
        return self.builds.find(self.plc, text)

    def _apply_breaks(self) -> None:
        self.builds.apply(self.plc, suspended=self.control.reset_after_scan)

    def _do_trend(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.trend.start(self.plc, msg["signals"])
        self._broadcast(self.trend.message())

    def _trend_message(self) -> dict[str, Any]:
        return self.trend.message()

    def _do_history(self, client: Client | None, msg: dict[str, Any]) -> None:
        if client is not None:
            client.mailbox.put(self.trend.message())

    def _do_view(self, client: Client | None, msg: dict[str, Any]) -> None:
        block = self.program.blocks.get(msg["block"].upper())
        if block is None:
            raise PlcConfigError(f"no block '{msg['block']}' in the program")
        if client is not None:
            client.view = block
            nets = msg.get("networks")
            client.nets = None if nets is None else frozenset(nets)

    # ------------------------------------------------------------------
    # Builds and pauses
    # ------------------------------------------------------------------
    def _use_build(self, probes: bool) -> None:
        """Scan from now on in the build with (or without) network probes,
        in exactly the state of the one in use: between scans only (never
        while paused inside one).  Watches, the trend, a running ``until``
        and the power-up state follow."""
        new = self.builds.moved(self.plc, probes)
        if new is None:
            return
        self.plc = new
        self.harness = Harness(new)
        self.watch_table.rebind(new)
        self.trend.rebind(new)
        control = self.control
        if control.until is not None:
            pred, what = condition(self.harness, control.until_cond)
            control.until = (pred, what, control.until[2])
        self._apply_breaks()

    def _on_break(self, net: NetworkRef) -> None:
        """Called by the program's code before a network with a breakpoint;
        must never raise (it would fault the PLC)."""
        control = self.control
        try:
            if net.index not in self.builds.breaks or control.reset_after_scan \
                    or self._closed:
                return
            before = control.pause(net)
            self._notice("info", printable(f"break at {net.name} (t={self.plc.time:g} s,"
                                           f" scan {self.plc.scans + 1})"))
            self._publish()
            while control.state == "paused" and not self._closed:
                # inside a scan: network requests wait for its end
                self._drain(block=True, timeout=1 / self.display_hz, jobs=False)
                if self._dirty and control.state == "paused":
                    self._publish()
            control.resumed(before)
        except Exception as e:  # noqa: BLE001 - see above
            control.state = "stopped"
            self._notice("error", f"internal error while paused: {e}")
        finally:
            control.paused_at = None

    # ------------------------------------------------------------------
    # Frames
    # ------------------------------------------------------------------
    def _maybe_frame(self) -> None:
        now = self.clock()
        if now - self._last_frame >= 1 / self.display_hz or \
                (self._dirty and self.control.state in ("stopped", "paused")):
            self._publish()

    def _publish(self) -> None:
        if self.diagnostics.sync(self.plc):
            self._broadcast(self.diagnostics.message())
        frame = self.frame()
        with self._lock:
            clients = list(self.clients.values())
        for c in clients:
            c.mailbox.put_frame(frame)
        self._last_frame = self.clock()
        self._dirty = False

    def frame(self) -> dict[str, Any]:
        """The state now, as the ``frame`` message."""
        plc, control = self.plc, self.control
        self._seq += 1
        rate = self.pacer.rate(self.clock(), plc.now_us)
        with self._lock:
            views = {c.view for c in self.clients.values() if c.nets is None} or \
                ({"OB1"} if not self.clients else set())
            shown = {n for c in self.clients.values() if c.nets is not None for n in c.nets}
        nets = self.program.states(plc, views, shown)
        bits = {}
        for a in self.inputs + self.outputs:
            try:
                bits[a] = plc.read(a)
            except PlcError:
                pass
        mode = plc.mode if plc.mode == "RUN" else \
            ("STOP (fault)" if plc.fault is not None else "STOP")
        trend = self.trend.tail()
        run = control.state if control.state in ("stopped", "paused") else "running"
        return {
            "type": "frame", "seq": self._seq, "t": plc.now_us / 1e6, "scans": plc.scans,
            "mode": mode, "run": run,
            "paused_at": control.paused_at.name if control.paused_at else None,
            "speed": self.pacer.to_dict(),
            "rate": round(rate, 3), "io": bits, "nets": nets,
            "watch": [self.watch_table.row(plc, w) for w in self.watch_table.rows],
            "forces": {k: finite(v) for k, v in plc.forces.items()},
            "breaks": self.builds.names(plc),
            "axes": [dict(a.to_dict()) for a in plc.axes()],
            "drives": [dict(d.to_dict()) for d in plc.drives()],
            "trend": trend, "machines": machine_states(plc),
            "until": control.until[1] if control.until else None,
        }

    def _watch_row(self, w: Watch) -> dict[str, Any]:
        return self.watch_table.row(self.plc, w)


__all__ = ["CHUNK_S", "Client", "DISPLAY_HZ", "Mailbox", "PanelSession", "TREND_MAX"]
