"""Network read and write between CPUs: NETR / NETW (PPI master) and the
S7-200 SMART's GET / PUT (Ethernet).

What it is: the jobs these instructions start, run on the scan's time line
through the inbox of a port (:class:`plcrt.engine.ports.Port`) or of the
CPU's Ethernet interface (:class:`Ethernet`).  The remote CPU's memory is
read or written at the exact µs the request has reached it (an item in the
*remote* CPU's inbox, so it happens in its own time line); the local table
gets its result when the answer has come back.

* NETR/NETW (S7-200 System Manual, "Network Read and Network Write"): the
  table is ``D A E 0 | error code`` (byte 0), the remote station address
  (1), a pointer to the remote I, Q, M or V data (2..5), the length 1..16
  (6) and the data (7..22).  The port must be a PPI master (SMB30 /
  SMB130 protocol 10); at most 8 jobs run at once.  Error codes: 1 time-out
  (no station answers), 4 more than 8 jobs, 5 not PPI master, 6 illegal
  parameter, 9 wrong data address or length.  Timing: the characters of
  the PPI exchange at the port's PPI baud rate (docs/decisions.md,
  "Communication ports").
* GET/PUT (S7-200 SMART System Manual, "GET and PUT"): the table is the
  status byte, the remote IP (1..4), two reserved bytes (5, 6), a pointer to
  the remote data (7..10), the length (11; GET 1..222, PUT 1..212 bytes)
  and a pointer to the local data (12..15).  Error codes: 1 illegal
  parameter, 2 more than 8 active, 4 the remote CPU refused (its area is too
  small), 5 no connection to the remote CPU.

What it is not: no PPI or S7 telegrams on a wire (a freeport receiver never
sees them); no connection limits beyond the 8 active jobs.
"""

from __future__ import annotations

from typing import Any, Callable, Optional

from .serial import Framing, Inbox, table_at

__all__ = ["Ethernet", "netr_netw", "make_ethernet", "PPI_CHARS", "NO_ANSWER_US", "LATENCY_US"]

#: PPI characters of one exchange, by kind: (request, rest of the exchange)
#: with n data bytes.  Request SD2 frame, the remote's short acknowledge
#: (1), the master's poll (SD1, 6) and the response SD2 frame; the frame
#: sizes of the PPI read/write job telegrams (decided, docs/decisions.md)
PPI_CHARS: dict[str, tuple[Callable[[int], int], Callable[[int], int]]] = {
    "NETR": (lambda n: 33, lambda n: 1 + 6 + 27 + n),
    "NETW": (lambda n: 37 + n, lambda n: 1 + 6 + 24),
}
#: a PPI request nobody answers ends with error 1 this long after it was sent
NO_ANSWER_US = 100_000
#: one way over Ethernet (request or answer), when the plant says nothing
LATENCY_US = 1000
#: areas a remote pointer may name (pointer area code -> area)
_DATA_AREAS = {0x01: "I", 0x02: "Q", 0x03: "M", 0x08: "V"}
MAX_JOBS = 8


class _Job:
    """One NETR/NETW/GET/PUT in progress."""

    __slots__ = ("kind", "buf", "off", "remote_ptr", "n", "data", "error", "local")

    def __init__(self, kind: str, buf: bytearray, off: int, remote_ptr: int, n: int) -> None:
        self.kind, self.buf, self.off = kind, buf, off
        self.remote_ptr, self.n = remote_ptr, n
        self.data = b""
        self.error = 0
        self.local: Optional[tuple[bytearray, int]] = None


def _area(areas: dict[str, bytearray], ptr: int, n: int) -> Optional[tuple[bytearray, int]]:
    name = _DATA_AREAS.get(ptr >> 24)
    off = ptr & 0xFFFFFF
    if name is None or off + n > len(areas[name]):
        return None
    return areas[name], off


def _serve(areas: dict[str, bytearray], job: _Job, refused: int) -> None:
    """The remote CPU acts on a request (its own memory, now)."""
    at = _area(areas, job.remote_ptr, job.n)
    if at is None:
        job.error = refused
        return
    buf, off = at
    if job.kind in ("NETR", "GET"):
        job.data = bytes(buf[off:off + job.n])
    else:
        buf[off:off + job.n] = job.data


def _finish(jobs: list[_Job], job: _Job) -> None:
    jobs.remove(job)
    buf, off = job.buf, job.off
    if not job.error and job.kind in ("NETR", "GET") and len(job.data) != job.n:
        job.error = 1 if job.kind == "NETR" else 5     # no answer came (never by design)
    if job.error:
        buf[off] = 0xA0 | job.error         # D and E, the error code
        return
    if job.kind == "NETR":
        buf[off + 7:off + 7 + job.n] = job.data
    elif job.kind == "GET":
        lbuf, loff = job.local
        lbuf[loff:loff + job.n] = job.data
    buf[off] = 0x80                         # D: done without error


def _active(jobs: list[_Job], buf: bytearray, off: int) -> bool:
    return any(j.buf is buf and j.off == off for j in jobs)


