"""S7-200 counters CTU, CTD, CTUD (System Manual, "Counter instructions").

The boxes take several inputs from the logic stack: CTU: CU (second level),
R (top); CTD: CD (second), LD (top); CTUD: CU (third), CD (second), R (top).
Counting happens on the rising edge of CU/CD; the previous input states are
kept per counter number (one edge memory per counter, as one counter number
must not be used by two boxes).  A counter sees a 1 at its first execution
after entering RUN as a rising edge (edge memory starts at 0 at power-up,
see docs/decisions.md).

* CTU: CV stops at 32767; the bit is on while CV >= PV.
* CTD: LD=1 loads CV := PV and clears the bit; CV stops at 0; bit on at CV = 0.
* CTUD: counts up and down and wraps (32767 + 1 -> -32768 and back); bit on
  while CV >= PV.  R clears CV and the bit.

Visible state (CV words, bits) lives in the image (``CV``/``CB`` areas).
"""

from __future__ import annotations

from struct import Struct

_H = Struct(">h")
_UH = Struct(">H")


class CounterBank:
    """Hidden edge memory of all counters."""

    def __init__(self, cv: bytearray, cb: bytearray, count: int = 256) -> None:
        self.cv = cv
        self.cb = cb
        self.prev_up = [0] * count
        self.prev_dn = [0] * count

    def _set(self, n: int, cv: int, bit: int) -> None:
        _UH.pack_into(self.cv, n * 2, cv & 0xFFFF)
        mask = 1 << (n & 7)
        if bit:
            self.cb[n >> 3] |= mask
        else:
            self.cb[n >> 3] &= ~mask & 0xFF

    def reset(self, n: int) -> None:
        """``R Cn``: clear current value and bit."""
        self._set(n, 0, 0)

    def ctu(self, n: int, cu: int, r: int, pv: int) -> None:
        rise = cu and not self.prev_up[n]
        self.prev_up[n] = cu
        if r:
            self._set(n, 0, 0)
            return
        cv = _H.unpack_from(self.cv, n * 2)[0]
        if rise and cv < 32767:
            cv += 1
        self._set(n, cv, cv >= pv)

    def ctd(self, n: int, cd: int, ld: int, pv: int) -> None:
        fall = cd and not self.prev_dn[n]
        self.prev_dn[n] = cd
        if ld:
            self._set(n, pv, 0)
            return
        cv = _H.unpack_from(self.cv, n * 2)[0]
        if fall and cv > 0:
            cv -= 1
        self._set(n, cv, cv == 0)

    def ctud(self, n: int, cu: int, cd: int, r: int, pv: int) -> None:
        up = cu and not self.prev_up[n]
        dn = cd and not self.prev_dn[n]
        self.prev_up[n] = cu
        self.prev_dn[n] = cd
        if r:
            self._set(n, 0, 0)
            return
        cv = _H.unpack_from(self.cv, n * 2)[0]
        if up:
            cv = -32768 if cv == 32767 else cv + 1
        if dn:
            cv = 32767 if cv == -32768 else cv - 1
        self._set(n, cv, cv >= pv)
