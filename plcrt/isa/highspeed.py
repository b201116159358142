"""Instruction family: the CPU's high-speed outputs.

PLS (S7-200 System Manual, "Pulse Output (PLS)"): acts on the control byte
of Q0.0 (SMB67) or Q0.1 (SMB77) and starts, updates or stops the output's
PTO or PWM generator, :class:`plcrt.engine.pulse.PulseOutput`.  HDEF and
HSC (the high-speed counters) are not built yet.
"""

from __future__ import annotations

from ..compiler.emit import Gen
from ..compiler.operands import Const
from ..compiler.resolve import ResolveError
from ..isa.registry import insn
from ..safetext import excerpt

F = "high-speed"


@insn("PLS", family=F, summary="start, update or stop the PTO/PWM of Q0.0 or Q0.1",
      variadic=True)
def _pls(g: Gen, insn_ir, resolver, *_ops) -> None:
    ops = [o.text for o in insn_ir.operands]
    if len(ops) != 1:
        g.fail(f"PLS takes the pulse output (0 for Q0.0, 1 for Q0.1), got {len(ops)} operand(s)")
    text = ops[0].strip()
    if text.upper() in ("Q0.0", "Q0.1"):
        number = int(text[-1])
    else:
        try:
            op = resolver.parse(text)
        except ResolveError as e:
            g.fail(f"PLS: {e}")
        if not isinstance(op, Const) or op.is_real or op.value not in (0, 1):
            g.fail(f"PLS takes the constant 0 (Q0.0) or 1 (Q0.1), got '{excerpt(text)}'")
        number = int(op.value)
    pls = g.bind(g.unit.hooks["plc"]._pls, "pls")
    with g.box():
        g.line(f"{pls}({number})")
