"""The wizard subroutines of the built-in pulse outputs as built-in blocks:
PTOx_CTRL, PTOx_RUN, PTOx_MAN, PTOx_LDPOS, PTOx_ADV (Position Control
wizard) and PWMx_RUN (PWM wizard), x = 0 for Q0.0 and 1 for Q0.1 (System
Manual, "Open-loop motion control"; interfaces in library/pto_wizard.toml).

What it is: one block object per CALL site (as for every library block);
the blocks of one output share a :class:`WizardAxis` (initialised, manual
mode, the motion running, the counter of C_Pos).  Motion is planned by
:mod:`.plan` and run by :class:`plcrt.engine.pulse.PulseOutput` as trains:
the output behaves as a PLS-started PTO for everything else (SM66.7, the
terminal, HSC mode 12, event 19/20 at the end of a motion).

What it is not: the wizard's code.  Its error numbers, ramp algorithm and
V-memory table are not public; plcrt's choices (the ERRORS table below,
docs/pto-wizard.md) are announced by a warning when the program loads.
A protected, empty SUBROUTINE_BLOCK of the export named like one of these
blocks runs it (``plcrt.blocks.register_protected``;
plcrt.blocks.call.protected_call).
"""

from __future__ import annotations

from typing import Any, Optional

from ...blocks import register_block, register_protected
from ...engine.pulse import FAST_OUTPUTS, MIN_CYCLE_US
from .config import PROJECT_WIZARDS
from .plan import change_trains, continuous_trains, profile_trains, stop_trains

#: Error output codes (plcrt's own: the wizard's numbers are not public)
OK, NO_CONFIG, NOT_INIT, BUSY, MANUAL, BAD_PROFILE, BAD_SPEED, STOP_INPUT, NO_HSC, \
    NO_ADV, TOO_FAST, COUNTER, BAD_CYCLE = range(13)
ERRORS = {
    OK: "no error",
    NO_CONFIG: "no wizard configuration for this output in the plant file",
    NOT_INIT: "PTOx_CTRL has not run yet",
    BUSY: "another motion (or a PLS train) runs on the output",
    MANUAL: "manual mode (PTOx_MAN) is on",
    BAD_PROFILE: "no such profile in the configuration",
    BAD_SPEED: "Speed is outside SS_SPEED..MAX_SPEED",
    STOP_INPUT: "I_STOP or D_STOP of PTOx_CTRL is on",
    NO_HSC: "the configuration has no high-speed counter (hsc = false)",
    NO_ADV: "the running motion is no continuous profile with stop_pulses",
    TOO_FAST: "MAX_SPEED is above what the CPU's output makes",
    COUNTER: "the program gave the high-speed counter another mode",
    BAD_CYCLE: "Cycle is below the shortest cycle the output makes",
}
#: mode 12 counter of each output (System Manual, HSC modes: HSC0 counts
#: Q0.0's pulses, HSC3 Q0.1's)
COUNTER_OF = {0: 0, 1: 3}
KINDS = ("CTRL", "RUN", "MAN", "LDPOS", "ADV")
NAMES = tuple(f"PTO{n}_{k}" for n in (0, 1) for k in KINDS) + ("PWM0_RUN", "PWM1_RUN")



def _plant(plc: Any, key: str) -> dict:
    return getattr(plc._config.get("plant"), key, None) or {}


