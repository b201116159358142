"""pytest plugin for unit tests of S7-200 ladder programs.

Registered through the ``pytest11`` entry point, so every pytest run in an
environment where plcrt is installed loads it.  It provides:

* the marker ``@pytest.mark.plc(program, symbols=, data=, plant=, scan_ms=,
  cpu=, watch=[...], history=, max_time=, encoding=, clock=)`` naming the
  program of a test (the closest marker wins: function over class over
  module ``pytestmark``);
* the fixture ``plc``: a fresh :class:`~plcrt.testing.Harness` at power-up,
  built from the marker;
* the fixture ``plc_factory``: ``plc_factory(program, **same options)`` for
  tests with several programs or configurations;
* the options ``--plc-scan-ms``, ``--plc-history``, ``--plc-coverage`` and
  ``--plc-coverage-report`` (and the ini keys ``plc_scan_ms``, ``plc_history``,
  ``plc_coverage``, ``plc_coverage_report``);
* a "PLC trace" report section (and a ``plc_trace`` JUnit property) on every
  failing test that used a harness;
* a network/rung-output coverage report, merged across pytest-xdist workers.

It is not the harness (see :mod:`plcrt.testing.harness`) and runs no scan
itself.  Importing it must stay cheap, because every pytest run does: the
engine, lark, numpy and rich are imported only inside fixtures and hooks
that need them.
"""

from __future__ import annotations

import difflib
import hashlib
import os
from collections import OrderedDict
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterator

import pytest

if TYPE_CHECKING:
    from ..engine.runtime import Plc
    from .harness import Harness

#: keyword arguments of the marker and of ``plc_factory``
OPTIONS = ("symbols", "data", "plant", "scan_ms", "cpu", "watch", "history", "max_time",
           "encoding", "clock")
DEFAULT_SCAN_MS = 10.0
DEFAULT_HISTORY = 20
#: power-up PLCs the plugin keeps per session (one per program and options)
PRISTINE_PLCS = 32
#: name of the JUnit XML property that carries the trace of a failing test
JUNIT_PROPERTY = "plc_trace"
#: key of the coverage data in an xdist worker's ``workeroutput``
WORKEROUTPUT_KEY = "plcrt_coverage"

MARKER_HELP = (
    "plc(program, *, symbols=None, data=None, plant=None, scan_ms=None, cpu=None, "
    "watch=(), history=None, max_time=None, encoding=None, clock=None): the S7-200 STL "
    "program "
    "(a .awl path or a list of them, relative to the test file or the rootdir) that the "
    "`plc` fixture loads"
)


class PlcUsageError(Exception):
    """A wrong marker or factory argument; the message says what to change."""


@dataclass
class _Session:
    """What the plugin keeps for one pytest session (one per xdist worker)."""

    rootpath: Path
    scan_ms: float
    history: int
    max_time: float | None
    coverage: bool
    coverage_report: Path | None
    #: the code generator of every PLC (None: $PLCRT_BACKEND, else Python)
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


@dataclass
class _Spec:
    """Validated arguments of one harness to build."""

    program: tuple[Path, ...] | str     #: resolved files, or STL text
    label: str                          #: the program as the test named it
    key: str                            #: coverage key (rootdir-relative paths)
    symbols: Any = None
    data: Any = None
    plant: Any = None
    scan_ms: float | None = None
    cpu: str | None = None
    watch: tuple[str, ...] = ()
    history: int | None = None
    max_time: float | None = None
    encoding: str | None = None         #: codec name, None to detect
    clock: Any = None                   #: the real-time clock's start (load's clock=)


_SESSION = pytest.StashKey[_Session]()
_USED = pytest.StashKey[list]()   # item -> [(spec, Harness), ...] in creation order


# ---------------------------------------------------------------------------
# Options
# ---------------------------------------------------------------------------

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
    group.addoption("--plc-backend", dest="plc_backend", choices=("python", "native"),
                    default=None,
                    help="code generator of the PLCs: python or native (machine code through "
                         "llvmlite; default: ini plc_backend, else $PLCRT_BACKEND, else python)")
    parser.addini("plc_backend", "PLC code generator: python or native (plcrt)", default=None)
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
    if backend not in (None, "python", "native"):
        raise pytest.UsageError(f"plc_backend must be python or native, got {backend!r:.40}")
    return _Session(rootpath=Path(config.rootpath), scan_ms=scan_ms, history=history,
                    max_time=max_time, coverage=coverage, coverage_report=report_path,
                    backend=backend)


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", MARKER_HELP)
    config.stash[_SESSION] = _session_from_config(config)


