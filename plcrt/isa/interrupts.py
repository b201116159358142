"""Instruction family: interrupts.

ATCH DTCH ENI DISI RETI CRETI CEVNT (S7-200 System Manual, "Interrupt
instructions"; CEVNT from the S7-200 SMART).  The emitters check what the
CPU checks when the program is downloaded (the routine exists, the event is
in the event table, ENI/DISI/HDEF/END/SCR not in a routine) and call the
run-time interrupt system, :class:`plcrt.engine.interrupts.Interrupts`,
through the engine.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..safetext import excerpt
from .args import int_constant, operand_texts
from .registry import insn

F = "interrupt"

#: the event numbers of the S7-200's event table (System Manual, table
#: "Interrupt events"; plcrt.engine.interrupts.EVENTS)
EVENT_NUMBERS = range(0, 34)


def _kind(g: Gen) -> str:
    return g.unit.current.pou.kind


def _event(g: Gen, resolver, text: str) -> int:
    event = int_constant(g, resolver, text, "EVNT",
                         f"EVNT must be a constant event number, got '{excerpt(text)}'")
    if event not in EVENT_NUMBERS:
        g.fail(f"event {event} is not in the S7-200's event table (0..33)")
    return event


def _guarded(g: Gen):
    """A coil-like instruction: conditional on the top of the stack, and
    unconditional at the start of a network (LAD draws it on the rail)."""
    if g.depth == 0 and g.pending is None:
        from contextlib import nullcontext
        return nullcontext()
    return g.box()


@insn("ATCH", family=F, summary="attach an interrupt routine to an event and enable it",
      variadic=True)
def _atch(g: Gen, insn_ir, resolver, *_ops) -> None:
    name, evnt = operand_texts(g, insn_ir, 2, "an interrupt routine and an event (ATCH INT, EVNT)")
    callee = g.unit.callee(name.split(":")[0])
    if callee is None:
        g.fail(f"no interrupt routine named '{excerpt(name)}' in the program")
    if callee.pou.kind != "INT":
        g.fail(f"{callee.pou.ident} is not an interrupt routine (INTERRUPT_BLOCK)")
    event = _event(g, resolver, evnt)
    attach = g.cpu("_irq_attach", "atch")
    with _guarded(g):
        g.line(f"{attach}({int(callee.pou.number)}, {event})")


@insn("DTCH", family=F, summary="detach (disable) an interrupt event", variadic=True)
def _dtch(g: Gen, insn_ir, resolver, *_ops) -> None:
    evnt, = operand_texts(g, insn_ir, 1, "an event (DTCH EVNT)")
    event = _event(g, resolver, evnt)
    detach = g.cpu("_irq_detach", "dtch")
    with _guarded(g):
        g.line(f"{detach}({event})")


@insn("CEVNT", family=F, summary="clear the queued occurrences of an event (SMART)",
      variadic=True)
def _cevnt(g: Gen, insn_ir, resolver, *_ops) -> None:
    evnt, = operand_texts(g, insn_ir, 1, "an event (CEVNT EVNT)")
    event = _event(g, resolver, evnt)
    clear = g.cpu("interrupts.clear", "cevnt")
    with _guarded(g):
        g.line(f"{clear}({event})")


@insn("ENI", family=F, summary="enable interrupt processing")
def _eni(g: Gen) -> None:
    if _kind(g) == "INT":
        g.fail("ENI is not allowed in an interrupt routine")
    eni = g.cpu("_irq_enable", "eni")
    with _guarded(g):
        g.line(f"{eni}()")


@insn("DISI", family=F, summary="disable interrupt processing (events are queued)")
def _disi(g: Gen) -> None:
    if _kind(g) == "INT":
        g.fail("DISI is not allowed in an interrupt routine")
    disi = g.cpu("interrupts.disable", "disi")
    with _guarded(g):
        g.line(f"{disi}()")


@insn("RETI", family=F, summary="return from an interrupt routine", flow="ret")
def _reti(g: Gen) -> None:
    if _kind(g) != "INT":
        g.fail("RETI is only allowed in an interrupt routine")
    g.line("return -1")


@insn("CRETI", family=F, summary="conditional return from an interrupt routine", flow="ret")
def _creti(g: Gen) -> None:
    if _kind(g) != "INT":
        g.fail("CRETI is only allowed in an interrupt routine")
    with g.box():
        g.line("return -1")
