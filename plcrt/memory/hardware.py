"""Fixed facts of the S7-200 CPU besides its area sizes (:mod:`.cpu`).

Data and two pure functions, shared by the instruction checks
(:mod:`plcrt.isa`, the native backend) and the engine that runs them
(:mod:`plcrt.engine`), which both import them from here: timer numbers and
their resolutions, the communication ports of each model, the modes of the
high-speed counters, the size of a PID loop table and the ports whose
station address GPA/SPA read and set (S7-200 System Manual: "Timer
instructions", "Communication", "High-speed counter", "PID loop",
"Get Port Address and Set Port Address").  Nothing here runs anything.
"""

from __future__ import annotations

# -- timers --------------------------------------------------------------------
#: the largest current value of a timer (an INT)
MAX_CV = 32767

#: retentive (TONR) timers with a resolution other than 100 ms
TONR_RES = {0: 1, 64: 1, **{n: 10 for n in (1, 2, 3, 4, 65, 66, 67, 68)}}
#: TON/TOF timers with a resolution other than 100 ms
TON_RES = {32: 1, 96: 1, **{n: 10 for n in (33, 34, 35, 36, 97, 98, 99, 100)}}


def timer_kind_ok(kind: str, n: int) -> bool:
    """Whether timer number ``n`` may be used by a ``kind`` box (TON/TOF/TONR)."""
    tonr = n < 32 or 64 <= n < 96
    return tonr if kind == "TONR" else not tonr


def resolution_ms(n: int) -> int:
    """Resolution of timer ``n`` in milliseconds (1, 10 or 100)."""
    if n < 32 or 64 <= n < 96:
        return TONR_RES.get(n, 100)
    return TON_RES.get(n, 100)


# -- communication ports -------------------------------------------------------
#: CPU model -> its ports (CPU 221, 222 and 224 have one, 224XP and 226 two)
PORTS_OF = {"CPU221": 1, "CPU222": 1, "CPU224": 1, "CPU224XP": 2, "CPU226": 2}
#: GPA/SPA ports (their PPI station addresses are 0..126)
PORTS = (0, 1)

# -- high-speed counters -------------------------------------------------------
#: counter -> the modes it has
MODES: dict[int, tuple[int, ...]] = {
    0: (0, 1, 3, 4, 6, 7, 9, 10, 12), 1: tuple(range(12)), 2: tuple(range(12)),
    3: (0, 12), 4: (0, 1, 3, 4, 6, 7, 9, 10), 5: (0,)}

# -- PID -----------------------------------------------------------------------
#: bytes of one PID loop table (nine REALs)
TABLE_BYTES = 36

__all__ = ["MAX_CV", "MODES", "PORTS", "PORTS_OF", "TABLE_BYTES", "TONR_RES", "TON_RES",
           "resolution_ms", "timer_kind_ok"]
