"""Network, rung-output and contact coverage of a pytest session.

What it is: the plugin's hooks that collect the coverage of every
instrumented harness when its test ends (``--plc-coverage``), hand a
pytest-xdist worker's results to the controller, which merges them, and
print the report (and write the JSON of ``--plc-coverage-report``) once at
the end.  What it is not: the coverage data and its merging and report
lines (:mod:`plcrt.testing.coverage_report`, no pytest), nor the probes
(:mod:`plcrt.engine.coverage`).
"""

from __future__ import annotations

from typing import Any, Iterator

import pytest

from .failures import _all_harnesses
from .options import _SESSION, _USED

#: key of the coverage data in an xdist worker's ``workeroutput``
WORKEROUTPUT_KEY = "plcrt_coverage"


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


__all__ = ["WORKEROUTPUT_KEY"]
