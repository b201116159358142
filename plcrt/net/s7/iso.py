"""ISO-on-TCP (RFC 1006): TPKT framing and the COTP class 0 transport
(ISO 8073) that S7 communication runs on.

- a TPKT is ``03 00 LEN(2)`` followed by one COTP TPDU; ``LEN`` counts the
  whole frame and is bounded here (:data:`MAX_TPKT`);
- COTP CR (connection request, 0xE0) carries the TSAPs (parameters 0xC1
  calling, 0xC2 called) and the TPDU size (0xC0); it is answered with CC
  (0xD0) or refused with DR (0x80);
- COTP DT (0xF0) carries the S7 PDU; a PDU may span several DTs, the last
  one flagged EOT (0x80), and the reassembled PDU is bounded too.

What it is: parsing and building these frames, every length checked.
What it is not: S7 (:mod:`.pdu`), the connection's life (:mod:`.server`).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from ...errors import PlcError

__all__ = ["CONN_BASIC", "CONN_OP", "CONN_PG", "CR", "DR", "DT", "ConnectRequest", "FrameError",
           "MAX_TPKT", "Tpdu",
           "build_cc", "build_dr", "build_dt", "connection_type", "parse_cotp",
           "parse_tpkt_header"]

#: longest TPKT accepted (a TPDU of 1024 bytes and the headers)
MAX_TPKT = 1024 + 7
#: COTP TPDU codes (ISO 8073 §13.1)
CR, CC, DR, DC, DT = 0xE0, 0xD0, 0x80, 0xC0, 0xF0
#: COTP parameter codes
P_TPDU_SIZE, P_CALLING, P_CALLED = 0xC0, 0xC1, 0xC2
#: the TPDU size answered at most (2**10 = 1024 bytes)
MAX_TPDU_CODE = 0x0A

#: connection types by the high byte of the called TSAP (S7 addressing:
#: type << 8 | rack << 5 | slot); a text TSAP (an HMI's
#: "SIMATIC-ROOT-HMI") counts as an HMI/OP connection
CONN_PG, CONN_OP, CONN_BASIC = "PG", "OP", "basic"
_TSAP_TYPES = {1: CONN_PG, 2: CONN_OP, 3: CONN_BASIC}


class FrameError(PlcError):
    """A frame that is not ISO-on-TCP or not S7: the connection is closed."""


@dataclass(frozen=True)
class ConnectRequest:
    """What a COTP CR asks for."""

    src_ref: int
    calling: bytes
    called: bytes
    tpdu_code: int


def parse_tpkt_header(head: bytes) -> int:
    """The payload length of a TPKT from its four header bytes.

    Raises:
        FrameError: not version 3, or a length outside 7..:data:`MAX_TPKT`.
    """
    if len(head) != 4 or head[0] != 3:
        raise FrameError("not a TPKT (RFC 1006) frame")
    length = head[2] << 8 | head[3]
    if not 7 <= length <= MAX_TPKT:
        raise FrameError(f"TPKT length {length} outside 7..{MAX_TPKT}")
    return length - 4


@dataclass(frozen=True)
class Tpdu:
    """A parsed COTP TPDU: its code (:data:`CR`, :data:`DT` or :data:`DR`),
    the request of a CR, the EOT flag and data of a DT."""

    code: int
    request: ConnectRequest | None = None
    eot: bool = False
    data: bytes = b""


def parse_cotp(payload: bytes) -> Tpdu:
    """A COTP TPDU: CR, DT or DR (DC counts as DR).

    Raises:
        FrameError: a length indicator that does not fit, an unknown TPDU,
            or a malformed parameter.
    """
    if len(payload) < 2:
        raise FrameError("COTP TPDU too short")
    li, code = payload[0], payload[1] & 0xF0     # low nibble: the credit (class 0)
    if li + 1 > len(payload) or li < 2:
        raise FrameError("COTP length indicator does not fit the frame")
    if code == DT:
        if li != 2:
            raise FrameError("COTP DT header must be 2 bytes")
        return Tpdu(DT, eot=bool(payload[2] & 0x80), data=bytes(payload[3:]))
    if code == CR:
        if li < 6 or li + 1 != len(payload):
            raise FrameError("malformed COTP CR")
        src_ref = payload[4] << 8 | payload[5]
        return Tpdu(CR, request=_connect_params(src_ref, payload[7:li + 1]))
    if code in (DR, DC):
        return Tpdu(DR)
    raise FrameError(f"COTP TPDU 0x{payload[1]:02X} not supported")


def _connect_params(src_ref: int, params: bytes) -> ConnectRequest:
    calling = called = b""
    tpdu = 0x07
    i = 0
    while i < len(params):            # at most len(params) / 2 rounds
        if i + 2 > len(params):
            raise FrameError("truncated COTP parameter")
        code, n = params[i], params[i + 1]
        value = params[i + 2:i + 2 + n]
        if len(value) != n:
            raise FrameError("truncated COTP parameter")
        if code == P_CALLING:
            calling = bytes(value)
        elif code == P_CALLED:
            called = bytes(value)
        elif code == P_TPDU_SIZE and n == 1:
            tpdu = value[0]
        i += 2 + n
    return ConnectRequest(src_ref, calling, called, tpdu)


def connection_type(called: bytes) -> str:
    """PG, OP or basic, from the called TSAP's first byte (a two-byte
    TSAP), OP for a text TSAP, basic for anything else."""
    if len(called) == 2:
        return _TSAP_TYPES.get(called[0], CONN_BASIC)
    return CONN_OP if len(called) > 2 else CONN_BASIC


def _tpkt(body: bytes) -> bytes:
    return struct.pack(">BBH", 3, 0, len(body) + 4) + body


def build_cc(req: ConnectRequest, our_ref: int) -> bytes:
    """The TPKT of a COTP CC answering ``req``: the TPDU size is the
    smaller of the asked one and :data:`MAX_TPDU_CODE`; the TSAPs are
    echoed."""
    code = min(max(req.tpdu_code, 0x07), MAX_TPDU_CODE)
    params = bytes([P_TPDU_SIZE, 1, code])
    if req.calling:
        params += bytes([P_CALLING, len(req.calling)]) + req.calling
    if req.called:
        params += bytes([P_CALLED, len(req.called)]) + req.called
    head = struct.pack(">BHHB", CC, req.src_ref, our_ref, 0)
    return _tpkt(bytes([len(head) + len(params)]) + head + params)


def build_dr(req: ConnectRequest, our_ref: int, reason: int) -> bytes:
    """The TPKT of a COTP DR refusing ``req`` (reason per ISO 8073
    §13.5.3: 0x81 congestion at connect request time)."""
    return _tpkt(struct.pack(">BBHHB", 6, DR, req.src_ref, our_ref, reason))


def build_dt(pdu: bytes) -> bytes:
    """The TPKT of one COTP DT (EOT set) carrying ``pdu``."""
    return _tpkt(b"\x02\xf0\x80" + pdu)
