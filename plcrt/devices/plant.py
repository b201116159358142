"""Plant files: the machine around simulated modules (TOML).

::

    [module.0]                  # slot (EmNo) 0; kind defaults to "EM253"
    [module.0.axis.0]
    start = 50000               # mechanical position at power-up (pulses)
    rps = [10000, 20000]        # reference switch active in this closed range
    limit_neg = -100000         # L- active at and below
    limit_pos = 400000          # L+ active at and above
    z_period = 4000             # one Z pulse per period ...
    z_offset = 1000             # ... at this mechanical position (and +/- periods)
    events = [ { at = 2.5, input = "STF", value = true } ]   # scripted inputs

Only this module reads the format; it returns plain dataclasses that the
device implementations consume.  Every problem is a PlcConfigError naming
the file and the key.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import PlcConfigError, PlcError
from ..lang.limits import file_limit, read_capped
from .em253.axis import AxisPlant

KINDS = ("EM253",)
EVENT_INPUTS = ("STF",)
_AXIS_KEYS = {"start", "rps", "limit_neg", "limit_pos", "z_period", "z_offset", "events"}
_MODULE_KEYS = {"kind", "axis"}


@dataclass
class ModuleConfig:
    slot: int
    kind: str = "EM253"
    axes: dict[int, AxisPlant] = field(default_factory=dict)


@dataclass
class Plant:
    modules: dict[int, ModuleConfig]
    file: str = "<plant>"


def load_plant(source: str | Path | dict, file: str | None = None) -> Plant:
    """Read a plant from a TOML file path, TOML text, or a parsed dict."""
    if isinstance(source, dict):
        return _build(source, file or "<plant>")
    if isinstance(source, Path) or ("\n" not in str(source) and "=" not in str(source)):
        path = Path(source)
        try:
            # regular files of at most the input limit only (not /dev/zero)
            text = read_capped(path, file_limit()).decode("utf-8")
        except PlcError as e:
            reason = e.message.removeprefix("cannot read file: ")
            raise PlcConfigError(f"{path}: cannot read plant file: {reason}") from None
        except UnicodeDecodeError:
            raise PlcConfigError(f"{path}: the plant file is not UTF-8 text (TOML)") from None
        file = str(path)
    else:
        text = str(source)
        file = file or "<plant>"
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise PlcConfigError(f"{file}: {e}") from None
    return _build(data, file)


def _int(v: Any, where: str) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise PlcConfigError(f"{where} must be an integer, got {v!r}")
    return v


def _build(data: dict, file: str) -> Plant:
    modules: dict[int, ModuleConfig] = {}
    # A misspelt table ([modules.0]) would otherwise give a plant without
    # modules and only run-time warnings: reject unknown keys at every level.
    unknown = set(data) - {"module"}
    if unknown:
        raise PlcConfigError(f"{file}: unknown key(s) {', '.join(sorted(unknown))} "
                             f"(a plant file has [module.N] tables)")
    raw = data.get("module", {})
    if not isinstance(raw, dict):
        raise PlcConfigError(f"{file}: [module] must be a table of slots")
    for key, mod in raw.items():
        where = f"{file}: module.{key}"
        if not str(key).isdigit() or not 0 <= int(key) <= 6:
            raise PlcConfigError(f"{where}: the slot (EmNo) must be 0..6")
        slot = int(key)
        if not isinstance(mod, dict):
            raise PlcConfigError(f"{where} must be a table")
        unknown = set(mod) - _MODULE_KEYS
        if unknown:
            raise PlcConfigError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}")
        kind = str(mod.get("kind", "EM253")).upper()
        if kind not in KINDS:
            raise PlcConfigError(f"{where}: unknown module kind {kind!r} (known: {', '.join(KINDS)})")
        cfg = ModuleConfig(slot, kind)
        axes = mod.get("axis", {})
        if not isinstance(axes, dict):
            raise PlcConfigError(f"{where}.axis must be a table of axes "
                                 f"([module.{key}.axis.0], [module.{key}.axis.1])")
        for akey, ax in axes.items():
            awhere = f"{where}.axis.{akey}"
            if akey not in ("0", "1"):
                raise PlcConfigError(f"{awhere}: an EM253 has axes 0 and 1")
            if not isinstance(ax, dict):
                raise PlcConfigError(f"{awhere} must be a table")
            unknown = set(ax) - _AXIS_KEYS
            if unknown:
                raise PlcConfigError(f"{awhere}: unknown key(s) {', '.join(sorted(unknown))}")
            cfg.axes[int(akey)] = _axis(ax, awhere)
        modules[slot] = cfg
    return Plant(modules, file)


def _axis(ax: dict, where: str) -> AxisPlant:
    p = AxisPlant(start=_int(ax.get("start", 0), f"{where}.start"))
    if "rps" in ax:
        r = ax["rps"]
        if not (isinstance(r, list) and len(r) == 2):
            raise PlcConfigError(f"{where}.rps must be [low, high]")
        lo, hi = _int(r[0], f"{where}.rps"), _int(r[1], f"{where}.rps")
        if lo > hi:
            raise PlcConfigError(f"{where}.rps: low {lo} is above high {hi}")
        p.rps = (lo, hi)
    if "limit_neg" in ax:
        p.limit_neg = _int(ax["limit_neg"], f"{where}.limit_neg")
    if "limit_pos" in ax:
        p.limit_pos = _int(ax["limit_pos"], f"{where}.limit_pos")
    if p.limit_neg is not None and p.limit_pos is not None and p.limit_neg >= p.limit_pos:
        raise PlcConfigError(f"{where}: limit_neg must be below limit_pos")
    if "z_period" in ax:
        zp = _int(ax["z_period"], f"{where}.z_period")
        if zp <= 0:
            raise PlcConfigError(f"{where}.z_period must be positive")
        p.z_period = zp
    p.z_offset = _int(ax.get("z_offset", 0), f"{where}.z_offset")
    events = ax.get("events", [])
    if not isinstance(events, list):
        raise PlcConfigError(f"{where}.events must be a list of {{ at, input, value }} tables")
    for i, ev in enumerate(events):
        ew = f"{where}.events[{i}]"
        try:
            at = float(ev["at"])
            name = str(ev["input"]).upper()
            value = ev["value"]
        except (KeyError, TypeError, ValueError):
            raise PlcConfigError(f"{ew}: needs at (seconds), input and value") from None
        # bool('false') would be True: only a TOML boolean (or 0/1) is a value
        if not isinstance(value, (bool, int)) or value not in (0, 1):
            raise PlcConfigError(f"{ew}: value must be true or false, got {value!r}")
        if not math.isfinite(at):
            raise PlcConfigError(f"{ew}: at must be a finite number of seconds, got {at}")
        if name not in EVENT_INPUTS or at < 0:
            raise PlcConfigError(f"{ew}: input must be one of {EVENT_INPUTS}, at >= 0")
        p.events.append((int(round(at * 1e6)), name, bool(value)))
    p.events.sort()
    return p
