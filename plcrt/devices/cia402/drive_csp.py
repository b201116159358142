"""The steady CSP bus cycle of a simulated CiA 402 drive, written out.

What it is: :class:`CspCycle`, the part of :class:`~.drive.Drive` that runs
the bus cycle of a drive following CSP set-points (6060h = 8) in one
function when nothing but the set-point can change what the cycle does
(:meth:`CspCycle._csp_fast`: what :meth:`Drive._step` does -- advance,
received objects, the mode's cycle, publish -- for that case), and the two
steps of a CANopen SYNC for a caller that holds the store's lock
(:meth:`CspCycle.hold_locked`: the objects at the SYNC, held for its TPDOs;
the cycle itself is :meth:`~.drive_io.ProcessData.exchange_locked`).  Each
shortcut gives the values, log and store the general path gives
(``tests/devices/cia402/test_bus_cycle.py`` runs both on the same sessions).

What it is not: the general cycle (:mod:`.drive`, :mod:`.drive_time`,
:mod:`.drive_io`), which every other case takes.  It is a base class of
:class:`~.drive.Drive` and works on a drive's attributes.
"""

from __future__ import annotations

from typing import Optional

from ..motion import US
from .axis import LinLeg
from .drive_io import (CW, I32_HIGH, I32_LOW, MISSING, MOTION_KEYS, OE, _B8, _B10, _B12, _B13,
                       _ESM_OP, _HOOK_INDEXES, _K60B8, _PLAIN_PLANT, DriveFields)
from .modes import CyclicPosition
from .plant import DrivePlant
from .store import key

__all__ = ["CspCycle"]

#: Objects the CSP cycle reads besides 607Ah (HCFA §7.5.1): a received one
#: that changes takes the general cycle.
_CSP_READS = frozenset({(0x6065, 0), (0x6066, 0), (0x6080, 0), (0x1C32, 2)})
_K6065, _K607A, _K6080 = key(0x6065, 0), key(0x607A, 0), key(0x6080, 0)
_K6062, _K6064, _K606C, _K60F4, _K6063, _K606B = MOTION_KEYS


