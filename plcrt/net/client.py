"""The Python client of the lockstep protocol (:mod:`plcrt.net.lockstep`):
what a plant simulator or a test on another process uses to step a served
PLC.

>>> with LockstepClient("127.0.0.1", port) as plc:      # doctest: +SKIP
...     plc.write({"I0.0": 1})
...     plc.advance(scans=10)
...     plc.read("Q0.0", "VW0")

Blocking, one request at a time, plain sockets (no event loop needed by
the caller).  Errors the server answers are raised as
:class:`plcrt.errors.PlcConfigError` with its message; a connection that
fails or closes is a :class:`LockstepError` too.

What it is: the client.  What it is not: the server.
"""

from __future__ import annotations

import json
import socket
from typing import Any

from ..errors import PlcConfigError
from ..safetext import printable
from .lockstep import MAX_LINE

__all__ = ["LockstepClient", "LockstepError"]


class LockstepError(PlcConfigError):
    """The server answered an error, or the connection failed."""


class LockstepClient:
    """A connection to a lockstep server.

    Args:
        host, port: the server (``plcrt serve --lockstep PORT``).
        timeout: seconds one request may take (a long ``advance`` needs
            more).
    """

    def __init__(self, host: str = "127.0.0.1", port: int = 0, *,
                 timeout: float = 30.0) -> None:
        try:
            self._sock = socket.create_connection((host, port), timeout=timeout)
        except OSError as e:
            raise LockstepError(f"cannot connect to {printable(str(host))}:{port}: "
                                f"{printable(e.strerror or str(e))}") from None
        self._file = self._sock.makefile("rb")
        self._id = 0

    # -- operations --------------------------------------------------------
    def hello(self) -> dict[str, Any]:
        """The CPU, scan time (µs), speed and simulated time (µs)."""
        return self.request("hello")

    def state(self) -> dict[str, Any]:
        """The CPU mode, simulated time (µs), scans run and fault."""
        return self.request("state")

    def advance(self, *, scans: int | None = None, seconds: float | str | None = None,
                to_us: int | None = None) -> int:
        """Run ``scans`` scans, ``seconds`` of simulated time or up to
        ``to_us``; returns the scans run."""
        args = {k: v for k, v in (("scans", scans), ("seconds", seconds), ("to_us", to_us))
                if v is not None}
        return int(self.request("advance", **args)["scans"])

    def read(self, *addresses: str) -> dict[str, int | float]:
        """The values of ``addresses`` (addresses or symbols), at one scan
        boundary."""
        return dict(self.request("read", addresses=list(addresses))["values"])

    def write(self, values: dict[str, int | float]) -> None:
        """Write ``values`` (address -> number) before the next scan; all
        or nothing."""
        self.request("write", values=dict(values))

    def set_mode(self, mode: str) -> str:
        """Switch the CPU to RUN or STOP."""
        return str(self.request("mode", mode=mode)["mode"])

    # -- the wire ----------------------------------------------------------
    def request(self, op: str, **fields: Any) -> dict[str, Any]:
        """Send one request and return the answer's fields.

        Raises:
            LockstepError: the server answered an error, or the connection
                failed.
        """
        self._id += 1
        line = json.dumps({"op": op, "id": self._id, **fields}, separators=(",", ":"))
        try:
            self._sock.sendall(line.encode() + b"\n")
            raw = self._file.readline(MAX_LINE + 1)
        except OSError as e:
            raise LockstepError(f"lockstep connection failed: "
                                f"{printable(e.strerror or str(e))}") from None
        if not raw.endswith(b"\n"):
            raise LockstepError("the lockstep server closed the connection")
        try:
            answer = json.loads(raw)
        except ValueError:
            raise LockstepError("the lockstep server sent something that is not JSON") from None
        if not isinstance(answer, dict) or answer.get("id") != self._id:
            raise LockstepError("the lockstep server's answer does not match the request")
        if not answer.get("ok"):
            raise LockstepError(printable(str(answer.get("error", "error"))))
        return {k: v for k, v in answer.items() if k not in ("ok", "id")}

    def close(self) -> None:
        try:
            self._file.close()
            self._sock.close()
        except OSError:
            pass

    def __enter__(self) -> "LockstepClient":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
