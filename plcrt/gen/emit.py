"""The code generator's per-function context (:class:`Gen`).

Instruction emitters (``plcrt.isa.*``) write Python source through this
object: it owns the statically allocated logic stack (``s1`` .. ``s9`` as
locals), turns resolved operands into constant-offset buffer expressions, and
binds run-time objects (timers, helpers) as fast locals.

Nothing from program text is ever formatted into the source here: operands
arrive resolved (:mod:`plcrt.gen.operands`) and only their validated
integers and floats are printed, with ``repr`` for floats.

It is not the driver: splitting programs into functions, control flow and
``compile()`` live in :mod:`plcrt.compiler`; the text of constants and the
shape of expressions are :mod:`.exprs`'.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Iterator

from ..errors import SourceLoc
from .errors import CodegenError
from .exprs import VALUE_WIDTH, const_expr, is_atom, is_int_literal
from .limits import MAX_STACK
from .operands import Addr, Const, Indirect, Pointer
from .recipe import CPU, Attr
from .rt import EXACT_CODE, PACK_CODE, packer

# Memory areas and the local names their buffers have in generated code.
BUFFER_NAME = {
    "I": "I", "Q": "Q", "M": "M", "V": "V", "SM": "SM", "S": "S", "L": "L",
    "AI": "AI", "AQ": "AQ", "AC": "AC", "HC": "HC", "PI": "PI", "PQ": "PQ",
}

_MASK = {"B": 255, "W": 65535, "D": 4294967295}
#: Gen.wr_seq joins two values at most this many bytes apart
MAX_GAP = 2


class Gen:
    """Source builder for one generated function (one network or network piece).

    Attributes:
        depth: current static logic-stack depth (0 = empty).
        used: names of bound objects the function body refers to.
    """

    def __init__(self, unit: Any, loc: SourceLoc | None = None, depth: int = 0) -> None:
        self.unit = unit
        self.lines: list[str] = []
        self.indent = 1
        self.depth = depth
        self.used: set[str] = set()
        self.loc = loc            #: location of the instruction being emitted
        self.insn_id = -1         #: index of that instruction in unit.locs
        self.eno_valid = False    #: the previous box set ``eno``
        #: (index of the line where its code starts, insn id, indentation)
        self.line_map: list[tuple[int, int, int]] = []
        #: perf: expression of the top stack level not stored yet, so that a
        #: run like ``LD a / A b / AN c`` becomes one assignment.  Any emitted
        #: statement stores it first, so memory is always read in program order.
        self.pending: str | None = None
        self._terms = 0
        #: (pending expression, its top-level operator) once combine()
        #: built it: decides which parentheses the next combine() needs
        self._pending_op: tuple[str, str] | None = None
        #: inside a box under SM0.0: statements do not store a pending "1"
        self._hold_one = False
        #: the bits kept in locals while a bit-logic region is emitted
        #: (:class:`plcrt.compiler.bitcache.BitCache`), else None
        self.bits: Any = None

    # -- source ---------------------------------------------------------
    def line(self, text: str) -> None:
        """Append one statement at the current indentation."""
        if self.pending is not None and not (self._hold_one and self.pending == "1"):
            self.flush()
        self.lines.append("    " * self.indent + text)

    def comment(self, text: str) -> None:
        """Append a comment line (does not store a pending stack value)."""
        self.lines.append("    " * self.indent + "# " + text)

    def flush(self) -> None:
        """Store the pending top-of-stack expression in its local."""
        expr, self.pending = self.pending, None
        if expr is not None:
            self.lines.append("    " * self.indent + f"s{self.depth} = {expr}")

    @contextmanager
    def block(self, header: str) -> Iterator[None]:
        """``with g.block("if s1:"):`` emits an indented suite."""
        if self.pending is not None:
            self.flush()    # stored before the suite, never only inside it
        self.line(header)
        self.indent += 1
        n = len(self.lines)
        yield
        if len(self.lines) == n:
            self.line("pass")
        self.indent -= 1

    @contextmanager
    def box(self, alone: bool = False) -> Iterator[None]:
        """Body of a box instruction: executes only when the top of stack is 1.

        ``alone``: no ``else:`` follows the body, so a box whose power is
        the constant 1 (SM0.0, see :meth:`rbit`) may run without the test.
        """
        if alone and self.pending == "1":
            # perf: a box under SM0.0 runs without a test, and the constant
            # is stored only if something after the box reads the stack
            self._hold_one = True
            try:
                yield
            finally:
                self._hold_one = False
            return
        with self.block(f"if {self.top}:"):
            yield

    def use(self, name: str) -> str:
        self.used.add(name)
        return name

    def bind(self, obj: object, hint: str = "o") -> str:
        """Bind a run-time object as a fast local; returns its generated name."""
        name = self.unit.bind(obj, hint)
        self.used.add(name)
        return name

    def cpu(self, path: str, hint: str = "o") -> str:
        """Bind the CPU's object at attribute ``path`` (``"timers.reset"``)
        as a fast local: a recipe each PLC of the program resolves to its
        own (:mod:`plcrt.gen.recipe`)."""
        return self.bind(Attr(CPU, path), hint)

    def const(self, obj: object, hint: str = "k") -> str:
        """Bind a constant (a lookup table, a string constant's bytes) that
        the generated code only reads: every PLC of the program shares it
        and a fork does not copy it."""
        name = self.unit.bind(obj, hint, constant=True)
        self.used.add(name)
        return name

    def tmp(self, hint: str = "t") -> str:
        """A fresh local variable name."""
        return self.unit.fresh(hint)

    def warn(self, message: str, code: str = "") -> None:
        self.unit.diag.warning(message, self.loc, code)

    def fail(self, message: str, loc: SourceLoc | None = None, *,
             reported: bool = False) -> None:
        raise CodegenError(message, loc, reported=reported)

    # -- logic stack ----------------------------------------------------
    @property
    def top(self) -> str:
        if self.pending is not None:
            self.flush()
        if self.depth < 1:
            self.fail("the logic stack is empty here: start the network with a "
                      "load (LD, LDN, LDx=, ...)")
        return f"s{self.depth}"

    def level(self, n: int) -> str:
        """Stack level ``n`` counted from the top (0 = top)."""
        if self.pending is not None:
            self.flush()
        if self.depth - n < 1:
            self.fail(f"needs {n + 1} values on the logic stack, it holds {self.depth}")
        return f"s{self.depth - n}"

    def push(self, expr: str) -> None:
        """Push ``expr`` (0/1).  Beyond nine levels the bottom level is lost."""
        if self.pending is not None:
            self.flush()
        if self.depth == MAX_STACK:
            self.warn("logic stack overflow: a tenth level is pushed and the bottom "
                      "level is lost, as on the S7-200", "stack-overflow")
            lhs = ", ".join(f"s{i}" for i in range(1, MAX_STACK + 1))
            rhs = ", ".join(f"s{i}" for i in range(2, MAX_STACK + 1))
            self.line(f"{lhs} = {rhs}, {expr}")
            return
        self.depth += 1
        self.pending = expr
        self._terms = 1

    def combine(self, op: str, expr: str) -> None:
        """``top := top <op> expr`` for ``op`` in ``&``, ``|`` (A, O, ...)."""
        if self.pending is not None and self._terms < 24:
            # perf: only the parentheses the operators need (an expression
            # with fewer of them compiles faster; the syntax tree is the
            # same).  ``&`` binds tighter than ``|``: ``a & b | c`` is
            # ``(a & b) | c``, but ``(a | b) & c`` keeps its parentheses.
            pending = self.pending
            shape = self._pending_op
            top = shape[1] if shape is not None and shape[0] is pending else None
            if not (top == op or (top == "&" and op == "|")
                    or (top is None and is_atom(pending))):
                pending = f"({pending})"
            self.pending = f"{pending} {op} {expr if is_atom(expr) else f'({expr})'}"
            self._pending_op = (self.pending, op)
            self._terms += 1
        else:
            self.line(f"{self.top} {op}= {expr}")

    def pop(self, n: int = 1) -> None:
        # A pending value of a popped level is simply dropped: reading
        # memory has no side effects.
        self.pending = None
        if self.depth < n:
            self.fail(f"needs {n + 1 if n == 1 else n} values on the logic stack, "
                      f"it holds {self.depth}")
        self.depth -= n

    # -- operands -------------------------------------------------------
    def _buf(self, area: str) -> str:
        return self.use(BUFFER_NAME[area])

    def rbit(self, op: Addr) -> str:
        """Expression (0/1) reading a bit operand."""
        if op.area in ("T", "C"):
            buf = self.use("TB" if op.area == "T" else "CB")
            byte, bit = op.offset >> 3, op.offset & 7
        elif op.area == "SM" and op.offset == 0 and op.bit == 0:
            # perf: SM0.0 is on whenever the program runs: the scan sets it
            # before OB1 runs and the program cannot write it (SMB0 is
            # read-only, System Manual, "Special memory bits")
            return "1"
        else:
            buf, byte, bit = self._buf(op.area), op.offset, op.bit
        plain = f"({buf}[{byte}] & 1)" if bit == 0 else f"({buf}[{byte}] >> {bit} & 1)"
        if self.bits is not None:
            return self.bits.read(self, op, plain)
        return plain

    def wbit(self, op: Addr, expr: str) -> None:
        """Statements writing ``expr`` (0/1, evaluated once) to a bit."""
        if self.bits is not None and self.bits.write(self, op, expr):
            return
        buf = self._buf(op.area)
        mask = 1 << op.bit
        if expr.isidentifier():
            with self.block(f"if {expr}:"):
                self.line(f"{buf}[{op.offset}] |= {mask}")
            with self.block("else:"):
                self.line(f"{buf}[{op.offset}] &= {~mask & 0xFF}")
        else:
            self.line(f"{buf}[{op.offset}] = {buf}[{op.offset}] & {~mask & 0xFF} "
                      f"| ({expr}) << {op.bit}")

    def set_bit(self, op: Addr, value: int) -> None:
        buf = self._buf(op.area)
        mask = 1 << op.bit
        if value:
            self.line(f"{buf}[{op.offset}] |= {mask}")
        else:
            self.line(f"{buf}[{op.offset}] &= {~mask & 0xFF}")

    def _place(self, op: Addr, width: int) -> tuple[str, int]:
        if op.area == "T":
            return self.use("TV"), op.offset * 2
        if op.area == "C":
            return self.use("CV"), op.offset * 2
        if op.area == "AC":
            return self.use("AC"), op.offset * 4 + 4 - width
        if op.area == "HC":
            return self.use("HC"), op.offset * 4
        return self._buf(op.area), op.offset

    def rd(self, op: Any, kind: str) -> str:
        """Expression reading a value.

        Args:
            op: resolved operand (Addr, Const, Pointer or Indirect).
            kind: ``B`` (unsigned byte), ``W``/``D`` (signed INT/DINT),
                ``WU``/``DU`` (unsigned), ``R`` (REAL as float).
        """
        width = VALUE_WIDTH[kind[0]]
        if isinstance(op, Const):
            return const_expr(op, kind)
        if isinstance(op, Pointer):
            return str(op.value)
        if isinstance(op, Indirect):
            pbuf, poff = self._place(op.ptr, 4)
            sign = "r" if kind == "R" else ("u" if kind.endswith("U") else "s")
            return (f"{self.use('_ird')}({pbuf}, {poff}, {width}, '{sign}', "
                    f"{self.insn_id})")
        buf, off = self._place(op, width)
        if width == 1:
            return f"{buf}[{off}]"
        if kind == "WU":
            # perf: two byte reads beat struct.unpack_from + tuple indexing
            return f"({buf}[{off}] << 8 | {buf}[{off + 1}])"
        codec = {"W": "_rh", "WU": "_rH", "D": "_ri", "DU": "_rI", "R": "_rf"}[kind]
        return f"{self.use(codec)}({buf}, {off})[0]"

    def wr(self, op: Any, kind: str, expr: str, exact: bool = False) -> None:
        """Statements writing ``expr`` to a value operand.

        Integer values are masked to the width, so callers may pass signed or
        oversized results.  REAL values must already be finite single
        precision numbers.  ``exact=True`` promises a value already in the
        range of ``kind`` (0..255 for ``B``, signed for ``W``/``D``, unsigned
        for ``WU``/``DU``): no mask is applied, and a word or double word
        out of that range raises (struct.error) instead of wrapping.
        """
        width = VALUE_WIDTH[kind[0]]
        if isinstance(op, Indirect):
            pbuf, poff = self._place(op.ptr, 4)
            self.line(f"{self.use('_iwr')}({pbuf}, {poff}, {width}, {expr}, "
                      f"{self.insn_id})")
            return
        buf, off = self._place(op, width)
        if kind != "R" and is_int_literal(expr):
            # perf: a constant becomes byte stores computed at compile time
            v = int(expr) & ((1 << 8 * width) - 1)
            data = v.to_bytes(width, "big")
            for i, b in enumerate(data):
                self.line(f"{buf}[{off + i}] = {b}")
            return
        if kind == "R":
            self.line(f"{self.use('_wf')}({buf}, {off}, {expr})")
        elif width == 1:
            self.line(f"{buf}[{off}] = {expr}" if exact else f"{buf}[{off}] = ({expr}) & 255")
        elif exact:
            self.line(f"{self.use('_w' + EXACT_CODE[kind])}({buf}, {off}, {expr})")
        elif width == 2:
            self.line(f"{self.use('_wH')}({buf}, {off}, ({expr}) & 65535)")
        else:
            self.line(f"{self.use('_wI')}({buf}, {off}, ({expr}) & 4294967295)")

    def wr_seq(self, items: list[tuple[Any, str, str]] | list[tuple[Any, str, str, bool]]
               ) -> None:
        """Statements writing several values in the order given: ``(operand,
        kind, expr)`` or ``(operand, kind, expr, exact)`` each, ``kind`` as
        for :meth:`wr` or ``"X"`` for a bit (0/1), ``exact`` as for
        :meth:`wr`.  Every ``expr`` must be free of side effects.

        perf: writes that follow each other in one buffer become one store:
        bits of one byte one byte store, values at neighbouring addresses
        (at most :data:`MAX_GAP` bytes apart, the bytes between kept) one
        struct call (a library block's outputs usually lie side by side).
        Operands that overlap, indirect ones, constants and the timer,
        counter, accumulator and HC areas are written one by one.
        """
        items4 = [(*it, False) if len(it) == 3 else it for it in items]
        exacts = [it[3] for it in items4]
        items = [it[:3] for it in items4]
        i = 0
        while i < len(items):
            op, kind, expr = items[i]
            j = i + 1
            if kind == "X":
                bits = {op.bit} if isinstance(op, Addr) else set()
                while bits and j < len(items) and _same_byte(op, items[j]) \
                        and items[j][0].bit not in bits:
                    bits.add(items[j][0].bit)
                    j += 1
                if j - i == 1:
                    self.wbit(op, expr)
                else:
                    buf = self._buf(op.area)
                    keep = ~sum(1 << b for b in bits) & 0xFF
                    parts = " | ".join(f"({e}) << {o.bit}" for o, _, e in items[i:j])
                    store = f"{buf}[{op.offset}] = {buf}[{op.offset}] & {keep} | {parts}"
                    if all(e.isidentifier() for _, _, e in items[i:j]):
                        # perf: the byte is stored only when a bit differs
                        # from the byte as it is now (storing bits it already
                        # holds changes nothing), compared through the bit
                        # table: tuple subscripts and small-integer compares
                        # instead of the masks, shifts and ors of the store
                        now = self.tmp("t")
                        self.line(f"{now} = {self.use('_bits')}[{buf}[{op.offset}]]")
                        differs = " or ".join(f"{e} != {now}[{o.bit}]"
                                              for o, _, e in items[i:j])
                        # one line, not a suite: the logic stack's pending
                        # value has nothing to do with it and stays pending
                        self.line(f"if {differs}: {store}")
                    else:
                        self.line(store)
            else:
                end = _packable_end(op, kind, expr)
                while end is not None and j < len(items):
                    nxt = _packable_end(*items[j])
                    if nxt is None or items[j][0].area != op.area \
                            or not 0 <= items[j][0].offset - end <= MAX_GAP:
                        break
                    end = nxt
                    j += 1
                if j - i == 1 and exacts[i] and kind in ("W", "WU") \
                        and end is not None and expr.isidentifier():
                    # perf: a lone word result of a block (mostly a status
                    # word, the same scan after scan) is stored only when
                    # the memory does not hold it already: two byte reads
                    # and compares instead of a struct call.  Only a value
                    # of 0..255 can match the bytes (0, v); any other is
                    # always stored
                    buf = self._buf(op.area)
                    self.line(f"if {buf}[{op.offset}] or {buf}[{op.offset + 1}] != {expr}: "
                              f"{self.use('_w' + EXACT_CODE[kind])}({buf}, {op.offset}, {expr})")
                elif j - i == 1:
                    self.wr(op, kind, expr, exact=exacts[i])
                else:
                    # bytes between two values are written again with their
                    # own value, read in the same statement (perf: a byte
                    # read is cheaper than a second struct call)
                    buf = self._buf(op.area)
                    codes, values, pos = [], [], op.offset
                    for (o, k, e), exact in zip(items[i:j], exacts[i:j]):
                        for gap in range(pos, o.offset):
                            codes.append("B")
                            values.append(f"{buf}[{gap}]")
                        codes.append((EXACT_CODE if exact else PACK_CODE)[k])
                        values.append(e if k == "R" or exact else f"({e}) & {_MASK[k[0]]}")
                        pos = o.offset + VALUE_WIDTH[k[0]]
                    self.line(f"{self.use(packer(''.join(codes)))}({buf}, {op.offset}, "
                              f"{', '.join(values)})")
            i = j

    def copy(self, src: Any, dst: Any, kind: str) -> None:
        """Move a value; plain byte-slice copy where both are direct (perf)."""
        width = VALUE_WIDTH[kind[0]]
        if (isinstance(src, Addr) and isinstance(dst, Addr) and width > 1
                and src.area not in ("AC",) and dst.area not in ("AC",)):
            sbuf, soff = self._place(src, width)
            dbuf, doff = self._place(dst, width)
            if width == 2:
                # perf: two byte stores beat a slice copy for words (the right
                # side is evaluated first, so overlap is safe)
                self.line(f"{dbuf}[{doff}], {dbuf}[{doff + 1}] = "
                          f"{sbuf}[{soff}], {sbuf}[{soff + 1}]")
                return
            # perf: slice copy avoids decode/encode (big-endian bytes move as is)
            self.line(f"{dbuf}[{doff}:{doff + width}] = {sbuf}[{soff}:{soff + width}]")
            return
        self.wr(dst, kind, self.rd(src, kind))

    # -- status flags (SMB1) ---------------------------------------------
    def flags_zn(self, value: str) -> None:
        """SM1.0 (zero) and SM1.2 (negative) from a result; SM1.1 cleared."""
        sm = self.use("SM")
        self.line(f"{sm}[1] = {sm}[1] & 248 | ({value} == 0) | ({value} < 0) << 2")

    def flag_overflow(self) -> None:
        """SM1.1 set (result out of range, output unchanged); SM1.0/SM1.2 cleared."""
        sm = self.use("SM")
        self.line(f"{sm}[1] = {sm}[1] & 248 | 2")

    def store_checked(self, out: Any, kind: str, r: str, lo: int | None, hi: int) -> None:
        """Write result ``r`` with SM1.0/SM1.2 when ``lo <= r <= hi``; else set
        SM1.1 and leave ``out`` unchanged (System Manual, math: "the output
        is not altered").  ``lo=None`` checks only the upper bound."""
        cond = f"{r} <= {hi}" if lo is None else f"{lo} <= {r} <= {hi}"
        with self.block(f"if {cond}:"):
            self.wr(out, kind, r)
            self.flags_zn(r)
            self.eno("1")
        with self.block("else:"):
            self.flag_overflow()
            self.line("eno = 0")

    @contextmanager
    def divisor_guard(self, d: str) -> Iterator[None]:
        """Divide by zero sets SM1.3 (other flags and the output unchanged,
        ENO 0); the body runs for a non-zero divisor with SM1.3 cleared."""
        sm = self.use("SM")
        with self.block(f"if {d} == 0:"):
            self.line(f"{sm}[1] |= 8")
            self.line("eno = 0")
        with self.block("else:"):
            self.line(f"{sm}[1] &= 247")
            yield

    def eno(self, expr: str) -> None:
        """Record the box's ENO (for a following AENO)."""
        self.line(f"eno = {expr}")
        self.eno_valid = True


#: areas whose values lie at their own byte offsets in one buffer
_PLAIN_AREAS = frozenset(BUFFER_NAME) - {"AC", "HC"}


def _same_byte(op: Any, item: tuple[Any, str, str]) -> bool:
    """*item* is a bit write into the byte of bit operand *op*."""
    o, kind, _ = item
    return kind == "X" and isinstance(o, Addr) and o.area == op.area and o.offset == op.offset


def _packable_end(op: Any, kind: str, expr: str) -> int | None:
    """The offset after a value write that :meth:`Gen.wr_seq` may join to
    its neighbours, or None."""
    if kind == "X" or not isinstance(op, Addr) or op.area not in _PLAIN_AREAS \
            or is_int_literal(expr):
        return None
    return op.offset + VALUE_WIDTH[kind[0]]


__all__ = ["BUFFER_NAME", "MAX_GAP", "MAX_STACK", "VALUE_WIDTH", "CodegenError", "Gen",
           "const_expr"]
