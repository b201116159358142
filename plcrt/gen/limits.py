"""Limits of the S7-200 that the code generator and the emitters both check.

Data only (S7-200 System Manual): how deep subroutines, FOR loops and the
logic stack nest.
"""

from __future__ import annotations

#: subroutines nest at most eight levels deep from the main program (CALL)
MAX_NESTING = 8
#: FOR/NEXT loops nest at most eight levels deep
MAX_FOR_NESTING = 8
#: depth of the logic stack ("Logic stack")
MAX_STACK = 9

__all__ = ["MAX_FOR_NESTING", "MAX_NESTING", "MAX_STACK"]
