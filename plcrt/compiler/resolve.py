"""Operand resolution and role checking (IR -> checked IR).

For each instruction operand this stage resolves symbols (user table first,
then the Micro/WIN SMART system symbols) and ``#locals`` (the subroutine's
L-memory layout), parses the address, and checks it against the role the
instruction requires at that position (:class:`plcrt.isa.registry.Role`).
Problems become messages that name the operand and what was expected.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from ..isa.registry import Role
from ..lang import ir
from ..lang.codepage import DEFAULT_CODEPAGE
from ..memory.cpu import CpuModel
from ..safetext import excerpt
from .operands import (Addr, Const, Indirect, Name, OperandError, Pointer, Resolved,
                       parse_operand, string_constant)

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


_READ_BYTE_AREAS = ("I", "Q", "M", "V", "SM", "S", "L")
_VALUE_WIDTH = {Role.B_R: 1, Role.B_W: 1, Role.W_R: 2, Role.W_W: 2, Role.D_R: 4,
                Role.D_W: 4, Role.R_R: 4, Role.R_W: 4, Role.D_PTR: 4,
                Role.B_IB: 1, Role.B_QB: 1}
_WRITE_ROLES = (Role.B_W, Role.W_W, Role.D_W, Role.R_W, Role.B_QB)


def _bad(text: str, role: Role, why: str = "") -> ResolveError:
    extra = f" ({why})" if why else ""
    return ResolveError(f"operand '{excerpt(text)}' is not a valid {role.value}{extra}")


def check_role(op: Resolved, role: Role, text: str, model: CpuModel) -> Resolved:
    """Check one resolved operand against a role; returns the operand with
    its width fixed for context-sized areas (T, C, AC)."""
    if isinstance(op, Name):
        if role in (Role.LABEL,):
            raise _bad(text, role)
        raise ResolveError(f"unknown symbol '{excerpt(text)}': not an address or constant, "
                           f"and not in the symbol table (give one with --symbols)")
    if role is Role.LABEL:
        if isinstance(op, Const) and isinstance(op.value, int) and 0 <= op.value <= 255:
            return op
        raise _bad(text, role)
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
    width = _VALUE_WIDTH[role]
    writing = role in _WRITE_ROLES
    if isinstance(op, Const):
        if writing:
            raise _bad(text, role, "a constant cannot be written")
        return _check_const(op, role, text)
    if isinstance(op, Pointer):
        if role is Role.D_PTR:
            return op
        raise _bad(text, role, "an address '&...' is only valid as a double-word input")
    if isinstance(op, Indirect):
        if role in (Role.B_IB, Role.B_QB):
            raise _bad(text, role)
        return op
    assert isinstance(op, Addr)
    if op.width == 0:
        raise _bad(text, role, "this is a bit")
    if op.area == "AC":
        return Addr("AC", op.offset, width, 0, op.text)
    if op.area in ("T", "C"):
        if width != 2:
            raise _bad(text, role, "timer and counter values are words")
        return Addr(op.area, op.offset, 2, 0, op.text)
    if op.area == "HC":
        if writing or width != 4 or role is Role.R_R:
            raise _bad(text, role, "HC is a read-only double word")
        return op
    if role is Role.B_IB and op.area != "I":
        raise _bad(text, role)
    if role is Role.B_QB and op.area != "Q":
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


def _check_const(op: Const, role: Role, text: str) -> Const:
    width = _VALUE_WIDTH[role]
    if isinstance(op.value, bytes):
        if op.is_string:
            raise _bad(text, role, "a string constant is only valid where a string is")
        if len(op.value) > width or not op.value:
            raise _bad(text, role, "literal too long")
        return op
    if isinstance(op.value, float):
        if role in (Role.R_R, Role.D_R):
            return op
        raise _bad(text, role, "a real constant needs a real operand")
    lo, hi = _CONST_RANGE[width]
    if role is Role.R_R:
        return Const(float(op.value), op.text, is_real=True)
    if not lo <= op.value <= hi:
        raise _bad(text, role, f"constant out of range {lo}..{hi}")
    return op
