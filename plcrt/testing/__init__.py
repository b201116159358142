"""Testing ladder programs: the :class:`Harness` and the pytest plugin.

``from plcrt.testing import Harness`` works without pytest.  The plugin
(:mod:`plcrt.testing.plugin`) is registered through the ``pytest11`` entry
point and imports the engine only when a test asks for a PLC.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .harness import AxisState, Harness, PlcTimeout, seconds

__all__ = ["AxisState", "Harness", "PlcTimeout", "seconds"]


def __getattr__(name: str) -> Any:
    # perf: keep `import plcrt.testing.plugin` (done by every pytest run
    # once plcrt is installed) free of the engine's import cost
    if name in __all__:
        from . import harness
        return getattr(harness, name)
    raise AttributeError(f"module 'plcrt.testing' has no attribute {name!r}")
