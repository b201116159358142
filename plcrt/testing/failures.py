"""The report on a failing test that used a harness.

What it is: the "PLC trace" section pytest shows under a failing test
(:func:`trace_text`: for each harness the test used, and each fork of one,
the simulated time, CPU mode, forces, fault and the watched addresses over
the last scans), the same text as the ``plc_trace`` JUnit property, and the
traceback without plcrt's own frames (:mod:`plcrt.testing.frames`) for an
error plcrt means for the test.  What it is not: the harness's own failure
messages (:mod:`plcrt.testing.harness`), which it leaves as they are.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Iterator

import pytest

from .options import _USED

if TYPE_CHECKING:
    from .harness import Harness
    from .markers import _Spec

#: name of the JUnit XML property that carries the trace of a failing test
JUNIT_PROPERTY = "plc_trace"


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


__all__ = ["JUNIT_PROPERTY", "trace_text"]
