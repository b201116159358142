"""Re-export of :mod:`plcrt.gen.emit`, the code generator's per-function context,
from its former place.

The instruction emitters (:mod:`plcrt.isa`) import it from :mod:`plcrt.gen`,
below them; the modules above the compiler may use either path.
"""

from __future__ import annotations

from ..gen.emit import (
    BUFFER_NAME, MAX_GAP, MAX_STACK, VALUE_WIDTH, CodegenError, Gen, const_expr)

__all__ = ["BUFFER_NAME", "MAX_GAP", "MAX_STACK", "VALUE_WIDTH", "CodegenError", "Gen",
           "const_expr"]
