"""Tiered loading: ``backend="auto"`` runs Python at once, machine code when ready.

What it is: :class:`Tiering`, a mixin of :class:`plcrt.engine.runtime.Plc`.
A PLC loaded with ``backend="auto"`` where the native backend works is
bound first to the Python build of its program (as fast to load as
``backend="python"``).  Once it has spent some wall time scanning (about
twice its load's compile time, at least :data:`START_AFTER_S`), or at once
when a run of known length would outlast that (:data:`PLAN_FACTOR`), the
native build is compiled in a background thread (one job per Python build,
shared by its forks), and the PLC switches to it at the next scan boundary
after the job is done.  The job leaves the machine code on disk with a
mark of the program (:mod:`plcrt.compiler.tiermarks`), so that a later
load of it, in any process, binds the native build at once
(:mod:`.binding`): no tier at all.

Both builds bind the same objects under the same names
(the code generator numbers them in one order), so the switch keeps this
PLC's resolved bindings -- edge memories, L buffers, library blocks -- and
only executes the native build's code objects in a new namespace over
them: memory, timers, devices and coverage tables are untouched, and the
memory image after every scan is the same whenever the switch happens.

The worker threads are daemons; at interpreter exit a job that has started
is waited for (machine code generation must not run while the process
tears down its libraries), and no new job starts.

What it is not: the compiler (:mod:`plcrt.compiler.program`) or the scan
loop (:mod:`.scan`, which calls :meth:`Tiering._tiered_scan`).
"""

from __future__ import annotations

import atexit
import gc
import logging
import sys
import threading
import time
import weakref
from concurrent.futures import Future
from typing import Any, Callable

from ..compiler.cache import programs, release_free_memory

__all__ = ["Tiering", "LLVM_START_S", "LOAD_FACTOR", "PLAN_FACTOR", "START_AFTER_S"]

#: the least wall time a PLC scans in Python before its native build starts
#: compiling: a short run (a test, ``plcrt run`` of a few seconds of
#: simulated time) never pays for machine code it would not use
START_AFTER_S = 0.05
#: ... and at least what the native compile is expected to take: this many
#: times the seconds its load spent compiling, plus :data:`LLVM_START_S`
#: where LLVM is not loaded yet.  Measured on 2026-12-05 (wall time of the
#: compile thread while the PLC scans beside it, load average 3-5): 7-9
#: times the Python build's for the 1000-statement programs of
#: bench/run.py, 22 times for the corpus file roundtrip.awl
LOAD_FACTOR = 6.0
#: loading LLVM's library in the compile thread (about 30 ms of CPU, twice
#: that in wall time beside a scanning PLC; the programs/timers.awl job:
#: 0.1 s for a 4 ms load)
LLVM_START_S = 0.08
#: scans between two looks at the background job (a look is a clock read)
CHUNK_SCANS = 64
#: statements from which the switch frees the Python build at once (below,
#: the collector's next run does, and the few pages are not worth a pause)
RELEASE_STATEMENTS = 5000
#: a run whose length is known (``scan(n)``, ``run()``, ``plcrt run``)
#: starts the compile at once, without waiting, when its first scans say
#: that the rest of it would take at least this many times the wait in
#: Python: the machine code is then ready well before the end and runs
#: most of the run.  A run that says it is the last thing the PLC does
#: (``plcrt run``) compiles only then: a compile that could not pay within
#: the run would only cost it time
PLAN_FACTOR = 4.0

_log = logging.getLogger("plcrt")
#: the Python build -> the job compiling its native twin
_jobs: "weakref.WeakKeyDictionary[Any, Future[Any]]" = weakref.WeakKeyDictionary()
_lock = threading.Lock()
_running: set[threading.Thread] = set()
_closing = False


def _start(key: Any, make: Callable[[], Any]) -> "Future[Any]":
    """The job compiling ``key``'s native build with ``make`` (started now,
    or the one already started for it)."""
    with _lock:
        fut = _jobs.get(key)
        if fut is None:
            fut = Future()
            _jobs[key] = fut
            if _closing:
                fut.cancel()
                return fut
            thread = threading.Thread(target=_work, args=(fut, make), daemon=True,
                                      name="plcrt-native-compile")
            _running.add(thread)
            thread.start()
    return fut


def _work(fut: "Future[Any]", make: Callable[[], Any]) -> None:
    try:
        fut.set_result(make())
    except BaseException as e:  # noqa: BLE001 - reported where the PLC looks at it
        fut.set_exception(e)
    finally:
        with _lock:
            _running.discard(threading.current_thread())


@atexit.register
def _at_exit() -> None:
    """No new job; wait for the ones under way (LLVM must not be compiling
    while the process unloads it)."""
    global _closing
    with _lock:
        _closing = True
        threads = list(_running)
    for thread in threads:
        thread.join()


