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
  uses;
* a symbol that starts a run of memory (``S name, 8``, ``RI name, 8``,
  ``BMW name, VW0, 10``, a table, a clock buffer: the instruction's
  :class:`~plcrt.isa.registry.Span`) gets room for the whole run: whole
  free bytes for a run of bits, the run's bytes in V for values.  A count
  that is not a constant reserves the most the instruction allows;
* an operand written as ``Name:M2.0`` (Micro/WIN's symbol with its address)
  is the symbol ``Name`` at the address given, for that operand and for
  every other use of ``Name``.

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
from ..gen.operands import Addr, Name, OperandError, parse_constant, parse_operand
from ..gen.resolve import LocalVar, ResolveError, Resolver, layout_locals
from ..isa.libraries import interfaces
from ..isa.registry import Role, Span, lookup
from ..lang import ir
from ..lang.symbols import Symbol, SymbolTable
from ..memory.cpu import CpuModel
from ..safetext import excerpt

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


_BIT_KINDS = ("bit", "I", "Q")


@dataclass
class _Use:
    kind: str | int | None     #: None: used only where no address can be made up
    loc: SourceLoc             #: the first use
    clash: SourceLoc | None = None   #: a use that needs another kind
    #: the run its uses reach from its address: bits for a bit, bytes for a value
    size: int = 1


def auto_symbols(program: ir.Program, model: CpuModel, symbols: SymbolTable | None,
                 system_symbols: dict[str, str], data: Any = None
                 ) -> tuple[SymbolTable | None, list[Diagnostic]]:
    """The symbol table extended by an address for each unknown symbol the
    program uses, and the diagnostics that report them (warnings)."""
    uses, used, pinned = _collect(program, model, symbols, system_symbols)
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
        pin = pinned.get(name)      # Name:ADDR, or a plain use of a Name given so
        if pin is not None:
            entries[name] = Symbol(name, pin, "assigned by auto-symbols", use.loc)
            base = _base(name)
            if base is not None and base not in entries:
                entries[base] = Symbol(base, pin, "assigned by auto-symbols", use.loc)
            diags.append(Diagnostic("warning", (
                f"auto-symbols: '{shown}' is not in a symbol table; it is {pin} "
                f"(the address written with '{excerpt(base or name)}')"), use.loc, "auto-symbol"))
            continue
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
        address = alloc.take(use.kind, use.size)
        what = _KIND_NAME[use.kind] + _run_text(use)
        if address is None:
            diags.append(Diagnostic("warning", (
                f"auto-symbols: no free memory left for '{shown}' ({what})"),
                use.loc, "auto-symbol"))
            continue
        entries[name] = Symbol(name, address, "assigned by auto-symbols", use.loc)
        diags.append(Diagnostic("warning", (
            f"auto-symbols: '{shown}' is not in a symbol table; it is {address} "
            f"({what}, first used here)"), use.loc, "auto-symbol"))
    table = SymbolTable(entries=entries,
                        file=symbols.file if symbols is not None else "<auto-symbols>")
    return table, diags


# -- finding the unknown symbols ----------------------------------------------

def _collect(program: ir.Program, model: CpuModel, symbols: SymbolTable | None,
             system_symbols: dict[str, str]
             ) -> tuple[dict[str, _Use], set[tuple[str, int]], dict[str, str]]:
    """Unknown symbols with their uses, the (area, byte) the program
    addresses, and the addresses ``Name:ADDR`` operands give (by the
    operand text and by the name)."""
    uses: dict[str, _Use] = {}
    used: set[tuple[str, int]] = set()
    pinned: dict[str, str] = {}
    layouts = {pou.ident: _locals(pou, model) for pou in program.pous}
    params = _subroutine_params(program, layouts)
    for pou in program.pous:
        resolver = Resolver(model, symbols, system_symbols, layouts[pou.ident])
        for net in pou.networks:
            for insn in net.insns:
                for text, kind, bits, loc in _operands(insn, params, pou, net):
                    try:
                        op = resolver.parse(text)
                    except ResolveError:
                        continue
                    if isinstance(op, Addr):
                        _mark(used, op, bits)
                    elif isinstance(op, Name):
                        at = _pin(op.name, model)
                        if at is not None:
                            _mark(used, at, bits)
                            pinned[op.name] = at.text
                            pinned.setdefault(op.name.partition(":")[0].strip(), at.text)
                        _note(uses, op.name, kind, bits, loc)
    return uses, used, pinned


def _base(name: str) -> str | None:
    """``Name`` of an operand written ``Name:ADDR``, else None."""
    base, sep, _ = name.partition(":")
    return base.strip() if sep and base.strip() else None


def _pin(name: str, model: CpuModel) -> Addr | None:
    """The address of ``Name:ADDR`` (Micro/WIN shows a symbol with its
    address that way), or None when the text is not of that form."""
    base = _base(name)
    if base is None:
        return None
    try:
        at = parse_operand(name.partition(":")[2].strip(), model)
    except OperandError:
        return None
    return at if isinstance(at, Addr) and at.area in _AREAS else None


#: areas whose bytes the allocator hands out or that a pinned address may name
_AREAS = ("I", "Q", "M", "V", "S", "SM", "AI", "AQ", "T", "C", "AC", "L")


def _mark(used: set[tuple[str, int]], op: Addr, bits: int | None) -> None:
    """Note the bytes of M, V, I and Q that an address reaches (with the
    run of its instruction, *bits* long, if any) as taken."""
    if op.area not in ("M", "V", "I", "Q"):
        return
    if op.width == 0:
        nbytes = (op.bit + (bits or 1) + 7) // 8
    else:
        nbytes = max(op.width or 1, ((bits or 0) + 7) // 8)
    used.update((op.area, op.offset + k) for k in range(nbytes))


def _note(uses: dict[str, _Use], name: str, kind: str | int | None, bits: int | None,
          loc: SourceLoc) -> None:
    use = uses.get(name)
    if use is None:
        use = uses[name] = _Use(kind, loc)
    elif kind is not None and kind != use.kind:
        if use.kind is None or (use.kind == "bit" and kind in ("I", "Q")):
            use.kind = kind                 # an I or Q bit also serves as a plain bit
        elif not (kind == "bit" and use.kind in ("I", "Q")) and use.clash is None:
            use.clash = loc
    if kind is not None:
        need = (bits or 1) if kind in _BIT_KINDS else max(int(kind), ((bits or 0) + 7) // 8)
        use.size = max(use.size, need)


def _run_text(use: _Use) -> str:
    """", 8 bits from it" for a symbol that starts a run, else ""."""
    if use.kind in _BIT_KINDS:
        return f", {use.size} bits from it" if use.size > 1 else ""
    return f", {use.size} bytes from it" if use.kind is not None and use.size > int(use.kind) \
        else ""


def _operands(insn: ir.Insn, params: dict[str, list[str | int]], pou: ir.Pou, net: ir.Network
              ) -> Iterable[tuple[str, str | int | None, int | None, SourceLoc]]:
    """(text, kind or None, bits of the run it starts or None, location) of
    each operand of one instruction."""
    spec = lookup(insn.mnemonic)
    if spec is None:
        return
    ops = insn.operands
    runs: dict[int, int] = {}
    if spec.variadic:          # CALL name, args: the widths of the callee's parameters
        if not ops:
            return
        widths = params.get(ops[0].text.split(":")[0].strip().upper(), [])
        typed = [(o, w) for o, w in zip(ops[1:], widths)]
    else:
        typed = [(o, _KIND.get(r)) for o, r in zip(ops, spec.roles)]
        texts = [o.text for o in ops]
        runs = {span.at: _span_bits(span, texts) for span in spec.spans}
    for i, (op, kind) in enumerate(typed):
        loc = op.loc.within(pou.ident, net.number) if op.loc.block is None else op.loc
        yield op.text, kind, runs.get(i), loc


def _span_bits(span: Span, operands: list[str]) -> int:
    """Bits a run takes: its count operand's magnitude when that is a
    constant (at most the span's count), else the span's count."""
    n = span.count
    if span.by is not None and span.by < len(operands):
        try:
            const = parse_constant(operands[span.by])
        except OperandError:
            const = None
        if const is not None and isinstance(const.value, int) and not const.is_real:
            n = max(1, min(abs(const.value), span.count))
    return n * span.unit


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
    free V bytes from the top of V down; a run of bits takes whole free
    bytes, a run of values the bytes of the whole run."""

    def __init__(self, model: CpuModel, used: set[tuple[str, int]]) -> None:
        self.used = used
        self.size = {"M": model.m_bytes, "I": model.i_bytes, "Q": model.q_bytes,
                     "V": model.v_bytes}
        #: area -> [current byte, bits left in it (0: none open)]
        self.bits = {"M": [model.m_bytes, 0], "I": [model.i_bytes, 0], "Q": [model.q_bytes, 0]}
        #: (area, bytes, alignment) -> where the last such run was found: the
        #: runs above it were taken then and stay taken (``used`` only grows)
        self.below: dict[tuple[str, int, int], int] = {}

    def take(self, kind: str | int, size: int = 1) -> str | None:
        """An address for a symbol of *kind* whose uses reach *size* bits
        (bit kinds) or bytes (values) from it; None when nothing is free."""
        if kind in _BIT_KINDS:
            area = "M" if kind == "bit" else str(kind)
            bit = self._bit(area) if size == 1 else self._bytes(area, (size + 7) // 8, 1)
            if bit is not None or kind != "bit":
                return bit if size == 1 or bit is None else f"{area}{bit}.0"
            byte = self._bytes("V", (size + 7) // 8, 1)
            return None if byte is None else f"V{byte}.0"
        assert isinstance(kind, int)
        byte = self._bytes("V", max(size, kind), kind)
        return None if byte is None else f"V{'BW?D'[kind - 1]}{byte}"

    def _bit(self, area: str) -> str | None:
        cur = self.bits[area]
        if cur[1] == 0:                # open the next byte nobody uses
            byte = self._bytes(area, 1, 1)
            if byte is None:
                return None
            cur[0], cur[1] = byte, 8
        cur[1] -= 1
        return f"{area}{cur[0]}.{cur[1]}"

    def _bytes(self, area: str, nbytes: int, align: int) -> int | None:
        """The highest free run of *nbytes* bytes of *area* starting at a
        multiple of *align*, now taken; None when there is none."""
        key = (area, nbytes, align)
        at = min(self.below.get(key, self.size[area]), self.size[area] - nbytes) // align * align
        while at >= 0:
            if all((area, at + k) not in self.used for k in range(nbytes)):
                self.used.update((area, at + k) for k in range(nbytes))
                self.below[key] = at
                return at
            at -= align
        self.below[key] = 0
        return None
