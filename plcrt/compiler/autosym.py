"""Addresses for the symbols a program uses but no symbol table defines
(``--auto-symbols`` / ``plcrt.load(..., auto_symbols=True)``).

What it is: a pass over the parsed program, before compilation, that finds
every unknown symbolic operand, infers the width its uses need from the
instruction's operand roles (a contact or coil: a bit; ``MOVW``: a word;
``MOVD``/``+R``: a double word; a ``CALL`` argument: the parameter's type),
and gives it a free address:

* bits in M memory, from M31.7 downwards, in M bytes the program does not
  address itself; when M is full, in V like the others;
* a bit that an immediate instruction reads (``LDI``, ``AI`` ...): an input
  I, from I15.7 downwards; one an immediate output writes (``=I``, ``SI``):
  an output Q, from Q15.7 downwards; in bytes the program does not use;
* bytes, words and double words in V memory, from the top of V downwards,
  aligned to their width, in bytes neither the program nor the data block
  uses.

Every assignment is reported as a warning naming the symbol, its address
and its first use, so nothing is guessed silently.  A symbol used with two
widths (a bit here, a word there), or only where no address can be made up
(a timer, a counter, a label), is reported and left unknown: the compiler
then reports each of its uses as usual.

What it is not: a symbol table reader (:mod:`plcrt.lang.symbols`), or a
guess of what an address "should" be; the addresses only keep the program
running.  Indirect accesses (``*VD100``) are invisible to it, so a program
that walks a pointer over high V memory may meet an assigned symbol there;
the warning lists every address it took.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable

from ..errors import Diagnostic, PlcConfigError, SourceLoc
from ..isa.registry import Role, lookup
from ..lang import ir
from ..lang.symbols import Symbol, SymbolTable
from ..memory.cpu import CpuModel
from ..safetext import excerpt
from .operands import Addr, Name
from .resolve import LocalVar, ResolveError, Resolver, layout_locals

__all__ = ["auto_symbols"]

#: operand role -> the kind of address it needs: "bit", "I" / "Q" (an input
#: or output bit: immediate instructions), or a width in bytes; roles missing
#: here (timers, counters, labels) cannot take a made-up address
_KIND: dict[Role, str | int] = {
    Role.BIT_R: "bit", Role.BIT_W: "bit", Role.BIT_TC: "bit",
    Role.IBIT: "I", Role.QBIT: "Q",
    Role.B_R: 1, Role.B_W: 1,
    Role.W_R: 2, Role.W_W: 2,
    Role.D_R: 4, Role.D_W: 4, Role.R_R: 4, Role.R_W: 4, Role.D_PTR: 4,
    Role.B_M: 1, Role.B_MW: 1, Role.W_M: 2, Role.W_MW: 2, Role.D_M: 4, Role.D_MW: 4,
}
_KIND_NAME: dict[str | int, str] = {"bit": "a bit", "I": "an input bit (immediate)",
                                    "Q": "an output bit (immediate)", 1: "a byte",
                                    2: "a word", 4: "a double word"}
_TYPE_KIND: dict[str, str | int] = {"BOOL": "bit", "BYTE": 1, "WORD": 2, "INT": 2,
                                    "DINT": 4, "DWORD": 4, "REAL": 4}


@dataclass
class _Use:
    kind: str | int | None     #: None: used only where no address can be made up
    loc: SourceLoc             #: the first use
    clash: SourceLoc | None = None   #: a use that needs another kind


def auto_symbols(program: ir.Program, model: CpuModel, symbols: SymbolTable | None,
                 system_symbols: dict[str, str], data: Any = None
                 ) -> tuple[SymbolTable | None, list[Diagnostic]]:
    """The symbol table extended by an address for each unknown symbol the
    program uses, and the diagnostics that report them (warnings)."""
    uses, used = _collect(program, model, symbols, system_symbols)
    if not uses:
        return symbols, []
    if data is not None:
        for entry in data.entries:
            used.update(("V", entry.offset + k) for k in range(max(1, len(entry.data))))
    entries = dict(symbols.entries) if symbols is not None else {}
    diags: list[Diagnostic] = []
    alloc = _Allocator(model, used)
    for name, use in sorted(uses.items(), key=lambda kv: (kv[1].loc.line, kv[1].loc.column)):
        shown = excerpt(name)
        if use.clash is not None:
            diags.append(Diagnostic("warning", (
                f"auto-symbols: '{shown}' is used as {_KIND_NAME[use.kind or 'bit']} and, at "
                f"line {use.clash.line}, as something else: it gets no address (give it "
                f"one in a symbol table)"), use.loc, "auto-symbol"))
            continue
        if use.kind is None:
            diags.append(Diagnostic("warning", (
                f"auto-symbols: '{shown}' is used only where no address can be made up "
                f"(a timer, counter or label): give it one in a symbol table"),
                use.loc, "auto-symbol"))
            continue
        address = alloc.take(use.kind)
        if address is None:
            diags.append(Diagnostic("warning", (
                f"auto-symbols: no free memory left for '{shown}' ({_KIND_NAME[use.kind]})"),
                use.loc, "auto-symbol"))
            continue
        entries[name] = Symbol(name, address, "assigned by auto-symbols", use.loc)
        diags.append(Diagnostic("warning", (
            f"auto-symbols: '{shown}' is not in a symbol table; it is {address} "
            f"({_KIND_NAME[use.kind]}, first used here)"), use.loc, "auto-symbol"))
    table = SymbolTable(entries=entries,
                        file=symbols.file if symbols is not None else "<auto-symbols>")
    return table, diags


# -- finding the unknown symbols ----------------------------------------------

def _collect(program: ir.Program, model: CpuModel, symbols: SymbolTable | None,
             system_symbols: dict[str, str]) -> tuple[dict[str, _Use], set[tuple[str, int]]]:
    """Unknown symbols with their uses, and the (area, byte) the program addresses."""
    uses: dict[str, _Use] = {}
    used: set[tuple[str, int]] = set()
    layouts = {pou.ident: _locals(pou, model) for pou in program.pous}
    params = _subroutine_params(program, layouts)
    for pou in program.pous:
        resolver = Resolver(model, symbols, system_symbols, layouts[pou.ident])
        for net in pou.networks:
            for insn in net.insns:
                for text, width, loc in _operands(insn, params, pou, net):
                    try:
                        op = resolver.parse(text)
                    except ResolveError:
                        continue
                    if isinstance(op, Addr):
                        if op.area in ("M", "V", "I", "Q"):
                            used.update((op.area, op.offset + k) for k in range(max(1, op.width or 1)))
                    elif isinstance(op, Name):
                        _note(uses, op.name, width, loc)
    return uses, used


def _note(uses: dict[str, _Use], name: str, kind: str | int | None, loc: SourceLoc) -> None:
    use = uses.get(name)
    if use is None:
        uses[name] = _Use(kind, loc)
        return
    if kind is None or kind == use.kind:
        return
    if use.kind is None or (use.kind == "bit" and kind in ("I", "Q")):
        use.kind = kind                 # an I or Q bit also serves as a plain bit
    elif not (kind == "bit" and use.kind in ("I", "Q")) and use.clash is None:
        use.clash = loc


def _operands(insn: ir.Insn, params: dict[str, list[str | int]], pou: ir.Pou,
              net: ir.Network) -> Iterable[tuple[str, str | int | None, SourceLoc]]:
    """(text, kind or None, location) of each operand of one instruction."""
    spec = lookup(insn.mnemonic)
    if spec is None:
        return
    ops = insn.operands
    if spec.variadic:          # CALL name, args: the widths of the callee's parameters
        if not ops:
            return
        widths = params.get(ops[0].text.split(":")[0].strip().upper(), [])
        typed = [(o, w) for o, w in zip(ops[1:], widths)]
    else:
        typed = [(o, _KIND.get(r)) for o, r in zip(ops, spec.roles)]
    for op, kind in typed:
        loc = op.loc.within(pou.ident, net.number) if op.loc.block is None else op.loc
        yield op.text, kind, loc


def _locals(pou: ir.Pou, model: CpuModel) -> dict[str, LocalVar]:
    """The block's locals, or none when they cannot be laid out (the
    compiler reports why)."""
    try:
        return layout_locals(pou, model.l_bytes)
    except ResolveError:
        return {}


def _subroutine_params(program: ir.Program, layouts: dict[str, dict[str, LocalVar]]
                       ) -> dict[str, list[str | int]]:
    """Callee name (block id and symbolic name, upper case) -> the kinds of
    its parameters in call order; the library blocks' too."""
    out: dict[str, list[str | int]] = {}
    try:
        from ..blocks.interface import interfaces
        for name, itf in interfaces().items():
            out[name] = [_TYPE_KIND.get(p.type, 4) for p in itf.params]
    except PlcConfigError:      # a bad library file: the compiler reports it
        pass
    for pou in program.pous:
        if pou.kind != "SBR":
            continue
        local_vars = layouts[pou.ident]
        kinds: list[str | int] = [lv.addr.width or "bit" for lv in local_vars.values()
                                  if lv.decl.section != "TEMP"]
        out[pou.ident] = kinds
        if pou.name:
            out[pou.name.upper()] = kinds
    return out


