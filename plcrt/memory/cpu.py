"""CPU model table: the size of every memory area per S7-200 CPU.

Data only.  Sizes follow the S7-200 System Manual, appendix A (CPU
specifications): process image I/Q 128 points each, M 32 bytes, S 32 bytes,
V memory by model, AIW/AQW 32 words each, 256 timers and counters, four
accumulators, six high-speed counters, 64 bytes of L memory per program unit.
"""

from __future__ import annotations

import re

from dataclasses import dataclass

from ..errors import PlcConfigError
from ..safetext import shown_value


@dataclass(frozen=True, slots=True)
class CpuModel:
    """Area sizes in bytes (T/C in elements) of one CPU type."""

    name: str
    v_bytes: int
    sm_bytes: int
    i_bytes: int = 16
    q_bytes: int = 16
    m_bytes: int = 32
    s_bytes: int = 32
    ai_bytes: int = 64
    aq_bytes: int = 64
    l_bytes: int = 64
    timers: int = 256
    counters: int = 256
    accumulators: int = 4
    hsc: int = 6
    sm_readonly: int = 30  #: SMB0..SMB29 are read-only to the program
    onboard_di_bytes: int = 3  #: bytes of I used by the CPU's own inputs
    onboard_do_bytes: int = 2  #: bytes of Q used by the CPU's own outputs
    max_modules: int = 7       #: expansion modules the CPU takes


CPU_MODELS: dict[str, CpuModel] = {
    m.name: m
    for m in (
        # onboard I/O: 221 6 DI/4 DO, 222 8/6, 224 and 224XP 14/10, 226 24/16
        # expansion: CPU 221 none, CPU 222 two modules, the others seven
        CpuModel("CPU221", v_bytes=2048, sm_bytes=180, ai_bytes=0, aq_bytes=0,
                 onboard_di_bytes=1, onboard_do_bytes=1, max_modules=0),
        CpuModel("CPU222", v_bytes=2048, sm_bytes=300, onboard_di_bytes=1, onboard_do_bytes=1,
                 max_modules=2),
        CpuModel("CPU224", v_bytes=8192, sm_bytes=550, onboard_di_bytes=2, onboard_do_bytes=2),
        CpuModel("CPU224XP", v_bytes=10240, sm_bytes=550, onboard_di_bytes=2,
                 onboard_do_bytes=2),
        CpuModel("CPU226", v_bytes=10240, sm_bytes=550),
    )
}

DEFAULT_CPU = "CPU226"

#: an S7-200 CPU as Micro/WIN names it in a project ("CPU 224 REL 02.01",
#: "CPU 224XP", "CPU226XM"): the model of the table above it runs as
_NAMED = re.compile(r"\bCPU\s*(22[1246])(?![0-9])\s*(XP)?", re.IGNORECASE)


def model_named(text: str) -> str | None:
    """The model of :data:`CPU_MODELS` a project's CPU description names,
    or None (a CPU this table has no model of: an older CPU 21x, a SMART
    CPU)."""
    match = _NAMED.search(text[:80]) if isinstance(text, str) else None
    if match is None:
        return None
    name = "CPU" + match.group(1) + ("XP" if match.group(2) else "")
    return name if name in CPU_MODELS else None


def cpu_model(name: str | None) -> CpuModel:
    """Look up a model by name (case and blanks ignored)."""
    if name is not None and not isinstance(name, str):
        raise PlcConfigError(f"the CPU model is a name such as 'CPU226' (known: "
                             f"{', '.join(CPU_MODELS)}), got {type(name).__name__} "
                             f"{shown_value(name)}")
    key = (name or DEFAULT_CPU).upper().replace(" ", "").replace("-", "")
    if not key.startswith("CPU"):
        key = "CPU" + key
    try:
        return CPU_MODELS[key]
    except KeyError:
        known = ", ".join(CPU_MODELS)
        raise PlcConfigError(f"unknown CPU model {name!r:.40} (known: {known})") from None
