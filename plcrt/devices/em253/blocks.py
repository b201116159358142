"""The instructions of the EM253 library ``EM253_Ext_v1.0`` (EM253 user
manual, chapter 3.2) as built-in blocks: MOTION_EN3, GET_AbsPos and
SET_AbsPos here, SPD_CTRL, POS_GOTO_R and HOMING in :mod:`.moves`, POS_RUN
in :mod:`.pos_run`, what they share in :mod:`.base`.  Importing this module
registers all seven (:mod:`plcrt.devices.libraries` lists it).

Each CALL site gets its own block object (the instance memory a library
subroutine has on the CPU).  The generated code calls it with the IN values
and writes back what it returns (see ``library/EM253_Ext_v1.0.toml``).

Common rules (manual 3.2, notes 1-5; decisions in docs/em253.md):

* MOTION_EN3 must have run for the module earlier in the same scan;
  otherwise a motion instruction does nothing and a diagnostic says why.
* InnerState must be 0 before first use; the block sets it to 257.  If the
  program changes it later the block stops its axis at once (the manual
  only says the output "will be wrong") and reports it.
* Update != 0 applies changed parameters to a running operation; the block
  clears it.  E_Stop stops the pulses at once; a new start needs a new
  rising edge of Run.  C_Status: 0 before the first run, 1 while running,
  8 once stopped.
* SpdSs must not be above SpdSet (note 4), speeds are limited by the output
  type (200 kHz single-ended, 500 kHz differential): otherwise the module's
  behaviour is kept (no start / clamped) and a diagnostic is emitted.
"""

from __future__ import annotations

from typing import Any

from ...blocks import register_block
from .base import MotionBlock, dint
# importing these registers SPD_CTRL, POS_GOTO_R, HOMING and POS_RUN; the
# classes stay importable from here
from .moves import Homing, PosGotoR, SpdCtrl
from . import pos_run  # noqa: F401  (registers POS_RUN)

__all__ = ["GetAbsPos", "Homing", "MotionEn3", "PosGotoR", "SetAbsPos", "SpdCtrl"]


@register_block("MOTION_EN3")
class MotionEn3(MotionBlock):
    name = "MOTION_EN3"
    #: the Clr bits are the inputs' 0/1 (or 0), Status 1 or 4
    exact_results = ("Clr0", "Clr1", "Status")

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self._last_key: tuple = ()
        self._last_out: tuple = ()

    def __call__(self, em_no: int, p_dor_ccw: int, sev0: int, sev1: int,
                 clr0: int, clr1: int) -> tuple:
        # perf: nothing to do when the inputs are as last scan and no CLR
        # pulse or emergency stop is pending: the module is enabled for this
        # scan and the outputs are those of the last call
        # (the key holds EmNo: when it matches, self.module is that slot's;
        # there is a key only after a call with Status 1)
        mod = self.module
        if (em_no, p_dor_ccw, sev0, sev1, clr0, clr1) == self._last_key \
                and not mod.clr_pending and not mod.stf_any:
            mod.enabled_scan = self.plc.scans
            return self._last_out
        return self.call_exact(em_no, p_dor_ccw, sev0, sev1, clr0, clr1)

    def call_exact(self, em_no: int, p_dor_ccw: int, sev0: int, sev1: int,
                   clr0: int, clr1: int) -> tuple:
        """The instruction without the shortcut of :meth:`__call__`."""
        mod = self.plc.modules.get(em_no)
        if mod is None:
            self.warn(f"no EM253 module in slot {em_no} (EmNo): Status 4", "nomodule")
            return clr0, clr1, 4
        self.module = mod
        mod.enabled_scan = self.plc.scans
        key = (em_no, p_dor_ccw, sev0, sev1, clr0, clr1)
        if key == self._last_key and not mod.clr_pending and not mod.stf_any:
            return self._last_out
        t = self.now()
        lowered = mod.differential and not p_dor_ccw
        mod.differential = bool(p_dor_ccw)
        if lowered:
            for ax in mod.axes:
                owner = ax.owner
                if ax.segs and abs(ax.speed(t)) > mod.max_hz and owner is not None:
                    owner.output_limit_lowered(t)
        out = []
        for i, (sev, clr) in enumerate(((sev0, clr0), (sev1, clr1))):
            ax = mod.axes[i]
            if sev and ax.moving and not ax.masked:
                self.warn(f"SevOn{i} masks pulse and direction while axis {i} moves: the "
                          f"counter keeps counting but the motor does not follow", f"sev{i}")
            ax.set_masked(t, bool(sev))
            until = mod.clr_until[i]
            if clr and until is None:
                mod.clr_until[i] = t + 200_000
            elif until is not None and t >= until:
                mod.clr_until[i] = None
                clr = 0  # the bit clears itself after the pulse (manual 3.2.1)
            out.append(clr)
        status = 4 if any(a.stf for a in mod.axes) else 1
        mod.clr_pending = any(u is not None for u in mod.clr_until)
        if mod.clr_pending:
            mod.quiet_to = 0   # the module's next step ends the pulse
        mod.stf_any = status == 4
        result = (out[0], out[1], status)
        self._last_out = result
        self._last_key = (em_no, p_dor_ccw, sev0, sev1, out[0], out[1]) if status == 1 else ()
        return result