# -- giving addresses -----------------------------------------------------------

class _Allocator:
    """Free M bits from M31.7 down (then V), I and Q bits from byte 15 down,
    free V bytes from the top of V down."""

    def __init__(self, model: CpuModel, used: set[tuple[str, int]]) -> None:
        self.used = used
        self.v_top = model.v_bytes     #: V bytes at and above this are taken
        #: area -> [current byte, bits left in it (0: none open)]
        self.bits = {"M": [model.m_bytes, 0], "I": [model.i_bytes, 0], "Q": [model.q_bytes, 0]}

    def take(self, kind: str | int) -> str | None:
        if kind in ("bit", "I", "Q"):
            bit = self._bit("M" if kind == "bit" else str(kind))
            if bit is not None or kind != "bit":
                return bit
            byte = self._v(1)
            return None if byte is None else f"V{byte}.0"
        assert isinstance(kind, int)
        byte = self._v(kind)
        return None if byte is None else f"V{'BW?D'[kind - 1]}{byte}"

    def _bit(self, area: str) -> str | None:
        cur = self.bits[area]
        if cur[1] == 0:                # open the next byte nobody uses
            byte = cur[0] - 1
            while byte >= 0 and (area, byte) in self.used:
                byte -= 1
            if byte < 0:
                return None
            self.used.add((area, byte))
            cur[0], cur[1] = byte, 8
        cur[1] -= 1
        return f"{area}{cur[0]}.{cur[1]}"

    def _v(self, width: int) -> int | None:
        at = (self.v_top - width) // width * width
        while at >= 0:
            if all(("V", at + k) not in self.used for k in range(width)):
                self.used.update(("V", at + k) for k in range(width))
                self.v_top = at
                return at
            at -= width
        return None
