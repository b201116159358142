"""Forks, snapshots and recompiled twins of a PLC: copying its state.

What it is: :class:`Forking`, a mixin of :class:`plcrt.engine.runtime.Plc`:
:meth:`~Forking.fork` (a twin of the same compiled program),
:meth:`~Forking.snapshot` / :meth:`~Forking.restore`,
:meth:`~Forking.recompiled` (the same state under other probes or another
backend), and the state copy they share: memory buffers in place, every
other stateful object deep-copied in one pass with a memo that maps each
object to its twin's.

What it is not: building the twin (``Plc.__init__`` with the compiled
program, :mod:`.binding`).
"""

from __future__ import annotations

import copy
import types
from typing import Any, Self

from ..errors import PlcConfigError
from .values import check_backend

__all__ = ["Forking"]


class Forking:
    """Forks and snapshots (a mixin of :class:`plcrt.engine.runtime.Plc`)."""

    def fork(self) -> Self:
        """An independent twin in exactly this state (memory, timers,
        counters, edges, library blocks, devices, time, forces); running one
        never affects the other."""
        # the same compiled program (never compiled again, cached or not)
        twin = type(self)(self.program, **self._config, _entry=self._entry,
                          _parts=self._parts)
        self._copy_state(twin)
        return twin

    def _twin_at_power_up(self) -> Self:
        """:meth:`fork` of a PLC that has not been touched since its load
        (the pytest plugin's power-up PLCs, which no test sees): a new PLC
        of the same compiled program with this one's memory (the data
        block).  Everything else already is as the load left it, so nothing
        needs deep-copying (perf: a fraction of a fork's time)."""
        twin = type(self)(self.program, **self._config, _entry=self._entry,
                          _parts=self._parts)
        dareas = twin.mem.areas
        for k, buf in self.mem.areas.items():
            dareas[k][:] = buf
        return twin

    def snapshot(self) -> Self:
        """The current state, to :meth:`restore` later (a stopped twin)."""
        return self.fork()

    def restore(self, snapshot: Self) -> None:
        """Go back to a state taken with :meth:`snapshot` of this PLC or of
        a fork of it (the same program object, compiled the same way).

        Raises:
            PlcConfigError: ``snapshot`` is not a snapshot, or it was taken
                from a different program, or from the same parsed program
                compiled with other options (symbols, CPU, plant, probes), or this
                PLC is linked to others (plcrt.link).
        """
        if not isinstance(snapshot, Forking):
            raise PlcConfigError(f"restore() needs a snapshot made by snapshot(), got "
                                 f"{type(snapshot).__name__}")
        if snapshot.program is not self.program:
            raise PlcConfigError("this snapshot was taken from a different program")
        if self.network is not None:
            raise PlcConfigError("this PLC is linked to others (plcrt.link): going back in time "
                                 "would break what they exchanged; restore before linking, or "
                                 "fork and restore the unlinked twin")
        if (not _same_build(snapshot, self) or snapshot.model != self.model
                or len(snapshot.devices) != len(self.devices)
                or (snapshot.coverage is None) != (self.coverage is None)):
            raise PlcConfigError("this snapshot was taken from the same program compiled "
                                 "with other options (symbols, CPU, plant or instrumentation); "
                                 "restore it into a PLC loaded the same way")
        snapshot._copy_state(self)

    def recompiled(self, *, instrument: bool | None = None,
                   backend: str | None = None) -> Self:
        """This PLC's program compiled with other probes or another code
        generator, in exactly this PLC's state (memory, timers, counters,
        edges, library blocks, devices, time, forces), as :meth:`fork` gives
        a twin compiled the same way.  The coverage counts start empty.

        A tool that shows breakpoints only now and then runs the fast
        build (no probes, the native backend) and moves to an instrumented
        one while a breakpoint is set, without losing a scan.

        Raises:
            PlcConfigError: a bad ``backend``, or ``native`` without llvmlite.
        """
        cfg = dict(self._config)
        if instrument is not None:
            if not isinstance(instrument, bool):
                raise PlcConfigError(f"instrument must be True, False or None, got "
                                     f"{type(instrument).__name__}")
            cfg["instrument"] = instrument
        if backend is not None:
            cfg["backend"] = check_backend(backend)
        if cfg == self._config:
            return self.fork()
        twin = type(self)(self.program, **cfg, _parts=self._parts)
        self._copy_state(twin, across=True)
        return twin

    def _copy_state(self, dst: Self, across: bool = False) -> None:
        """Make ``dst`` (the same program, compiled the same way) equal to self.

        Everything stateful is either a memory buffer (copied in place) or a
        Python object bound into the generated code or held by the engine
        (timer and counter banks, library blocks, devices); those are deep-
        copied in one pass with a memo that maps each of our objects to its
        twin, so references between them (a block's axis, an axis's
        end-of-move handler) land on the twin's objects.
        """
        areas, dareas = self.mem.areas, dst.mem.areas
        memo: dict[int, Any] = {id(self): dst, id(self.mem): dst.mem}
        for k, buf in areas.items():
            dareas[k][:] = buf
            memo[id(buf)] = dareas[k]
        pairs: list[tuple[Any, Any]] = [(self.timers, dst.timers),
                                        (self.counters, dst.counters),
                                        (self.interrupts, dst.interrupts),
                                        *zip(self.pulse, dst.pulse),
                                        (self.pid, dst.pid),
                                        (self.edges, dst.edges),
                                        (self.clock, dst.clock), (self.station, dst.station),
                                        *zip(self.hsc, dst.hsc),
                                        *zip(self.ports, dst.ports),
                                        (self.ethernet, dst.ethernet)]
        pairs += list(zip(self.devices, dst.devices))
        constants = self.unit.constants   # shared, read-only: nothing to copy
        for name, obj, other in (_binding_pairs(self, dst) if across else
                                 ((n, o, dst._bindings.get(n))
                                  for n, o in self._bindings.items() if n not in constants)):
            if other is None or type(other) is not type(obj):
                raise PlcConfigError("internal error: the twin was compiled differently")
            if isinstance(obj, bytearray):
                other[:] = obj
                memo[id(obj)] = other
            elif isinstance(obj, list) and all(isinstance(b, bytearray) for b in obj):
                for mine, theirs in zip(obj, other):   # L buffers per nesting level
                    theirs[:] = mine
                    memo[id(mine)] = theirs
            elif isinstance(obj, (types.FunctionType, types.MethodType,
                                  types.BuiltinFunctionType)):
                continue   # code and bound methods of the banks: no own state
            elif hasattr(obj, "__dict__"):
                pairs.append((obj, other))   # library blocks
            else:
                raise PlcConfigError(f"internal error: cannot copy the state of "
                                     f"{type(obj).__name__}")
        for a, b in pairs:
            memo[id(a)] = b
        # a twin is not linked: what links other CPUs stays here
        if self.network is not None:
            memo[id(self.network)] = None
            for port in self.ports:
                if port.peer is not None and hasattr(port.peer, "other"):
                    memo[id(port.peer)] = None
        states = copy.deepcopy([a.__dict__ for a, _ in pairs], memo)
        for (_, b), state in zip(pairs, states):
            b.__dict__.clear()
            b.__dict__.update(state)
        dst.modules = {d.slot: d for d in dst.devices if d.slot is not None}
        if dst._native is not None:
            # the timer bank's arrays were replaced by copies: point the
            # native segments at them
            dst._native.point(dst._native_buffers())
        dst._int_l[:] = self._int_l
        dst._counted[:] = [dst.hsc[c.number] for c in self._counted]   # HDEF order
        dst._defined[:] = [dst.hsc[c.number] for c in self._defined]
        for port in (*dst.ports, dst.ethernet):
            port.drop_links()
        # the sources that joined the time line, in the order they joined
        twin = {id(c): dst.hsc[c.number] for c in self._counted}
        twin.update({id(p): dst.ports[p.number] for p in self.ports})
        twin[id(self.ethernet)] = dst.ethernet
        dst.scheduler.reset([dst.interrupts, dst.edges, *dst.pulse,
                             *(twin[id(s)] for s in self.scheduler.sources[4:])])
        for name in ("scans", "_t_us", "_prev_start", "mode", "fault", "stop_requested",
                     "_entered_run", "_permanent", "_sm0_lost",
                     "_irq_t", "_pi0", "_sources_on"):
            setattr(dst, name, getattr(self, name))
        dst._calm_hi = 0   # its timer bank and scan count are ours now
        dst._warned = set(self._warned)
        dst.diagnostics = list(self.diagnostics)
        dst.wd[:] = self.wd
        dst.forces = {}
        dst._force_slots = []
        for key, value in self.forces.items():
            dst.force(key, value)
        dst._replain()