class WizardAxis:
    """What the PTOx_* blocks of one output share."""

    def __init__(self, plc: Any, output: int) -> None:
        self.plc = plc
        self.output = output
        self.cfg = _plant(plc, "pto").get(output)
        self.pulse = plc.pulse[output]
        self.counter: Any = None
        self.initialised = False
        self.ctrl_error = NO_CONFIG if self.cfg is None else OK
        self.stop_inputs = False     #: I_STOP or D_STOP at the last PTOx_CTRL
        self.motion = 0              #: number of the last motion started
        self.kind = ""               #: the block kind that started it: RUN or MAN
        self.profile: Any = None     #: the profile it runs (RUN)
        self.stopping = False        #: a decelerated stop (or ADV) is planned
        self.man_run = False         #: RUN of PTOx_MAN at its last call
        self.speed = 0               #: manual mode: the speed asked for

    def now(self) -> int:
        return self.plc._irq_t       # the running code's time (OB1 or a routine)

    def busy(self) -> bool:
        return bool(self.pulse.trains)

    def manual(self) -> bool:
        """Manual mode: PTOx_MAN's RUN is on or its motion still runs."""
        return self.kind == "MAN" and (self.man_run or self.busy())

    def too_fast(self) -> bool:
        return self.cfg is not None and self.cfg.max_speed * self.pulse.min_cycle > 1_000_000

    def refusal(self, manual_ok: bool = False, motion: bool = True) -> int:
        """Why a new motion (or, *motion* False, a position load) cannot
        start now (0: it can)."""
        for code, bad in ((NO_CONFIG, self.cfg is None), (NOT_INIT, not self.initialised),
                          (STOP_INPUT, motion and self.stop_inputs),
                          (TOO_FAST, motion and self.too_fast()),
                          (MANUAL, not manual_ok and self.manual()), (BUSY, self.busy())):
            if bad:
                return code
        return OK

    def _touch(self) -> None:
        self.plc._sources_on = True       # the time line runs from now on
        self.plc.scheduler.touch()        # the output's next event moved

    def start(self, trains: list, kind: str) -> int:
        self.pulse.run_trains(trains)
        self.motion += 1
        self.kind, self.stopping = kind, False
        self._touch()
        return self.motion

    def change_speed(self, t: int, speed: int) -> None:
        """Manual mode: keep the pulse in progress at *t*, then ramp from its
        speed to *speed* and run on (also out of a stop under way)."""
        cur = self.pulse.pulse_in_progress(t)
        if cur is None or self.cfg is None:
            return
        self.pulse.run_trains([cur, *change_trains(cur.end, cur.c0, speed, self.cfg,
                                                   cur.segment)])
        self.stopping = False
        self._touch()

    def decel_stop(self, t: int, total: Optional[int] = None) -> None:
        """A decelerated stop from the pulse in progress at *t* (with *total*:
        after exactly that many more pulses); never beyond the end the
        running motion already has (a relative profile in its last pulses
        ends as planned)."""
        po, cfg = self.pulse, self.cfg
        cur = po.pulse_in_progress(t)
        if cfg is None or self.stopping or cur is None:
            return
        down = stop_trains(cur.end, cur.c0, cfg, cur.segment, total)
        left = po.sent + sum(tr.count for tr in po.trains) - po.pulses_until(cur.start)
        self.stopping = True
        if sum(tr.count for tr in down) < left:
            po.run_trains([cur, *down])
            self._touch()

    def init(self, t: int, warn: Any) -> None:
        """The first PTOx_CTRL: with the HSC option, HSC0 (HSC3) in mode 12,
        enabled, counting up from 0."""
        self.initialised = True
        if self.cfg is None or not self.cfg.hsc:
            return
        num = COUNTER_OF[self.output]
        hsc = self.plc.hsc
        c = hsc[num] if num < len(hsc) else None
        if c is None or c.mode not in (None, 12):
            warn(f"the wizard's counter HSC{num} has mode {getattr(c, 'mode', None)} from the "
                 f"program, not 12: C_Pos stays 0 (Error {COUNTER})", "counter")
            self.ctrl_error = COUNTER
            return
        if c.mode is None:
            self.plc._hdef(num, 12)
        if not c.enabled:
            c.enabled, c.direction = True, 1
            c.base = c.pulse.pulses_until(t)
            c._publish()
        self.counter = c
        self._touch()

    def c_pos(self, t: int) -> int:
        c = self.counter
        if c is None:
            return 0
        c.sync(t)
        return c.cv


def _axis(plc: Any, output: int) -> WizardAxis:
    """The axis of ``output`` the PTOx_* blocks of ``plc`` share, made with
    the first of them (a fork copies blocks and axis together)."""
    axes = plc.family_states.setdefault(_axis, {})
    if output not in axes:
        axes[output] = WizardAxis(plc, output)
    return axes[output]