@register_block("GET_AbsPos")
class GetAbsPos(MotionBlock):
    name = "GET_AbsPos"
    #: C_Pos is the counter's low 32 bits as a DINT (dint(): what a masked
    #: store of the counter writes, so it is stored without a mask)
    exact_results = ("C_Pos", "C_Status")
    last_out = (0, 0)

    def __call__(self, em_no: int, axis_no: int) -> tuple:
        plc = self.plc
        # perf: the usual case: the module and axis of the last call (always
        # so at a site that gives them as constants, once found), enabled in
        # this scan; the time read from the PLC's field, not its property
        if (self._site_ok or em_no == self._em and axis_no == self._axn) \
                and self.module.enabled_scan == plc.scans:  # type: ignore[union-attr]
            ax, t = self.axis, plc._t_us
            if ax._w_lo <= t and t < ax._w_hi:  # type: ignore[union-attr]
                # perf: Axis.position inline (its window test and formula)
                a, b, c, d = ax._w_pos  # type: ignore[union-attr]
                pos = ((a * t + b) * t + c) // d
            else:
                pos = ax.position(t)  # type: ignore[union-attr]
            if pos < -0x3FFFFFFF or pos > 0x3FFFFFFF:   # perf: one-digit bounds
                pos = dint(pos)
            self.last_out = out = (pos, 1)
            return out
        return self.call_exact(em_no, axis_no)

    def call_exact(self, em_no: int, axis_no: int) -> tuple:
        """The instruction without the shortcut of :meth:`__call__`."""
        if not self.find(em_no, axis_no):
            return self.last_out
        assert self.axis is not None
        self.last_out = (dint(self.axis.position(self.now())), 1)
        return self.last_out


@register_block("SET_AbsPos")
class SetAbsPos(MotionBlock):
    name = "SET_AbsPos"
    exact_results = ("Start", "C_Status")

    def __call__(self, em_no: int, axis_no: int, pos: int, start: int) -> tuple:
        # perf: Start = 0 with the module and axis of the last call, enabled
        # in this scan: nothing to do
        if not start and (self._site_ok or em_no == self._em and axis_no == self._axn) \
                and self.module.enabled_scan == self.plc.scans:  # type: ignore[union-attr]
            return 0, self.status
        return self.call_exact(em_no, axis_no, pos, start)

    def call_exact(self, em_no: int, axis_no: int, pos: int, start: int) -> tuple:
        """The instruction without the shortcut of :meth:`__call__`."""
        if not self.find(em_no, axis_no):
            return start, self.status
        assert self.axis is not None
        if start:
            self.axis.set_position(self.now(), pos)
            self.status = 1
            return 0, self.status
        return 0, self.status