# ---------------------------------------------------------------------------
# Arguments -> spec
# ---------------------------------------------------------------------------

def _is_pathlike(x: Any) -> bool:
    return isinstance(x, (str, os.PathLike))


def _scan_us(scan_ms: Any, what: str, error: type[Exception]) -> None:
    """The scan time checked as :func:`plcrt.load` checks it, the message
    naming the option (the engine is imported only when one is given)."""
    from ..engine.values import scan_time_us
    from ..errors import PlcConfigError
    try:
        scan_time_us(scan_ms, what)
    except PlcConfigError as e:
        raise error(e.message) from None


def _resolve(value: Any, what: str, bases: list[Path]) -> Path:
    """A file named relative to the test's directory first, then the rootdir."""
    from ..errors import PlcConfigError
    from ..paths import check_path
    try:
        p = check_path(value, f"{what}=")
    except PlcConfigError as e:
        raise PlcUsageError(e.message) from None
    candidates = [p] if p.is_absolute() else [b / p for b in bases]
    for c in candidates:
        if c.is_file():
            return c.resolve()
    looked = ", ".join(str(c) for c in candidates)
    raise PlcUsageError(f"{what} file {os.fspath(value)!r} not found (looked for {looked})")


def _file_or_text(value: Any, what: str, bases: list[Path]) -> Any:
    """Strings with a newline are the file's text, as in Harness.load."""
    if value is None or (isinstance(value, str) and "\n" in value):
        return value
    if not _is_pathlike(value):
        raise PlcUsageError(f"{what}= must be a file path, got {type(value).__name__} "
                            f"{value!r}")
    return _resolve(value, what, bases)


def _display(p: Path, root: Path) -> str:
    try:
        return p.relative_to(root.resolve()).as_posix()
    except ValueError:
        return p.as_posix()


