"""The plant file's ``[pto.N]`` and ``[pwm.N]`` tables: the configuration
the Micro/WIN Position Control and PWM wizards keep in their protected code
(and a V-memory table whose layout is not public), which an export does
not carry.

::

    [pto.0]                 # the PTO of Q0.0 (pto.1: Q0.1)
    max_speed = 20000       # MAX_SPEED, pulses/s
    ss_speed = 200          # SS_SPEED, the start/stop speed, pulses/s
    accel_ms = 500          # time from SS_SPEED to MAX_SPEED
    decel_ms = 500          # time from MAX_SPEED to SS_SPEED
    hsc = true              # C_Pos from HSC0 (pto.1: HSC3) in mode 12
    [[pto.0.profile]]       # profile 0, then 1, ...
    mode = "relative"
    steps = [ { speed = 5000, pulses = 20000 }, { speed = 1000, pulses = 2000 } ]
    [[pto.0.profile]]       # profile 1
    mode = "continuous"     # single-speed continuous rotation
    speed = 3000
    stop_pulses = 6000      # optional: pulses PTO0_ADV still sends (ramp included)

    [pwm.1]                 # PWM1_RUN on Q0.1
    time_base = "us"        # or "ms": Cycle and Duty_Cycle in this unit

What it is: validation into plain dataclasses; every problem is a
PlcConfigError naming the file and the key.  What it is not: no motion
(that is :mod:`.plan`), no check against the CPU's output limit (the CPU
is known only when the program loads; the blocks warn then).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

from ...errors import PlcConfigError
from ..keys import checked_table
from .plan import cycle_us, ramp_pulses, speed_of

#: limits the plant accepts (decisions in docs/pto-wizard.md)
MAX_HZ = 100_000            #: the fastest built-in output (CPU 224XP, 100 kHz)
MIN_HZ = 16                 #: slowest speed whose cycle fits a word of µs (62500 µs)
MAX_PROFILES = 32           #: S7-200 SMART's motion wizard limits (the S7-200 ones
MAX_STEPS = 16              #: are not public); the Profile input is a byte
MAX_RAMP_MS = 32_000
MAX_PULSES = (1 << 31) - 1  #: a step's pulses fit the wizard's DINT positions

_PTO_KEYS = {"max_speed", "ss_speed", "accel_ms", "decel_ms", "hsc", "profile"}
_PROFILE_KEYS = {"relative": {"mode", "steps"},
                 "continuous": {"mode", "speed", "stop_pulses"}}
_STEP_KEYS = {"speed", "pulses"}
_PWM_KEYS = {"time_base"}
TIME_BASES = {"us": 1, "ms": 1000}
#: the file name of the tables a project file's wizards give, after the
#: project's name (plcrt.loader; docs/project-files.md, "Wizards")
PROJECT_WIZARDS = "(its wizards)"


@dataclass(frozen=True)
class Step:
    speed: int              #: pulses/s
    pulses: int             #: pulses of the step, its ramps included


@dataclass(frozen=True)
class Profile:
    mode: str                               #: "relative" or "continuous"
    steps: tuple[Step, ...] = ()            #: relative: 1..MAX_STEPS steps
    speed: int = 0                          #: continuous: the speed
    stop_pulses: Optional[int] = None       #: continuous: the PTOx_ADV distance


@dataclass(frozen=True)
class PtoConfig:
    """One ``[pto.N]`` table."""

    output: int
    max_speed: int
    ss_speed: int
    accel_ms: int
    decel_ms: int
    hsc: bool = False
    profiles: tuple[Profile, ...] = ()
    where: str = field(default="", compare=False)


@dataclass(frozen=True)
class PwmConfig:
    """One ``[pwm.N]`` table: the time base of Cycle and Duty_Cycle, in µs."""

    output: int
    unit: int
    where: str = field(default="", compare=False)


def _int(v: Any, where: str, lo: int, hi: int, what: str = "") -> int:
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise PlcConfigError(f"{where} must be a whole number {lo}..{hi}{what}, got "
                             f"{str(v)[:20]!r}")
    return v


def _outputs(raw: Any, file: str, name: str) -> list[tuple[int, dict, str]]:
    if not isinstance(raw, dict):
        raise PlcConfigError(f"{file}: [{name}] must be a table of outputs "
                             f"([{name}.0] for Q0.0, [{name}.1] for Q0.1)")
    out = []
    for key, value in raw.items():
        where = f"{file}: {name}.{key}"
        if str(key) not in ("0", "1"):
            raise PlcConfigError(f"{where}: the outputs are {name}.0 (Q0.0) and {name}.1 (Q0.1)")
        out.append((int(key), value, where))
    return out


def parse_pto(raw: Any, file: str) -> dict[int, PtoConfig]:
    """``[pto.N]`` tables by output number."""
    result: dict[int, PtoConfig] = {}
    for n, table, where in _outputs(raw, file, "pto"):
        t = checked_table(table, where, _PTO_KEYS)
        for key in ("max_speed", "ss_speed"):
            if key not in t:
                raise PlcConfigError(f"{where}.{key} is missing (pulses/s)")
        mx = _int(t["max_speed"], f"{where}.max_speed", MIN_HZ, MAX_HZ, " pulses/s")
        ss = _int(t["ss_speed"], f"{where}.ss_speed", MIN_HZ, mx, " pulses/s (not above "
                  "max_speed)")
        acc = _int(t.get("accel_ms", 0), f"{where}.accel_ms", 0, MAX_RAMP_MS, " ms")
        dec = _int(t.get("decel_ms", 0), f"{where}.decel_ms", 0, MAX_RAMP_MS, " ms")
        hsc = t.get("hsc", False)
        if not isinstance(hsc, bool):
            raise PlcConfigError(f"{where}.hsc must be true or false, got {str(hsc)[:20]!r}")
        cfg = PtoConfig(n, mx, ss, acc, dec, hsc, where=where)
        profiles = t.get("profile", [])
        if not isinstance(profiles, list) or len(profiles) > MAX_PROFILES:
            raise PlcConfigError(f"{where}.profile must be an array of at most {MAX_PROFILES} "
                                 f"tables ([[pto.{n}.profile]])")
        cfg = PtoConfig(n, mx, ss, acc, dec, hsc,
                        tuple(_profile(p, f"{where}.profile[{i}]", cfg)
                              for i, p in enumerate(profiles)), where)
        result[n] = cfg
    return result


def _speed(v: Any, where: str, cfg: PtoConfig) -> int:
    return _int(v, where, cfg.ss_speed, cfg.max_speed, " pulses/s (ss_speed..max_speed)")


def _profile(raw: Any, where: str, cfg: PtoConfig) -> Profile:
    if not isinstance(raw, dict):
        raise PlcConfigError(f"{where} must be a table")
    mode = raw.get("mode")
    if not isinstance(mode, str) or mode not in _PROFILE_KEYS:
        raise PlcConfigError(f"{where}.mode must be \"relative\" or \"continuous\", got "
                             f"{str(mode)[:20]!r}")
    checked_table(raw, where, _PROFILE_KEYS[mode])
    if mode == "continuous":
        if "speed" not in raw:
            raise PlcConfigError(f"{where}.speed is missing (pulses/s)")
        speed = _speed(raw["speed"], f"{where}.speed", cfg)
        stop = raw.get("stop_pulses")
        if stop is not None:
            # from the speed of its cycle in whole µs, as PTOx_ADV plans it
            need = ramp_pulses(speed_of(cycle_us(speed)), cfg.ss_speed, cfg, decel=True)
            stop = _int(stop, f"{where}.stop_pulses", max(need, 1), MAX_PULSES,
                        f" (the deceleration from {speed} pulses/s takes {need})")
        return Profile(mode, speed=speed, stop_pulses=stop)
    steps_raw = raw.get("steps")
    if not isinstance(steps_raw, list) or not 1 <= len(steps_raw) <= MAX_STEPS:
        raise PlcConfigError(f"{where}.steps must be an array of 1..{MAX_STEPS} "
                             f"{{ speed, pulses }} tables")
    steps = []
    prev = cfg.ss_speed
    for i, s in enumerate(steps_raw):
        sw = f"{where}.steps[{i}]"
        s = checked_table(s, sw, _STEP_KEYS)
        if "speed" not in s or "pulses" not in s:
            raise PlcConfigError(f"{sw} needs speed and pulses")
        speed = _speed(s["speed"], f"{sw}.speed", cfg)
        last = i == len(steps_raw) - 1
        # the step's ramps lie inside its pulses: the change from the
        # previous speed at its start, the stop at the end of the last one
        need = ramp_pulses(prev, speed, cfg, decel=speed < prev)
        if last:
            need += ramp_pulses(speed, cfg.ss_speed, cfg, decel=True)
        pulses = _int(s["pulses"], f"{sw}.pulses", max(need, 1), MAX_PULSES,
                      f" (its ramps take {need})")
        steps.append(Step(speed, pulses))
        prev = speed
    return Profile(mode, tuple(steps))


def parse_pwm(raw: Any, file: str) -> dict[int, PwmConfig]:
    """``[pwm.N]`` tables by output number."""
    result: dict[int, PwmConfig] = {}
    for n, table, where in _outputs(raw, file, "pwm"):
        t = checked_table(table, where, _PWM_KEYS)
        base = t.get("time_base")
        if not isinstance(base, str) or base not in TIME_BASES:
            raise PlcConfigError(f"{where}.time_base must be \"us\" or \"ms\", got "
                                 f"{str(base)[:20]!r}")
        result[n] = PwmConfig(n, TIME_BASES[base], where)
    return result


def check_outputs(pto: dict[int, PtoConfig], pwm: dict[int, PwmConfig], file: str) -> None:
    """One output is a PTO or a PWM, not both."""
    both = sorted(set(pto) & set(pwm))
    if both:
        raise PlcConfigError(f"{file}: pto.{both[0]} and pwm.{both[0]}: Q0.{both[0]} is "
                             f"configured as a PTO and as a PWM; the wizards give an output "
                             f"one of the two")
