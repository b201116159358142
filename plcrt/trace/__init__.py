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
* :mod:`.progress`: :func:`run_with_progress`, ``plc.run`` with a progress bar;
* :mod:`.cli`: the ``plcrt trace`` command.

See docs/traces.md.  matplotlib and rich are imported only when used.
"""

from __future__ import annotations

from .plot import plot
from .progress import run_with_progress
from .recorder import Trace
from .spark import sparkline, trend

__all__ = ["Trace", "plot", "run_with_progress", "sparkline", "trend"]
