"""What the S7 server's tests share: a ladder program that reacts to what
clients write, a served PLC on a free loopback port, python-snap7 clients,
and raw S7 requests for what python-snap7's API has no name for (the 200
family's area codes), built here from the protocol's layout and sent
through python-snap7's own ISO-on-TCP connection.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Callable
from typing import Any

import pytest

import plcrt

snap7 = pytest.importorskip("snap7")

#: VW0 -> QW0 every scan; I0.0 starts T33 (TON, 10 ms timer, 0.2 s) which sets Q1.0;
#: I0.1 counts C5 up (preset 3), I0.2 resets it; C5 sets Q1.1; M0.0 copies
#: to M0.1; MB10 counts scans and MB11 copies it at the end of the scan
PROGRAM = """\
ORGANIZATION_BLOCK MAIN:OB1
TITLE=S7 server tests
BEGIN
Network 1
LD     SM0.0
MOVW   VW0, QW0
Network 2
LD     I0.0
TON    T33, +20
Network 3
LD     T33
=      Q1.0
Network 4
LD     I0.1
LD     I0.2
CTU    C5, +3
Network 5
LD     C5
=      Q1.1
Network 6
LD     M0.0
=      M0.1
Network 7
LD     SM0.0
INCB   MB10
Network 8
LD     SM0.0
MOVB   MB10, MB11
END_ORGANIZATION_BLOCK
"""


def load() -> Any:
    return plcrt.load(PROGRAM, scan_ms=10)


def connect(port: int, *, ctype: int = 3, pdu: int | None = None) -> Any:
    """A python-snap7 client connected to rack 0 slot 1 (a SMART) with
    connection type ``ctype`` (1 PG, 2 OP, 3 basic)."""
    c = snap7.Client()
    c.set_connection_type(ctype)
    if pdu is not None:
        c.pdu_length = pdu
    c.connect("127.0.0.1", 0, 1, port)
    return c


def wait_for(cond: Callable[[], Any], timeout: float = 5.0) -> Any:
    """Poll ``cond`` until it is true (returns its value) or fail."""
    end = time.monotonic() + timeout
    while True:
        v = cond()
        if v:
            return v
        if time.monotonic() > end:
            raise AssertionError("condition not met in time")
        time.sleep(0.01)


# -- raw requests ------------------------------------------------------------
_ref = [0x100]


def item(area: int, start: int, count: int, tsize: int = 0x02, db: int = 0) -> bytes:
    """An S7-ANY item: bit address ``start`` (or an element number)."""
    return struct.pack(">BBBBHHB", 0x12, 0x0A, 0x10, tsize, count, db, area) \
        + start.to_bytes(3, "big")


def job(params: bytes, data: bytes = b"") -> bytes:
    _ref[0] = _ref[0] % 0xFFFF + 1
    return struct.pack(">BBHHHH", 0x32, 1, 0, _ref[0], len(params), len(data)) + params + data


def exchange(client: Any, pdu: bytes) -> bytes:
    """Send one S7 PDU on the client's connection, return the answer."""
    client.connection.send_data(pdu)
    return client.connection.receive_data()


def header_error(answer: bytes) -> int:
    """The error word of an answer's 12-byte header."""
    return answer[10] << 8 | answer[11]


def read_items(client: Any, items: list[bytes]) -> list[tuple[int, bytes]]:
    """A raw read var: ``(return code, data)`` per item."""
    ans = exchange(client, job(bytes([0x04, len(items)]) + b"".join(items)))
    assert header_error(ans) == 0, hex(header_error(ans))
    plen = ans[6] << 8 | ans[7]
    data = ans[12 + plen:]
    out, i = [], 0
    for k in range(len(items)):
        rc, ts, length = data[i], data[i + 1], data[i + 2] << 8 | data[i + 3]
        n = length if ts in (0x03, 0x07, 0x09) else length // 8
        out.append((rc, bytes(data[i + 4:i + 4 + n])))
        i += 4 + n + (n & 1 if k < len(items) - 1 else 0)
    return out


def write_items(client: Any, items: list[tuple[bytes, int, bytes]]) -> list[int]:
    """A raw write var of ``(item, data transport size, bytes)``: the
    return code per item."""
    data = b""
    for k, (_, ts, value) in enumerate(items):
        length = len(value) if ts in (0x03, 0x07, 0x09) else len(value) * 8
        data += struct.pack(">BBH", 0, ts, length) + value
        if len(value) & 1 and k < len(items) - 1:
            data += b"\x00"
    ans = exchange(client, job(bytes([0x05, len(items)]) + b"".join(i for i, _, _ in items),
                               data))
    assert header_error(ans) == 0, hex(header_error(ans))
    plen = ans[6] << 8 | ans[7]
    return list(ans[12 + plen:])


def cpu_mode(client: Any) -> int:
    """The mode byte of SZL 0x0424 (0x08 RUN, 0x04 STOP), read as snap7's
    Cli_GetPlcStatus reads it (byte 3 of the record)."""
    szl = client.read_szl(0x0424, 0)
    data = bytes(b & 0xFF for b in szl.Data[:szl.Header.LengthDR])
    return data[7]


# -- raw sockets (the fault tests) ------------------------------------------------
def tpkt(body: bytes) -> bytes:
    return struct.pack(">BBH", 3, 0, len(body) + 4) + body


def cr_frame(called: int = 0x0301, tpdu: int = 0x0A) -> bytes:
    """A COTP connection request to a two-byte TSAP (default: basic, rack 0
    slot 1), TPDU size 2**tpdu (default 1024)."""
    params = bytes([0xC1, 2, 0x01, 0x00, 0xC2, 2, called >> 8, called & 0xFF, 0xC0, 1, tpdu])
    return tpkt(bytes([6 + len(params), 0xE0, 0, 0, 0, 1, 0]) + params)


def dt_frame(pdu: bytes) -> bytes:
    return tpkt(b"\x02\xf0\x80" + pdu)


SETUP = job(struct.pack(">BBHHH", 0xF0, 0, 1, 1, 240))


def recv_frames(sock: Any, timeout: float = 5.0) -> tuple[list[bytes], bool]:
    """Every TPKT the server sends until it closes (or ``timeout``), and
    whether it closed; asserts each frame is a well-formed TPKT."""
    sock.settimeout(timeout)
    buf, closed = b"", False
    try:
        while True:
            chunk = sock.recv(65536)
            if not chunk:
                closed = True
                break
            buf += chunk
    except ConnectionResetError:
        closed = True
    except (TimeoutError, OSError):
        pass
    frames = []
    while buf:
        assert buf[0] == 3 and len(buf) >= 4, buf[:8].hex()
        n = buf[2] << 8 | buf[3]
        assert 7 <= n <= len(buf), buf[:8].hex()
        frames.append(buf[:n])
        buf = buf[n:]
    return frames, closed