class _Block:
    """One CALL site of a wizard block."""

    kind = ""

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        self.plc, self.loc, self.name = plc, loc, itf.name
        self.output = int(itf.name[3])
        self.ax = _axis(plc, self.output) if self.name.startswith("PTO") else None
        self.error = OK
        self.done = False
        self.motion = 0      #: the motion this call site started last

    def warn(self, msg: str, code: str) -> None:
        self.plc.warn(f"{self.name}: {msg}", self.loc, f"{self.name}:{code}:{id(self)}")

    def refuse(self, code: int) -> int:
        self.warn(f"refused with Error {code}: {ERRORS[code]}", f"err{code}")
        self.error = code
        return code

    def finished(self) -> bool:
        """This call site's last motion has ended."""
        ax = self.ax
        return self.motion != 0 and not (ax.motion == self.motion and ax.busy())

    @classmethod
    def at_load(cls, g: Any, itf: Any) -> None:
        """Load-time warnings (once per output): where the configuration
        comes from and that plcrt's choices stand for the wizard's code
        (compile-time facts: the plant the program is compiled for and the
        CPU model)."""
        output = int(itf.name[3])
        once = g.unit.hooks.setdefault("ptowizard-once", set())
        family = itf.name[:3]
        if (family, output) in once:
            return
        once.add((family, output))
        table = "pto" if family == "PTO" else "pwm"
        cfg = (getattr(g.unit.plant, table, None) or {}).get(output)
        wizard = "Position Control" if family == "PTO" else "PWM"
        if cfg is None:
            g.warn(f"{itf.name}: the {wizard} wizard's configuration is not in the export; it "
                   f"must come from the plant file ([{table}.{output}]): without it the "
                   f"{family}{output}_* blocks report Error {NO_CONFIG} (docs/pto-wizard.md)",
                   f"ptowizard-noconfig-{table}{output}")
            return
        origin = (f"the project's {wizard} wizard configuration" if PROJECT_WIZARDS in cfg.where
                  else "the plant's")
        g.warn(f"{itf.name}: the {wizard} wizard's subroutines for Q0.{output} are emulated "
               f"from {origin} [{table}.{output}]; the wizard's ramp algorithm, error "
               f"numbers and V-memory table are not public: plcrt's choices are in "
               f"docs/pto-wizard.md", f"ptowizard-{table}{output}")
        limit = 1_000_000 // FAST_OUTPUTS.get(g.unit.model.name, MIN_CYCLE_US)
        if family == "PTO" and cfg.max_speed > limit:
            g.warn(f"{itf.name}: max_speed {cfg.max_speed} pulses/s of [pto.{output}] is above "
                   f"the {limit} pulses/s of this CPU's Q0.{output}: PTO{output}_RUN and "
                   f"PTO{output}_MAN report Error {TOO_FAST}", f"ptowizard-fast-{output}")


@register_block("PTO0_CTRL")
@register_block("PTO1_CTRL")
class PtoCtrl(_Block):
    """PTOx_CTRL(I_STOP, D_STOP) -> Done, Error, C_Pos; called every scan."""

    def __call__(self, i_stop: int, d_stop: int) -> tuple:
        ax = self.ax
        t = ax.now()
        if not ax.initialised:
            ax.init(t, self.warn)
        ax.stop_inputs = bool(i_stop or d_stop)
        if i_stop and ax.busy():
            # manual: "the pulses stop at once"
            ax.pulse.stop_now(t)
            ax._touch()
        elif d_stop and ax.busy():
            ax.decel_stop(t)
        return int(not ax.busy()), ax.ctrl_error, ax.c_pos(t)


@register_block("PTO0_RUN")
@register_block("PTO1_RUN")
class PtoRun(_Block):
    """PTOx_RUN(START, Profile, Abort) -> Done, Error, C_Profile, C_Step, C_Pos."""

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self.profile = 0
        self.step = 0

    def __call__(self, start: int, profile: int, abort: int) -> tuple:
        ax = self.ax
        t = ax.now()
        mine = self.motion != 0 and ax.motion == self.motion and ax.busy()
        if abort and mine:
            ax.decel_stop(t)
        elif start and not mine:
            self._start(t, profile)
        cur = ax.pulse.pulse_in_progress(t) if self.motion and self.motion == ax.motion \
            else None
        if cur is not None:
            self.step = cur.segment
        return int(self.finished()), self.error, self.profile, self.step, ax.c_pos(t)

    def _start(self, t: int, profile: int) -> None:
        ax = self.ax
        code = ax.refusal()
        if code == OK and not 0 <= profile < len(ax.cfg.profiles):
            code = BAD_PROFILE
        if code:
            self.refuse(code)
            return
        prof = ax.cfg.profiles[profile]
        self.motion = ax.start(profile_trains(t, ax.cfg, prof), "RUN")
        ax.profile = prof
        self.profile, self.step, self.error = profile, 0, OK


