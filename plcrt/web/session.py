"""The panel's PLC runner: run modes, speed, breakpoints, watch and force,
trends and frames.  No web code: the server hands it checked messages
(:mod:`plcrt.web.protocol`) and carries its frames; tests drive it
directly.

One thread touches the PLC: :meth:`PanelSession.start` runs
:meth:`PanelSession.tick` in a loop, and every command a client sends is
queued (:meth:`submit`) and applied between two chunks of scans.  The scan
runs in simulated time; a *frame* (time, scans, run state, the status of
the networks clients look at, inputs and outputs, watch table, forces,
axes, drives and new trend samples) is sampled at the end of a scan at the
display rate (:data:`DISPLAY_HZ`), never per scan, and put into every
client's one-slot :class:`Mailbox`: a slow client skips frames, the scan
never waits for it.

Speed: ``realtime`` paces simulated time to the wall clock, ``factor``
runs N simulated seconds per wall second, ``max`` runs as fast as it can
in chunks of about :data:`CHUNK_S` wall seconds.

Breakpoints stop inside a scan, as the debugger's do (:mod:`plcrt.debug.
session`): the program is loaded with network probes
(``instrument=True``) and ``CoverageMap.on_break`` is called before a
network with a breakpoint.  The handler, in the runner thread, publishes a
frame of that moment and applies commands until one resumes the scan
(``continue``, ``run``, ``step``, ``stop``, ``until`` or ``reset``; the
scan in progress always runs to its end first).

It is not a second engine: scans are :meth:`plcrt.Plc.scan`, conditions
the test harness's, values go through the PLC's address access and
``set``/``force`` through the code of ``plcrt run --set``.
"""

from __future__ import annotations

import queue
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..engine.access import force_covers
from ..engine.coverage import NetworkRef
from ..engine.runtime import Plc
from ..errors import PlcConfigError, PlcError, PlcRuntimeError
from ..lang import ir
from ..safetext import printable
from ..term.options import SetItem, apply_sets, parse_sets
from ..testing.harness import Harness, condition, reader
from ..view.ladder import Ladder, to_ladder
from ..view.status import PlcStatus
from .diagnostics import DiagnosticLog
from .mailbox import Client, Mailbox
from .present import INPUT_KINDS, axis_marks, drive_marks, format_value, input_kinds, io_bits, \
    symbol_names
from .protocol import MAX_WATCH, finite
from .svg import network_state, network_svg, stl_lines

#: frames per wall second
DISPLAY_HZ = 15.0
#: wall seconds one chunk of scans takes at most in "as fast as possible"
CHUNK_S = 0.05
#: trend samples kept (one per scan)
TREND_MAX = 20000
#: trend samples one frame carries at most (more are thinned out)
TREND_TAIL = 2000
#: real time that may be lost before the pacing starts again from now
MAX_LAG_S = 0.5
#: default timeout of ``until`` (simulated seconds)
UNTIL_TIMEOUT = 10.0


@dataclass
class _Watch:
    spec: str
    format: str
    read: Callable[[], Any]
    width: int              #: bytes, 0 for a bit


