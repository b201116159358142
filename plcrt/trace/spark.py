"""Quick looks at a trace in a terminal: sparklines and a one-line trend
per signal.

Plain strings only (no colours, no terminal control), so they can be
printed anywhere, logged, or compared in tests.  This is not a plot: the
vertical resolution is eight levels.  See :mod:`plcrt.trace.plot` for files.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..errors import PlcConfigError
from .recorder import format_value

#: the widest sparkline drawn, in characters (a terminal line is far less)
MAX_WIDTH = 10_000


def _check_width(width: Any) -> None:
    if isinstance(width, bool) or not isinstance(width, int) or not 1 <= width <= MAX_WIDTH:
        raise PlcConfigError(f"width must be a whole number of characters from 1 to "
                             f"{MAX_WIDTH}, got {type(width).__name__}")


#: the eight levels, lowest first
BLOCKS = "▁▂▃▄▅▆▇█"


def sparkline(values: Sequence[float] | np.ndarray, width: int = 60, *,
              bits: bool | None = None) -> str:
    """``values`` as ``width`` block characters (fewer values: stretched).

    Each column stands for an equal share of the samples.  When several
    samples fall into one column, a number shows their mean, but a bit
    shows their maximum, so that a pulse shorter than a column still shows.
    Numbers are scaled from their minimum (``▁``) to their maximum (``█``);
    a constant is drawn as ``▁``.  Bits (``bits=True``, or by default any
    sequence of only 0 and 1) are ``▁`` for 0 and ``█`` for 1.  Values that
    are not finite (a NaN REAL) are a space.
    """
    _check_width(width)
    if bits is not None and not isinstance(bits, bool):
        raise PlcConfigError(f"bits must be True, False or None, got {type(bits).__name__}")
    try:
        v = np.asarray(values, dtype=np.float64).ravel()
    except (TypeError, ValueError, OverflowError):
        raise PlcConfigError(f"sparkline() takes a sequence of numbers, got "
                             f"{type(values).__name__}") from None
    n = len(v)
    if n == 0:
        return ""
    finite = np.isfinite(v)
    if bits is None:
        bits = bool(finite.all() and np.isin(v, (0.0, 1.0)).all())
    # column j covers samples [edges[j], edges[j + 1]); with fewer samples
    # than columns a sample covers several columns (it holds, like a step)
    if n >= width:
        edges = np.arange(width + 1) * n // width
        cols = []
        for j in range(width):
            chunk = v[edges[j]:edges[j + 1]]
            chunk = chunk[np.isfinite(chunk)]
            if len(chunk) == 0:
                cols.append(np.nan)
            else:
                cols.append(chunk.max() if bits else chunk.mean())
        col = np.array(cols)
    else:
        col = v[np.arange(width) * n // width]
    if bits:
        lo, hi = 0.0, 1.0
    elif finite.any():
        lo, hi = float(v[finite].min()), float(v[finite].max())
    else:
        lo = hi = 0.0
    out = []
    for x in col:
        if not np.isfinite(x):
            out.append(" ")
        elif hi == lo:
            out.append(BLOCKS[0])
        else:
            # round half up, so the result does not depend on banker's rounding
            level = int(np.floor((x - lo) / (hi - lo) * (len(BLOCKS) - 1) + 0.5))
            out.append(BLOCKS[min(max(level, 0), len(BLOCKS) - 1)])
    return "".join(out)


def trend(trace: Any, width: int = 60) -> str:
    """One line per signal: ``name  min..max  <sparkline>  last=<value>``.

    A first line gives the number of samples and the time they span.  The
    columns are aligned; the result ends without a newline.
    """
    from .recorder import Trace
    if not isinstance(trace, Trace):
        raise PlcConfigError(f"trend() takes a plcrt.trace.Trace, got {type(trace).__name__}")
    _check_width(width)
    n = len(trace)
    if n == 0:
        return "0 samples"
    t = trace.time
    lines = [f"{n} sample{'s' if n != 1 else ''}, t = {t[0].item()!r}..{t[-1].item()!r} s"]
    names = trace.names
    ranges = []
    for name in names:
        a = trace.array(name)
        # the range of the values that are numbers: a REAL that is +-inf
        # all along shows as inf..inf, only NaNs as nan
        finite = a[~np.isnan(a)] if a.dtype.kind == "f" else a
        if len(finite) == 0:
            ranges.append("nan")
        else:
            ranges.append(f"{format_value(finite.min().item())}.."
                          f"{format_value(finite.max().item())}")
    wn = max(len(s) for s in names)
    wr = max(len(r) for r in ranges)
    for name, rng in zip(names, ranges):
        a = trace.array(name)
        line = sparkline(a, width, bits=trace.kind(name) == "bit")
        lines.append(f"{name:<{wn}}  {rng:<{wr}}  {line}  last={format_value(a[-1].item())}")
    return "\n".join(lines)


__all__ = ["BLOCKS", "sparkline", "trend"]