@register_block("PTO0_MAN")
@register_block("PTO1_MAN")
class PtoMan(_Block):
    """PTOx_MAN(RUN, Speed) -> Error, C_Pos."""

    def __call__(self, run: int, speed: int) -> tuple:
        ax = self.ax
        t = ax.now()
        ax.man_run = bool(run)
        mine = ax.kind == "MAN" and ax.busy()
        if run:
            cfg = ax.cfg
            # a stop input holds even the manual motion's own stop
            code = ax.refusal(manual_ok=True) if not mine else \
                STOP_INPUT if ax.stop_inputs else OK
            if code == OK and not cfg.ss_speed <= speed <= cfg.max_speed:
                code = BAD_SPEED
            if code:
                self.refuse(code)
            elif not mine:
                self.motion = ax.start(continuous_trains(t, cfg, speed), "MAN")
                ax.speed, self.error = speed, OK
            elif speed != ax.speed or ax.stopping:
                # a new Speed (or RUN again while stopping): ramp from the
                # speed of the pulse in progress
                ax.change_speed(t, speed)
                ax.speed, self.error = speed, OK
        elif mine:
            ax.decel_stop(t)
        return self.error, ax.c_pos(t)


@register_block("PTO0_LDPOS")
@register_block("PTO1_LDPOS")
class PtoLdpos(_Block):
    """PTOx_LDPOS(START, New_Pos) -> Done, Error, C_Pos."""

    def __call__(self, start: int, new_pos: int) -> tuple:
        ax = self.ax
        t = ax.now()
        if start:
            code = ax.refusal(motion=False)
            if code == OK and ax.counter is None:
                code = NO_HSC if ax.cfg is not None and not ax.cfg.hsc else COUNTER
            if code:
                self.refuse(code)
                self.done = False
            else:
                c = ax.counter
                c.sync(t)
                c.cv = new_pos
                c._publish()
                ax._touch()               # the counter's CV=PV time moved
                self.done, self.error = True, OK
        return int(self.done), self.error, ax.c_pos(t)


@register_block("PTO0_ADV")
@register_block("PTO1_ADV")
class PtoAdv(_Block):
    """PTOx_ADV(START) -> Done, Error, C_Pos."""

    def __call__(self, start: int) -> tuple:
        ax = self.ax
        t = ax.now()
        if start and ax.busy() and not ax.stopping:
            prof = ax.profile
            if ax.manual():
                self.refuse(MANUAL)
            elif ax.kind != "RUN" or prof is None or prof.mode != "continuous" \
                    or prof.stop_pulses is None:
                self.refuse(NO_ADV)
            else:
                ax.decel_stop(t, prof.stop_pulses)
                self.motion, self.error = ax.motion, OK
        return int(self.finished()), self.error, ax.c_pos(t)


@register_block("PWM0_RUN")
@register_block("PWM1_RUN")
class PwmRun(_Block):
    """PWMx_RUN(RUN, Cycle, Duty_Cycle) -> Error: Cycle and the pulse width
    Duty_Cycle in the wizard's time base; changes while running take effect
    at the end of the running cycle (synchronous update)."""

    def __init__(self, plc: Any, loc: Any, itf: Any) -> None:
        super().__init__(plc, loc, itf)
        self.cfg = _plant(plc, "pwm").get(self.output)
        self.pulse = plc.pulse[self.output]

    def __call__(self, run: int, cycle: int, duty: int) -> tuple:
        po = self.pulse
        t = self.plc._irq_t
        if self.cfg is None:
            if run:
                self.refuse(NO_CONFIG)
            return (self.error,)
        before = (po.mode, po.pwm, po.pwm_next)
        if run:
            unit = self.cfg.unit
            if cycle * unit < po.min_cycle:
                self.refuse(BAD_CYCLE)
                return (self.error,)
            po.pwm_run(t, cycle * unit, duty * unit)
            self.error = OK
        elif po.mode == "PWM":
            po.stop_now(t)
        if (po.mode, po.pwm, po.pwm_next) != before:
            # perf: the time line is asked again only when the PWM changed
            self.plc._sources_on = True
            self.plc.scheduler.touch()
        return (self.error,)


register_protected("PTO/PWM wizard", {n: (n,) for n in NAMES})