def _make_spec(args: tuple[Any, ...], kwargs: dict[str, Any], bases: list[Path],
               root: Path) -> _Spec:
    """Check the marker's or factory's arguments; raise PlcUsageError."""
    if len(args) != 1:
        raise PlcUsageError(
            f"expected one program (a path, or a list of paths) as the only positional "
            f"argument, got {len(args)} positional argument(s)")
    unknown = [k for k in kwargs if k not in OPTIONS]
    if unknown:
        hints = []
        for k in unknown:
            close = difflib.get_close_matches(k, OPTIONS, n=1)
            hints.append(f"{k!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
        raise PlcUsageError(f"unknown argument(s) {', '.join(hints)}; "
                            f"the options are {', '.join(OPTIONS)}")
    program = args[0]
    if isinstance(program, str) and "\n" in program:
        digest = hashlib.sha1(program.encode("utf-8")).hexdigest()[:10]
        prog: tuple[Path, ...] | str = program
        label, key = "<STL text>", f"<STL text {digest}>"
    else:
        items = list(program) if isinstance(program, (list, tuple)) else [program]
        if not items or not all(_is_pathlike(x) for x in items):
            raise PlcUsageError(f"the program must be a .awl path or a non-empty list of "
                                f"paths, got {program!r}")
        prog = tuple(_resolve(x, "program", bases) for x in items)
        label = " + ".join(os.fspath(x) for x in items)
        key = " + ".join(_display(p, root) for p in prog)
    spec = _Spec(prog, label, key)
    spec.symbols = _file_or_text(kwargs.get("symbols"), "symbols", bases)
    spec.data = _file_or_text(kwargs.get("data"), "data", bases)
    plant = kwargs.get("plant")
    spec.plant = plant if isinstance(plant, dict) else _file_or_text(plant, "plant", bases)
    scan_ms = kwargs.get("scan_ms")
    if scan_ms is not None:
        _scan_us(scan_ms, "scan_ms=", PlcUsageError)
        spec.scan_ms = float(scan_ms)
    cpu = kwargs.get("cpu")
    if cpu is not None and not isinstance(cpu, str):
        raise PlcUsageError(f"cpu= must be a CPU name such as 'CPU224', got {cpu!r}")
    spec.cpu = cpu
    watch = kwargs.get("watch", ())
    if isinstance(watch, str) or not isinstance(watch, (list, tuple)) or \
            not all(isinstance(a, str) for a in watch):
        raise PlcUsageError(f"watch= must be a list of addresses such as ['Q0.0', 'VW100'], "
                            f"got {watch!r}")
    spec.watch = tuple(watch)
    history = kwargs.get("history")
    if history is not None and (isinstance(history, bool) or not isinstance(history, int)
                                or history < 1):
        raise PlcUsageError(f"history= must be a whole number of scans >= 1, got {history!r}")
    spec.history = history
    max_time = kwargs.get("max_time")
    if max_time is not None:
        from ..errors import PlcConfigError
        from .harness import seconds
        try:
            spec.max_time = seconds(max_time)
        except PlcConfigError:
            raise PlcUsageError(f"max_time= must be a duration such as 60, '90s' or '5min', "
                                f"got {max_time!r}") from None
    encoding = kwargs.get("encoding")
    if encoding is not None:
        from ..errors import PlcConfigError
        from ..lang.encoding import resolve_encoding
        try:
            spec.encoding = resolve_encoding(encoding)
        except PlcConfigError as e:
            raise PlcUsageError(e.message) from None
    clock = kwargs.get("clock")
    if clock is not None:
        from ..engine.clock import start_time
        from ..errors import PlcConfigError
        try:
            spec.clock = start_time(clock, "clock=")
        except PlcConfigError as e:
            raise PlcUsageError(e.message) from None
    return spec


# ---------------------------------------------------------------------------
# Building harnesses
# ---------------------------------------------------------------------------

def _parsed(sess: _Session, spec: _Spec) -> tuple[Any, Any, Any]:
    """(program, symbols, data) of ``spec``, parsed once per session and
    version of the files.  The program files and the symbol and data files
    are decoded together, as :func:`plcrt.load` does; tables given as text
    are returned as they are."""
    from ..lang.sources import read_program
    assert not isinstance(spec.program, str)
    tables = [x if isinstance(x, Path) else None for x in (spec.symbols, spec.data)]
    key = (tuple((str(p), st.st_mtime_ns, st.st_size) for p, st in
                 ((p, p.stat()) for p in (*spec.program, *(t for t in tables if t)))),
           tuple(t is not None for t in tables), spec.encoding)
    parsed = sess.programs.get(key)
    if parsed is None:
        parsed = read_program(list(spec.program), *tables, encoding=spec.encoding)
        sess.programs[key] = parsed
    program, symbols, data = parsed
    return (program, symbols if tables[0] else spec.symbols,
            data if tables[1] else spec.data)


def _option_key(value: Any) -> Any:
    """A hashable stand-in for a marker option: a file by its name and
    version, anything else (text, a plant dict, a number) by its repr."""
    if isinstance(value, Path):
        st = value.stat()
        return ("file", str(value), st.st_mtime_ns, st.st_size)
    return ("value", repr(value))


def _pristine(sess: _Session, spec: _Spec, scan_ms: float) -> Plc:
    """The power-up PLC of ``spec``, loaded once per session and version of
    its files; every test gets a fork of it (its own memory, timers,
    devices and time, nothing shared)."""
    from .harness import Harness
    if isinstance(spec.program, str):
        program_key: Any = ("text", spec.program)
    else:
        program_key = tuple(_option_key(p) for p in spec.program)
    key = (program_key, _option_key(spec.symbols), _option_key(spec.data),
           _option_key(spec.plant), scan_ms, spec.cpu, sess.coverage, spec.encoding,
           _option_key(spec.clock), sess.backend)
    plc = sess.plcs.get(key)
    if plc is not None:
        sess.plcs.move_to_end(key)
        return plc
    if isinstance(spec.program, str):
        program, symbols, data = spec.program, spec.symbols, spec.data
    else:
        program, symbols, data = _parsed(sess, spec)
    plc = Harness.load(program, symbols=symbols, data=data, plant=spec.plant,
                       scan_ms=scan_ms, cpu=spec.cpu, instrument=sess.coverage,
                       encoding=spec.encoding, clock=spec.clock, backend=sess.backend).plc
    sess.plcs[key] = plc
    while len(sess.plcs) > PRISTINE_PLCS:
        sess.plcs.popitem(last=False)
    return plc


def _build(sess: _Session, spec: _Spec) -> Harness:
    """A harness for ``spec``; plcrt's own errors propagate (PlcError: a
    program without OB1 is a compile error), a bad ``watch`` address is a
    PlcUsageError."""
    from ..errors import PlcError
    from .harness import Harness
    scan_ms = spec.scan_ms if spec.scan_ms is not None else sess.scan_ms
    # perf: a twin of the session's power-up PLC (which no test touches),
    # not a new load per test
    h = Harness(_pristine(sess, spec, scan_ms)._twin_at_power_up(),
                history=spec.history if spec.history is not None else sess.history,
                max_time=spec.max_time if spec.max_time is not None else sess.max_time)
    for address in spec.watch:
        try:
            h.watch(address)
        except PlcError as e:
            raise PlcUsageError(f"watch {address!r}: {e.message}") from None
    h.name = spec.label
    return h


def _bases(node: pytest.Item, root: Path) -> list[Path]:
    base = Path(node.path).parent
    return [base] if base == root else [base, root]


def _track(node: pytest.Item, spec: _Spec, h: Harness) -> None:
    node.stash.setdefault(_USED, []).append((spec, h))


@pytest.fixture
def plc(request: pytest.FixtureRequest) -> Harness:
    """A fresh :class:`plcrt.testing.Harness` at power-up, loaded from the
    test's ``@pytest.mark.plc(...)`` marker (the closest one)."""
    node = request.node
    sess = request.config.stash[_SESSION]
    marker = node.get_closest_marker("plc")
    if marker is None:
        pytest.fail(f"{node.nodeid}: the `plc` fixture needs a @pytest.mark.plc(\"program.awl\", "
                    f"...) marker on the test, its class or its module (or use plc_factory)",
                    pytrace=False)
    from ..errors import PlcError
    problem = ""
    try:
        spec = _make_spec(tuple(marker.args), dict(marker.kwargs), _bases(node, sess.rootpath),
                          sess.rootpath)
    except PlcUsageError as e:
        problem = str(e)
    else:
        try:
            h = _build(sess, spec)
        except PlcUsageError as e:
            problem = str(e)
        except PlcError as e:
            problem = f"cannot load {spec.label}:\n{e}"
    if problem:
        # failed outside the except blocks, so pytest shows only the message
        # (no chained exception, no plcrt frames)
        pytest.fail(f"{node.nodeid}: @pytest.mark.plc: {problem}", pytrace=False)
    _track(node, spec, h)
    return h


@pytest.fixture
def plc_factory(request: pytest.FixtureRequest) -> Callable[..., Harness]:
    """``plc_factory("prog.awl", **options) -> Harness``: a fresh harness per
    call, with the marker's options (``symbols``, ``data``, ``plant``,
    ``scan_ms``, ``cpu``, ``watch``, ``history``, ``max_time``,
    ``encoding``).  Paths are relative to
    the test file, then the rootdir.  Every harness made is in the PLC
    trace and the coverage."""
    node = request.node
    sess = request.config.stash[_SESSION]
    bases = _bases(node, sess.rootpath)

    def factory(program: Any, **options: Any) -> Harness:
        __tracebackhide__ = True
        from ..errors import PlcConfigError, PlcError
        problem: BaseException
        try:
            spec = _make_spec((program,), options, bases, sess.rootpath)
            h = _build(sess, spec)
        except PlcUsageError as e:
            problem = PlcConfigError(f"plc_factory: {e}")
        except PlcError as e:
            problem = e
        else:
            _track(node, spec, h)
            return h
        # raised outside the except block, without plcrt's internal frames:
        # the test sees its own line and plcrt's message, and can still use
        # pytest.raises(plcrt.PlcCompileError) to expect a load error
        problem.__cause__ = None
        problem.__suppress_context__ = True
        raise problem.with_traceback(None)

    return factory


# ---------------------------------------------------------------------------
# The trace of a failing test
# ---------------------------------------------------------------------------

def _all_harnesses(used: list[tuple[_Spec, Harness]]) -> Iterator[tuple[str, _Spec, Harness]]:
    """Every harness of a test, with the forks made from them."""
    for spec, h in used:
        stack = [(h.name, h)]
        n = 0
        while stack:
            label, cur = stack.pop(0)
            yield label, spec, cur
            for child in getattr(cur, "forks", ()):
                n += 1
                stack.append((f"{h.name} (fork {n})", child))


def trace_text(used: list[tuple[Any, Harness]]) -> str:
    """The "PLC trace" text for the harnesses a test used."""
    parts = []
    for label, _, h in _all_harnesses(used):
        p = h.plc
        forced = ", ".join(f"{a}={v}" for a, v in p.forces.items()) or "none"
        lines = [f"program {label}",
                 f"  simulated time {h.time:.3f} s after {h.scans} scan(s) of "
                 f"{p.scan_us / 1000:g} ms, CPU mode {p.mode}",
                 f"  forced: {forced}"]
        if p.fault is not None:
            lines.append("  fault: " + str(p.fault).replace("\n", "\n    "))
        if h.watched:
            lines.append(f"  watched addresses, last {len(h.history)} scan(s) "
                         f"(values after each scan):")
        table = h.history_table()
        lines += ["    " + ln for ln in table.splitlines()]
        if not h.watched:
            lines[-1] += " - add watch=[...] to the marker or factory call for a history"
        parts.append("\n".join(lines))
    return "\n\n".join(parts)


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]
                              ) -> Iterator[None]:
    # tryfirst on a wrapper: outermost, so xfail has already been decided
    excinfo = call.excinfo
    if (call.when == "call" and excinfo is not None and item.stash.get(_USED, None)
            and not item.config.option.fulltrace):
        from .frames import drop_plcrt_frames, meant_for_the_test
        if meant_for_the_test(excinfo.value):
            # the test's line and plcrt's message, not plcrt's internals
            drop_plcrt_frames(excinfo.tb)
    report = yield
    if report.when == "call" and report.failed:
        used = item.stash.get(_USED, None)
        if used:
            try:
                text = trace_text(used)
            except Exception as e:  # noqa: BLE001 - never break pytest's reporting
                text = f"(no PLC trace: {type(e).__name__}: {e})"
            report.sections.append(("PLC trace", text))
            # pytest writes only captured stdout/stderr/log sections to the
            # JUnit XML; a property always reaches it (also through xdist)
            item.user_properties.append((JUNIT_PROPERTY, text))
            report.user_properties.append((JUNIT_PROPERTY, text))
    return report


