"""A served PLC: the runner thread, the door, and the protocol servers on
one asyncio loop in a thread of their own.

:class:`Serving` is what ``plcrt.serve(plc, s7=..., modbus=...)`` returns
and what ``plcrt serve`` runs: it starts the servers (each a
:class:`plcrt.net.tcp.TcpService` made by its factory in
:data:`SERVICES`), then the runner (:class:`plcrt.net.runner.Runner`),
and stops them in the reverse order.  When the browser panel runs the PLC,
its session serves the same door from its own thread and no runner is
started (``runner=False``).

What it is: start-up, addresses and shut-down.  What it is not: a
protocol (each has its module), the pacing (:mod:`plcrt.net.runner`).
"""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Callable, Mapping
from typing import Any

from ..engine.runtime import Plc
from ..errors import PlcConfigError, PlcError
from ..safetext import printable
from .door import ScanDoor
from .options import ServerOptions
from .runner import Runner
from .tcp import TcpService

__all__ = ["SERVICES", "Serving", "ServiceFactory"]

#: builds a protocol server for a PLC: (door, the PLC's static facts, options)
ServiceFactory = Callable[[ScanDoor, Plc, ServerOptions], TcpService]

#: the protocol servers by name (``plcrt.serve(plc, s7=...)``, ``plcrt
#: serve --s7``); each protocol module adds itself in :mod:`plcrt.net.serving`
SERVICES: dict[str, ServiceFactory] = {}

#: seconds start-up may take before it is given up
START_TIMEOUT = 10.0


class Serving:
    """A PLC served on the network (a context manager).

    Args:
        plc: the PLC; while served, only the runner's thread touches it
            (use :attr:`door` — or the servers — to read and write it).
        servers: protocol name -> options (see :data:`SERVICES`).
        speed: the runner's speed (``"realtime"``, ``"max"``,
            ``"lockstep"`` or a factor).
        runner: start a runner thread (False: the caller's own thread runs
            the PLC and serves :attr:`door`, as the panel does).
        door: the door to use (a new one if not given).
    """

    def __init__(self, plc: Plc, servers: Mapping[str, ServerOptions], *,
                 speed: Any = "realtime", runner: bool = True,
                 door: ScanDoor | None = None) -> None:
        unknown = [k for k in servers if k not in SERVICES]
        if unknown:
            raise PlcConfigError(f"no server called {printable(unknown[0])} (there are: "
                                 f"{', '.join(sorted(SERVICES)) or 'none'})")
        self.plc = plc
        self.door = door if door is not None else ScanDoor()
        self.runner = Runner(plc, speed=speed, door=self.door) if runner else None
        self.services: dict[str, TcpService] = {
            name: SERVICES[name](self.door, plc, opts) for name, opts in servers.items()}
        self.addresses: dict[str, tuple[str, int]] = {}
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._started = False

    # -- life ----------------------------------------------------------------
    def start(self) -> "Serving":
        """Listen on every server's address, then start the runner.

        Raises:
            PlcConfigError: an address cannot be bound (in use, not this
                machine's); nothing is left listening then.
        """
        if self._started:
            return self
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever,
                                        name="plcrt-servers", daemon=True)
        self._thread.start()
        fut = asyncio.run_coroutine_threadsafe(self._start_all(), self._loop)
        try:
            fut.result(START_TIMEOUT)
        except OSError as e:
            self._stop_loop()
            raise PlcConfigError(f"cannot listen: {printable(str(e))}") from None
        except PlcError:
            self._stop_loop()
            raise
        self._started = True
        if self.runner is not None:
            self.runner.start()
        return self

    async def _start_all(self) -> None:
        done: list[TcpService] = []
        try:
            for name, svc in self.services.items():
                self.addresses[name] = await svc.start()
                done.append(svc)
        except BaseException:
            for svc in done:
                await svc.close()
            raise

    def close(self) -> None:
        """Stop the runner, close every server and its clients."""
        if self.runner is not None:
            self.runner.close()
        else:
            self.door.close()
        if self._thread is not None and self._loop is not None and self._loop.is_running():
            fut = asyncio.run_coroutine_threadsafe(self._close_all(), self._loop)
            try:
                fut.result(START_TIMEOUT)
            except Exception:
                pass
        self._stop_loop()

    async def _close_all(self) -> None:
        for svc in self.services.values():
            await svc.close()

    def _stop_loop(self) -> None:
        loop = self._loop
        if loop is None:
            return
        if self._thread is not None:
            loop.call_soon_threadsafe(loop.stop)
            self._thread.join(START_TIMEOUT)
            self._thread = None
        if not loop.is_running() and not loop.is_closed():
            loop.close()
        self._started = False

    def __enter__(self) -> "Serving":
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- conveniences ------------------------------------------------------
    def port(self, name: str) -> int:
        """The port a server really listens on (after :meth:`start`)."""
        try:
            return self.addresses[name][1]
        except KeyError:
            raise PlcConfigError(f"no {printable(name)} server is running") from None

    def call(self, job: Callable[[Plc], Any], timeout: float = 10.0) -> Any:
        """Run ``job(plc)`` at the next scan boundary and return its result
        (for tests and scripts beside the servers)."""
        return self.door.post(job).result(timeout)
