"""Instruction family: the real-time clock (TODR TODW; SMART TODRX TODWX).

S7-200 System Manual, "Clock instructions"; S7-200 SMART System Manual,
"Read/set real-time clock extended".  ``TODR T`` reads the clock into the
8-byte BCD buffer at T (year, month, day, hour, minute, second, 0, day of
week), ``TODW T`` sets it from that buffer; TODRX/TODWX add bytes 8..18,
the daylight-saving settings.  The clock itself, and what plcrt simulates
of it, is :mod:`plcrt.engine.clock` (daylight-saving rules:
:mod:`plcrt.engine.dst`).

Errors: a buffer that is not valid BCD in range (month 13, hour 24, a
non-decimal digit, a daylight-saving mode the SMART does not have) is run-
time error 0007 (TOD data error): the clock is not changed, SM4.3 is set,
ENO is 0.  No SMB1 bit changes.
"""

from __future__ import annotations

from ..gen.emit import Gen
from ..gen.recipe import CPU, Attr, Call
from .region import region, runtime_error
from .registry import Role, Span, insn

F = "clock"

#: mnemonic -> (buffer bytes, Clock method, sets the clock, summary)
TOD: dict[str, tuple[int, str, bool, str]] = {
    "TODR": (8, "read", False, "T[0..7] := the clock (BCD)"),
    "TODW": (8, "write", True, "the clock := T[0..7] (BCD)"),
    "TODRX": (19, "read_ext", False, "T[0..18] := the clock and daylight-saving settings"),
    "TODWX": (19, "write_ext", True, "the clock and daylight-saving settings := T[0..18]"),
}


def _checked(plc, mn: str, write):
    """TODW/TODWX for *plc*: ENO 1 when the clock was set, else error 0007."""

    def todw(where: tuple, insn_id: int) -> int:
        if write(*where):
            return 1
        return runtime_error(plc, insn_id, 0x0007, f"{mn}: the time and date are not "
                             f"valid BCD values in their ranges; the clock is unchanged")

    return todw


def _make(mn: str) -> None:
    nbytes, method, sets, summary = TOD[mn]

    def emit(g: Gen, t) -> None:
        where = region(g, t, nbytes, "the clock buffer T")
        with g.box():
            if sets:
                fn = g.bind(Call(_checked, (CPU, mn, Attr(CPU, f"clock.{method}"))), mn.lower())
                g.eno(f"{fn}({where}, {g.insn_id})")
            else:
                fn = g.cpu(f"clock.{method}", mn.lower())
                g.line(f"{fn}(*{where})")

    # TODW reads its buffer, TODR writes it
    insn(mn, Role.B_M if sets else Role.B_MW, family=F, summary=summary, may_fail=sets,
         spans=(Span(0, 8, nbytes),))(emit)


for _mn in TOD:
    _make(_mn)
