"""Instruction family: strings and the string conversions.

Mnemonics: SLEN SCPY SCAT SSCPY SFND CFND (System Manual, "String
instructions"), ITS DTS RTS STI STD STR ("String conversion instructions")
and the string compare contacts LDS= LDS<> AS= AS<> OS= OS<> ("Compare
instructions", compare string).

An S7-200 string is a length byte (0..254) followed by that many characters;
a string operand names its length byte: ``VB100``, ``LB4``, ``*VD20``,
``*LD8``, ``*AC1``, or for an input a double-quoted constant ``"ABC"``
(:func:`plcrt.gen.operands.string_constant` turns it into the same
bytes; generated code gets it as a bound ``bytes`` object, never as text).

Errors and flags (docs/decisions.md, "Strings", has every choice):

* A string whose length byte is 255, or that runs past the end of its memory
  area, is the manual's "operand out of range" (0091): ENO 0 and nothing is
  written; SLEN, SCPY, SCAT, SSCPY, SFND and CFND change no SM bit.
* SCAT never makes a string longer than 254: it appends what fits and sets
  ENO 0 when it had to cut.
* SSCPY, SFND and CFND with an index of 0 (009B), or an index or range
  past the end of the string: ENO 0, OUT unchanged.  SFND/CFND write 0 when
  nothing is found (ENO 1).
* ITS/DTS/RTS: nnn > 5, or a number that does not fit RTS's ssss
  characters, writes a string of spaces and sets ENO 0; a FMT the
  instruction cannot use at all (ITS/DTS high nibble set, RTS ssss < 3)
  leaves OUT unchanged, ENO 0.
* STI/STD/STR: no number at INDX or a value too large for OUT sets SM1.1,
  leaves OUT unchanged, ENO 0; a conversion clears SM1.1.  INDX is an input
  only (the manual lists constants for it), it is not written back.
* The compares have no ENO: a string longer than 254 characters, or one
  that runs past the end of its memory area, stops the CPU (System Manual,
  "Compare string": fatal errors).  Only IN1 may be a constant.

What this module is not: the ASCII conversions ITA/DTA/RTA/ATH/HTA (their
outputs are fixed-size buffers without a length byte) live elsewhere.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from decimal import ROUND_HALF_UP, Decimal
from typing import Any

from ..errors import PlcRuntimeError, SourceLoc
from ..gen.emit import Gen
from ..gen.operands import Addr, Const, Indirect, area_size
from ..gen.rt import to_f32
from ..lang.codepage import MAX_STRING
from .registry import Role, insn

F = "string"

#: A string operand at run time: (buffer, offset of its length byte).
Ref = tuple[Any, int]


# -- memory access --------------------------------------------------------------


def read_string(ref: Ref) -> bytes | None:
    """The characters of the string at ``ref``; None when its length byte
    is over 254 or it runs past the end of its area (0091)."""
    buf, off = ref
    n = buf[off]
    end = off + 1 + n
    if n > MAX_STRING or end > len(buf):
        return None
    return bytes(buf[off + 1:end])


def write_string(ref: Ref, data: bytes) -> bool:
    """Store ``data`` (at most 254 bytes) as the string at ``ref``; False,
    and nothing written, when it would run past the end of its area."""
    buf, off = ref
    end = off + 1 + len(data)
    if end > len(buf):
        return False
    buf[off] = len(data)
    buf[off + 1:end] = data
    return True


# -- run-time helpers: each returns ENO (1 done, 0 error) -----------------------


def scpy(src: Ref, dst: Ref) -> int:
    """SCPY: OUT := IN (the source is read whole first, so overlap is safe)."""
    data = read_string(src)
    return int(data is not None and write_string(dst, data))


def scat(src: Ref, dst: Ref) -> int:
    """SCAT: OUT := OUT + IN, cut to 254 characters (then ENO 0)."""
    tail = read_string(src)
    head = read_string(dst)
    if tail is None or head is None:
        return 0
    joined = head + tail
    if not write_string(dst, joined[:MAX_STRING]):
        return 0
    return int(len(joined) <= MAX_STRING)


def sscpy(src: Ref, indx: int, n: int, dst: Ref) -> int:
    """SSCPY: OUT := N characters of IN from position INDX (1-based)."""
    data = read_string(src)
    if data is None or indx == 0 or indx + n - 1 > len(data):
        return 0
    return int(write_string(dst, data[indx - 1:indx - 1 + n]))


def sfnd(hay: Ref, needle: Ref, start: int) -> int | None:
    """SFND: position of IN2 in IN1 searching from ``start``; 0 if absent;
    None on an error (ENO 0, OUT unchanged)."""
    text, sub = read_string(hay), read_string(needle)
    if text is None or sub is None or not 1 <= start <= len(text):
        return None
    if not sub:
        return 0
    return text.find(sub, start - 1) + 1


def cfnd(hay: Ref, chars: Ref, start: int) -> int | None:
    """CFND: position of the first character of IN1, from ``start``, that
    is one of the characters of IN2; 0 if none; None on an error."""
    text, wanted = read_string(hay), read_string(chars)
    if text is None or wanted is None or not 1 <= start <= len(text):
        return None
    for i in range(start - 1, len(text)):
        if text[i] in wanted:
            return i + 1
    return 0


def fixed(value: int | Decimal, nnn: int, sep: str) -> str:
    """``value`` scaled by 10**-nnn as the manual's number format: a minus
    sign for negative values only, leading zeros suppressed except the digit
    before the separator, ``nnn`` digits after it (none and no separator for
    0).  An integer is taken as the digits of the scaled value (ITS/DTS);
    a Decimal is already rounded to ``nnn`` places (RTS)."""
    if isinstance(value, Decimal):
        negative = value < 0
        body = f"{abs(value):.{nnn}f}".replace(".", sep)
    else:
        negative = value < 0
        digits = str(abs(value)).rjust(nnn + 1, "0")
        body = digits if nnn == 0 else digits[:-nnn] + sep + digits[-nnn:]
    return "-" + body if negative else body


def _blank(dst: Ref, size: int) -> int:
    """An illegal format: the output string is ``size`` spaces, ENO 0."""
    write_string(dst, b" " * size)
    return 0


def its(value: int, fmt: int, dst: Ref, size: int) -> int:
    """ITS (size 8) / DTS (size 12): the number as a string of ``size``
    characters, right-justified (System Manual, "Integer to string")."""
    if fmt & 0xF0:
        return 0
    nnn = fmt & 7
    if nnn > 5:
        return _blank(dst, size)
    text = fixed(value, nnn, "," if fmt & 8 else ".").rjust(size)
    return int(write_string(dst, text.encode("ascii")))


def rts(value: float, fmt: int, dst: Ref) -> int:
    """RTS: the REAL as a string of ssss (FMT bits 7..4) characters with nnn
    (bits 2..0) decimals, rounded half away from zero (System Manual, "Real
    to string")."""
    size, nnn = fmt >> 4, fmt & 7
    if size < 3:
        return 0
    if nnn > 5 or size < nnn + 3 or not abs(value) < 10.0 ** size:
        # (NaN and the infinities fail the last test; a value that has more
        # whole digits than the string has characters cannot fit either)
        return _blank(dst, size)
    q = Decimal(value).quantize(Decimal(1).scaleb(-nnn), rounding=ROUND_HALF_UP)
    if q == 0:
        q = abs(q)      # -0.0004 with one decimal is "0.0", not "-0.0"
    text = fixed(q, nnn, "," if fmt & 8 else ".")
    if len(text) > size:
        return _blank(dst, size)
    return int(write_string(dst, text.rjust(size).encode("ascii")))


#: STI/STD/STR status: converted, error without SM1.1, SM1.1 error
DONE, ERROR, OVERFLOW = 0, 1, 2

_DIGITS = b"0123456789"


def scan_number(text: bytes, indx: int, real: bool) -> tuple[bool, bytes, bytes] | None:
    """The number at 1-based position ``indx`` of ``text``: (negative, whole
    digits, fraction digits), or None when there is none.

    The form is ``[spaces] [+ or -] [digits]`` and for reals ``... [. or ,]
    [digits]``; the number ends at the end of the string or the first
    character that does not fit the form (System Manual, "Substring to
    integer ... to real")."""
    i, n = indx - 1, len(text)
    while i < n and text[i] == 0x20:
        i += 1
    negative = False
    if i < n and text[i] in b"+-":
        negative = text[i] == 0x2D
        i += 1
    j = i
    while i < n and text[i] in _DIGITS:
        i += 1
    whole, frac = text[j:i], b""
    if real and i < n and text[i] in b".,":
        k = i + 1
        while k < n and text[k] in _DIGITS:
            k += 1
        frac = text[i + 1:k]
    if not whole and not frac:
        return None
    return negative, whole, frac


def sto(src: Ref, indx: int, kind: str) -> tuple[int, int | float]:
    """STI (kind W), STD (D), STR (R): (status, value)."""
    text = read_string(src)
    if text is None or indx == 0:
        return ERROR, 0
    found = scan_number(text, indx, kind == "R")
    if found is None:
        return OVERFLOW, 0
    negative, whole, frac = found
    if kind == "R":
        d = Decimal(f"{(whole or b'0').decode()}.{(frac or b'0').decode()}")
        r = to_f32(float(-d if negative else d))
        if r is None:
            return OVERFLOW, 0
        return DONE, r + 0.0   # "-0" converts to 0.0
    v = int(whole)
    v = -v if negative else v
    lo, hi = (-32768, 32767) if kind == "W" else (-2**31, 2**31 - 1)
    if not lo <= v <= hi:
        return OVERFLOW, 0
    return DONE, v


def string_equal(a: Ref, b: Ref, insn_id: int, locs: Sequence[SourceLoc]) -> int:
    """1 when the two strings hold the same characters (compare string).

    A string longer than 254 characters, or one that runs past the end of
    its area, stops the CPU (System Manual, "Compare string": both are
    fatal errors)."""
    (abuf, aoff), (bbuf, boff) = a, b
    na, nb = abuf[aoff], bbuf[boff]
    if na > MAX_STRING or nb > MAX_STRING:
        string_too_long(insn_id, locs)
    if aoff + 1 + na > len(abuf) or boff + 1 + nb > len(bbuf):
        raise PlcRuntimeError("string compare reads past the end of memory; the CPU "
                              "goes to STOP", locs[insn_id])
    return int(na == nb and abuf[aoff + 1:aoff + 1 + na] == bbuf[boff + 1:boff + 1 + nb])


def string_too_long(insn_id: int, locs: Sequence[SourceLoc]) -> None:
    """Raise the fatal error of a compare that meets a length byte over 254."""
    raise PlcRuntimeError("string compare of a string longer than 254 characters; the "
                          "CPU goes to STOP", locs[insn_id])


# -- emitters ------------------------------------------------------------------------


def _ref(g: Gen, op: Any) -> str:
    """Source of the (buffer, offset) of a resolved string operand."""
    if isinstance(op, Const):
        # the validated bytes (length byte + characters), bound as an object
        return g.const((bytes(op.value), 0), "str")
    if isinstance(op, Indirect):
        pbuf, poff = g._place(op.ptr, 4)
        return f"{g.use('_ptr')}({pbuf}, {poff}, 1, {g.insn_id})"
    assert isinstance(op, Addr)
    buf, off = g._place(op, 1)
    return f"({buf}, {off})"


def _room(g: Gen, op: Any) -> int | None:
    """For a direct V address: how many characters fit between it and the end
    of V memory (at most 254), known at compile time; else None."""
    if isinstance(op, Addr) and op.area == "V":
        return min(MAX_STRING, area_size(g.unit.model, "V") - op.offset - 1)
    return None


@insn("SLEN", Role.STR_R, Role.B_W, family=F, may_fail=True,
      summary="OUT := length of the string IN")
def _slen(g: Gen, src, out) -> None:
    read = g.bind(read_string, "sread")
    room = _room(g, src)
    with g.box():
        if isinstance(src, Const):
            g.wr(out, "B", str(src.value[0]))
            g.eno("1")
            return
        if room is not None:
            # perf: the length byte itself, checked against a constant bound
            n = g.tmp("n")
            g.line(f"{n} = {g.use('V')}[{src.offset}]")
            with g.block(f"if {n} <= {room}:"):
                g.wr(out, "B", n, exact=True)
                g.eno("1")
            with g.block("else:"):
                g.line("eno = 0")
            return
        s = g.tmp("s")
        g.line(f"{s} = {read}({_ref(g, src)})")
        with g.block(f"if {s} is None:"):
            g.line("eno = 0")
        with g.block("else:"):
            g.wr(out, "B", f"len({s})", exact=True)
            g.eno("1")


def _helper_box(g: Gen, fn: Callable[..., int], hint: str, *args: str) -> None:
    """A box whose helper does all the work and returns ENO."""
    helper = g.bind(fn, hint)
    with g.box():
        g.eno(f"{helper}({', '.join(args)})")


@insn("SCPY", Role.STR_R, Role.STR_W, family=F, may_fail=True,
      summary="OUT := the string IN")
def _scpy(g: Gen, src, dst) -> None:
    _helper_box(g, scpy, "scpy", _ref(g, src), _ref(g, dst))


@insn("SCAT", Role.STR_R, Role.STR_W, family=F, may_fail=True,
      summary="OUT := OUT followed by IN (at most 254 characters)")
def _scat(g: Gen, src, dst) -> None:
    _helper_box(g, scat, "scat", _ref(g, src), _ref(g, dst))


@insn("SSCPY", Role.STR_R, Role.B_R, Role.B_R, Role.STR_W, family=F, may_fail=True,
      summary="OUT := N characters of IN from position INDX")
def _sscpy(g: Gen, src, indx, n, dst) -> None:
    _helper_box(g, sscpy, "sscpy", _ref(g, src), g.rd(indx, "B"), g.rd(n, "B"), _ref(g, dst))


def _make_find(mn: str, fn: Callable[[Ref, Ref, int], int | None], summary: str) -> None:
    def emit(g: Gen, hay, needle, out) -> None:
        helper = g.bind(fn, mn.lower())
        with g.box():
            r = g.tmp("p")
            g.line(f"{r} = {helper}({_ref(g, hay)}, {_ref(g, needle)}, {g.rd(out, 'B')})")
            with g.block(f"if {r} is None:"):
                g.line("eno = 0")
            with g.block("else:"):
                g.wr(out, "B", r, exact=True)
                g.eno("1")

    insn(mn, Role.STR_R, Role.STR_R, Role.B_W, family=F, may_fail=True,
         summary=summary)(emit)


_make_find("SFND", sfnd, "OUT := position of IN2 in IN1 from position OUT (0: none)")
_make_find("CFND", cfnd, "OUT := position in IN1, from OUT, of a character of IN2 (0: none)")


#: mnemonic -> (IN role, IN kind, characters); System Manual, ITS / DTS
TO_STRING = {"ITS": (Role.W_R, "W", 8), "DTS": (Role.D_R, "D", 12)}


def _make_to_string(mn: str) -> None:
    role, kind, size = TO_STRING[mn]

    def emit(g: Gen, a, dst, fmt) -> None:
        _helper_box(g, its, "its", g.rd(a, kind), g.rd(fmt, "B"), _ref(g, dst), str(size))

    insn(mn, role, Role.STR_W, Role.B_R, family=F, may_fail=True,
         summary=f"OUT := IN as a string of {size} characters, format FMT")(emit)


for _mn in TO_STRING:
    _make_to_string(_mn)


@insn("RTS", Role.R_R, Role.STR_W, Role.B_R, family=F, may_fail=True,
      summary="OUT := IN as a string of ssss characters with nnn decimals (FMT)")
def _rts(g: Gen, a, dst, fmt) -> None:
    _helper_box(g, rts, "rts", g.rd(a, "R"), g.rd(fmt, "B"), _ref(g, dst))


#: mnemonic -> (OUT role, kind); System Manual, STI / STD / STR
FROM_STRING = {"STI": (Role.W_W, "W"), "STD": (Role.D_W, "D"), "STR": (Role.R_W, "R")}


def _make_from_string(mn: str) -> None:
    role, kind = FROM_STRING[mn]

    def emit(g: Gen, src, indx, out) -> None:
        helper = g.bind(sto, "sto")
        sm = g.use("SM")
        with g.box():
            st, v = g.tmp("st"), g.tmp("v")
            g.line(f"{st}, {v} = {helper}({_ref(g, src)}, {g.rd(indx, 'B')}, '{kind}')")
            with g.block(f"if {st} == {DONE}:"):
                g.wr(out, kind, v)
                g.line(f"{sm}[1] &= 253")
                g.eno("1")
            with g.block("else:"):
                with g.block(f"if {st} == {OVERFLOW}:"):
                    g.line(f"{sm}[1] |= 2")
                g.line("eno = 0")

    insn(mn, Role.STR_R, Role.B_R, role, family=F, may_fail=True,
         summary=f"OUT := the number in IN from position INDX ({kind})")(emit)


for _mn in FROM_STRING:
    _make_from_string(_mn)


# -- compare string contacts ----------------------------------------------------------

COMBINE = {"LD": "push", "A": "&=", "O": "|="}
RELATIONS = {"=": "", "<>": "1 - "}


def _constant_compare(g: Gen, mem: Any, const: Any) -> tuple[str, str] | None:
    """(``V[a:b]``, bound bytes) for a V string compared with a constant, when
    no string at that address can run past the end of V memory (so the fatal
    error cannot happen); else None."""
    if not isinstance(const, Const) or _room(g, mem) != MAX_STRING:
        return None
    # perf: one slice compare of the length byte and characters, no call;
    # only a length byte over 254 needs the fatal error first
    v = g.use("V")
    with g.block(f"if {v}[{mem.offset}] > {MAX_STRING}:"):
        g.line(f"{g.bind(string_too_long, 'strlong')}({g.insn_id}, {g.use('_LOCS')})")
    data = g.const(bytes(const.value), "str")
    return f"{v}[{mem.offset}:{mem.offset + len(const.value)}]", data


def _make_compare(prefix: str, rel: str) -> None:
    how, negate = COMBINE[prefix], RELATIONS[rel]

    def emit(g: Gen, a, b) -> None:
        fast = _constant_compare(g, b, a)
        if fast is not None:
            expr = f"(1 if {fast[0]} {'!=' if negate else '=='} {fast[1]} else 0)"
        else:
            helper = g.bind(string_equal, "streq")
            expr = (f"{negate}{helper}({_ref(g, a)}, {_ref(g, b)}, {g.insn_id}, "
                    f"{g.use('_LOCS')})")
        if how == "push":
            g.push(expr)
        else:
            g.line(f"{g.top} {how} {expr}" if not negate else f"{g.top} {how} ({expr})")

    verb = {"push": "push", "&=": "AND", "|=": "OR"}[how]
    insn(f"{prefix}S{rel}", Role.STR_R, Role.STR_M, family=F,
         summary=f"{verb} IN1 {rel} IN2 (strings)")(emit)


for _p in COMBINE:
    for _r in RELATIONS:
        _make_compare(_p, _r)
