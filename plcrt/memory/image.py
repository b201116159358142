"""The S7-200 memory image: one ``bytearray`` per area.

Byte order is big-endian as on the S7-200 (VW100 = VB100 high byte, VB101 low
byte; VD100 overlaps VW102), and aliasing is real because every width reads
the same bytes.  Generated code indexes these buffers with constant offsets;
:meth:`MemoryImage.view` gives zero-copy numpy views for bulk work
(snapshots, diffs, traces), never for the scan path.

Areas: I, Q (process images), PI, PQ (the physical terminals behind them, for
immediate I/O), M, V, SM, S, AI, AQ, L (OB1's locals), TV/TB (timer values
and bits), CV/CB (counter values and bits), AC (four 32-bit accumulators),
HC (high-speed counters).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .cpu import CpuModel


@dataclass(frozen=True)
class Snapshot:
    """An immutable copy of every area (bytes)."""

    areas: dict[str, bytes]

    def __getitem__(self, area: str) -> bytes:
        return self.areas[area]


class MemoryImage:
    """Process image and data memory of one simulated CPU."""

    def __init__(self, model: CpuModel) -> None:
        self.model = model
        sizes = {
            "I": model.i_bytes, "Q": model.q_bytes, "PI": model.i_bytes,
            "PQ": model.q_bytes, "M": model.m_bytes, "V": model.v_bytes,
            "SM": model.sm_bytes, "S": model.s_bytes, "AI": model.ai_bytes,
            "AQ": model.aq_bytes, "L": model.l_bytes,
            "TV": model.timers * 2, "TB": (model.timers + 7) // 8,
            "CV": model.counters * 2, "CB": (model.counters + 7) // 8,
            "AC": model.accumulators * 4, "HC": model.hsc * 4,
        }
        self.areas: dict[str, bytearray] = {k: bytearray(n) for k, n in sizes.items()}

    def area(self, name: str) -> bytearray:
        return self.areas[name]

    def view(self, name: str) -> np.ndarray:
        """Zero-copy ``uint8`` numpy view of an area."""
        return np.frombuffer(self.areas[name], dtype=np.uint8)

    def snapshot(self) -> Snapshot:
        return Snapshot({k: bytes(v) for k, v in self.areas.items()})

    def restore(self, snap: Snapshot) -> None:
        for k, data in snap.areas.items():
            self.areas[k][:] = data

    def diff(self, before: Snapshot) -> dict[str, np.ndarray]:
        """Byte offsets that changed since ``before``, per area."""
        out = {}
        for k, buf in self.areas.items():
            old = np.frombuffer(before.areas[k], dtype=np.uint8)
            changed = np.flatnonzero(old != self.view(k))
            if changed.size:
                out[k] = changed
        return out
