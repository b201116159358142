"""Instruction family: numeric conversions, BCD, encode/decode, 7-segment.

Mnemonics: BTI ITB ITD DTI DTR ROUND TRUNC BCDI IBCD ENCO DECO SEG
(S7-200 System Manual, "Conversion instructions").  ``BCDI OUT`` and
``IBCD OUT`` convert in place; the others read IN and write OUT.

Flags and errors (SMB1):

* ITB, DTI, ROUND, TRUNC: a value that does not fit the output (or a REAL
  that is not a number) sets SM1.1, leaves OUT unchanged and makes ENO 0;
  a successful conversion clears SM1.1.  No other SMB1 bit is touched.
* BCDI, IBCD: an illegal BCD digit (BCDI) or a value outside 0..9999 (IBCD)
  sets SM1.6, OUT unchanged, ENO 0; success clears SM1.6.
* BTI, ITD, DTR, ENCO, DECO, SEG change no status bit and cannot fail.

ROUND rounds half away from zero (0.5 -> 1, -2.5 -> -3), TRUNC drops the
fraction.  DTR rounds to the nearest single-precision value.  The string
and ASCII conversions (ITA, DTA, RTA, ATH, HTA, ITS, ...) are not here.
"""

from __future__ import annotations

from collections.abc import Callable

from ..gen.emit import Gen
from .registry import Role, insn

F = "convert"

# -- range-checked integer narrowing ------------------------------------------

#: mnemonic -> (IN role, OUT role, IN kind, OUT kind, lo, hi, summary)
NARROW: dict[str, tuple[Role, Role, str, str, int, int, str]] = {
    # ITB converts 0..255 only; anything else is an overflow (System Manual,
    # "Byte to integer and integer to byte").
    "ITB": (Role.W_R, Role.B_W, "W", "B", 0, 255, "byte := INT (0..255)"),
    "DTI": (Role.D_R, Role.W_W, "D", "W", -32768, 32767, "INT := DINT"),
}

#: mnemonic -> (IN role, OUT role, IN kind, OUT kind, summary); never fail
WIDEN: dict[str, tuple[Role, Role, str, str, str]] = {
    "BTI": (Role.B_R, Role.W_W, "B", "W", "INT := byte (unsigned, no sign extension)"),
    "ITD": (Role.W_R, Role.D_W, "W", "D", "DINT := INT (sign-extended)"),
}


def _flagged(g: Gen, ok: str, write: Callable[[], None], bit: int) -> None:
    """``if ok``: write, clear SM1.<bit>, ENO 1; else set SM1.<bit>, ENO 0
    (output unchanged)."""
    sm = g.use("SM")
    mask = 1 << bit
    with g.block(f"if {ok}:"):
        write()
        g.line(f"{sm}[1] &= {~mask & 255}")
        g.eno("1")
    with g.block("else:"):
        g.line(f"{sm}[1] |= {mask}")
        g.line("eno = 0")


def _overflow(g: Gen, ok: str, write: Callable[[], None]) -> None:
    """SM1.1: overflow / illegal value (conversion out of range)."""
    _flagged(g, ok, write, 1)


def _make_narrow(mn: str) -> None:
    role_in, role_out, kin, kout, lo, hi, summary = NARROW[mn]

    def emit(g: Gen, a, out) -> None:
        with g.box():
            v = g.tmp("v")
            g.line(f"{v} = {g.rd(a, kin)}")
            _overflow(g, f"{lo} <= {v} <= {hi}", lambda: g.wr(out, kout, v))

    insn(mn, role_in, role_out, family=F, summary=summary, may_fail=True)(emit)


def _make_widen(mn: str) -> None:
    role_in, role_out, kin, kout, summary = WIDEN[mn]

    def emit(g: Gen, a, out) -> None:
        with g.box():
            g.wr(out, kout, g.rd(a, kin))

    insn(mn, role_in, role_out, family=F, summary=summary)(emit)


for _mn in NARROW:
    _make_narrow(_mn)
for _mn in WIDEN:
    _make_widen(_mn)


@insn("DTR", Role.D_R, Role.R_W, family=F, summary="REAL := DINT (nearest single)")
def _dtr(g: Gen, a, out) -> None:
    with g.box():
        # float() is exact for 32-bit integers; storing it as a single rounds
        # to nearest, ties to even (the IEEE-754 default rounding).
        g.wr(out, "R", f"float({g.rd(a, 'D')})")


# -- REAL -> DINT -------------------------------------------------------------
#
# System Manual, "Round" / "Truncate": a REAL that is not a number or does
# not fit a DINT sets SM1.1 and leaves OUT alone.  The bounds are open
# intervals on the (exact) double value of the single-precision input, chosen
# so that the integer result lies in -2**31 .. 2**31 - 1; a NaN fails every
# comparison and so lands in the overflow branch.  The manual says a fraction
# of 0.5 or more rounds "up"; plcrt reads that as away from zero for negative
# values too (-2.5 -> -3), matching the magnitude rule it states.

