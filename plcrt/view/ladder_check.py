"""Checks of an edited ladder model: operands, the STL round trip, the program.

Three checks, from cheap to complete:

* :func:`check_operands`: each element's mnemonic is in the instruction
  registry, it has the operand count the registry gives, each operand
  that is an address or a constant fits the instruction's role (the checks
  ``plcrt check`` runs, :mod:`plcrt.gen.resolve`), and a timer box's number
  is one of its kind; symbols and ``#locals``
  are checked for their spelling only, since the symbol table and the
  block's interface are the program's;
* :func:`check_round_trip`: the model's STL, read by the STL parser, gives
  the model's instructions with the operand texts as typed (an operand with
  a comma, a line break or ``//`` would not) and reads back as the same
  ladder;
* :func:`check_in_program`: the network put into its program text, which
  is loaded as ``plcrt check`` loads it.

Every refusal is a :class:`~plcrt.errors.PlcConfigError` that names the
element (its path in the model) and the reason.
"""

from __future__ import annotations

from typing import Any

from ..errors import PlcConfigError, PlcError
from ..gen.operands import Name, OperandError, parse_operand
from ..gen.resolve import ResolveError, check_role
from ..isa.registry import lookup
from ..lang import ir
from ..lang.stl import parse_program
from ..memory.cpu import cpu_model
from ..memory.hardware import timer_kind_ok
from ..safetext import excerpt
from .ladder_model import Box, Coil, Contact, Model, Node, Parallel, Series
from .ladder_stl import NoLadder, model_lines, network_text, network_to_model, normalize

#: timer boxes, whose number says which box may use it
TIMER_BOXES = ("TON", "TOF", "TONR")
#: the program a network is wrapped in for the parser (OB1, no interface)
_WRAP = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n{}END_ORGANIZATION_BLOCK\n"


def _path_text(path: tuple[Any, ...]) -> str:
    return "/".join(str(p) for p in path) or "(model)"


def elements(model: Model) -> list[tuple[tuple[Any, ...], str, tuple[str, ...]]]:
    """Every instruction-bearing element with its path, its STL mnemonic (in
    the series form for contacts) and its operands."""
    found: list[tuple[tuple[Any, ...], str, tuple[str, ...]]] = []

    def logic(x: Any, path: tuple[Any, ...]) -> None:
        if isinstance(x, Contact):
            found.append((path, x.mnemonic("A"), x.ops))
        elif isinstance(x, (Series, Parallel)):
            for k, i in enumerate(x.items):
                logic(i, path + (k,))

    def out(x: Any, path: tuple[Any, ...]) -> None:
        if isinstance(x, Node):
            if x.logic is not None:
                logic(x.logic, path + ("logic",))
            for k, o in enumerate(x.outs):
                out(o, path + ("outs", k))
        elif isinstance(x, (Coil, Box)):
            found.append((path, x.insn, x.ops))
            if isinstance(x, Box):
                for k, i in enumerate(x.inputs):
                    logic(i, path + ("inputs", k))
                if x.next is not None:
                    out(x.next, path + ("next",))

    if model.rung is not None:
        out(model.rung, ("rung",))
    for k, e in enumerate(model.rail):
        out(e, ("rail", k))
    return found


def check_operands(model: Model, cpu: str | None = None) -> None:
    """Mnemonics, operand counts and the operands' kinds (see the module
    docstring); raises :class:`PlcConfigError`."""
    cm = cpu_model(cpu)
    for path, mnemonic, ops in elements(model):
        where = f"ladder element {_path_text(path)} ({excerpt(mnemonic, 16)})"
        spec = lookup(mnemonic)
        if spec is None:
            raise PlcConfigError(f"{where}: unknown instruction")
        roles = spec.roles
        if (len(ops) < len(roles)) if spec.variadic else (len(ops) != len(roles)):
            raise PlcConfigError(f"{where}: takes {len(roles)} operand(s), got {len(ops)}")
        if mnemonic in TIMER_BOXES and ops and ops[0][:1] in "Tt" and ops[0][1:].isdigit():
            # the timer number decides the kind (System Manual, timers; isa/timers.py)
            if not timer_kind_ok(mnemonic, int(ops[0][1:])):
                raise PlcConfigError(f"{where}: {excerpt(ops[0], 8)} is not a {mnemonic} timer "
                                     "number (TONR: T0-T31, T64-T95; TON/TOF: the others)")
        for k, text in enumerate(ops):
            if not text.strip() or text != text.strip():
                raise PlcConfigError(f"{where}: operand {k + 1} is empty or has blanks around it")
            if k >= len(roles):
                continue  # CALL parameters: the callee's interface decides
            try:
                op = parse_operand(text, cm)
                if not isinstance(op, Name):
                    check_role(op, roles[k], text, cm)
            except (OperandError, ResolveError) as e:
                raise PlcConfigError(f"{where}: operand {k + 1}: {e}") from None


