"""Instruction family: the S7-200 SMART's extras BITIM, CITIM, DLED, and the
port addresses GPA, SPA.

* ``BITIM OUT`` stores the 1 ms system timer (a DWORD counting simulated
  milliseconds from power-up, wrapping at 2**32) in OUT; ``CITIM IN, OUT``
  stores the milliseconds since the timer read IN, ``now - IN`` modulo
  2**32, so one wrap of the timer between the two is handled (SMART System
  Manual, "Interval timers").  Code runs at the instant of its scan (or of
  its interrupt), so two BITIMs of one scan read the same value.
* ``DLED IN``: the diagnostic LED is on (yellow) for IN > 0, off for 0;
  its state is ``plc.station.led`` and part of the PLC's state report.
* ``GPA ADDR, PORT`` reads the station address of port PORT (0 or 1, a
  constant) into ADDR; ``SPA ADDR, PORT`` sets it (S7-200 System Manual,
  "Get Port Address and Set Port Address").  The address is not kept over
  a power cycle (a new load starts at the system block's address, 2).
  SPA with an address outside 0..126 is run-time error 0091, SPA executed
  by an interrupt routine error 0004: the address is unchanged, SM4.3 set,
  ENO 0.

The settings live in :class:`plcrt.engine.clock.Station`.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.recipe import CPU, Call
from ..gen.operands import Const
from ..memory.hardware import PORTS
from .region import runtime_error
from .registry import Role, insn

F = "smart"


def _ms_timer(plc):
    """The 1 ms system timer of *plc* (bound as a recipe: each PLC makes its own)."""

    def ms() -> int:
        return plc._irq_t // 1000 & 0xFFFFFFFF

    return ms


def _timer(g: Gen) -> str:
    hooks = g.unit.hooks
    if "ms_timer" not in hooks:
        hooks["ms_timer"] = Call(_ms_timer, (CPU,))
    return g.bind(hooks["ms_timer"], "ms")


@insn("BITIM", Role.D_W, family=F, summary="OUT := the 1 ms system timer")
def _bitim(g: Gen, out) -> None:
    ms = _timer(g)
    with g.box():
        g.wr(out, "DU", f"{ms}()")


@insn("CITIM", Role.D_R, Role.D_W, family=F,
      summary="OUT := milliseconds since the 1 ms timer read IN (wraps)")
def _citim(g: Gen, start, out) -> None:
    ms = _timer(g)
    with g.box():
        g.wr(out, "DU", f"{ms}() - {g.rd(start, 'DU')}")


@insn("DLED", Role.B_R, family=F, summary="diagnostic LED on for IN > 0, off for 0")
def _dled(g: Gen, value) -> None:
    fn = g.cpu("station.dled", "dled")
    with g.box():
        g.line(f"{fn}({g.rd(value, 'B')})")


def _port(g: Gen, op) -> int:
    if not isinstance(op, Const) or op.is_real or not isinstance(op.value, int) \
            or op.value not in PORTS:
        g.fail("PORT must be the constant 0 or 1")
    return int(op.value)


@insn("GPA", Role.B_W, Role.B_R, family=F, summary="ADDR := the station address of PORT")
def _gpa(g: Gen, addr, port) -> None:
    p = _port(g, port)
    fn = g.cpu("station.get_address", "gpa")
    with g.box():
        g.wr(addr, "B", f"{fn}({p})", exact=True)


def _spa_helper(plc):
    station, irq = plc.station, plc.interrupts

    def spa(address: int, port: int, insn_id: int) -> int:
        if irq.running:
            return runtime_error(plc, insn_id, 0x0004, "SPA executed by an interrupt "
                                 "routine; the port address is unchanged")
        if station.set_address(port, address):
            return 1
        return runtime_error(plc, insn_id, 0x0091, f"SPA: station address {address} is "
                             f"outside 0..126; the port address is unchanged")

    return spa


@insn("SPA", Role.B_R, Role.B_R, family=F, may_fail=True,
      summary="the station address of PORT := ADDR (not kept over power-off)")
def _spa(g: Gen, addr, port) -> None:
    p = _port(g, port)
    hooks = g.unit.hooks
    if "spa" not in hooks:
        hooks["spa"] = Call(_spa_helper, (CPU,))
    fn = g.bind(hooks["spa"], "spa")
    with g.box():
        g.eno(f"{fn}({g.rd(addr, 'B')}, {p}, {g.insn_id})")