#: mnemonic -> (exclusive bounds, integer expression template over {x}, summary)
REAL_TO_DINT: dict[str, tuple[tuple[float, float], str, str]] = {
    "ROUND": ((-2147483648.5, 2147483647.5),
              "(int({x} + 0.5) if {x} >= 0.0 else -int(0.5 - {x}))",
              "DINT := REAL rounded half away from zero"),
    "TRUNC": ((-2147483649.0, 2147483648.0), "int({x})",
              "DINT := REAL with the fraction dropped"),
}


def _make_real_to_dint(mn: str) -> None:
    (lo, hi), expr, summary = REAL_TO_DINT[mn]

    def emit(g: Gen, a, out) -> None:
        with g.box():
            x = g.tmp("x")
            g.line(f"{x} = {g.rd(a, 'R')}")
            _overflow(g, f"{lo!r} < {x} < {hi!r}",
                      lambda: g.wr(out, "D", expr.format(x=x)))

    insn(mn, Role.R_R, Role.D_W, family=F, summary=summary, may_fail=True)(emit)


for _mn in REAL_TO_DINT:
    _make_real_to_dint(_mn)


# -- BCD ----------------------------------------------------------------------
#
# Tables instead of digit arithmetic at run time: BCD_TO_INT holds the 10000
# legal BCD words, so a missing key is an illegal digit; INT_TO_BCD is
# indexed by the value after the 0..9999 check.

INT_TO_BCD: tuple[int, ...] = tuple(
    int(str(i), 16) for i in range(10000))
BCD_TO_INT: dict[int, int] = {b: i for i, b in enumerate(INT_TO_BCD)}


def _bcd_error(g: Gen, ok: str, write: Callable[[], None]) -> None:
    """SM1.6: illegal BCD value."""
    _flagged(g, ok, write, 6)


@insn("BCDI", Role.W_W, family=F, may_fail=True,
      summary="OUT := INT of the BCD word OUT")
def _bcdi(g: Gen, out) -> None:
    table = g.const(BCD_TO_INT, "bcd2i")
    with g.box():
        r = g.tmp("r")
        g.line(f"{r} = {table}.get({g.rd(out, 'WU')})")
        _bcd_error(g, f"{r} is not None", lambda: g.wr(out, "W", r))


@insn("IBCD", Role.W_W, family=F, may_fail=True,
      summary="OUT := BCD word of the INT OUT (0..9999)")
def _ibcd(g: Gen, out) -> None:
    table = g.const(INT_TO_BCD, "i2bcd")
    with g.box():
        v = g.tmp("v")
        g.line(f"{v} = {g.rd(out, 'W')}")
        _bcd_error(g, f"0 <= {v} <= 9999", lambda: g.wr(out, "WU", f"{table}[{v}]"))


# -- encode / decode / segment ------------------------------------------------

#: word -> number of its least significant set bit; 0 for the word 0 (the
#: manual does not define ENCO of 0, plcrt writes 0 as for bit 0).
LOWEST_BIT: bytes = bytes([0]) + bytes((v & -v).bit_length() - 1 for v in range(1, 65536))

#: 7-segment patterns (bit 0 = segment a ... bit 6 = segment g) for 0..F,
#: per the SEG table of the System Manual.
SEGMENTS: bytes = bytes((0x3F, 0x06, 0x5B, 0x4F, 0x66, 0x6D, 0x7D, 0x07,
                         0x7F, 0x6F, 0x77, 0x7C, 0x39, 0x5E, 0x79, 0x71))


@insn("ENCO", Role.W_R, Role.B_W, family=F,
      summary="OUT := number of the lowest set bit of IN")
def _enco(g: Gen, a, out) -> None:
    table = g.const(LOWEST_BIT, "enco")
    with g.box():
        # The manual puts the bit number "into the least significant nibble"
        # of OUT; plcrt stores it as the whole byte (high nibble 0), the
        # reading under which OUT equals the bit number.
        g.wr(out, "B", f"{table}[{g.rd(a, 'WU')}]")


@insn("DECO", Role.B_R, Role.W_W, family=F,
      summary="OUT := word with only bit (IN mod 16) set")
def _deco(g: Gen, a, out) -> None:
    with g.box():
        g.wr(out, "WU", f"1 << ({g.rd(a, 'B')} & 15)")


@insn("SEG", Role.B_R, Role.B_W, family=F,
      summary="OUT := 7-segment pattern of the low nibble of IN")
def _seg(g: Gen, a, out) -> None:
    table = g.const(SEGMENTS, "seg")
    with g.box():
        g.wr(out, "B", f"{table}[{g.rd(a, 'B')} & 15]")
