"""Helpers that generated network code calls at run time.

Only small, pure functions and factories live here: struct codecs bound as
fast locals, and the bounds-checked indirect-addressing helpers.  Anything an
instruction family needs at run time that is not a one-liner belongs in the
family module or in :mod:`plcrt.engine`.
"""

from __future__ import annotations

import math
from struct import Struct
from typing import Any, Callable, Sequence

from ..errors import PlcRuntimeError, SourceLoc
from .operands import POINTER_AREA_NAMES

# perf: pre-bound struct methods; generated code calls them as fast locals.
_H = Struct(">h")
_UH = Struct(">H")
_I = Struct(">i")
_UI = Struct(">I")
_F = Struct(">f")

#: perf: the bits of every byte value, ``BITS[v][k] == v >> k & 1``: the
#: generated code takes the tuple of a byte once, then each of its bits
#: with one tuple subscript instead of a shift and a mask
#: (plcrt.blocks.call)
BITS: tuple[tuple[int, ...], ...] = tuple(tuple(v >> k & 1 for k in range(8))
                                          for v in range(256))

CODECS: dict[str, Any] = {
    "_rh": _H.unpack_from, "_rH": _UH.unpack_from,
    "_ri": _I.unpack_from, "_rI": _UI.unpack_from, "_rf": _F.unpack_from,
    "_wH": _UH.pack_into, "_wI": _UI.pack_into, "_wf": _F.pack_into,
    # signed writers: for values known to be in range (no mask; an
    # out-of-range value raises instead of wrapping)
    "_wh": _H.pack_into, "_wi": _I.pack_into,
    "_bits": BITS,
}


#: struct format letter of each value kind written in one call (unsigned:
#: the generated code masks integers to the width first)
PACK_CODE = {"B": "B", "W": "H", "WU": "H", "D": "I", "DU": "I", "R": "f"}
#: struct format letter of a value known to be within its kind's range
#: (signed kinds signed, nothing masked)
EXACT_CODE = {"B": "B", "W": "h", "WU": "H", "D": "i", "DU": "I", "R": "f"}


def packer(codes: str) -> str:
    """The name of a codec writing several big-endian values at once
    (``"IB"``: a DWORD then a BYTE), added to :data:`CODECS` on first use.
    Only the letters of :data:`PACK_CODE` and :data:`EXACT_CODE` are
    accepted."""
    if len(codes) < 2 or not set(codes) <= set(PACK_CODE.values()) | set(EXACT_CODE.values()):
        raise ValueError(f"not a packer format: {codes!r}")
    name = "_w" + codes
    if name not in CODECS:
        CODECS[name] = Struct(">" + codes).pack_into
    return name


F32_MAX = 3.4028234663852886e38


def to_f32(x: float) -> float | None:
    """Round to IEEE single precision; ``None`` if not representable (overflow/NaN)."""
    if x != x or math.isinf(x):
        return None
    try:
        return _F.unpack(_F.pack(x))[0]
    except OverflowError:
        return None


def s16(v: int) -> int:
    v &= 0xFFFF
    return v - 0x10000 if v & 0x8000 else v


def s32(v: int) -> int:
    v &= 0xFFFFFFFF
    return v - 0x100000000 if v & 0x80000000 else v


def make_indirect(areas: dict[str, bytearray], locs: Sequence[SourceLoc],
                  sm_readonly: int = 0,
                  warn: Callable[[str, SourceLoc, str], None] | None = None
                  ) -> tuple[Callable, Callable, Callable]:
    """Build the ``_ird`` / ``_iwr`` / ``_ptr`` helpers for one memory image.

    A pointer holds the area code in its high byte and the byte offset in the
    low 24 bits (see :data:`plcrt.gen.operands.POINTER_AREAS`).  Every
    access is bounds-checked; a bad pointer is a fatal run-time error naming
    the instruction, as on the S7-200 (non-fatal error 0x0013 territory is
    not modelled: the CPU goes to STOP).

    SMB0 .. SMB(*sm_readonly* - 1) are read-only to the program: a direct
    write is refused when the program loads, a write through a pointer
    leaves those bytes as they are (the rest of a wider value is written)
    and *warn* says so, once per instruction.
    """
    sm = areas["SM"]
    by_code = {code: areas["TV" if n == "T" else "CV" if n == "C" else n]
               for code, n in POINTER_AREA_NAMES.items()}
    unpack = {1: None, 2: _H.unpack_from, 4: _I.unpack_from}
    unpack_u = {2: _UH.unpack_from, 4: _UI.unpack_from}

    def target(pbuf: bytearray, poff: int, width: int, insn: int) -> tuple[bytearray, int]:
        p = _UI.unpack_from(pbuf, poff)[0]
        buf = by_code.get(p >> 24)
        off = p & 0xFFFFFF
        if buf is None or off + width > len(buf):
            raise PlcRuntimeError(
                f"indirect access through pointer 16#{p:08X} is outside memory "
                f"({width}-byte access)", locs[insn])
        return buf, off

    def ird(pbuf: bytearray, poff: int, width: int, kind: str, insn: int):
        buf, off = target(pbuf, poff, width, insn)
        if width == 1:
            return buf[off]
        if kind == "r":
            return _F.unpack_from(buf, off)[0]
        if kind == "u":
            return unpack_u[width](buf, off)[0]
        return unpack[width](buf, off)[0]

    def iwr(pbuf: bytearray, poff: int, width: int, value, insn: int) -> None:
        buf, off = target(pbuf, poff, width, insn)
        kept = sm[off:sm_readonly] if buf is sm and off < sm_readonly else None
        if width == 1:
            buf[off] = value & 0xFF
        elif width == 2:
            _UH.pack_into(buf, off, value & 0xFFFF)
        elif isinstance(value, float):
            _F.pack_into(buf, off, value)
        else:
            _UI.pack_into(buf, off, value & 0xFFFFFFFF)
        if kept is not None:
            sm[off:sm_readonly] = kept
            if warn is not None:
                warn(f"a write through a pointer to SMB{off} leaves SMB0..SMB{sm_readonly - 1} "
                     f"unchanged: they are read-only to the program", locs[insn],
                     f"sm-readonly-{insn}")

    return ird, iwr, target
