"""Traces of a running program: record signals per scan, then look at them.

::

    from plcrt.trace import Trace, plot, trend

    plc = plcrt.load("programs/timers.awl")
    plc["I0.0"] = 1
    with Trace(plc, ["I0.0", "T37", "Q0.0"]) as tr:
        plc.run(seconds=3)
    print(trend(tr))            # a sparkline per signal
    tr.to_csv("timers.csv")     # time_s,I0.0,T37,Q0.0
    plot(tr, "timers.svg")      # needs the optional extra: plcrt[plot]

* :mod:`.recorder`: :class:`Trace`, the per-scan recorder (numpy arrays, CSV);
* :mod:`.spark`: :func:`sparkline` and :func:`trend`, plain-text quick looks;
* :mod:`.plot`: :func:`plot` to PNG/SVG with matplotlib (optional);
* :func:`run_with_progress`, ``plc.run`` with a progress bar, is
  :mod:`plcrt.term.progress`'s (the ``plcrt`` commands share it), re-exported;
* :mod:`.cli`: the ``plcrt trace`` command.

See docs/traces.md.  matplotlib and rich are imported only when used.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

# plot is light (matplotlib is imported when a plot is made) and shares its
# name with its module: imported here, the package's ``plot`` is the function
from .plot import plot

if TYPE_CHECKING:
    from ..term.progress import run_with_progress
    from .recorder import Trace
    from .spark import sparkline, trend

__all__ = ["Trace", "plot", "run_with_progress", "sparkline", "trend"]

#: public name -> the module that defines it (imported on first use)
_LAZY = {"Trace": ".recorder", "run_with_progress": "plcrt.term.progress",
         "sparkline": ".spark", "trend": ".spark"}


def __getattr__(name: str) -> Any:
    # perf: `plcrt --help` imports plcrt.trace.cli to register `trace`; the
    # recorder (numpy) and the engine load only when a trace is made
    if name in _LAZY:
        import importlib
        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
