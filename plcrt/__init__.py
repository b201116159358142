"""plcrt: run S7-200 (STEP 7-Micro/WIN) STL programs in Python, scan by scan.

Public API::

    import plcrt
    plc = plcrt.load("programs/seal_in.awl", scan_ms=10)
    plc["I0.0"] = 1
    plc.scan()            # one scan cycle
    plc.run(seconds=2.0)  # simulated time, deterministic
    plc["Q0.0"], plc["VW100"], plc.time
    net = plcrt.link(plc_a, 0, plc_b, 0)   # two CPUs port to port, run together
    net.run(1.0)

Everything else is internal and may change.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .blocks import add_library_loader as _add_library_loader
from .parts import add_parts_loader as _add_parts_loader
from .errors import (Diagnostic, PlcAddressError, PlcCompileError, PlcConfigError,
                     PlcError, PlcRuntimeError, PlcSyntaxError, SourceLoc)

__version__ = "0.1.0"

if TYPE_CHECKING:
    from .engine.link import Network, link
    from .engine.runtime import Plc
    from .loader import load
    from .net.serving import serve


def __getattr__(name: str) -> Any:
    # perf: the engine (lark, the compiler) loads on first use, so that
    # `import plcrt` stays cheap for the pytest plugin and the CLI's --help
    if name in ("Plc", "load"):
        from . import loader
        return getattr(loader, name)
    if name == "serve":
        from .net import serving
        return serving.serve
    if name in ("link", "Network"):
        from .engine import link
        return getattr(link, name)
    raise AttributeError(f"module 'plcrt' has no attribute {name!r}")


# The composition: the registries below hold what the layers above them
# supply, and never import it; this module hands them the imports, run
# when first needed (perf: not by `import plcrt`).

def _load_device_libraries() -> None:
    """The library blocks of plcrt's devices, for the block registry, which
    sits below them and never imports them (plcrt.blocks)."""
    from .devices import libraries  # noqa: F401


def _load_parts() -> None:
    """What every PLC is fitted with (devices, port devices, the library
    blocks' compiler hooks), for the engine, which sits below them and
    never imports them (plcrt.parts): plcrt.loader supplies it."""
    from . import loader  # noqa: F401


_add_library_loader(_load_device_libraries)
_add_parts_loader(_load_parts)

__all__ = [
    "load", "Plc", "link", "Network", "serve", "Diagnostic", "SourceLoc", "PlcError", "PlcSyntaxError",
    "PlcCompileError", "PlcRuntimeError", "PlcAddressError", "PlcConfigError",
    "__version__",
]
