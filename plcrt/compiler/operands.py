"""Re-export of :mod:`plcrt.gen.operands`, the operand model, from its former
place.

The instruction emitters (:mod:`plcrt.isa`) import it from :mod:`plcrt.gen`,
below them; the modules above the compiler may use either path.
"""

from __future__ import annotations

from ..gen.operands import (
    BYTE_AREAS, POINTER_AREAS, POINTER_AREA_NAMES, WIDTH_OF, Addr, Const, Indirect, Name,
    OperandError, Pointer, Resolved, area_size, parse_address, parse_constant, parse_operand,
    string_constant)

__all__ = ["BYTE_AREAS", "POINTER_AREAS", "POINTER_AREA_NAMES", "WIDTH_OF", "Addr", "Const",
           "Indirect", "Name", "OperandError", "Pointer", "Resolved", "area_size",
           "parse_address", "parse_constant", "parse_operand", "string_constant"]
