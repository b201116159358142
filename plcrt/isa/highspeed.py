"""Instruction family: the CPU's high-speed outputs.

PLS (S7-200 System Manual, "Pulse Output (PLS)"): acts on the control byte
of Q0.0 (SMB67) or Q0.1 (SMB77) and starts, updates or stops the output's
PTO or PWM generator, :class:`plcrt.engine.pulse.PulseOutput`.  HDEF and
HSC ("High-Speed Counter instructions") define a counter's mode and apply
its control byte, :class:`plcrt.engine.hsc.HighSpeedCounter`; the modes a
counter has are checked when the program is loaded.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..memory.hardware import MODES
from ..safetext import excerpt
from .args import int_constant, operand_texts
from .registry import insn

F = "high-speed"


@insn("PLS", family=F, summary="start, update or stop the PTO/PWM of Q0.0 or Q0.1",
      variadic=True)
def _pls(g: Gen, insn_ir, resolver, *_ops) -> None:
    text = operand_texts(g, insn_ir, 1, "the pulse output (0 for Q0.0, 1 for Q0.1)")[0].strip()
    if text.upper() in ("Q0.0", "Q0.1"):
        number = int(text[-1])
    else:
        wrong = f"PLS takes the constant 0 (Q0.0) or 1 (Q0.1), got '{excerpt(text)}'"
        number = int_constant(g, resolver, text, "PLS", wrong)
        if number not in (0, 1):
            g.fail(wrong)
    pls = g.cpu("_pls", "pls")
    with g.box():
        g.line(f"{pls}({number})")


def _const(g: Gen, resolver, text: str, what: str, allowed) -> int:
    value = int_constant(g, resolver, text, what, f"{what} must be a constant, got "
                         f"'{excerpt(text)}'")
    if value not in allowed:
        g.fail(f"{what} {value} is not one of {', '.join(map(str, allowed))}")
    return value


@insn("HDEF", family=F, summary="define the mode of a high-speed counter", variadic=True)
def _hdef(g: Gen, insn_ir, resolver, *_ops) -> None:
    ops = operand_texts(g, insn_ir, 2, "a counter and a mode (HDEF HSC, MODE)")
    if g.unit.current.pou.kind == "INT":
        g.fail("HDEF is not allowed in an interrupt routine")
    n = _const(g, resolver, ops[0], "HSC", range(g.unit.model.hsc))
    mode = _const(g, resolver, ops[1], f"HSC{n} mode", MODES[n])
    hdef = g.cpu("_hdef", "hdef")
    with g.box():
        g.line(f"{hdef}({n}, {mode})")


@insn("HSC", family=F, summary="apply the control byte of a high-speed counter",
      variadic=True)
def _hsc(g: Gen, insn_ir, resolver, *_ops) -> None:
    ops = operand_texts(g, insn_ir, 1, "the counter number")
    n = _const(g, resolver, ops[0], "HSC", range(g.unit.model.hsc))
    hsc = g.cpu("_hsc", "hsc")
    with g.box():
        g.line(f"{hsc}({n})")
