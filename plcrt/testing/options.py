"""The plugin's command-line options and ini keys, and what it keeps per
pytest session.

What it is: ``pytest_addoption`` (``--plc-scan-ms``, ``--plc-history``,
``--plc-max-time``, ``--plc-backend``, ``--plc-coverage``,
``--plc-coverage-report`` and their ini keys), ``pytest_configure``, which
checks them into one :class:`_Session` (with the session's caches of
parsed programs, power-up PLCs and merged coverage), and the stash keys
through which the plugin's other modules find the session and the
harnesses each test used.  What it is not: the marker's own arguments
(:mod:`plcrt.testing.markers`) or the fixtures
(:mod:`plcrt.testing.plugin`).  Importing it stays cheap: the engine is
imported only when an option needs its checks.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from .markers import MARKER_HELP, _scan_us

#: plcrt.engine.values.BACKENDS (kept here: importing the engine is not cheap)
BACKENDS = ("auto", "python", "native")

if TYPE_CHECKING:
    from ..engine.runtime import Plc

DEFAULT_SCAN_MS = 10.0
DEFAULT_HISTORY = 20


@dataclass
class _Session:
    """What the plugin keeps for one pytest session (one per xdist worker)."""

    rootpath: Path
    scan_ms: float
    history: int
    max_time: float | None
    coverage: bool
    coverage_report: Path | None
    #: the code generator of every PLC (None: $PLCRT_BACKEND, else auto)
    backend: str | None = None
    #: parsed programs with their tables: (((path, mtime_ns, size), ...),
    #: which tables, encoding) -> (ir.Program, symbols, data).  The IR is
    #: frozen and the tables are only read, so one parse can serve every
    #: test; each test gets its own fork of one power-up PLC (:attr:`plcs`).
    programs: dict[Any, tuple[Any, Any, Any]] = field(default_factory=dict)
    #: power-up PLCs by program and options (:func:`_pristine`), least
    #: recently used first; each test gets a fork
    plcs: OrderedDict[Any, Plc] = field(default_factory=OrderedDict)
    #: merged coverage: program key -> coverage_report entry
    store: dict[str, Any] = field(default_factory=dict)


_SESSION = pytest.StashKey[_Session]()
_USED = pytest.StashKey[list]()   # item -> [(spec, Harness), ...] in creation order


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("plcrt", "plcrt: unit tests of S7-200 ladder programs")
    group.addoption("--plc-scan-ms", dest="plc_scan_ms", metavar="MS", default=None,
                    help="scan time in ms of PLCs whose marker or factory call gives none "
                         f"(default: ini plc_scan_ms, else {DEFAULT_SCAN_MS:g})")
    group.addoption("--plc-history", dest="plc_history", metavar="N", default=None,
                    help="scans of the watched addresses kept for the PLC trace of a failing "
                         f"test (default: ini plc_history, else {DEFAULT_HISTORY})")
    group.addoption("--plc-coverage", dest="plc_coverage", action="store_true", default=None,
                    help="instrument PLC programs and report network and rung-output "
                         "coverage at the end")
    group.addoption("--plc-coverage-report", dest="plc_coverage_report", metavar="PATH",
                    default=None,
                    help="also write the PLC coverage as JSON to PATH (implies --plc-coverage)")
    parser.addini("plc_scan_ms", "default PLC scan time in ms (plcrt)", default=None)
    group.addoption("--plc-max-time", dest="plc_max_time", metavar="DURATION", default=None,
                    help="fail a test whose PLC runs past this much simulated time, e.g. "
                         "60s or 10min (default: ini plc_max_time, else no limit)")
    group.addoption("--plc-backend", dest="plc_backend", choices=BACKENDS,
                    default=None,
                    help="code generator of the PLCs: auto, native (machine code through "
                         "llvmlite) or python (default: ini plc_backend, else "
                         "$PLCRT_BACKEND, else auto: native where llvmlite works)")
    parser.addini("plc_backend", "PLC code generator: auto, native or python (plcrt)",
                  default=None)
    parser.addini("plc_history", "scans kept for the PLC trace (plcrt)", default=None)
    parser.addini("plc_max_time", "simulated-time limit per PLC (plcrt)", default=None)
    parser.addini("plc_coverage", "report PLC network coverage (plcrt)", type="bool",
                  default=False)
    parser.addini("plc_coverage_report", "write PLC coverage JSON here (plcrt)", default=None)


def _setting(config: pytest.Config, name: str) -> Any:
    """Command line first, then the ini file."""
    value = config.getoption(name)
    if value is None:
        value = config.getini(name)
    return value if value not in ("", None) else None


def _session_from_config(config: pytest.Config) -> _Session:
    scan_ms = _setting(config, "plc_scan_ms")
    if scan_ms is None:
        scan_ms = DEFAULT_SCAN_MS
    else:
        try:
            scan_ms = float(scan_ms)
        except ValueError:
            raise pytest.UsageError(f"--plc-scan-ms / plc_scan_ms: {scan_ms!r} is not a "
                                    f"number of milliseconds") from None
        _scan_us(scan_ms, "--plc-scan-ms / plc_scan_ms", pytest.UsageError)
    history = _setting(config, "plc_history")
    try:
        history = DEFAULT_HISTORY if history is None else int(history)
    except ValueError:
        raise pytest.UsageError(f"--plc-history / plc_history: {history!r} is not a whole "
                                f"number of scans") from None
    if history < 1:
        raise pytest.UsageError(f"--plc-history / plc_history must be at least 1, got {history}")
    max_time = _setting(config, "plc_max_time")
    if max_time is not None:
        from ..errors import PlcConfigError
        from .harness import seconds   # only when the option is used
        try:
            max_time = seconds(max_time)
        except PlcConfigError as e:
            raise pytest.UsageError(f"--plc-max-time / plc_max_time: {e.message}") from None
    report = _setting(config, "plc_coverage_report")
    report_path = Path(report) if report is not None else None
    if report_path is not None and not report_path.is_absolute():
        report_path = Path(config.invocation_params.dir) / report_path
    coverage = bool(_setting(config, "plc_coverage")) or report_path is not None
    backend = _setting(config, "plc_backend")
    if backend not in (None, *BACKENDS):
        raise pytest.UsageError(f"plc_backend must be one of {', '.join(BACKENDS)}, "
                                f"got {backend!r:.40}")
    return _Session(rootpath=Path(config.rootpath), scan_ms=scan_ms, history=history,
                    max_time=max_time, coverage=coverage, coverage_report=report_path,
                    backend=backend)


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", MARKER_HELP)
    config.stash[_SESSION] = _session_from_config(config)


__all__ = ["DEFAULT_HISTORY", "DEFAULT_SCAN_MS"]