# ---------------------------------------------------------------- NETR / NETW
def netr_netw(port: Any, t: int, ptr: int, kind: str) -> bool:
    """NETR or NETW at *t* over *port* with the table *ptr* points to; the ENO."""
    at = port.table(ptr)
    if at is None or at[1] + 23 > len(at[0]):
        port.warn(f"{kind} on port {port.number}: the table at pointer 16#{ptr:08X} is not "
                  f"23 bytes in I, Q, M, S, SM or V; nothing is done, ENO = 0",
                  f"net-table-{port.number}")
        return False
    buf, off = at
    jobs = port.jobs
    if _active(jobs, buf, off):
        return True                         # A is set: the job runs (decided)
    station, n = buf[off + 1], buf[off + 6]
    job = _Job(kind, buf, off, int.from_bytes(buf[off + 2:off + 6], "big"), n)
    fr = port.framing()
    error = 0
    if fr.protocol != "PPI master":
        error = 5                           # protocol violation: SMB30 is not PPI master
        port.warn(f"{kind} on port {port.number} at {t / 1e6:.6f} s: SMB{port.control} "
                  f"selects {fr.protocol} mode, not PPI master (10): error 5",
                  f"net-protocol-{port.number}")
    elif not 1 <= n <= 16 or station > 126:
        error = 6
    elif len(jobs) >= MAX_JOBS:
        error = 4
    if error:
        buf[off] = 0xA0 | error
        return True
    if kind == "NETW":
        job.data = bytes(buf[off + 7:off + 7 + n])
    buf[off] = 0x40                         # A: active
    jobs.append(job)
    ppi = Framing(port.ppi_baud, 8, "even", "PPI master")   # PPI: 11-bit characters
    req, rest = PPI_CHARS[kind]
    t_req = ppi.end(t, req(n))
    t_done = ppi.end(t, req(n) + rest(n))
    remote = getattr(port.peer, "station", lambda a: None)(station)
    if remote is None or station == port.address:
        job.error = 1
        port.push(t_req + NO_ANSWER_US, _netr_done, port, job, t_req)
        return True
    remote.push(t_req, _netr_serve, remote, job, link=True)
    port.push(t_done, _netr_done, port, job, t_req)
    return True


def _netr_serve(t: int, remote: Any, job: _Job) -> None:
    if remote.framing().protocol == "freeport":
        job.error = 1                       # a freeport port does not answer PPI
        return
    _serve(remote.areas, job, 9)


def _netr_done(t: int, port: Any, job: _Job, t_req: int) -> None:
    if job.error == 1 and t < t_req + NO_ANSWER_US:
        # the station did not answer: the master waits out its time-out
        port.push(t_req + NO_ANSWER_US, _netr_done, port, job, t_req)
        return
    _finish(port.jobs, job)


# ---------------------------------------------------------------- GET / PUT
class Ethernet(Inbox):
    """The CPU's Ethernet interface for GET/PUT: its IP, its jobs, and the
    network of linked CPUs that can be reached (:mod:`.link`)."""

    def __init__(self, areas: dict[str, bytearray], warn: Callable[[str, str], None],
                 touch: Callable[[Any], None], ip: Optional[bytes] = None,
                 latency_us: int = LATENCY_US) -> None:
        super().__init__(touch)
        self.areas, self.warn = areas, warn
        self.ip = ip
        self.latency_us = latency_us
        self.jobs: list[_Job] = []
        self.network: Any = None            #: plcrt.engine.link.Network, when linked

    def get_put(self, t: int, ptr: int, kind: str) -> bool:
        """GET or PUT at *t* with the table *ptr* points to; the ENO."""
        at = table_at(self.areas, ptr, 16)
        if at is None:
            self.warn(f"{kind}: the table at pointer 16#{ptr:08X} is not 16 bytes in I, Q, M, "
                      f"S, SM or V; nothing is done, ENO = 0", "getput-table")
            return False
        buf, off = at
        if _active(self.jobs, buf, off):
            return True
        ip = bytes(buf[off + 1:off + 5])
        n = buf[off + 11]
        job = _Job(kind, buf, off, int.from_bytes(buf[off + 7:off + 11], "big"), n)
        job.local = _area(self.areas, int.from_bytes(buf[off + 12:off + 16], "big"), n)
        limit = 212 if kind == "PUT" else 222
        error = 0
        if (not 1 <= n <= limit or buf[off + 5] or buf[off + 6] or job.local is None
                or (job.remote_ptr >> 24) not in _DATA_AREAS or not _unicast(ip)
                or ip == self.ip):
            error = 1
        elif len(self.jobs) >= MAX_JOBS:
            error = 2
        if error:
            buf[off] = 0xA0 | error
            return True
        if kind == "PUT":
            lbuf, loff = job.local
            job.data = bytes(lbuf[loff:loff + n])
        buf[off] = 0x40
        self.jobs.append(job)
        remote = self.network.ethernet_of(ip) if self.network is not None else None
        lat = self.latency_us
        if remote is None or self.ip is None:
            job.error = 5                   # no connection to the remote CPU
            self.push(t + lat, self._done, job)
            return True
        remote.push(t + lat, self._serve, remote, job, link=True)
        self.push(t + 2 * lat, self._done, job)
        return True

    @staticmethod
    def _serve(t: int, remote: Ethernet, job: _Job) -> None:
        _serve(remote.areas, job, 4)

    def _done(self, t: int, job: _Job) -> None:
        _finish(self.jobs, job)

    def drop_links(self) -> None:
        super().drop_links()
        self.network = None


def _unicast(ip: bytes) -> bool:
    """An address a CPU can have (not 0.0.0.0, broadcast, multicast or loopback)."""
    return ip[0] not in (0, 127) and ip[0] < 224 and ip[3] not in (0, 255)


def make_ethernet(plc: Any, plant: Any) -> Ethernet:
    """*plc*'s Ethernet interface, with the plant's IP address and latency."""
    cfg = getattr(plant, "ethernet", None)
    ip, latency = (cfg.ip, cfg.latency_us) if cfg is not None else (None, LATENCY_US)
    return Ethernet(plc.mem.areas, plc._irq_warn, plc._wake, ip, latency)