def check_round_trip(model: Model) -> Model:
    """Parse the model's STL and read it back as a model; the result must
    be the model (normalized).  Returns the normalized model."""
    norm = normalize(model)
    lines = model_lines(norm)
    text = network_text(norm, 1)
    try:
        prog = parse_program(_WRAP.format(text), "<ladder>")
    except PlcError as e:
        raise PlcConfigError(f"the drawing's STL does not parse: {e}") from None
    nets = prog.pous[0].networks if prog.pous else ()
    if len(nets) != 1:
        raise PlcConfigError("the drawing's STL does not read back as one network "
                             "(a title or comment with a line that starts a network?)")
    net = nets[0]
    got = [(i.mnemonic, tuple(o.text for o in i.operands)) for i in net.insns]
    for k, (a, b) in enumerate(zip(got, lines)):
        if a != b:
            raise PlcConfigError(f"instruction {k + 1} reads back as {excerpt(a[0], 16)} "
                                 f"{excerpt(', '.join(a[1]))}, not as written: an operand "
                                 "with a comma, a line break or // in it?")
    if len(got) != len(lines):
        raise PlcConfigError("the drawing's STL does not read back as its instructions "
                             "(an operand with a line break in it?)")
    back = network_to_model(net)
    if isinstance(back, NoLadder):
        raise PlcConfigError(f"the drawing has no ladder form in STL: {back.reason}")
    if back != norm:
        raise PlcConfigError("the drawing's STL reads back as a different ladder")
    return norm


def replace_network(text: str, block: str, number: int, model: Model) -> str:
    """The program text with network ``number`` of ``block`` (``OB1``,
    ``SBR0``, or the block's name) replaced by the model's network.  The
    program is parsed to find the network's lines; the rest is kept byte
    for byte."""
    prog = parse_program(text, "<program>")
    pou = _block(prog, block)
    idx = next((k for k, n in enumerate(pou.networks) if n.number == number), None)
    if idx is None:
        raise PlcConfigError(f"block {excerpt(block, 40)} has no network {number}")
    lines = text.splitlines(keepends=True)
    start = pou.networks[idx].loc.line - 1
    if idx + 1 < len(pou.networks):
        end = pou.networks[idx + 1].loc.line - 1
    else:
        end = next(k for k in range(start + 1, len(lines))
                   if lines[k].strip().upper().startswith("END_"))
    return "".join(lines[:start]) + network_text(model, number) + "".join(lines[end:])


def _block(prog: ir.Program, block: str) -> ir.Pou:
    key = block.upper()
    for p in prog.pous:
        if key in (p.ident.upper(), p.name.upper()):
            return p
    raise PlcConfigError(f"no block {excerpt(block, 40)} in the program")


def check_in_program(text: str, block: str, number: int, model: Model, *,
                     symbols: Any = None) -> str:
    """Put the model into its program and load it as ``plcrt check`` does
    (:func:`plcrt.load` with ``library=True``); returns the new program
    text, raises the load's :class:`PlcError` when the program is refused."""
    new = replace_network(text, block, number, model)
    from ..loader import load  # the compiler: only when a program is checked
    load(new, symbols=symbols, library=True, backend="python")
    return new


__all__ = ["check_in_program", "check_operands", "check_round_trip", "elements",
           "replace_network"]
