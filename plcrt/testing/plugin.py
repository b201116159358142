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

This module is the entry point and holds the fixtures and how they build
harnesses (one parse per program and one power-up PLC per program and
options each session, a fork of it per test); the hooks come from the
modules of the plugin's other parts, imported here so that pytest finds
them: :mod:`~plcrt.testing.options` (options, ini keys, the session),
:mod:`~plcrt.testing.markers` (the marker's arguments),
:mod:`~plcrt.testing.failures` (the report on a failing test) and
:mod:`~plcrt.testing.coverage_hooks` (the coverage of the session).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import pytest

# the hooks of the plugin's parts: pytest finds them in this module
from .coverage_hooks import (WORKEROUTPUT_KEY, pytest_runtest_teardown,  # noqa: F401
                             pytest_sessionfinish, pytest_terminal_summary,
                             pytest_testnodedown)
from .failures import JUNIT_PROPERTY, pytest_runtest_makereport, trace_text  # noqa: F401
from .markers import OPTIONS, PlcUsageError, _make_spec, _Spec
from .options import (DEFAULT_HISTORY, DEFAULT_SCAN_MS, _SESSION, _USED,  # noqa: F401
                      _Session, pytest_addoption, pytest_configure)

if TYPE_CHECKING:
    from ..engine.runtime import Plc
    from .harness import Harness

#: power-up PLCs the plugin keeps per session (one per program and options)
PRISTINE_PLCS = 32


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


__all__ = ["JUNIT_PROPERTY", "OPTIONS", "PlcUsageError", "plc", "plc_factory", "trace_text"]
