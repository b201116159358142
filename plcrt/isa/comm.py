"""Instruction family: communications.

``XMT TBL, PORT`` and ``RCV TBL, PORT`` (S7-200 System Manual,
"Communications instructions", Transmit and Receive; freeport mode),
``NETR TBL, PORT`` and ``NETW TBL, PORT`` (Network Read / Network Write,
PPI master) and the S7-200 SMART's ``GET TBL`` and ``PUT TBL`` (SMART
System Manual, "GET and PUT").  TBL is a byte address in I, Q, M, S, SM or
V (the table's first byte) or an indirect ``*VDn`` / ``*ACn`` / ``*LDn``;
PORT the constant 0 or 1 (a port the CPU has).  Each box runs with its
power flow and gives ENO 0 when the instruction refuses (freeport not
selected, a busy port, a bad table).  The ports and jobs are
:mod:`plcrt.engine.ports` and :mod:`plcrt.engine.netjobs`.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.operands import POINTER_AREAS, Addr, Indirect
from ..gen.resolve import ResolveError
from ..memory.hardware import PORTS_OF
from ..safetext import excerpt
from .args import int_constant, operand_texts
from .registry import insn

F = "communications"
_TABLE_AREAS = ("I", "Q", "M", "S", "SM", "V")


def _table(g: Gen, resolver, text: str, what: str) -> str:
    """An expression for the pointer to the table TBL names."""
    try:
        op = resolver.parse(text)
    except ResolveError as e:
        g.fail(f"TBL: {e}")
    if isinstance(op, Indirect):
        return g.rd(op.ptr, "DU")
    if not (isinstance(op, Addr) and op.width == 1 and op.area in _TABLE_AREAS):
        g.fail(f"TBL must be a byte address in I, Q, M, S, SM or V (the table's first "
               f"byte) or *VD/*AC/*LD, got '{excerpt(text)}'")
    return str(POINTER_AREAS[op.area] << 24 | op.offset)


def _port(g: Gen, resolver, text: str, what: str) -> int:
    port = int_constant(g, resolver, text, "PORT",
                        f"PORT must be the constant 0 or 1, got '{excerpt(text)}'")
    ports = PORTS_OF.get(g.unit.model.name, 2)
    if not 0 <= port < ports:
        g.fail(f"PORT {port}: the {g.unit.model.name} has "
               f"{'port 0 only' if ports == 1 else 'ports 0 and 1'}")
    return port


def _port_insn(name: str, method: str, kind: str = ""):
    def emit(g: Gen, insn_ir, resolver, *_ops) -> None:
        tbl, port_text = operand_texts(g, insn_ir, 2, f"a table and a port ({name} TBL, PORT)")
        ptr = _table(g, resolver, tbl, name)
        port = _port(g, resolver, port_text, name)
        fn = g.cpu(method, method.strip("_"))
        extra = f", '{kind}'" if kind else ""
        g.eno(f"1 if {g.top} and {fn}({port}, {ptr}{extra}) else 0")
    return emit


def _eth_insn(name: str):
    def emit(g: Gen, insn_ir, resolver, *_ops) -> None:
        tbl = operand_texts(g, insn_ir, 1, f"a table ({name} TBL)")[0]
        ptr = _table(g, resolver, tbl, name)
        fn = g.cpu("_getput", "getput")
        g.eno(f"1 if {g.top} and {fn}({ptr}, '{name}') else 0")
    return emit


insn("XMT", family=F, summary="freeport: transmit the table's characters at PORT",
     variadic=True, may_fail=True)(_port_insn("XMT", "_xmt"))
insn("RCV", family=F, summary="freeport: start or stop the receive message function",
     variadic=True, may_fail=True)(_port_insn("RCV", "_rcv"))
insn("NETR", family=F, summary="PPI master: read up to 16 bytes from a remote station",
     variadic=True, may_fail=True)(_port_insn("NETR", "_net", "NETR"))
insn("NETW", family=F, summary="PPI master: write up to 16 bytes to a remote station",
     variadic=True, may_fail=True)(_port_insn("NETW", "_net", "NETW"))
insn("GET", family=F, summary="SMART: read up to 222 bytes from a remote CPU over Ethernet",
     variadic=True, may_fail=True)(_eth_insn("GET"))
insn("PUT", family=F, summary="SMART: write up to 212 bytes to a remote CPU over Ethernet",
     variadic=True, may_fail=True)(_eth_insn("PUT"))
