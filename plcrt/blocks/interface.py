"""Re-export of :mod:`plcrt.isa.libraries`, the interface descriptions of
instruction libraries (``library/*.toml``), from its former place.

The tables lie below the compiler, which checks library calls against
them; the block registry and the devices may use either path.
"""

from __future__ import annotations

from ..isa.libraries import TYPES, BlockInterface, Param, interfaces, library_dirs

__all__ = ["TYPES", "BlockInterface", "Param", "interfaces", "library_dirs"]