class _Tier:
    """A tiered PLC's state while it runs its Python build."""

    __slots__ = ("key", "make", "start_after", "busy", "future", "first", "planned", "final")

    def __init__(self, key: Any, make: Callable[[], Any], start_after: float,
                 first: int) -> None:
        self.key = key
        self.make = make
        self.start_after = start_after
        self.busy = 0.0                     #: wall seconds scanned in Python
        self.first = first                  #: the scan count when the tier began
        self.planned = first                #: the scan count the caller asked to reach
        self.final = False                  #: the planned run is the PLC's last
        self.future: Future[Any] | None = _jobs.get(key)   # a fork's parent's job


class Tiering:
    """Python first, native when ready (a mixin of :class:`plcrt.engine.runtime.Plc`)."""

    _tier: _Tier | None = None
    #: scans run in Python before the switch (None: never tiered)
    _python_scans: int | None = None

    def _tier_begin(self, make: Callable[[], Any], load_s: float) -> None:
        """Run the Python build now; ``make()`` compiles the native build."""
        # perf: read at the PLC's load, so a test may set them to 0
        llvm = LLVM_START_S if "llvmlite.binding" not in sys.modules else 0.0
        self._tier = _Tier(self._entry, make,
                           max(START_AFTER_S, LOAD_FACTOR * load_s + llvm), self.scans)
        self._python_scans = self.scans

    def _tiered_scan(self, n: int) -> None:
        """``scan(n)`` of a PLC on its Python build: in chunks, looking at
        the native job between them and switching when it is done."""
        clock = time.perf_counter
        self._tier_plan(n)
        while n > 0:
            tier = self._tier
            if tier is None:
                self.scan(n)
                return
            self._tier_poll(tier)
            if self._tier is None:
                continue
            k = min(n, CHUNK_SCANS)
            self._tier = None        # scan() below runs the plain loop
            t0 = clock()
            try:
                self.scan(k)
            finally:
                tier.busy += clock() - t0
                self._tier = tier
                self._python_scans = self.scans
            if self.mode != "RUN":    # scan() ends early only here (an observer
                return                # may restore a snapshot: scans go back)
            n -= k

    def _tier_plan(self, scans: int, final: bool = False) -> None:
        """The caller will run ``scans`` more scans (``plcrt run`` says its
        whole run before running it in chunks, ``final``: nothing follows
        it in this PLC's life): see :data:`PLAN_FACTOR`."""
        tier = self._tier
        if tier is not None:
            tier.planned = max(tier.planned, self.scans + scans)
            tier.final = tier.final or final

    def _tier_poll(self, tier: _Tier) -> None:
        if tier.future is None:
            if not (self._tier_pays(tier) or (tier.busy >= tier.start_after
                                              and not tier.final)):
                return
            tier.future = _start(tier.key, tier.make)
        if tier.future.done():
            self._tier_switch(tier)

    def _tier_pays(self, tier: _Tier) -> bool:
        """Whether the planned rest of the run, at the rate of the scans run
        in Python so far, takes :data:`PLAN_FACTOR` times the wait."""
        done = self.scans - tier.first
        if done <= 0 or tier.busy <= 0.0:
            return False
        rest = tier.planned - self.scans
        return tier.busy / done * rest >= PLAN_FACTOR * tier.start_after

    def _tier_up(self) -> None:
        """Compile the native build now (or wait for the job under way) and
        switch to it before the next scan; nothing when this PLC is not on
        the Python tier of ``backend="auto"``.  The memory image is the same
        as without the switch (a test pins this at several scans)."""
        tier = self._tier
        if tier is None:
            return
        if tier.future is None:
            tier.future = _start(tier.key, tier.make)
        try:
            tier.future.exception()      # waits for the job
        except BaseException:  # noqa: BLE001 - a cancelled job: stay on Python
            pass
        self._tier_switch(tier)

    def _tier_switch(self, tier: _Tier) -> None:
        """Bind the native build of ``tier``'s finished job over this PLC's
        objects (scan boundary)."""
        self._tier = None
        future, tier.key = tier.future, None    # the Python build: see below
        assert future is not None
        try:
            native = future.result(timeout=0)
        except BaseException as e:  # noqa: BLE001 - stay on Python, say why once
            _log.warning("plcrt: the native build could not be made (%s); this PLC keeps "
                         "running on the Python backend", type(e).__name__)
            return
        if native is not None:       # None: LLVM does not work here (said once)
            python = self._entry
            self._rebind(native)
            # the next load of this program finds the native build first:
            # the Python one is kept only by the PLCs still running it
            programs.drop(python)
            del python
            if self.program.instruction_count() >= RELEASE_STATEMENTS:
                # perf: the Python build's namespace is a cycle (its functions
                # hold it): collect it now and hand its C heap pages back
                # (about 20 MiB at 100 000 statements), not at the
                # collector's next full run
                gc.collect()
                release_free_memory()
