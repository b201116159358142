"""Plotting a trace to a PNG or SVG file, like a logic analyser.

One subplot per signal, stacked, sharing the time axis.  Bits and integer
signals are drawn as steps that hold each sample until the next one
(``drawstyle="steps-post"``): a sample is the state at the end of a scan,
and the PLC's memory does not change between scans, so an instantaneous
change must never be drawn as a ramp.  REAL values and axis speeds are
drawn as lines.

matplotlib is an optional dependency (the ``plot`` extra; the error names the
install command for this installation, :mod:`plcrt.extras`),
imported only when a plot is made, and only its Agg canvas is used: no
window, no pyplot state, no change of the user's backend.  The files are
reproducible: SVG ids are salted with a fixed string and no date is
written.  This module does not record anything (see
:mod:`plcrt.trace.recorder`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

from ..errors import PlcConfigError
from ..paths import check_path
from ..safetext import printable

_FORMATS = {".png": "png", ".svg": "svg"}

#: rc settings that make the output independent of time and of the
#: user's matplotlibrc; fonts as text in SVG keep the names searchable.
_RC = {
    "svg.hashsalt": "plcrt-trace",
    "svg.fonttype": "none",
    "savefig.dpi": 100,
    "font.size": 9,
}

#: what the hint says before the install command (plcrt.extras.install_hint)
_MISSING = "plotting needs matplotlib, which is not installed"


def plot_format(path: str | Path) -> str:
    """``"png"`` or ``"svg"`` from the file name's extension.

    Raises:
        PlcConfigError: for any other extension.
    """
    fmt = _FORMATS.get(check_path(path, "plot(): the file name").suffix.lower())
    if fmt is None:
        raise PlcConfigError(f"cannot plot to '{path}': the file name must end in "
                             f".png or .svg")
    return fmt


def require_matplotlib() -> Any:
    """Import matplotlib (once) or explain how to install it.

    Raises:
        PlcConfigError: when matplotlib is not installed.
    """
    try:
        import matplotlib
        from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: F401
        from matplotlib.figure import Figure  # noqa: F401
    except ImportError:
        from ..extras import install_hint
        raise PlcConfigError(install_hint(_MISSING, "plot")) from None
    return matplotlib


def plot(trace: Any, path: str | Path, *, signals: Sequence[str] | None = None,
         title: str | None = None) -> Path:
    """Write ``trace`` to ``path`` (PNG or SVG by extension); returns the path.

    Args:
        trace: a :class:`plcrt.trace.Trace` with at least one sample.
        path: the file to write; ``.png`` or ``.svg``.
        signals: the signals to draw, in this order (default: all).
        title: a title above the plot.

    Raises:
        PlcConfigError: a bad extension, an unknown signal, an empty trace,
            or matplotlib missing.
    """
    from .recorder import Trace
    if not isinstance(trace, Trace):
        raise PlcConfigError(f"plot() draws a plcrt.trace.Trace, got {type(trace).__name__}")
    fmt = plot_format(path)
    if signals is not None and (not isinstance(signals, (list, tuple))
                                or not all(isinstance(s, str) for s in signals)):
        raise PlcConfigError(f"signals= is a list of signal names, got "
                             f"{type(signals).__name__}")
    if title is not None and not isinstance(title, str):
        raise PlcConfigError(f"title= is a str, got {type(title).__name__}")
    names = list(trace.names if signals is None else signals)
    if not names:
        raise PlcConfigError("nothing to plot: no signal selected")
    for name in names:
        if name not in trace:
            raise PlcConfigError(f"cannot plot {name!r}: it is not a signal of this "
                                 f"trace ({', '.join(trace.names)})")
    if len(trace) == 0:
        raise PlcConfigError("nothing to plot: the trace has no samples yet")
    mpl = require_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    t = trace.time
    with mpl.rc_context(_RC):
        heights = [0.8 if trace.kind(n) == "bit" else 1.4 for n in names]
        fig = Figure(figsize=(10, 0.6 + sum(heights)), layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(len(names), 1, sharex=True, squeeze=False,
                            gridspec_kw={"height_ratios": heights})[:, 0]
        for i, (ax, name) in enumerate(zip(axes, names)):
            kind = trace.kind(name)
            style = "default" if kind == "real" else "steps-post"
            (line,) = ax.plot(t, trace.array(name), drawstyle=style, linewidth=1.2,
                              color=f"C{i % 10}")
            # a stable id per signal, so the SVG can be inspected by signal
            line.set_gid(f"signal-{i}")
            # names and titles are shown as written: no mathtext ("$...$")
            ax.set_ylabel(name, rotation=0, ha="right", va="center", parse_math=False)
            ax.grid(True, axis="x", linewidth=0.4, alpha=0.5)
            if kind == "bit":
                ax.set_yticks([0, 1])
                ax.set_ylim(-0.2, 1.2)
        axes[-1].set_xlabel("time (s)")
        if title:
            # control characters and lone surrogates (undecodable bytes) as
            # escapes: the font renderer takes only encodable text
            fig.suptitle(printable(title), parse_math=False)
        metadata: dict[str, Any] = {"Software": None} if fmt == "png" else \
            {"Date": None, "Creator": "plcrt"}
        try:
            fig.savefig(path, format=fmt, metadata=metadata)
        except OSError as e:
            raise PlcConfigError(f"cannot write the plot to '{printable(str(path))[:80]}': "
                                 f"{e.strerror or type(e).__name__}") from None
    return Path(path)


__all__ = ["plot", "plot_format", "require_matplotlib"]
