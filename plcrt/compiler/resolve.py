"""Re-export of :mod:`plcrt.gen.resolve`, operand resolution and role checking,
from its former place.

The instruction emitters (:mod:`plcrt.isa`) import it from :mod:`plcrt.gen`,
below them; the modules above the compiler may use either path.
"""

from __future__ import annotations

from ..gen.resolve import (
    REAL_MAX, SECTION_ORDER, TYPE_WIDTH, LocalVar, ResolveError, Resolver, check_role, layout_locals)

__all__ = ["REAL_MAX", "SECTION_ORDER", "TYPE_WIDTH", "LocalVar", "ResolveError", "Resolver",
           "check_role", "layout_locals"]
