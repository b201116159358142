"""The S7 protocol server: a served PLC answers S7 clients as an
S7-200 SMART CPU does (ISO-on-TCP, RFC 1006; port 102 by default).

Layout: :mod:`.iso` (TPKT and COTP), :mod:`.pdu` (the S7 PDU),
:mod:`.areas` (area codes, transport sizes, return codes, the door jobs),
:mod:`.szl` (the identity and the system status list), :mod:`.server`
(:class:`S7Server`, a :class:`plcrt.net.tcp.TcpService`).  See
docs/network.md, "S7".
"""

from .server import S7Options, S7Server, make_s7
from .szl import S7Identity

__all__ = ["S7Identity", "S7Options", "S7Server", "make_s7"]
