"""Re-export of :mod:`plcrt.gen.rt`, the run-time helpers of generated code, from
its former place.

The instruction emitters (:mod:`plcrt.isa`) import it from :mod:`plcrt.gen`,
below them; the modules above the compiler may use either path.
"""

from __future__ import annotations

from ..gen.rt import (
    BITS, CODECS, EXACT_CODE, F32_MAX, PACK_CODE, make_indirect, packer, s16, s32, to_f32)

__all__ = ["BITS", "CODECS", "EXACT_CODE", "F32_MAX", "PACK_CODE", "make_indirect", "packer",
           "s16", "s32", "to_f32"]