class CspCycle(DriveFields):
    """The steady CSP cycle of a :class:`~.drive.Drive` (see the module docstring)."""

    # the drive's attributes it reads besides DriveFields'
    _published: tuple
    _plain_motion: bool
    _batch: bool
    _qs_wait: bool
    _motion_out: dict[tuple[int, int], int]

    def hold_locked(self, t: int) -> None:
        """``advance(t, hold=True)`` for a caller that holds the store's
        lock (a CANopen port at a SYNC): the drive's own objects at *t* held
        in :attr:`deferred` (:meth:`~.drive.Drive.publish_deferred`)."""
        # perf: no second acquisition of the lock; a CSP line that ends by t
        # (the steady cycle: each line spans one bus cycle) read at its end,
        # as _outputs reads it, without _eventless, publish_deferred and
        # _outputs in between
        ax, sm, plant = self.axis, self.sm, self.plant
        line = ax._line
        if (line is not None and t >= line.t1 and t >= self.now and not self._batch
                and not self._qs_wait and sm.state is OE and self.mode_number == 8
                and self.stops is None and plant.pos_limit is None and plant.neg_limit is None
                and ax.bounds is None):
            csp = self.engines[8]
            if csp.__class__ is CyclicPosition:
                self.now = t
                sm._mode_bits = ((_B8 if csp.limit_stop else 0) | _B12 | _B10
                                 | (_B13 if csp._fe_since is not None else 0))
                mech = line.x1
                pos = mech + ax.shift
                if self.probe.function or self._live.get(_K60B8):
                    self._probe_update(t, mech)            # touch probe armed (drive_service.py)
                inputs = 0 if _PLAIN_PLANT and plant.__class__ is DrivePlant \
                    and plant.home_switch is None else plant.inputs(mech)
                motion = (csp.demand, pos, 0, csp.following_error, pos, 0)
                state = (sm.statusword, 8, sm.error_code, sm.error_register, inputs)
                if (self._plain_motion and I32_LOW <= min(motion) and max(motion) <= I32_HIGH
                        and (state == self._held_state or state == self._published[1])):
                    # perf: _hold's case of a state group found in range before
                    self._held_state = state
                    self.deferred = motion + state
                else:
                    self._hold(motion, state)
                return
        if t >= self.now and not self._batch and self._eventless():
            self.now = t              # perf: what _advance does when no event can come
            self.publish_deferred()
        else:
            self._advance(t, True)

    def _csp_fast(self, t: int, rx: Optional[bytes],
                  values: Optional[dict[tuple[int, int], int]]) -> bool:
        """The bus cycle of a drive following CSP set-points, written out:
        what :meth:`_step` does (advance, received objects, the mode's
        cycle, publish) when no event can come, no object the drive acts on
        changes (6040h held; no 6060h, 605Ah, 6084h, 6085h, 6065h, 6066h,
        6080h, 1C32h), no switch is configured and the following error lies
        within 6065h.  Returns False, having done nothing, otherwise."""
        # perf: the steady CSP cycle in one function: no stage calls, no
        # Result, no Write, only the values that change written
        sm = self.sm
        if (sm.state is not OE or self.mode_number != 8 or self._qs_wait or t < self.now
                or self.esm.state is not _ESM_OP):
            return False
        hooked = self.store.hooked
        if hooked is not self._hooked_ok:
            if hooked != self._only_hook:
                return False
            self._hooked_ok = hooked        # perf: the same subscriptions, seen before
        plant = self.plant
        if plant.pos_limit is not None or plant.neg_limit is not None or self.stops is not None:
            return False
        ax = self.axis
        if ax._line is None and ax.legs:
            return False
        csp = self.engines[8]
        if csp.__class__ is not CyclicPosition or csp._last is None:
            return False
        live = self._live
        window, v_max = live.get(_K6065), live.get(_K6080)
        if window.__class__ is not int or v_max.__class__ is not int:
            return False
        held = self.deferred
        if held is None:
            mech = ax.mechanical(t)
            pos = mech + ax.shift
        else:
            pos = held[1]               # perf: 6064h at t, as publish_deferred found it
            mech = pos - ax.shift
        fe = csp.demand - pos
        if fe > window or -fe > window:
            return False
        known = rx is not None
        if known:
            rx_map = self.pdo.active_rx
            codec = self._csp_codec
            if codec[0] is not rx_map:
                codec = self._csp_codec = (rx_map, self._csp_rx_codec(rx_map))
            codec = codec[1]
            if codec is None or len(rx) != codec[0]:
                return False
            _, objects, keys, cw_st, at = codec
            if cw_st is not None and cw_st.unpack_from(rx, at)[0] != self.controlword:
                return False
            changed = []
            for kv in zip(keys, objects.unpack(rx)):
                if live[kv[0]] != kv[1]:
                    changed.append(kv)
        else:
            changed = []
            for key, v in values.items():                   # type: ignore[union-attr]
                if key == CW:
                    if v != self.controlword:
                        return False
                    continue
                cur = live.get(key, MISSING)
                if not cur == v:
                    if cur is MISSING or key[0] in _HOOK_INDEXES or key in _CSP_READS:
                        return False
                    changed.append((key, v))
        # from here on as _step: the time, then the objects (no hook acts on them)
        self.now = t
        store = self.store
        fit = known or self._fit       # perf: unpacked at the object's width: it fits
        for key, v in changed:
            if fit and not store._pending:
                live[key] = v         # perf: set_known with nothing pending, inline
            elif fit:
                store.set_known(key, v)
            else:
                store.set(key[0], key[1], v)
        # CyclicPosition.cycle with no switch and the following error within 6065h
        csp.following_error = fe
        csp._fe_since = None
        period = t - csp._last
        csp._last = t
        target = live.get(_K607A)
        if target.__class__ is not int:
            target = self.param(0x607A)
        csp.limit_stop = False
        # Axis.linear(t, t1, target, v_max, mech), then publish():
        # CyclicPosition.bits (no limit stop, no following error beyond
        # 6065h); the line, if any, starts at t, so the count there is still
        # mech; moving(t) and velocity(t) of that line written out
        t1 = t + (period if period > 1 else 1)
        x1 = target - ax.shift
        cap = v_max * (t1 - t) // US
        if x1 > mech + cap:
            x1 = mech + cap
        elif x1 < mech - cap:
            x1 = mech - cap
        if x1 == mech:
            ax.linear(t, t1, target, v_max, mech)      # at rest: no line
            bits, vel = _B12 | _B10, 0
        else:
            # perf: Axis.linear's line (its _set(x0, [line])) written out
            ax._dir = 1 if x1 > mech else -1
            ax._rest = ax._count = x1
            ax._line = line = LinLeg(t, t1, mech, x1)
            ax.legs = [line]
            ax.version += 1
            num, den = (x1 - mech) * US, t1 - t
            bits, vel = _B12, num // den if num >= 0 else -(-num // den)
        csp.demand = target
        sm._mode_bits = bits     # perf: set_mode_bits of bits that are mode bits (8, 10-15)
        if self.probe.function or live.get(_K60B8):
            self._probe_update(t, mech)            # touch probe armed (drive_service.py)
        # a plant without switches gives 60FDh = 0 wherever the axis is
        inputs = 0 if _PLAIN_PLANT and plant.__class__ is DrivePlant \
            and plant.home_switch is None else plant.inputs(mech)
        motion = (target, pos, vel, fe, pos, vel)
        state = (sm.statusword, 8, sm.error_code, sm.error_register, inputs)
        last_motion, last_state = self._published
        if state == last_state and self._plain_motion \
                and I32_LOW <= min(motion) and max(motion) <= I32_HIGH:
            # perf: _publish_values for a changed motion group alone, written
            # out (the state group equal to the one written last)
            if motion != last_motion:
                group = self._motion_out
                (group[_K6062], group[_K6064], group[_K606C], group[_K60F4], group[_K6063],
                 group[_K606B]) = motion
                if store._pending:
                    store.set_status_group(group)
                else:
                    # perf: set_status_group inline: the caller holds the
                    # store's lock (cycle, exchange, exchange_locked)
                    live.update(group)
                self._out.update(group)
                self._published = (motion, last_state)
        else:
            self._publish_values(motion, state)
        return True

    def _csp_rx_codec(self, entries: tuple) -> Optional[tuple]:
        """:meth:`_rx_fast_codec` for :meth:`_csp_fast`: None when the map
        holds an object the drive acts on besides 6040h and 607Ah."""
        codec = self._rx_fast_codec(entries)
        if codec is None or any(k[0] in _HOOK_INDEXES or k in _CSP_READS for k in codec[2]):
            return None
        return codec
