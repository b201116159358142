"""Operand resolution and role checking (IR -> checked IR).

For each instruction operand this stage resolves symbols (user table first,
then the Micro/WIN SMART system symbols) and ``#locals`` (the subroutine's
L-memory layout), parses the address, and checks it against the role the
instruction requires at that position (:class:`plcrt.gen.roles.Role`).
Problems become messages that name the operand and what was expected.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Any, Mapping

from ..lang import ir
from ..lang.codepage import DEFAULT_CODEPAGE
from ..memory.cpu import CpuModel
from ..safetext import excerpt
from .operands import (Addr, Const, Indirect, Name, OperandError, Pointer, Resolved,
                       parse_operand, string_constant)
from .roles import Role

TYPE_WIDTH = {"BOOL": 0, "BYTE": 1, "CHAR": 1, "WORD": 2, "INT": 2,
              "DWORD": 4, "DINT": 4, "REAL": 4}
SECTION_ORDER = ("IN", "IN_OUT", "OUT", "TEMP")


class ResolveError(Exception):
    """The operand does not fit; the message is user-facing."""


@dataclass(frozen=True, slots=True)
class LocalVar:
    """A subroutine parameter or temporary and its place in L memory."""

    decl: ir.VarDecl
    addr: Addr


def layout_locals(pou: ir.Pou, l_bytes: int,
                  bad_types: list[ir.VarDecl] | None = None) -> dict[str, LocalVar]:
    """Allocate a POU's variables in L memory in Micro/WIN's order.

    IN, then IN_OUT, then OUT, then temporaries, each in declaration order.
    Consecutive BOOLs pack into one byte; other types start on the next byte
    boundary (S7-200 System Manual, "Subroutine parameters").

    Names are case-sensitive, as in Micro/WIN: a Siemens library block
    declares ``tmp_b`` (BOOL) and ``tmp_B`` (BYTE) side by side.

    *bad_types*: when given, a variable of a type plcrt cannot hold is
    appended to it and left out (the others keep their places as far as
    they come before it), instead of raising.

    Raises:
        ResolveError: unknown type, duplicate name, or L memory exhausted.
    """
    out: dict[str, LocalVar] = {}
    byte, bit = 0, 0
    for section in SECTION_ORDER:
        for d in (v for v in pou.variables if v.section == section):
            key = d.name
            if key in out:
                raise ResolveError(f"variable '#{excerpt(d.name)}' declared twice")
            width = TYPE_WIDTH.get(d.type.upper())
            if width is None:
                if bad_types is not None:
                    bad_types.append(d)
                    continue
                raise ResolveError(f"variable '#{excerpt(d.name)}': type {excerpt(d.type)} "
                                   f"is not supported")
            if width == 0:
                addr = Addr("L", byte, 0, bit, f"L{byte}.{bit}")
                bit += 1
                if bit == 8:
                    byte, bit = byte + 1, 0
            else:
                if bit:
                    byte, bit = byte + 1, 0
                addr = Addr("L", byte, width, 0, f"L{'BWxD'[width - 1]}{byte}")
                byte += width
            if byte + (1 if bit else 0) > l_bytes:
                raise ResolveError(f"variables of {pou.ident} need more than "
                                   f"{l_bytes} bytes of L memory")
            out[key] = LocalVar(d, addr)
    return out


class Resolver:
    """Resolves operands of one POU."""

    def __init__(self, model: CpuModel, symbols: Any = None,
                 system_symbols: Mapping[str, str] | None = None,
                 local_vars: Mapping[str, LocalVar] | None = None,
                 codepage: str = DEFAULT_CODEPAGE) -> None:
        self.model = model
        #: code page of double-quoted string constants (the program's)
        self.codepage = codepage
        self.symbols = symbols
        self.system = {k.upper(): v for k, v in (system_symbols or {}).items()}
        self.locals = local_vars or {}
        #: (operand text, role) -> resolved operand.  Resolving depends only
        #: on the text, the role and this resolver's fixed tables, and the
        #: results are immutable, so a program that names the same address
        #: many times resolves it once (failures are not kept: they raise
        #: again, with the same message, at each use)
        self._done: dict[tuple[str, Role], Resolved] = {}

    # -- text -> typed operand ------------------------------------------
    def parse(self, text: str) -> Resolved:
        t = text.strip()
        if t.startswith("#"):
            return self._local(t).addr
        if t.startswith("*#"):
            # *#Ptr: the symbolic form of *LDn, a pointer held in a DWORD
            # local (Micro/WIN shows local addresses by their names)
            var = self._local(t[1:])
            if var.addr.width != 4:
                raise ResolveError(f"{excerpt(t)}: indirect addressing needs a pointer in a "
                                   f"double-word local, and #{excerpt(var.decl.name)} is "
                                   f"{excerpt(var.decl.type)}")
            return Indirect(var.addr, t)
        try:
            if t.startswith('"'):
                return string_constant(t, self.codepage)
            op = parse_operand(t, self.model)
        except OperandError as e:
            raise ResolveError(str(e)) from None
        if isinstance(op, Name):
            return self._symbol(op, t)
        return op

    def _local(self, t: str) -> LocalVar:
        var = self.locals.get(t[1:])
        if var is not None:
            return var
        # spelt in another case: the one variable of that name, if only one
        # (hand-written programs); tmp_b / tmp_B need the declared spelling
        same = [v for k, v in self.locals.items() if k.upper() == t[1:].upper()]
        if len(same) == 1:
            return same[0]
        if same:
            names = " and ".join(f"#{excerpt(v.decl.name)}" for v in same)
            raise ResolveError(f"'{excerpt(t)}' could be {names} (local names differ by case): "
                               f"write it as declared")
        raise ResolveError(f"unknown local variable '{excerpt(t)}'")

    def _symbol(self, op: Name, text: str) -> Resolved:
        target = None
        if self.symbols is not None:
            sym = self.symbols.lookup(op.name)
            if sym is not None:
                target = sym.address
        if target is None:
            target = self.system.get(op.name.upper())
        if target is None:
            return op
        try:
            res = parse_operand(target, self.model)
        except OperandError as e:
            raise ResolveError(f"symbol '{excerpt(text)}' stands for {excerpt(target)!r}: "
                               f"{e}") from None
        if isinstance(res, Name):
            raise ResolveError(f"symbol '{excerpt(text)}' stands for {excerpt(target)!r}, "
                               f"which is not an address")
        return res

    # -- role checks ----------------------------------------------------
    def resolve(self, operand: ir.Operand, role: Role) -> Resolved:
        """Resolve one operand for ``role``.

        Raises:
            ResolveError: with a message naming the operand and the role.
        """
        key = (operand.text, role)
        done = self._done.get(key)
        if done is None:
            done = check_role(self.parse(operand.text), role, operand.text, self.model)
            self._done[key] = done
        return done


@dataclass(frozen=True, slots=True)
class _Value:
    """What a value role takes: one row of :data:`_VALUES`."""

    width: int                 #: bytes
    write: bool = False        #: the instruction writes it
    constant: bool = True      #: a constant may stand here
    real_constant: bool = False  #: a REAL constant may stand here
    real: bool = False         #: the value is a REAL (int constants become reals)
    pointer: bool = False      #: an address ``&VB100`` may stand here
    indirect: bool = True      #: ``*VD``, ``*LD``, ``*AC``
    registers: bool = True     #: AC and HC (not memory: no run of bytes follows)
    area: str = ""             #: only this area (``I`` for BIR, ``Q`` for BIW)


def _out(width: int) -> _Value:
    return _Value(width, write=True, constant=False)


#: value roles and what each takes (the bit, string, count, label, timer and
#: counter roles are checked by their own functions below)
_VALUES: dict[Role, _Value] = {
    Role.B_R: _Value(1), Role.W_R: _Value(2), Role.D_R: _Value(4, real_constant=True),
    Role.R_R: _Value(4, real_constant=True, real=True),
    Role.B_W: _out(1), Role.W_W: _out(2), Role.D_W: _out(4),
    Role.R_W: _Value(4, write=True, constant=False, real=True),
    Role.D_PTR: _Value(4, pointer=True),
    Role.B_IB: _Value(1, constant=False, indirect=False, registers=False, area="I"),
    Role.B_QB: _Value(1, write=True, constant=False, indirect=False, registers=False,
                      area="Q"),
    Role.B_M: _Value(1, constant=False, registers=False),
    Role.W_M: _Value(2, constant=False, registers=False),
    Role.D_M: _Value(4, constant=False, registers=False),
    Role.B_MW: _Value(1, write=True, constant=False, registers=False),
    Role.W_MW: _Value(2, write=True, constant=False, registers=False),
    Role.D_MW: _Value(4, write=True, constant=False, registers=False),
}


def _bad(text: str, role: Role, why: str = "") -> ResolveError:
    extra = f" ({why})" if why else ""
    return ResolveError(f"operand '{excerpt(text)}' is not a valid {role.value}{extra}")


def check_role(op: Resolved, role: Role, text: str, model: CpuModel) -> Resolved:
    """Check one resolved operand against a role; returns the operand with
    its width fixed for context-sized areas (T, C, AC) and a character
    constant as the number it stands for.  Every role of the registry is
    checked here, so an emitter only ever sees the operand kinds its
    signature names.

    Raises:
        ResolveError: the operand is of a kind the role does not take, or
            a constant out of its range; the message says what was expected.
    """
    if isinstance(op, Name):
        if role in (Role.LABEL,):
            raise _bad(text, role)
        raise ResolveError(f"unknown symbol '{excerpt(text)}': not an address or constant, "
                           f"and not in the symbol table (give one with --symbols)")
    if role is Role.LABEL:
        if isinstance(op, Const) and isinstance(op.value, int) and 0 <= op.value <= 255:
            return op
        raise _bad(text, role, "0..255")
    if role is Role.N:
        if isinstance(op, Const) and isinstance(op.value, int) and 1 <= op.value <= 255:
            return op
        raise _bad(text, role, "1..255")
    if role in (Role.TIMER, Role.COUNTER):
        area = "T" if role is Role.TIMER else "C"
        if isinstance(op, Addr) and op.area == area:
            return op
        raise _bad(text, role)
    if role in (Role.BIT_R, Role.BIT_W, Role.BIT_TC, Role.IBIT, Role.QBIT, Role.SBIT):
        return _check_bit(op, role, text, model)
    if role in (Role.STR_R, Role.STR_M, Role.STR_W):
        return _check_string(op, role, text)
    spec = _VALUES.get(role)
    if spec is None:
        raise _bad(text, role)
    if isinstance(op, Const):
        if not spec.constant:
            raise _bad(text, role, "a constant cannot be written" if spec.write
                       else "a constant has no address")
        return _check_const(op, role, spec, text)
    if isinstance(op, Pointer):
        if spec.pointer:
            return op
        raise _bad(text, role, "an address '&...' is only valid as a double-word input")
    if isinstance(op, Indirect):
        if spec.indirect:
            return op
        raise _bad(text, role)
    return _check_addr(op, role, spec, text, model)


_REGISTERS = {"AC": "an accumulator", "HC": "a high-speed counter value"}


def _check_addr(op: Addr, role: Role, spec: _Value, text: str, model: CpuModel) -> Addr:
    width, writing = spec.width, spec.write
    if op.width == 0:
        raise _bad(text, role, "this is a bit")
    if op.area in ("AC", "HC") and not spec.registers:
        raise _bad(text, role, f"{_REGISTERS[op.area]} is a register, not memory")
    if op.area == "AC":
        return Addr("AC", op.offset, width, 0, op.text)
    if op.area in ("T", "C"):
        if width != 2 or spec.area:
            raise _bad(text, role, "timer and counter values are words")
        return Addr(op.area, op.offset, 2, 0, op.text)
    if op.area == "HC":
        if writing or width != 4 or spec.real:
            raise _bad(text, role, "HC is a read-only double word")
        return op
    if spec.area and op.area != spec.area:
        raise _bad(text, role)
    if op.width != width:
        raise _bad(text, role, f"this is a {('byte', 'word', '', 'double word')[op.width - 1]}")
    if writing and op.area == "AI":
        raise _bad(text, role, "analog inputs are read-only")
    if not writing and op.area == "AQ":
        raise _bad(text, role, "analog outputs are write-only")
    if writing and op.area == "SM" and op.offset < model.sm_readonly:
        raise _bad(text, role, f"SMB0..SMB{model.sm_readonly - 1} are read-only")
    return op


def _check_bit(op: Resolved, role: Role, text: str, model: CpuModel) -> Addr:
    if not isinstance(op, Addr):
        raise _bad(text, role)
    if op.area in ("T", "C"):
        if role in (Role.BIT_R, Role.BIT_TC):
            return Addr(op.area, op.offset, 0, 0, op.text)
        raise _bad(text, role)
    if op.width != 0:
        raise _bad(text, role, "this is not a bit address")
    if role is Role.IBIT and op.area != "I":
        raise _bad(text, role)
    if role is Role.QBIT and op.area != "Q":
        raise _bad(text, role)
    if role is Role.SBIT and op.area != "S":
        raise _bad(text, role)
    if role in (Role.BIT_W, Role.BIT_TC, Role.QBIT):
        if op.area == "SM" and op.offset < model.sm_readonly:
            raise _bad(text, role, f"SM0.0..SM{model.sm_readonly - 1}.7 are read-only")
    return op


def _check_string(op: Resolved, role: Role, text: str) -> Resolved:
    """A string operand: its length byte in V or L memory (``VB100``,
    ``LB4``), a pointer to it (``*VD``, ``*LD``, ``*AC``), or for inputs a
    double-quoted constant (System Manual, "String instructions")."""
    if isinstance(op, Const):
        if role is Role.STR_W:
            raise _bad(text, role, "a constant cannot be written")
        if role is Role.STR_M:
            raise _bad(text, role, "a string constant can only be the first operand")
        if not op.is_string:
            raise _bad(text, role, 'a string constant is written in double quotes: "ABC"')
        return op
    if isinstance(op, Indirect):
        return op
    if isinstance(op, Addr) and op.area in ("V", "L") and op.width == 1:
        return op
    raise _bad(text, role, "a string starts at its length byte, VBn or LBn")


_CONST_RANGE = {1: (-128, 255), 2: (-32768, 65535), 4: (-2**31, 2**32 - 1)}

#: the largest REAL (IEEE single precision): a constant beyond it has no REAL
REAL_MAX = 3.4028234663852886e38


def _single(value: float) -> bool:
    """Whether ``value`` rounds to a finite IEEE single (a REAL)."""
    try:
        struct.pack(">f", value)
    except (OverflowError, struct.error):
        return False
    return True


def _check_const(op: Const, role: Role, spec: _Value, text: str) -> Const:
    """A constant in a value role: strings refused, a character constant
    turned into the number it stands for (its characters as bytes, from the
    most significant, as ``'AB'`` is the word 16#4142), a REAL checked
    against the REAL range, an integer against the width."""
    width = spec.width
    if isinstance(op.value, bytes):
        if op.is_string:
            raise _bad(text, role, "a string constant is only valid where a string is")
        if spec.real:
            raise _bad(text, role, "a character constant is not a REAL")
        if len(op.value) > width or not op.value:
            raise _bad(text, role, f"a character constant of 1 to {width} characters")
        return Const(int.from_bytes(op.value.ljust(width, b"\0"), "big"), op.text)
    if isinstance(op.value, float):
        if not spec.real_constant:
            raise _bad(text, role, "a real constant needs a real operand")
        if not _single(op.value):
            raise _bad(text, role, f"outside the REAL range, ±{REAL_MAX:.7G}")
        return op
    lo, hi = _CONST_RANGE[width]
    if spec.real:
        if abs(op.value) > REAL_MAX:
            raise _bad(text, role, f"outside the REAL range, ±{REAL_MAX:.7G}")
        return Const(float(op.value), op.text, is_real=True)
    if not lo <= op.value <= hi:
        raise _bad(text, role, f"constant out of range {lo}..{hi}")
    return op
