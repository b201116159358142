"""The PID loop instruction's algorithm over its loop table (S7-200 System
Manual, "PID Loop instruction" and "Understanding the PID equation").

What it is: :class:`PidLoops`, the eight loops of one CPU.  ``PID TBL,
LOOP`` runs :meth:`PidLoops.execute` with the power flow into the box; the
loop table is 36 bytes of V memory at TBL, REALs in S7-200 byte order::

    offset  field   meaning
     0      PVn     process variable, normalised 0.0 .. 1.0
     4      SPn     setpoint, normalised 0.0 .. 1.0
     8      Mn      output, 0.0 .. 1.0 (written)
    12      Kc      gain (negative: a reverse-acting loop)
    16      Ts      sample time, seconds
    20      Ti      integral time, minutes (+INF: no integral action)
    24      Td      derivative time, minutes (0.0: no derivative action)
    28      MX      bias: the running integral sum (written)
    32      PVn-1   the process variable of the last execution (written)

Each execution computes, with e = SPn − PVn::

    MPn = Kc · e
    MIn = Kc · Ts / Ti · e + MX
    MDn = Kc · Td / Ts · (PVn-1 − PVn)      (on the PV, not the error)
    Mn  = MPn + MIn + MDn, limited to 0.0 .. 1.0

When Mn is limited, the bias is set so that the output just reaches the
limit (MX = 1.0 − (MPn + MDn) or −(MPn + MDn)), then MX itself is kept in
0.0 .. 1.0: the manual's protection against integral windup.  A gain of 0.0
gives integral and derivative action with a gain of 1.0 (an I or ID loop).
Power flow 0 → 1 is the change from manual to automatic: SPn = PVn,
PVn-1 = PVn and MX = Mn, so the output continues without a bump.

The CPU computes once per execution: the program is responsible for running
PID every Ts (a timed interrupt, or a timer), as the manual says.

What it is not: the code generation (:mod:`plcrt.isa.pid`) or the
auto-tuning extension of the table (bytes 36 on, CPU 22x v2.3), which is
not simulated.
"""

from __future__ import annotations

import math
import struct
from typing import Any, Callable

__all__ = ["PidLoops", "TABLE_BYTES"]

from ..memory.hardware import TABLE_BYTES  # noqa: E402
_TABLE = struct.Struct(">9f")
_OUT = struct.Struct(">f")


class PidLoops:
    """The PID loops 0..7 of one CPU: the power flow each last saw."""

    def __init__(self, v: bytearray, sm: bytearray,
                 warn: Callable[[str, str], None]) -> None:
        self.v, self.sm, self.warn = v, sm, warn
        self.enabled = [False] * 8     #: power flow at the loop's last execution

    def execute(self, loop: int, table: int, en: int) -> int:
        """PID at the V offset *table* with power flow *en*; returns ENO."""
        was = self.enabled[loop]
        self.enabled[loop] = bool(en)
        if not en:
            return 0
        v = self.v
        pv, sp, m, kc, ts, ti, td, mx, pv1 = _TABLE.unpack_from(v, table)
        if not was:
            # manual -> automatic: bumpless transfer (manual, "Modes")
            sp, pv1, mx = pv, pv, m
            _OUT.pack_into(v, table + 4, sp)
        if not (0.0 <= pv <= 1.0 and 0.0 <= sp <= 1.0):
            self.warn(f"PID loop {loop} (VB{table}): PV {pv:g} or SP {sp:g} is outside the "
                      f"normalised range 0.0..1.0; the CPU computes with it anyway (System "
                      f"Manual, converting the loop inputs)", f"pid-range-{loop}")
        try:
            out = _compute(sp, pv, kc, ts, ti, td, mx, pv1)
        except (ArithmeticError, ValueError):
            out = None
        if out is None:
            # a math error: SM1.1, the loop terminates with its outputs as
            # they were (manual, PID error conditions)
            self.sm[1] |= 0x02
            self.warn(f"PID loop {loop} (VB{table}): a math error in the loop table (Kc "
                      f"{kc:g}, Ts {ts:g}, Ti {ti:g}, Td {td:g}, MX {mx:g}): SM1.1 is set and "
                      f"the outputs are not updated", f"pid-math-{loop}")
            return 0
        m, mx = out
        _OUT.pack_into(v, table + 8, m)
        _OUT.pack_into(v, table + 28, mx)
        _OUT.pack_into(v, table + 32, pv)
        return 1


def _finite(*xs: float) -> bool:
    return all(math.isfinite(x) for x in xs)


def _compute(sp: float, pv: float, kc: float, ts: float, ti: float, td: float,
             mx: float, pv1: float) -> tuple[float, float] | None:
    """(Mn, MX) of one execution, or None on a math error."""
    if not _finite(sp, pv, kc, ts, td, mx, pv1) or math.isnan(ti) or ts <= 0.0:
        return None
    e = sp - pv
    mp = kc * e
    k = kc if kc != 0.0 else 1.0       # a gain of 0.0: I and D with gain 1.0
    if ti == math.inf:
        mi = mx                        # no integral action: the bias only
    elif ti > 0.0:
        mi = k * ts / (ti * 60.0) * e + mx
    else:
        return None
    md = k * (td * 60.0) / ts * (pv1 - pv) if td != 0.0 else 0.0
    m = mp + mi + md
    if not _finite(m, mi, md):
        return None
    if m > 1.0:
        m, mi = 1.0, 1.0 - (mp + md)
    elif m < 0.0:
        m, mi = 0.0, -(mp + md)
    mi = min(1.0, max(0.0, mi))
    return m, mi


def make_loops(plc: Any) -> PidLoops:
    """The PID loops of *plc*, reporting through its diagnostics."""
    return PidLoops(plc.mem.areas["V"], plc.mem.areas["SM"], plc._irq_warn)
