"""The TCP side every server of a served PLC shares: listening, the
connection limit, the idle timeout, one task per client, and the client
counted, served and closed without touching the others.

A protocol is a subclass of :class:`TcpService` that implements
:meth:`TcpService.session`: read requests from the stream, answer them
(asking the PLC through the door, :mod:`plcrt.net.door`), return when the
client is done or has sent something that ends the connection.  The base
class does the rest:

- a client beyond ``max_connections`` is accepted and closed at once;
- :meth:`TcpService.read_exactly` bounds every read by the idle timeout;
  a client that says nothing for that long is closed;
- whatever one session raises closes that connection only (a
  :class:`plcrt.errors.PlcError` is counted as a protocol error, anything
  else as a server error and logged once per kind), never the server;
- ``stats`` counts connections, refusals, requests and errors.

What it is: asyncio plumbing.  What it is not: a protocol (S7:
:mod:`plcrt.net.s7`, Modbus: :mod:`plcrt.net.modbus`, lockstep:
:mod:`plcrt.net.lockstep`), nor the loop's thread (:mod:`plcrt.net.host`).
"""

from __future__ import annotations

import asyncio
import logging
from abc import ABC, abstractmethod
from collections import Counter
from concurrent.futures import Future
from typing import Any, Callable, TypeVar

from ..errors import PlcError
from .door import ScanDoor
from .options import ServerOptions

__all__ = ["ClosedByPeer", "TcpService"]

T = TypeVar("T")

log = logging.getLogger("plcrt.net")


class ClosedByPeer(Exception):
    """The client closed its side (or was silent past the idle timeout)."""


class TcpService(ABC):
    """One listening protocol server bound to a door.

    Args:
        door: where requests for the PLC go.
        options: address and limits.
    """

    #: the protocol's name, for messages ("S7", "Modbus TCP")
    name = "TCP"

    def __init__(self, door: ScanDoor, options: ServerOptions) -> None:
        self.door = door
        self.options = options
        self.stats: Counter[str] = Counter()
        self._server: asyncio.base_events.Server | None = None
        self._clients: set[asyncio.Task[Any]] = set()
        self._logged: set[str] = set()
        self.address: tuple[str, int] | None = None

    # -- the protocol --------------------------------------------------------
    @abstractmethod
    async def session(self, reader: asyncio.StreamReader,
                      writer: asyncio.StreamWriter) -> None:
        """Serve one client until it is done (return) or must be closed
        (raise).  Called once per accepted connection."""

    async def ask(self, job: Callable[[Any], T]) -> T:
        """Run ``job(plc)`` at the next scan boundary and wait for its
        result without blocking the loop (other clients go on)."""
        fut: Future[T] = self.door.post(job)
        return await asyncio.wrap_future(fut)

    async def read_exactly(self, reader: asyncio.StreamReader, n: int,
                           first: bool = False) -> bytes:
        """``n`` bytes from the client, bounded by the idle timeout.

        ``first``: the first bytes of a request (the idle timeout applies);
        later bytes of the same request get the same bound.

        Raises:
            ClosedByPeer: the client closed or stayed silent too long.
        """
        timeout = self.options.idle_timeout or None
        try:
            return await asyncio.wait_for(reader.readexactly(n), timeout)
        except (asyncio.IncompleteReadError, ConnectionError, asyncio.TimeoutError):
            if first:
                self.stats["idle_or_closed"] += 1
            raise ClosedByPeer() from None

    # -- listening -----------------------------------------------------------
    async def start(self) -> tuple[str, int]:
        """Listen; returns the address (host, port) really bound."""
        lst = self.options.listen
        self._server = await asyncio.start_server(self._accept, lst.host, lst.port,
                                                  reuse_address=True)
        sock = self._server.sockets[0].getsockname()
        self.address = (sock[0], sock[1])
        return self.address

    async def close(self) -> None:
        """Stop listening and close every client."""
        if self._server is not None:
            self._server.close()
        for task in list(self._clients):
            task.cancel()
        if self._clients:
            await asyncio.gather(*self._clients, return_exceptions=True)
        if self._server is not None:
            await self._server.wait_closed()
            self._server = None

    @property
    def connections(self) -> int:
        """Clients connected now."""
        return len(self._clients)

    async def _accept(self, reader: asyncio.StreamReader,
                      writer: asyncio.StreamWriter) -> None:
        if len(self._clients) >= self.options.max_connections:
            self.stats["refused"] += 1
            writer.close()
            return
        task = asyncio.current_task()
        assert task is not None
        self._clients.add(task)
        self.stats["connections"] += 1
        try:
            await self.session(reader, writer)
        except ClosedByPeer:
            pass
        except asyncio.CancelledError:
            pass
        except PlcError:
            self.stats["protocol_errors"] += 1
        except ConnectionError:
            pass
        except Exception as e:  # a server bug: this connection only
            self.stats["server_errors"] += 1
            kind = type(e).__name__
            if kind not in self._logged:
                self._logged.add(kind)
                log.error("%s server: a client's connection ended on %s; please report it",
                          self.name, kind, exc_info=True)
        finally:
            self._clients.discard(task)
            writer.close()
            try:
                await asyncio.wait_for(writer.wait_closed(), 1.0)
            except (Exception, asyncio.CancelledError):
                pass
