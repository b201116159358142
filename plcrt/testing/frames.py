"""Failure tracebacks of PLC tests without plcrt's own frames.

What it is: the filter the pytest plugin applies to the exception of a
failing test that used a harness, before pytest formats it.  An error
plcrt means for the test engineer (a :class:`~plcrt.errors.PlcError`: a
mistyped symbol, a bad value; or an ``AssertionError``: a timeout, a
``max_time`` limit, a condition that did not stay true) is about the test's
own line, so the frames inside plcrt (the harness, the engine, the
generated scan code) are unlinked from the traceback and pytest shows the
test's code and the message.  The test's own frames stay, also those of a
condition function plcrt called.

What it is not: a filter of other exceptions.  A ``TypeError`` or any other
unexpected exception from plcrt keeps every frame (it is a bug to report,
with its traceback), and ``pytest --full-trace`` shows every frame always.
"""

from __future__ import annotations

import os
from pathlib import Path
from types import TracebackType

from ..errors import PlcError

#: source files under this directory are plcrt's own
PACKAGE_DIR = str(Path(__file__).resolve().parents[1]) + os.sep
#: file name prefix of the generated scan code (plcrt.engine.runtime)
GENERATED = "<plcrt "


def meant_for_the_test(exc: BaseException | None) -> bool:
    """Whether *exc* is one of the errors plcrt raises for the test engineer."""
    return isinstance(exc, (PlcError, AssertionError))


def is_plcrt_frame(tb: TracebackType) -> bool:
    name = tb.tb_frame.f_code.co_filename
    return name.startswith(PACKAGE_DIR) or name.startswith(GENERATED)


def drop_plcrt_frames(tb: TracebackType | None) -> None:
    """Unlink plcrt's frames from the traceback chain *tb*, in place.

    Frames before the first frame that is not plcrt's (the plugin's own
    hook) stay: pytest cuts the chain at the test function anyway.
    """
    node = tb
    while node is not None and is_plcrt_frame(node):
        node = node.tb_next
    while node is not None:
        nxt = node.tb_next
        while nxt is not None and is_plcrt_frame(nxt):
            nxt = nxt.tb_next
        node.tb_next = nxt
        node = nxt


__all__ = ["drop_plcrt_frames", "meant_for_the_test"]