# ---------------------------------------------------------------------------
# Coverage
# ---------------------------------------------------------------------------

@pytest.hookimpl(wrapper=True)
def pytest_runtest_teardown(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    try:
        return (yield)
    finally:
        used = item.stash.get(_USED, None)
        if used:
            sess = item.config.stash[_SESSION]
            if sess.coverage:
                from .coverage_report import entry_from_map, merge_entry
                for _, spec, h in _all_harnesses(used):
                    if h.coverage is not None:
                        merge_entry(sess.store, spec.key, entry_from_map(h.coverage))
            # items live until the session ends: do not keep compiled PLCs
            del item.stash[_USED]


def pytest_sessionfinish(session: pytest.Session) -> None:
    config = session.config
    sess = config.stash.get(_SESSION, None)
    if sess is None or not sess.coverage:
        return
    if hasattr(config, "workeroutput"):
        # an xdist worker: hand the coverage to the controller, which
        # merges it in pytest_testnodedown and reports once
        import json
        config.workeroutput[WORKEROUTPUT_KEY] = json.dumps(sess.store, allow_nan=False)
        return
    if sess.coverage_report is not None:
        import json
        from .coverage_report import to_json
        sess.coverage_report.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps(to_json(sess.store), indent=1, allow_nan=False)   # strict JSON
        sess.coverage_report.write_text(text + "\n", encoding="utf-8")


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node: Any, error: Any) -> None:
    """xdist controller: merge the coverage a worker sent (if any)."""
    sess = node.config.stash.get(_SESSION, None)
    output = getattr(node, "workeroutput", None) or {}
    raw = output.get(WORKEROUTPUT_KEY)
    if sess is None or not raw:
        return
    import json
    from .coverage_report import merge_store
    merge_store(sess.store, json.loads(raw))


def pytest_terminal_summary(terminalreporter: Any, exitstatus: int,
                            config: pytest.Config) -> None:
    sess = config.stash.get(_SESSION, None)
    if sess is None or not sess.coverage or hasattr(config, "workerinput"):
        return
    from .coverage_report import report_lines
    terminalreporter.write_sep("=", "plcrt coverage")
    for line in report_lines(sess.store):
        terminalreporter.write_line(line)
    if sess.coverage_report is not None:
        terminalreporter.write_line(f"coverage JSON written to {sess.coverage_report}")


__all__ = ["JUNIT_PROPERTY", "OPTIONS", "PlcUsageError", "plc", "plc_factory", "trace_text"]
