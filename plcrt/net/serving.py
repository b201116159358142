"""``plcrt.serve``: a PLC on the network, from Python.

Each protocol server adds its factory to :data:`plcrt.net.host.SERVICES`
here, so that one table says which servers exist; :func:`serve` checks the
arguments and builds a :class:`plcrt.net.host.Serving`.

What it is: the table and the public function.  What it is not: a
protocol, the runner or the loop (:mod:`plcrt.net.host`).
"""

from __future__ import annotations

from typing import Any

from ..engine.runtime import Plc
from ..errors import PlcConfigError
from ..safetext import shown_value
from .door import ScanDoor
from .host import SERVICES, Serving
from .lockstep import LockstepServer
from .modbus import create as _modbus, with_map
from .options import ServerOptions, WriteGuard, parse_listen, parse_ranges
from .s7 import make_s7
from .serial import pty_services

__all__ = ["serve"]

SERVICES["lockstep"] = LockstepServer
SERVICES["s7"] = make_s7
SERVICES["modbus"] = _modbus


def _options(name: str, spec: Any, *, max_connections: int, idle_timeout: float,
             guard: WriteGuard) -> ServerOptions:
    if isinstance(spec, ServerOptions):
        return spec
    return ServerOptions(listen=parse_listen(spec, what=f"{name} server"),
                         max_connections=max_connections, idle_timeout=idle_timeout,
                         guard=guard)


def serve(plc: Plc, *, s7: Any = None, modbus: Any = None, lockstep: Any = None,
          speed: Any = "realtime", max_connections: int = 8,
          idle_timeout: float = 60.0, read_only: bool = False,
          allow_writes: str | None = None, runner: bool = True,
          door: ScanDoor | None = None, start: bool = True,
          modbus_map: Any = None, serial: Any = None) -> Serving:
    """Serve ``plc`` on the network; returns the running :class:`Serving`
    (a context manager: leaving it closes everything).

    Args:
        s7, modbus, lockstep: the servers to start, each a port (``0``:
            any free one), ``"HOST:PORT"``, or a
            :class:`~plcrt.net.options.ServerOptions`; None: not started.
            Loopback unless a host is named.
        speed: ``"realtime"`` (default), ``"max"``, ``"lockstep"`` or
            simulated seconds per wall second.
        max_connections, idle_timeout: per server (seconds; 0 = never).
        read_only: refuse every write from a client.
        allow_writes: the address ranges clients may write
            (``"VB0-VB99,Q0.0-Q0.7"``); everything else is refused.
        start: start at once (else call :meth:`Serving.start`).
        modbus_map: the Modbus server's custom address map (a TOML file or
            a dict, :func:`plcrt.net.modbus.load_map`); None: the slave
            library's map.
        serial: CPU ports on pseudo-terminals, ``{0: "pty"}``
            (:mod:`plcrt.net.serial`; the path is
            ``addresses["serial0"][0]``).

    Raises:
        PlcConfigError: no server named, an unknown one, a bad address or
            option, an address that cannot be bound.
    """
    if not isinstance(plc, Plc):
        raise PlcConfigError(f"serve: a loaded PLC (plcrt.load), not {shown_value(plc)}")
    chosen = {k: v for k, v in (("s7", s7), ("modbus", modbus), ("lockstep", lockstep))
              if v is not None}
    if not chosen and serial is None:
        raise PlcConfigError("serve: name at least one server (s7, modbus, lockstep or serial)")
    if not isinstance(read_only, bool) or not isinstance(runner, bool) \
            or not isinstance(start, bool):
        raise PlcConfigError("serve: read_only, runner and start are True or False")
    if door is not None and not isinstance(door, ScanDoor):
        raise PlcConfigError(f"serve: door is a plcrt.net.ScanDoor, not {shown_value(door)}")
    guard = WriteGuard(read_only=read_only,
                       allow=parse_ranges(allow_writes) if allow_writes is not None else None)
    opts = {name: _options(name, spec, max_connections=max_connections,
                           idle_timeout=idle_timeout, guard=guard)
            for name, spec in chosen.items()}
    if modbus_map is not None:
        if "modbus" not in opts:
            raise PlcConfigError("serve: modbus_map needs a modbus server")
        opts["modbus"] = with_map(opts["modbus"], modbus_map)
    serving = Serving(plc, opts, speed=speed, runner=runner, door=door)
    if serial is not None:
        serving.services.update(pty_services(serving.door, plc, serial))  # type: ignore[arg-type]
    return serving.start() if start else serving
