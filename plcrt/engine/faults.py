"""Faults, the watchdog and run-time warnings of a PLC.

What it is: :class:`Faults`, a mixin of :class:`plcrt.engine.runtime.Plc`:
an exception while executing becomes a :class:`~plcrt.errors.PlcError` at
the program location it came from and the CPU goes to STOP; the watchdog's
messages (loops that run too long); a CALL nested too deep; run-time
warnings, each reported once.

What it is not: the watchdog's counting (the generated code counts, in
``plc.wd``), the scan loop that catches the exceptions (:mod:`.scan`).
"""

from __future__ import annotations

from typing import Any, NoReturn

from ..errors import Diagnostic, PlcConfigError, PlcError, PlcRuntimeError, SourceLoc
from ..lang import ir

__all__ = ["Faults", "WATCHDOG_MS", "WATCHDOG_US_PER_INSN"]

#: Estimated execution time per instruction for the watchdog (µs).  Only
#: loops (FOR/NEXT, backward jumps) are checked, and their instructions are
#: mostly word operations: even the faster S7-200 SMART needs 1.2 µs for a
#: word move (0.15 µs only for booleans), so 1.2 µs is a lower bound for the
#: classic CPU.  It also keeps an endless loop's fault well under a second
#: of wall time.
WATCHDOG_US_PER_INSN = 1.2
WATCHDOG_MS = 500  #: S7-200 watchdog time (System Manual, WDR)


class Faults:
    """Faults and warnings (a mixin of :class:`plcrt.engine.runtime.Plc`)."""

    def _fault(self, exc: Exception) -> NoReturn:
        """Stop on an exception raised while executing: a PlcError as it is,
        anything else as an internal error at the program location it came
        from."""
        if isinstance(exc, PlcError):
            self._fail(exc)
        self._fail(PlcRuntimeError(f"internal error while executing: {exc!r}",
                                   self._loc_from_tb(exc)), exc)

    def _fail(self, err: PlcError, cause: BaseException | None = None) -> NoReturn:
        self.mode = "STOP"
        self.fault = err
        m = self.mem.areas
        m["PQ"][:] = bytes(len(m["PQ"]))  # outputs go to their STOP state (off)
        raise err from cause

    def _loc_from_tb(self, exc: BaseException) -> SourceLoc | None:
        tb = exc.__traceback__
        loc = None
        while tb is not None:
            if tb.tb_frame.f_code.co_filename == self._filename:
                lineno = tb.tb_lineno
                # the nearest instruction comment above the failing line
                for ln in range(lineno, 0, -1):
                    if ln in self.line_locs:
                        loc = self.line_locs[ln]
                        break
            tb = tb.tb_next
        return loc

    def _watchdog(self, kind: str, number: int, pc: int, target: int) -> None:
        """The scan's loops ran past the watchdog time; ``pc`` is the piece
        of block ``kind``+``number`` that jumped back to piece ``target``."""
        info = self.unit.pous[f"{kind}{number}"]
        # the NEXT, or the JMP to the target's label (a piece may hold more
        # instructions after its JMP)
        back = next((i for i in reversed(info.pieces[pc].insns) if i.mnemonic == "NEXT"
                     or i.mnemonic == "JMP" and i.operands
                     and info.labels.get(_int_or_none(i.operands[0].text)) == target),
                    None)
        start = next((f for _b, (body, _e, f) in info.loops.items() if body == target), None)
        if start is None and info.pieces[target].insns:
            start = info.pieces[target].insns[0]    # the LBL a JMP goes back to
        where = ""
        if start is not None and back is not None:
            where = (f" in the loop from {start.mnemonic} at line {start.loc.line} to "
                     f"{back.mnemonic} at line {back.loc.line}")
        loc = start.loc.within(info.pou.ident, _network_of(info, start)) if start else None
        raise PlcRuntimeError(
            f"watchdog: the scan ran longer than {WATCHDOG_MS} ms{where} of {kind}{number} "
            f"({self._loop_work()}); the CPU goes to STOP", loc)

    def _watchdog_wdr(self, insn_id: int) -> None:
        """A loop that retriggers the watchdog with WDR ran ten times the
        watchdog time in one scan (the limit plcrt puts on it)."""
        loc = self.unit.locs[insn_id] if 0 <= insn_id < len(self.unit.locs) else None
        line = f" at line {loc.line}" if loc is not None else ""
        raise PlcRuntimeError(
            f"watchdog: the loop around WDR{line} ran ten times the {WATCHDOG_MS} ms watchdog "
            f"time in one scan ({self._loop_work()}); WDR retriggers the watchdog, but plcrt "
            f"stops a scan that never ends; the CPU goes to STOP", loc)

    def _nesting_exceeded(self, insn_id: int) -> None:
        """A CALL that would nest a ninth subroutine level: the CPU does not
        execute it, sets SM4.3 (run-time programming error, code 0008) and
        gives ENO 0; plcrt warns once per CALL (System Manual, CALL)."""
        self.mem.areas["SM"][4] |= 0x08
        loc = self.unit.locs[insn_id] if 0 <= insn_id < len(self.unit.locs) else None
        self.warn("CALL not executed: it would nest subroutines deeper than the S7-200's "
                  "limit of 8 levels (run-time error 0008; SM4.3 set, ENO 0)", loc,
                  f"nesting:{insn_id}")

    def _loop_work(self) -> str:
        """``about N instructions in loops, about T s`` of this scan (WDR
        resets included)."""
        n = self.wd[0] + self.wd[2]
        return (f"about {n} instructions in loops, about {n * WATCHDOG_US_PER_INSN / 1e6:.2g} s "
                f"at {WATCHDOG_US_PER_INSN} \u00b5s each")

    def warn(self, message: str, loc: SourceLoc | None, key: str) -> None:
        """A run-time diagnostic (reported once per ``key``).

        Raises:
            PlcConfigError: ``message`` or ``key`` not a str, ``loc`` not a
                :class:`~plcrt.errors.SourceLoc` or None.
        """
        if not (isinstance(message, str) and isinstance(key, str)
                and (loc is None or isinstance(loc, SourceLoc))):
            raise PlcConfigError("warn(message, loc, key) takes a str, a SourceLoc or None, "
                                 "and a str")
        if key in self._warned:
            return
        self._warned.add(key)
        self.diagnostics.append(Diagnostic("warning", message, loc, "runtime"))


def _int_or_none(text: str) -> int | None:
    t = text.strip()
    return int(t) if t.isdigit() and len(t) <= 3 else None


def _network_of(info: Any, insn: ir.Insn) -> int | None:
    """The number of the network of ``info``'s block that holds ``insn``."""
    for piece in info.pieces:
        if any(i is insn for i in piece.insns):
            return piece.network.number
    return None