def _same_build(a: Any, b: Any) -> bool:
    """Whether PLCs ``a`` and ``b`` run one compiled program, or the two
    builds of one ``backend="auto"`` load (engine/tiering.py: they bind the
    same state under the same names)."""
    if a._entry.source == b._entry.source:
        return True
    if a._config["backend"] != "auto" or b._config["backend"] != "auto":
        return False
    def rest(plc: Any) -> dict[str, Any]:
        return {k: v for k, v in plc._entry.options.items() if k != "backend"}
    return rest(a) == rest(b)


def _binding_pairs(src: Any, dst: Any) -> list[tuple[str, Any, Any]]:
    """(name, object, twin's object) for every stateful binding of ``src``,
    matched with ``dst``, a build of the same program with other probes or
    another backend.

    Names are numbered in the order the code generator bound its objects,
    and probes take numbers of their own, so the k-th binding of a kind
    (``_EM``, ``_blk``, ...) in one build is the k-th of that kind in the
    other.  The probes' own buffers and methods have no twin: skipped.
    """
    def stateful(plc: Any) -> dict[str, list[tuple[int, str, Any]]]:
        cov = plc.coverage
        own = () if cov is None else (cov.hits, cov.power, cov.closed, cov.breakpoints)
        kinds: dict[str, list[tuple[int, str, Any]]] = {}
        for name, obj in plc._bindings.items():
            if isinstance(obj, (types.FunctionType, types.MethodType,
                                types.BuiltinFunctionType)) or any(obj is b for b in own) \
                    or name in plc.unit.constants:
                continue
            kind = name.rstrip("0123456789")
            kinds.setdefault(kind, []).append((int(name[len(kind):] or 0), name, obj))
        return kinds

    mine, theirs = stateful(src), stateful(dst)
    pairs = []
    for kind, objs in mine.items():
        others = sorted(theirs.get(kind, []))
        if len(others) != len(objs):
            raise PlcConfigError("internal error: the two builds bind different state")
        for (_, name, obj), (_, _, other) in zip(sorted(objs), others):
            if getattr(obj, "loc", None) != getattr(other, "loc", None):
                raise PlcConfigError("internal error: the two builds bind different state")
            pairs.append((name, obj, other))
    return pairs