@dataclass
class _Trend:
    signals: list[str] = field(default_factory=list)
    readers: list[Callable[[], Any]] = field(default_factory=list)
    t: deque[float] = field(default_factory=lambda: deque(maxlen=TREND_MAX))
    rows: deque[list[Any]] = field(default_factory=lambda: deque(maxlen=TREND_MAX))
    count: int = 0          #: samples recorded since the trend started
    sent: int = 0           #: samples already carried by a frame


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
        clock, sleep: the wall clock (tests pass their own).
    """

    def __init__(self, plc: Plc, *, breakpoints: bool = True,
                 kinds: dict[str, str] | None = None,
                 display_hz: float = DISPLAY_HZ,
                 clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.plc = plc
        self.inputs, self.outputs = io_bits(plc)
        self.kinds = self._rest_inputs(kinds)     # before the power-up snapshot
        self.harness = Harness(plc)
        self.display_hz = display_hz
        self.clock, self.sleep = clock, sleep
        #: breakpoints may be set (in the build with probes)
        self.breakable = breakpoints or plc.coverage is not None
        #: the build scans run in when no breakpoint is set: with or without
        #: probes, and its backend
        self._home = (plc.coverage is not None, plc.backend["name"])
        #: the state at power-up in each build (with probes: True), for reset
        self._power_ups: dict[bool, Plc] = {self._home[0]: plc.snapshot()}
        self._until_cond = ""
        self.clients: dict[int, Client] = {}
        self._lock = threading.Lock()
        self._queue: queue.SimpleQueue[tuple[Client | None, dict[str, Any]]] = \
            queue.SimpleQueue()
        self.state = "stopped"          #: stopped, running, paused
        self.paused_at: NetworkRef | None = None
        self._left: int | None = None   # scans left of a step
        self._until: tuple[Callable[[], bool], str, int] | None = None
        self._stop_after_scan = False
        self._reset_after_scan = False
        self._before_pause = "running"
        self.speed = "realtime"
        self.factor = 1.0
        self._anchor: tuple[float, int] | None = None
        self._rate = 0.0
        self._rate_mark: tuple[float, int] = (clock(), plc.now_us)
        self.watches: list[_Watch] = []
        self.breaks: set[int] = set()
        self.trend = _Trend()
        self._seq = 0
        self._last_frame = -1e9
        self._dirty = True
        self._closed = False
        self._thread: threading.Thread | None = None
        self._chunk = 1
        prog = plc.program
        self._nets: dict[tuple[str, int], tuple[ir.Pou, ir.Network, Ladder]] = {
            (p.ident, n.number): (p, n, to_ladder(n, program=prog))
            for p in prog.pous for n in p.networks}
        self._blocks = {p.ident.upper(): p.ident for p in prog.pous}
        for p in prog.pous:
            self._blocks.setdefault(p.name.upper(), p.ident)
        self._names = symbol_names(plc.symbols)
        if plc.coverage is not None:
            plc.coverage.on_break = self._on_break
        self._hello: dict[str, Any] | None = None
        #: the error of the last command applied without a client (tests)
        self.last_error: dict[str, Any] | None = None
        #: load-time and run-time diagnostics, for the pages
        self.diagnostics = DiagnosticLog(self._blocks, set(self._nets))
        self.diagnostics.sync(plc)

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

    def _rest_inputs(self, declared: dict[str, str] | None) -> dict[str, str]:
        """Each input's kind; the inputs that rest at 1 (normally closed)
        are written 1, as their wiring gives them at power-up."""
        kinds = input_kinds(self.plc, self.inputs, declared)
        for addr, kind in kinds.items():
            if INPUT_KINDS.get(kind):
                self.plc.write(addr, 1)
        return kinds

    # ------------------------------------------------------------------
    # The program, once
    # ------------------------------------------------------------------
    def hello(self) -> dict[str, Any]:
        """What a page needs to draw the program (sent once per connection)."""
        if self._hello is None:
            self._hello = self._make_hello()
        return {**self._hello, "diagnostics": self.diagnostics.shown}

    def _make_hello(self) -> dict[str, Any]:
        plc, prog = self.plc, self.plc.program
        blocks = []
        for p in prog.pous:
            nets = []
            for n in p.networks:
                lad = self._nets[(p.ident, n.number)][2]
                svg = network_svg(p, n, program=prog, names=self._names, lad=lad)
                nets.append({"number": n.number, "id": f"{p.ident}/{n.number}",
                             "title": n.title, "comment": n.comment, "svg": svg,
                             "stl": stl_lines(n) if svg is None else None,
                             "why": lad.reason})
            blocks.append({"id": p.ident, "name": p.name, "title": p.title,
                           "comment": p.comment, "networks": nets})
        symbols = []
        table = plc.symbols
        if table is not None:
            for s in list(table.entries.values())[:5000]:
                symbols.append({"name": s.name, "address": s.address, "comment": s.comment})

        def io(addr: str) -> dict[str, str]:
            shown, tip = self._names(addr)
            return {"addr": addr, "name": shown if shown != addr else "", "comment": tip,
                    "kind": self.kinds.get(addr, "switch")}

        return {"type": "hello", "files": sorted({p.loc.file for p in prog.pous}),
                "blocks": blocks, "symbols": symbols,
                "inputs": [io(a) for a in self.inputs],
                "outputs": [io(a) for a in self.outputs],
                "scan_ms": plc.scan_us / 1000, "axes": axis_marks(plc),
                "drives": drive_marks(plc), "breakable": self.breakable}

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
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5)

    def _loop(self) -> None:
        while not self._closed:
            try:
                self.tick()
            except Exception as e:  # noqa: BLE001 - the runner must go on
                self.state = "stopped"
                self._broadcast({"type": "notice", "level": "error",
                                 "message": f"internal error: {type(e).__name__}: {e}"})

    def tick(self, wait: bool = True) -> None:
        """One round: apply queued commands, run a chunk of scans if a run
        is on, publish a frame if one is due.  ``wait``: block up to a
        frame period for a command when nothing runs."""
        busy = self.state == "running" or self._left is not None or self._until is not None
        self._drain(block=wait and not busy, timeout=1 / self.display_hz)
        if self._closed:
            return
        if not self.breaks and self.state != "paused":
            self._use_build(probes=self._home[0])
        if self.state == "running" or self._left is not None or self._until is not None:
            self._run_chunk()
        self._maybe_frame()

    def _drain(self, block: bool, timeout: float) -> None:
        try:
            item = self._queue.get(timeout=timeout) if block else self._queue.get_nowait()
        except queue.Empty:
            return
        while True:
            self._apply(*item)
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                return

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

    def _do_run(self, client: Client | None, msg: dict[str, Any]) -> None:
        self._left, self._until = None, None
        self._go("running")

    def _do_continue(self, client: Client | None, msg: dict[str, Any]) -> None:
        if self.state != "paused":
            raise PlcConfigError("continue: no scan is paused at a breakpoint")
        self.state = self._before_pause   # the step, until or run goes on

    def _do_stop(self, client: Client | None, msg: dict[str, Any]) -> None:
        self._left, self._until = None, None
        if self.state == "paused":
            self._stop_after_scan = True
        self.state = "stopped"

    def _do_step(self, client: Client | None, msg: dict[str, Any]) -> None:
        self._until = None
        n = msg.get("scans", 1)
        if self.state == "paused":   # the paused scan is the first of them
            self._left = n
            self.state = "stepping"
            return
        self._left = n
        self._go("stepping")

    def _do_until(self, client: Client | None, msg: dict[str, Any]) -> None:
        pred, what = condition(self.harness, msg["cond"])
        timeout = msg.get("timeout", UNTIL_TIMEOUT)
        self._left = None
        self._until = (pred, what, self.plc.now_us + round(timeout * 1e6))
        self._until_cond = msg["cond"]
        self._go("until")

    def _go(self, state: str) -> None:
        self.state = state
        self._anchor = (self.clock(), self.plc.now_us)

    def _do_speed(self, client: Client | None, msg: dict[str, Any]) -> None:
        mode = msg["mode"]
        if mode == "factor" and "factor" not in msg:
            raise PlcConfigError("speed factor needs a factor (simulated s per wall s)")
        self.speed = mode
        self.factor = msg.get("factor", 1.0) if mode == "factor" else 1.0
        self._anchor = (self.clock(), self.plc.now_us)

    def _do_reset(self, client: Client | None, msg: dict[str, Any]) -> None:
        if self.state == "paused":
            self._reset_after_scan = True
            self._stop_after_scan = True
            self.state = "stopped"
            return
        self._reset()

    def _reset(self) -> None:
        """Power-up: the state right after loading.  Forces, breakpoints,
        watches and trend signals stay (as a force stays in the CPU)."""
        forces = dict(self.plc.forces)
        self.plc.restore(self._power_up())
        for k, v in forces.items():
            self.plc.force(k, v)
        self._stop_after_scan = False
        self._apply_breaks()
        self.state, self._left, self._until = "stopped", None, None
        self._clear_trend()
        if self.trend.signals:   # the pages' trends start again too (their time went back)
            self._broadcast(self._trend_message())
            self.trend.sent = self.trend.count
        self._broadcast({"type": "notice", "level": "info", "message": "power-up reset"})

    def _do_set(self, client: Client | None, msg: dict[str, Any]) -> None:
        apply_sets(self.plc, self._sets(msg))

    def _do_force(self, client: Client | None, msg: dict[str, Any]) -> None:
        (item,) = self._sets(msg)
        try:
            self.plc.force(item.addr, item.value)
        except PlcError as e:
            raise PlcConfigError(f"force {printable(item.item)}: {e.message}") from None

    @staticmethod
    def _sets(msg: dict[str, Any]) -> list[SetItem]:
        """``addr``/``value`` read as one ``--set ADDR=VALUE``."""
        try:
            return parse_sets([f"{msg['addr']}={msg['value']}"])
        except PlcConfigError as e:
            raise PlcConfigError(e.message.removeprefix("--")) from None

    def _do_unforce(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.plc.unforce(msg.get("addr"))

    def _do_watch(self, client: Client | None, msg: dict[str, Any]) -> None:
        spec, fmt = msg["spec"], msg.get("format", "auto")
        if any(w.spec == spec and w.format == fmt for w in self.watches):
            return
        if len(self.watches) >= MAX_WATCH:
            # every row is read and sent to every page in every frame
            raise PlcConfigError(f"the watch table is full ({MAX_WATCH} rows at most): "
                                 f"remove a row first")
        read, width = self._watch_reader(spec, fmt)
        self.watches.append(_Watch(spec, fmt, read, width))

    def _watch_reader(self, spec: str, fmt: str) -> tuple[Callable[[], Any], int]:
        from ..trace.recorder import is_device_signal
        if is_device_signal(spec):
            if fmt not in ("auto", "int", "real"):
                raise PlcConfigError(f"{spec} is a device signal: watch it as auto")
            return reader(self.plc, spec), 4
        base = spec.split(":")[0].strip()
        _, _, width, _, _ = self.plc.locate(spec)
        if fmt == "real":
            if width != 4:
                raise PlcConfigError(f"{spec}: REAL needs a double word (VD, MD, ...)")
            return reader(self.plc, base + ":REAL"), 4
        if fmt == "bit":
            try:
                return reader(self.plc, base + ":BIT"), 0
            except PlcError:
                if width != 0:
                    raise PlcConfigError(f"{spec} is not a bit") from None
                return reader(self.plc, base), 0
        need = {"int": 2, "dint": 4}.get(fmt)
        if need is not None and width != need:
            raise PlcConfigError(f"{spec}: {fmt.upper()} needs a "
                                 f"{'word' if need == 2 else 'double word'}")
        return reader(self.plc, spec), width

    def _do_unwatch(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.watches = [w for w in self.watches if w.spec != msg["spec"]]

    def _network(self, text: str) -> NetworkRef:
        import re
        if not self.breakable:
            raise PlcConfigError("breakpoints are off (plcrt serve --no-breakpoints)")
        self._use_build(probes=True)
        cov = self.plc.coverage
        assert cov is not None
        m = re.fullmatch(r"(?:([^/\s]+)\s*/\s*)?(\d+)", text.strip())
        if m is None:
            raise PlcConfigError(f"'{text}' is not a network: write OB1/3, SBR0/1 or 3")
        block = self._blocks.get((m.group(1) or "OB1").upper())
        if block is None:
            raise PlcConfigError(f"no block '{m.group(1)}' in the program")
        net = cov.find(block, int(m.group(2)))
        if net is None:
            raise PlcConfigError(f"no network {block}/{m.group(2)} with code to stop in")
        return net

    def _do_break(self, client: Client | None, msg: dict[str, Any]) -> None:
        self.breaks.add(self._network(msg["network"]).index)
        self._apply_breaks()

    def _do_unbreak(self, client: Client | None, msg: dict[str, Any]) -> None:
        if not self.breaks:
            return
        self.breaks.discard(self._network(msg["network"]).index)
        self._apply_breaks()

    def _apply_breaks(self) -> None:
        cov = self.plc.coverage
        if cov is None:
            return
        cov.on_break = self._on_break
        bp = cov.breakpoints
        bp[:] = bytes(len(bp))
        if not self._reset_after_scan:
            for k in self.breaks:
                bp[k] = 1

    def _do_trend(self, client: Client | None, msg: dict[str, Any]) -> None:
        signals = list(dict.fromkeys(msg["signals"]))
        readers = [reader(self.plc, s) for s in signals]   # all checked first
        self.trend.signals, self.trend.readers = signals, readers
        self._clear_trend()
        obs = self.plc.observers
        if self._sample in obs:
            obs.remove(self._sample)
        if signals:
            obs.append(self._sample)
        self._broadcast(self._trend_message())

    def _clear_trend(self) -> None:
        tr = self.trend
        tr.t.clear()
        tr.rows.clear()
        tr.count = tr.sent = 0
        if tr.signals:
            self._sample(self.plc)

    def _sample(self, plc: Plc) -> None:
        tr = self.trend
        tr.t.append(plc.now_us / 1e6)
        tr.rows.append([finite(r()) for r in tr.readers])
        tr.count += 1

    def _trend_message(self) -> dict[str, Any]:
        tr = self.trend
        return {"type": "trend", "signals": tr.signals, "end": tr.count,
                "t": list(tr.t), "v": list(tr.rows)}

    def _do_history(self, client: Client | None, msg: dict[str, Any]) -> None:
        if client is not None:
            client.mailbox.put(self._trend_message())

    def _do_view(self, client: Client | None, msg: dict[str, Any]) -> None:
        block = self._blocks.get(msg["block"].upper())
        if block is None:
            raise PlcConfigError(f"no block '{msg['block']}' in the program")
        if client is not None:
            client.view = block
            nets = msg.get("networks")
            client.nets = None if nets is None else frozenset(nets)

    # ------------------------------------------------------------------
    # Running
    # ------------------------------------------------------------------
    def _run_chunk(self) -> None:
        """A chunk of scans sized to the speed; stops at a step's end, a
        condition, a breakpoint's stop, a fault or STOP mode."""
        plc = self.plc
        if plc.mode != "RUN":
            self._finish_run("the CPU is in STOP mode: scans do nothing")
            return
        n = self._scans_now()
        if n <= 0:
            return
        per_scan = (self._left is not None or self._until is not None
                    or bool(self.breaks))
        t0 = self.clock()
        try:
            if per_scan:
                for _ in range(n):
                    plc.scan(1)
                    if self._after_scan():
                        break
            else:
                if self._left is not None:
                    n = min(n, self._left)
                plc.scan(n)
        except PlcRuntimeError as e:
            self.state, self._left, self._until = "stopped", None, None
            self._broadcast({"type": "notice", "level": "error",
                             "message": printable("; ".join(str(d) for d in e.diagnostics)
                                                  or e.message)})
            return
        dt = self.clock() - t0
        if self.speed == "max" and n > 0:
            per = dt / n if dt > 0 else 1e-6
            self._chunk = max(1, min(100000, int(CHUNK_S / per)))

    def _after_scan(self) -> bool:
        """After one scan of a per-scan run: True ends the chunk."""
        if self._reset_after_scan:
            self._reset_after_scan = False
            self._reset()
            return True
        if self._stop_after_scan:
            self._stop_after_scan = False
            self.state = "stopped"
            return True
        if self._left is not None:
            self._left -= 1
            if self._left <= 0:
                self._left = None
                self.state = "stopped"
                return True
        if self._until is not None:
            pred, what, deadline = self._until
            if pred():
                return self._end_until("info", f"'{what}' is true at t={self.plc.time:g} s")
            if self.plc.now_us >= deadline:
                return self._end_until("warning", f"'{what}' still false at the timeout "
                                                  f"(t={self.plc.time:g} s)")
        if self.state not in ("running", "stepping", "until"):
            return True
        return self.plc.mode != "RUN"

    def _end_until(self, level: str, message: str) -> bool:
        """A run until a condition ends (met or timed out): stop and say so."""
        self._until = None
        self.state = "stopped"
        self._broadcast({"type": "notice", "level": level, "message": printable(message)})
        return True

    def _scans_now(self) -> int:
        """How many scans this chunk runs."""
        scan_us = self.plc.scan_us
        if self.state == "stepping" or self._left is not None:
            if self.speed == "max":
                return min(self._left or 1, self._chunk)
        if self.speed == "max":
            return self._chunk
        now = self.clock()
        sim = self.plc.now_us
        if self._anchor is None:
            self._anchor = (now, sim)
        w0, s0 = self._anchor
        factor = self.factor if self.speed == "factor" else 1.0
        target = s0 + (now - w0) * factor * 1e6
        lag = (target - sim) / 1e6 / factor
        if lag > MAX_LAG_S:   # too far behind: pace from here on
            self._anchor = (now, sim)
            target = sim + scan_us
        n = int((target - sim) // scan_us)
        if n <= 0:
            wait = (sim + scan_us - target) / 1e6 / factor
            self.sleep(min(wait, 1 / self.display_hz, 0.02))
            return 0
        cap = max(1, int(factor * 1e6 / self.display_hz / scan_us) + 1)
        return min(n, cap)

    def _finish_run(self, message: str) -> None:
        self.state, self._left, self._until = "stopped", None, None
        self._broadcast({"type": "notice", "level": "warning", "message": message})

    # ------------------------------------------------------------------
    # Breakpoints (inside a scan)
    # ------------------------------------------------------------------
    def _use_build(self, probes: bool) -> None:
        """Scan from now on in the build with (or without) network probes,
        in exactly the state of the one in use: between scans only (never
        while paused inside one).  Watches, the trend, a running ``until``
        and the power-up state follow."""
        old = self.plc
        if (old.coverage is not None) == probes:
            return
        new = old.recompiled(instrument=probes, backend=self._backend(probes))
        new.observers[:] = old.observers
        self.plc = new
        self.harness = Harness(new)
        for w in self.watches:
            w.read, w.width = self._watch_reader(w.spec, w.format)
        self.trend.readers = [reader(new, s) for s in self.trend.signals]
        if self._until is not None:
            pred, what = condition(self.harness, self._until_cond)
            self._until = (pred, what, self._until[2])
        if new.coverage is not None:
            new.coverage.on_break = self._on_break
        self._apply_breaks()

    def _power_up(self) -> Plc:
        """The power-up state in the build in use."""
        probes = self.plc.coverage is not None
        snap = self._power_ups.get(probes)
        if snap is None:
            home = self._power_ups[self._home[0]]
            snap = self._power_ups[probes] = home.recompiled(instrument=probes,
                                                             backend=self._backend(probes))
        return snap

    def _backend(self, probes: bool) -> str:
        """The backend of the build with (or without) probes: the loaded
        one's for its own kind, Python for the other (the native backend
        does not compile probes)."""
        return self._home[1] if probes == self._home[0] else "python"

    def _on_break(self, net: NetworkRef) -> None:
        """Called by the program's code before a network with a breakpoint;
        must never raise (it would fault the PLC)."""
        try:
            if net.index not in self.breaks or self._reset_after_scan or self._closed:
                return
            self.paused_at, before = net, self.state
            self._before_pause = before
            self.state = "paused"
            self._broadcast({"type": "notice", "level": "info",
                             "message": printable(f"break at {net.name} (t={self.plc.time:g} s,"
                                                  f" scan {self.plc.scans + 1})")})
            self._publish()
            while self.state == "paused" and not self._closed:
                self._drain(block=True, timeout=1 / self.display_hz)
                if self._dirty and self.state == "paused":
                    self._publish()
            if before == "until" and self.state == "stepping":
                self._until = None
        except Exception as e:  # noqa: BLE001 - see above
            self.state = "stopped"
            self._broadcast({"type": "notice", "level": "error",
                             "message": f"internal error while paused: {e}"})
        finally:
            self.paused_at = None

    # ------------------------------------------------------------------
    # Frames
    # ------------------------------------------------------------------
    def _maybe_frame(self) -> None:
        now = self.clock()
        if now - self._last_frame >= 1 / self.display_hz or \
                (self._dirty and self.state in ("stopped", "paused")):
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
        plc = self.plc
        self._seq += 1
        now, sim = self.clock(), plc.now_us
        w0, s0 = self._rate_mark
        if now - w0 >= 0.5:
            self._rate = (sim - s0) / 1e6 / (now - w0) if now > w0 else 0.0
            self._rate_mark = (now, sim)
        with self._lock:
            views = {c.view for c in self.clients.values() if c.nets is None} or \
                ({"OB1"} if not self.clients else set())
            shown = {n for c in self.clients.values() if c.nets is not None for n in c.nets}
        status = PlcStatus(plc)
        nets = {}
        for (b, n), (p, net, lad) in self._nets.items():
            key = f"{b}/{n}"
            if b in views or key in shown:
                nets[key] = network_state(p, net, status, program=plc.program,
                                          lad=lad).to_dict()
        bits = {}
        for a in self.inputs + self.outputs:
            try:
                bits[a] = plc.read(a)
            except PlcError:
                pass
        mode = plc.mode if plc.mode == "RUN" else \
            ("STOP (fault)" if plc.fault is not None else "STOP")
        tr = self.trend
        new = min(tr.count - tr.sent, len(tr.t))
        tail_t, tail_v = list(tr.t)[len(tr.t) - new:], list(tr.rows)[len(tr.rows) - new:]
        if new > TREND_TAIL:
            step = -(-new // TREND_TAIL)
            tail_t, tail_v = tail_t[::step] + tail_t[-1:], tail_v[::step] + tail_v[-1:]
        start = tr.count - new
        tr.sent = tr.count
        run = self.state if self.state in ("stopped", "paused") else "running"
        cov = plc.coverage
        return {
            "type": "frame", "seq": self._seq, "t": plc.now_us / 1e6, "scans": plc.scans,
            "mode": mode, "run": run,
            "paused_at": self.paused_at.name if self.paused_at else None,
            "speed": {"mode": self.speed, "factor": self.factor},
            "rate": round(self._rate, 3), "io": bits, "nets": nets,
            "watch": [self._watch_row(w) for w in self.watches],
            "forces": {k: finite(v) for k, v in plc.forces.items()},
            "breaks": sorted(cov.networks[k].name for k in self.breaks) if cov else [],
            "axes": [dict(a.to_dict()) for a in plc.axes()],
            "drives": [dict(d.to_dict()) for d in plc.drives()],
            "trend": {"signals": tr.signals, "start": start, "end": tr.count,
                      "t": tail_t, "v": tail_v},
            "until": self._until[1] if self._until else None,
        }

    def _watch_row(self, w: _Watch) -> dict[str, Any]:
        try:
            v = w.read()
            text = format_value(v, w.format, w.width)
        except PlcError as e:
            text = f"error: {e.message}"
        return {"spec": w.spec, "format": w.format, "value": text,
                "forced": self._is_forced(w.spec)}

    def _is_forced(self, spec: str) -> bool:
        """Whether a force overlaps ``spec`` (forcing Q0.0 marks QB0 too)."""
        return force_covers(self.plc, spec)


__all__ = ["CHUNK_S", "Client", "DISPLAY_HZ", "Mailbox", "PanelSession", "TREND_MAX"]
