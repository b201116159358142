"""What the Modbus server tests share: the programs, a wait on a served
PLC, and raw MBAP frames for what pymodbus's clients never send."""

from __future__ import annotations

import socket
import struct
import time
from typing import Any, Callable

#: OB1 that reacts to what clients write: Q0.1 follows I0.0, Q1.0 follows
#: Q0.0 (a coil a client sets), VW2 = VW0 + 1 (40002 = 40001 + 1), VW4 =
#: AIW0 + 1 and VW6 counts the scans
REACT = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     I0.0
=      Q0.1
Network 2
LD     Q0.0
=      Q1.0
Network 3
LD     SM0.0
MOVW   VW0, VW2
+I     1, VW2
MOVW   AIW0, VW4
+I     1, VW4
INCW   VW6
END_ORGANIZATION_BLOCK
"""

#: OB1 with the slave library: MBUS_INIT at the first scan (Addr 3, Baud
#: {baud}, Parity {parity}, MaxIQ 16, MaxAI 2, MaxHold 10, HoldStart
#: VB1000), MBUS_SLAVE every scan; VW1002 = VW1000 + 1
SLAVE = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.1
CALL   MBUS_INIT, 1, 3, {baud}, {parity}, 0, 16, 2, 10, &VB1000, M0.0, MB1
Network 2
LD     SM0.0
CALL   MBUS_SLAVE, M0.1, MB2
Network 3
LD     SM0.0
MOVW   VW1000, VW1002
+I     1, VW1002
END_ORGANIZATION_BLOCK
"""


def wait_for(pred: Callable[[], Any], timeout: float = 5.0, what: str = "") -> Any:
    """Poll ``pred`` until it is truthy (its value) or fail after ``timeout`` s."""
    end = time.monotonic() + timeout
    while True:
        v = pred()
        if v:
            return v
        if time.monotonic() > end:
            raise AssertionError(f"timed out waiting for {what or pred}")
        time.sleep(0.01)


def mbap(pdu: bytes, tid: int = 1, unit: int = 1, proto: int = 0,
         length: int | None = None) -> bytes:
    """An MBAP frame around ``pdu`` (``length``: a lying length field)."""
    n = len(pdu) + 1 if length is None else length
    return struct.pack(">HHHB", tid, proto, n, unit) + pdu


def recv_frame(sock: socket.socket) -> bytes:
    """One MBAP frame's PDU from ``sock`` (b"" when the server closed)."""
    head = recv_n(sock, 7)
    if len(head) < 7:
        return b""
    n = struct.unpack(">H", head[4:6])[0]
    return recv_n(sock, n - 1)


def recv_n(sock: socket.socket, n: int) -> bytes:
    out = b""
    while len(out) < n:
        chunk = sock.recv(n - len(out))
        if not chunk:
            break
        out += chunk
    return out


def closed(sock: socket.socket, timeout: float = 3.0) -> bool:
    """Whether the server closed ``sock`` (EOF) within ``timeout`` s."""
    sock.settimeout(timeout)
    try:
        return sock.recv(1) == b""
    except ConnectionResetError:
        return True
    except socket.timeout:
        return False


#: freeport 9600 8N1 (SMB30 = 2#0000_1001); each received character is
#: echoed from the receive-character routine (event 8) and counted in VW200
ECHO = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.1
MOVB   9, SMB30
ATCH   INT_0, 8
ENI
END_ORGANIZATION_BLOCK
INTERRUPT_BLOCK INT_0:INT0
BEGIN
Network 1
LD     SM0.0
MOVB   SMB2, VB101
MOVB   1, VB100
XMT    VB100, 0
INCW   VW200
END_INTERRUPT_BLOCK
"""
