"""Motion in the test harness: EM253 axes, bus drives, and waiting for moves.

What it is: the methods of :class:`plcrt.testing.Harness` that read the
simulated motion devices (:meth:`~Motion.axis`, :meth:`~Motion.drive`,
:meth:`~Motion.module`) and wait for an axis to start, to stop, or to end
its move within a time (:meth:`~Motion.axis_done_within`).  What it is not:
the devices (:mod:`plcrt.devices`), nor the harness's waiting and failure
messages, which it calls (:mod:`plcrt.testing.harness` combines this mixin
with them).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ..devices import AxisState, DriveState
from ..engine.values import Duration
from ..engine.values import duration as parse_duration

if TYPE_CHECKING:
    from ..engine.runtime import Plc


class Motion:
    """Axes and drives of the PLC's plant, and waiting for moves (a mixin of
    :class:`plcrt.testing.Harness`)."""

    plc: Plc
    # provided by the harness (plcrt.testing.harness)
    run_until: Callable[..., float]
    _scans_for: Callable[..., int]
    _timeout: Callable[..., None]

    def axis(self, slot: int = 0, axis: int = 0) -> AxisState:
        """State of one EM253 axis (needs a plant): ``a.position`` or
        ``a["position"]``, as :meth:`Plc.axis`."""
        return self.plc.axis(slot, axis)

    def axes(self) -> list[AxisState]:
        """State of every configured axis."""
        return self.plc.axes()

    def module(self, slot: int) -> Any:
        """The simulated module in expansion slot ``slot``, or None."""
        return self.plc.module(slot)

    def machine(self, name: str) -> Any:
        """The plant's machine *name* (``[machine.NAME]``): ``state()``,
        ``fault("jam")``, ``press("call_2")`` ..., as :meth:`Plc.machine`."""
        return self.plc.machine(name)

    def machines(self) -> list[Any]:
        """Every machine of the plant."""
        return self.plc.machines()

    def drive(self, node: int, slot: int | None = None) -> DriveState:
        """State of the bus drive at *node* (needs a plant with a FIELDBUS
        module): ``d.position``, ``d.statusword``, ``d.state``, ``d.flags``,
        as :meth:`Plc.drive`."""
        return self.plc.drive(node, slot)

    def drives(self) -> list[DriveState]:
        """State of every bus drive."""
        return self.plc.drives()

    def wait_axis_moving(self, slot: int = 0, axis: int = 0, *,
                         timeout: Duration = 1.0) -> float:
        """Run until the axis moves; seconds it took."""
        __tracebackhide__ = True  # pytest: report the test's line, not ours
        parse_duration(timeout)   # a bad timeout, then a bad axis, before any message
        self.axis(slot, axis)

        def moving() -> bool:
            return self.axis(slot, axis).moving

        moving.__name__ = f"axis {slot}.{axis} is moving"   # as messages name it
        return self.run_until(moving, timeout=timeout, message=f"axis {slot}.{axis} did not start")

    def wait_axis_stopped(self, slot: int = 0, axis: int = 0, *,
                          timeout: Duration = 60.0) -> float:
        """Run until the axis stands still; seconds it took."""
        __tracebackhide__ = True  # pytest: report the test's line, not ours
        parse_duration(timeout)   # a bad timeout, then a bad axis, before any message
        self.axis(slot, axis)

        def stopped() -> bool:
            return not self.axis(slot, axis).moving

        stopped.__name__ = f"axis {slot}.{axis} stands still"   # as messages name it
        return self.run_until(stopped, timeout=timeout, message=f"axis {slot}.{axis} did not stop")

    def axis_done_within(self, limit: Duration, slot: int = 0, axis: int = 0) -> float:
        """Assert a move that is running (or about to start within a few
        scans) ends within ``limit`` simulated seconds; returns the seconds
        until the axis stood still.  One more scan follows, so the outputs of
        the block that commanded the move (its Done, C_Status, C_Pos) are
        current when this returns."""
        __tracebackhide__ = True  # pytest: report the test's line, not ours
        total = parse_duration(limit)   # a bad limit is reported before anything runs
        moving = self.axis(slot, axis).moving   # a bad axis, before any message
        plc = self.plc
        t0 = plc.now_us
        who = f"axis {slot}.{axis}"
        expected = f"expected the move of {who} to be done within {total:g} s"
        signals = [f"axis{slot}.{axis}.position", f"axis{slot}.{axis}.speed"]
        if not moving:
            start = min(total, 1.0)
            for _ in range(self._scans_for(start)):
                plc.scan(1)
                self._axis_running(expected, signals)
                if self.axis(slot, axis).moving:
                    break
            else:
                self._timeout(f"{expected}; the axis did not start moving within {start:g} s",
                              "", shown=signals)
        for _ in range(self._scans_for(total - (plc.now_us - t0) / 1e6)):
            plc.scan(1)
            self._axis_running(expected, signals)
            if not self.axis(slot, axis).moving:
                took = (plc.now_us - t0) / 1e6
                plc.scan(1)     # the block sees the axis stopped and reports it
                return took
        self._timeout(f"{expected}; it was still moving {(plc.now_us - t0) / 1e6:g} s later",
                      "", shown=signals)
        raise AssertionError  # pragma: no cover - _timeout raises

    def _axis_running(self, expected: str, signals: list[str]) -> None:
        __tracebackhide__ = True  # pytest: report the test's line, not ours
        if self.plc.mode != "RUN":
            self._timeout(f"{expected}; the CPU went to STOP", "", shown=signals)


__all__ = ["Motion"]
