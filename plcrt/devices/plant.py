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

    [cpu]
    wire = { "I0.0" = "Q0.0" }  # the output Q0.0 (or its pulses) drives the input I0.0
    clock = "2026-12-02T08:00:00"   # the real-time clock at power-up (TODR)
    retentive = ["VB0:100", "MB14:18", "T0:32", "C0:256"]   # kept by power_cycle()
    startup = "RUN"             # or "STOP", "LAST": the mode at power-up

    [module.1]                  # a fieldbus master module with CiA 402 drives
    kind = "FIELDBUS"
    v = 1000                    # the drives' images from VB1000, 80 bytes each
    cycle_ms = 1                # bus cycle
    [module.1.drive.1]          # node address 1..127
    model = "hcfa-am0520b"      # or "kinco-servo"
    image = 1000                # this drive's image (default: the next free one)
    neg_limit = -50000          # NLS active at and below (counts)
    pos_limit = 50000           # PLS active at and above
    home_switch = [-1000, 1000] # home switch active in this closed range
    index_period = 10000        # one index pulse per period ...
    index_phase = 0             # ... at this position (and +/- periods)
    neg_stop = -60000           # mechanical ends (hard stops), beyond the limits
    pos_stop = 60000
    probe = [2000, 2100]        # touch probe input 1 active in this closed range (probe2: DI5)
    params = { "6099:01" = 20000, "6099:02" = 2000 }   # written by SDO at start-up
    layout = "fixed"            # or "mapping": the image is the drive's PDO mapping

    [pto.0]                     # the Position Control wizard of Q0.0 (docs/pto-wizard.md)
    max_speed = 20000
    ss_speed = 200
    accel_ms = 500
    decel_ms = 500
    hsc = true
    [[pto.0.profile]]
    mode = "relative"
    steps = [ { speed = 5000, pulses = 20000 } ]
    [pwm.1]                     # the PWM wizard of Q0.1
    time_base = "us"

    [port.0]                    # the CPU's port 0 (docs/ports.md, plcrt.devices.portdev)
    address = 2                 # PPI station address
    [[port.0.reply]]            # a scripted device answers a request
    request = "01 03 00 00 00 01 84 0A"
    reply = "01 03 02 00 2A 38 5B"
    delay_ms = 5
    [ethernet]                  # GET/PUT
    ip = "192.168.2.10"

    [machine.conveyor]          # a machine (docs/machines.md, plcrt.devices.machines)
    inputs = { eye_entry = "I1.0" }     # its signals' addresses (others: the defaults)
    faults = ["jam"]

Only this module reads the format; it returns plain dataclasses that the
device implementations consume.  Every problem is a PlcConfigError naming
the file and the key.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import PlcConfigError, PlcError
from ..safetext import printable, shown_value
from ..lang.limits import file_limit, read_capped
from .cia402.coupler import IMAGE_BYTES
from .keys import checked_table
from .em253.axis import AxisPlant
from .portdev import EthernetConfig, PortConfig, parse_ethernet, parse_ports
from .ptowizard.config import PtoConfig, PwmConfig, check_outputs, parse_pto, parse_pwm

KINDS = ("EM253", "FIELDBUS")
EVENT_INPUTS = ("STF",)
_AXIS_KEYS = {"start", "rps", "limit_neg", "limit_pos", "z_period", "z_offset", "events"}
_MODULE_KEYS = {"EM253": {"kind", "axis"},
                "FIELDBUS": {"kind", "v", "cycle_ms", "drive"}}
_DRIVE_KEYS = {"model", "image", "neg_limit", "pos_limit", "home_switch", "index_period",
               "index_phase", "neg_stop", "pos_stop", "probe", "probe2", "params", "layout"}
#: FIELDBUS image layouts: the module's fixed object set, or the drive's PDO mapping
LAYOUTS = ("fixed", "mapping")
_PARAM_RE = re.compile(r"(?:0x)?([0-9A-Fa-f]{4})(?::(?:0x)?([0-9A-Fa-f]{1,2}))?h?")


@dataclass
class DriveConfig:
    """One CiA 402 drive on a fieldbus module (node address, model, V image)."""

    node: int
    model: str
    image: int                                   #: first VB of its 64-byte image
    plant: dict[str, Any] = field(default_factory=dict)   #: DrivePlant keywords
    params: list[tuple[int, int, int, str]] = field(default_factory=list)
    where: str = field(default="", compare=False)   #: file and key, for messages
    layout: str = "fixed"                        #: "fixed" objects or the drive's "mapping"


@dataclass
class ModuleConfig:
    slot: int
    kind: str = "EM253"
    axes: dict[int, AxisPlant] = field(default_factory=dict)
    drives: dict[int, DriveConfig] = field(default_factory=dict)
    v: int = 1000                                #: FIELDBUS: first VB of the images
    cycle_us: int = 1000                         #: FIELDBUS: bus cycle
    where: str = field(default="", compare=False)


@dataclass
class Plant:
    modules: dict[int, ModuleConfig]
    file: str = "<plant>"
    #: CPU input bit number (I0.0 = 0, I1.2 = 10) -> output bit number (Q0.0 = 0, Q1.1 = 9)
    wiring: dict[int, int] = field(default_factory=dict)
    #: encoder signals: dicts of plcrt.engine.hsc.Encoder's arguments
    encoders: list[dict[str, Any]] = field(default_factory=list)
    #: the Position Control wizard's configuration of Q0.0 / Q0.1 ([pto.N])
    pto: dict[int, PtoConfig] = field(default_factory=dict)
    #: the PWM wizard's time base of Q0.0 / Q0.1 ([pwm.N])
    pwm: dict[int, PwmConfig] = field(default_factory=dict)
    #: first-order processes between an AQW and an AIW ([[cpu.process]])
    processes: list[dict[str, Any]] = field(default_factory=list)
    #: the real-time clock's reading at power-up (None: the default date)
    clock: Any = None
    #: the communication ports' set-up and devices ([port.N], plcrt.devices.portdev)
    ports: dict[int, PortConfig] = field(default_factory=dict)
    #: the Ethernet interface for GET/PUT ([ethernet])
    ethernet: EthernetConfig | None = None
    #: retentive ranges and start-up mode ([cpu] retentive, startup), or None
    system: Any = None
    #: the machines ([machine.NAME], plcrt.devices.machines)
    machines: list[Any] = field(default_factory=list)


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


def _keys(keys: set[Any]) -> str:
    """Unknown keys for a message: texts escaped, anything else (a dict
    given from Python may have any keys) shown by its value."""
    return ", ".join(sorted(printable(k) if isinstance(k, str) else shown_value(k)
                            for k in keys))


def _int(v: Any, where: str) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise PlcConfigError(f"{where} must be an integer, got {shown_value(v)}")
    return v


def _build(data: dict, file: str) -> Plant:
    modules: dict[int, ModuleConfig] = {}
    # A misspelt table ([modules.0]) would otherwise give a plant without
    # modules and only run-time warnings: reject unknown keys at every level.
    unknown = set(data) - {"module", "cpu", "pto", "pwm", "port", "ethernet", "machine"}
    if unknown:
        raise PlcConfigError(f"{file}: unknown key(s) {_keys(unknown)} "
                             f"(a plant file has [module.N] tables, a [cpu] table, "
                             f"[pto.N] / [pwm.N] tables, [port.N] tables, an [ethernet] "
                             f"table and [machine.NAME] tables)")
    ports = parse_ports(data.get("port", {}), file)
    ethernet = parse_ethernet(data["ethernet"], file) if "ethernet" in data else None
    wiring, encoders = _cpu(data.get("cpu", {}), file)
    processes = _processes(data.get("cpu", {}).get("process", []), f"{file}: cpu")
    pto = parse_pto(data.get("pto", {}), file)
    pwm = parse_pwm(data.get("pwm", {}), file)
    check_outputs(pto, pwm, file)
    clock = _clock(data.get("cpu", {}), file)
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
        kind = str(mod.get("kind", "EM253")).upper()
        if kind not in KINDS:
            raise PlcConfigError(f"{where}: unknown module kind {shown_value(kind)} (known: {', '.join(KINDS)})")
        unknown = set(mod) - _MODULE_KEYS[kind]
        if unknown:
            raise PlcConfigError(f"{where}: unknown key(s) {_keys(unknown)} "
                                 f"(a {kind} module has {', '.join(sorted(_MODULE_KEYS[kind]))})")
        cfg = ModuleConfig(slot, kind, where=where)
        if kind == "FIELDBUS":
            _fieldbus(cfg, mod, where, key)
            modules[slot] = cfg
            continue
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
                raise PlcConfigError(f"{awhere}: unknown key(s) {_keys(unknown)}")
            cfg.axes[int(akey)] = _axis(ax, awhere)
        modules[slot] = cfg
    plant = Plant(modules, file, wiring, encoders, pto, pwm, processes, clock, ports, ethernet,
                  system=_system(data.get("cpu", {}), file))
    if "machine" in data:
        from .machines import parse as parse_machines   # perf: only for a plant with machines
        taken = {("I", b): "cpu.wire/encoder" for b in (*wiring, *(
            x for e in encoders for x in (e["a"], e["b"]) if x is not None))}
        taken.update({("AIW", p["input"] // 2): "cpu.process" for p in processes})
        plant.machines = parse_machines(data["machine"], file, taken)
    return plant


_BIT_RE = re.compile(r"\s*([IQ])(\d{1,2})\.([0-7])\s*", re.I)


def _cpu(cpu: Any, file: str) -> tuple[dict[int, int], list[dict[str, Any]]]:
    """``[cpu] wire = { "I0.0" = "Q0.0" }``: an output of the CPU drives one
    of its inputs (the bench set-up of a PTO counted by a high-speed counter,
    or an output that triggers an edge interrupt)."""
    where = f"{file}: cpu"
    if not isinstance(cpu, dict):
        raise PlcConfigError(f"{where} must be a table")
    unknown = set(cpu) - {"wire", "encoder", "process", "clock", "retentive", "startup"}
    if unknown:
        raise PlcConfigError(f"{where}: unknown key(s) {_keys(unknown)} "
                             f"(known: wire, encoder, process, clock, retentive, startup)")
    wire = cpu.get("wire", {})
    if not isinstance(wire, dict):
        raise PlcConfigError(f"{where}.wire must be a table {{ \"I0.0\" = \"Q0.0\" }}")
    out: dict[int, int] = {}
    for dst, src in wire.items():
        inp = _input(dst, f"{where}.wire")
        m_out = _BIT_RE.fullmatch(str(src))
        if m_out is None or m_out.group(1).upper() != "Q" or int(m_out.group(2)) > 1:
            raise PlcConfigError(f"{where}.wire: {str(dst)} takes one of the CPU's outputs "
                                 f"Q0.0..Q1.7, got {str(src)[:20]!r}")
        out[inp] = int(m_out.group(2)) * 8 + int(m_out.group(3))
    return out, _encoders(cpu.get("encoder", []), where, out)


def _clock(cpu: dict, file: str) -> Any:
    """``[cpu] clock = "2026-12-02T08:00:00"`` (a TOML string or local
    date-time): the real-time clock at power-up, checked here."""
    if "clock" not in cpu:
        return None
    from ..engine.clock import start_time
    return start_time(cpu["clock"], f"{file}: cpu.clock")


def _system(cpu: dict, file: str) -> Any:
    """``[cpu] retentive = ["VB0:100", ...]`` and ``startup = "STOP"``: what a
    project's system block would set (docs/retentive.md), or None."""
    if "retentive" not in cpu and "startup" not in cpu:
        return None
    from ..memory.system import SystemSettings, parse_ranges, parse_startup
    ranges = parse_ranges(cpu["retentive"], f"{file}: cpu.retentive") \
        if "retentive" in cpu else None
    startup = parse_startup(cpu["startup"], f"{file}: cpu.startup") \
        if "startup" in cpu else None
    return SystemSettings(ranges, startup, source=file)


_ENCODER_KEYS = {"inputs", "hz", "start", "stop", "direction"}
_PROCESS_KEYS = {"output", "input", "gain", "offset", "tau", "dead_time", "start", "range"}
_ANALOG_RE = re.compile(r"\s*(AIW|AQW)(\d{1,2})\s*", re.I)


def _analog(text: Any, kind: str, where: str) -> int:
    """The byte offset of an analog word ``AIW0`` / ``AQW2`` (even, 0..62)."""
    m = _ANALOG_RE.fullmatch(str(text))
    if m is None or m.group(1).upper() != kind or int(m.group(2)) % 2 or int(m.group(2)) > 62:
        raise PlcConfigError(f"{where} must be an analog word {kind}0, {kind}2 .. {kind}62, "
                             f"got {str(text)[:20]!r}")
    return int(m.group(2))


def _number(v: Any, where: str, lo: float, hi: float) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
            or not lo <= v <= hi:
        raise PlcConfigError(f"{where} must be a number in {lo:g}..{hi:g}, got {shown_value(v)}")
    return float(v)


def _processes(raw: Any, where: str) -> list[dict[str, Any]]:
    """``[[cpu.process]]``: a first-order process from an AQW to an AIW
    (:mod:`plcrt.devices.process`)."""
    if not isinstance(raw, list):
        raise PlcConfigError(f"{where}.process must be an array of tables ([[cpu.process]])")
    out: list[dict[str, Any]] = []
    inputs: set[int] = set()
    for i, p in enumerate(raw):
        pw = f"{where}.process[{i}]"
        checked_table(p, pw, _PROCESS_KEYS, ("output", "input", "tau"))
        cfg = {"output": _analog(p["output"], "AQW", f"{pw}.output"),
               "input": _analog(p["input"], "AIW", f"{pw}.input"),
               "gain": _number(p.get("gain", 1.0), f"{pw}.gain", -1e6, 1e6),
               "offset": _number(p.get("offset", 0), f"{pw}.offset", -32768, 32767),
               "tau": _number(p["tau"], f"{pw}.tau", 1e-6, 1e6),
               "dead_time": _number(p.get("dead_time", 0.0), f"{pw}.dead_time", 0, 3600)}
        rng = p.get("range", [0, 32000])
        if (not isinstance(rng, list) or len(rng) != 2
                or any(isinstance(x, bool) or not isinstance(x, int) for x in rng)
                or not -32768 <= rng[0] < rng[1] <= 32767):
            raise PlcConfigError(f"{pw}.range must be [low, high], whole counts in "
                                 f"-32768..32767, got {shown_value(rng)}")
        cfg["range"] = (rng[0], rng[1])
        cfg["start"] = _number(p.get("start", cfg["offset"]), f"{pw}.start", -32768, 32767)
        if cfg["input"] in inputs:
            raise PlcConfigError(f"{pw}.input: AIW{cfg['input']} is already driven by "
                                 f"another process")
        inputs.add(cfg["input"])
        out.append(cfg)
    return out


def _input(text: Any, where: str) -> int:
    m = _BIT_RE.fullmatch(str(text))
    if m is None or m.group(1).upper() != "I" or int(m.group(2)) > 1:
        raise PlcConfigError(f"{where}: {str(text)[:20]!r} is not one of the CPU's inputs "
                             f"I0.0..I1.7")
    return int(m.group(2)) * 8 + int(m.group(3))


def _encoders(raw: Any, where: str, wired: dict[int, int]) -> list[dict[str, Any]]:
    """``[[cpu.encoder]]``: inputs = ["I0.0", "I0.1"] (A, and B for
    quadrature), hz (cycles per second), start / stop (s), direction "up" |
    "down" (A leads B, or B leads A)."""
    if not isinstance(raw, list):
        raise PlcConfigError(f"{where}.encoder must be an array of tables ([[cpu.encoder]])")
    out, used = [], set(wired)
    for i, enc in enumerate(raw):
        ew = f"{where}.encoder[{i}]"
        checked_table(enc, ew, _ENCODER_KEYS)
        inputs = enc.get("inputs")
        if not isinstance(inputs, list) or not 1 <= len(inputs) <= 2:
            raise PlcConfigError(f"{ew}.inputs must be [\"I0.0\"] or [\"I0.0\", \"I0.1\"] "
                                 f"(A, and B for quadrature)")
        bits = [_input(x, f"{ew}.inputs") for x in inputs]
        for b in bits:
            if b in used:
                raise PlcConfigError(f"{ew}.inputs: I{b // 8}.{b % 8} is already driven "
                                     f"(a wire or another encoder)")
            used.add(b)
        hz = enc.get("hz")
        if isinstance(hz, bool) or not isinstance(hz, int) or not 1 <= hz <= 1_000_000:
            raise PlcConfigError(f"{ew}.hz must be a whole number of cycles per second, "
                                 f"1..1000000, got {shown_value(hz)}")
        times = []
        for key in ("start", "stop"):
            v = enc.get(key, 0.0 if key == "start" else None)
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))
                                  or not math.isfinite(v) or v < 0
                                  or not math.isfinite(v * 1e6)):
                raise PlcConfigError(f"{ew}.{key} must be seconds (0 or more), got {shown_value(v)}")
            times.append(None if v is None else int(round(v * 1e6)))
        if times[1] is not None and times[1] < times[0]:
            raise PlcConfigError(f"{ew}: stop is before start")
        direction = enc.get("direction", "up")
        if direction not in ("up", "down"):
            raise PlcConfigError(f"{ew}.direction must be \"up\" or \"down\", got "
                                 f"{str(direction)[:20]!r}")
        out.append({"a": bits[0], "b": bits[1] if len(bits) > 1 else None, "hz": hz,
                    "start": times[0], "stop": times[1],
                    "direction": 1 if direction == "up" else -1})
    return out


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
            raise PlcConfigError(f"{ew}: value must be true or false, got {shown_value(value)}")
        if not math.isfinite(at):
            raise PlcConfigError(f"{ew}: at must be a finite number of seconds, got {at}")
        if name not in EVENT_INPUTS or at < 0:
            raise PlcConfigError(f"{ew}: input must be one of {EVENT_INPUTS}, at >= 0")
        p.events.append((int(round(at * 1e6)), name, bool(value)))
    p.events.sort()
    return p


def _fieldbus(cfg: ModuleConfig, mod: dict, where: str, key: str) -> None:
    """A FIELDBUS module: its V area, bus cycle and drives."""
    cfg.v = _int(mod.get("v", 1000), f"{where}.v")
    if cfg.v < 0:
        raise PlcConfigError(f"{where}.v must be a V byte address (0 or more), got {cfg.v}")
    cycle = mod.get("cycle_ms", 1)
    if isinstance(cycle, bool) or not isinstance(cycle, (int, float)) or not math.isfinite(cycle):
        raise PlcConfigError(f"{where}.cycle_ms must be a number of milliseconds, got {shown_value(cycle)}")
    cfg.cycle_us = int(round(cycle * 1000))
    if not 125 <= cfg.cycle_us <= 100_000 or cycle * 1000 != cfg.cycle_us:
        raise PlcConfigError(f"{where}.cycle_ms must be a whole number of µs from 0.125 to "
                             f"100 ms, got {shown_value(cycle)}")
    drives = mod.get("drive", {})
    if not isinstance(drives, dict) or not drives:
        raise PlcConfigError(f"{where}: a FIELDBUS module needs drives "
                             f"([module.{key}.drive.1] with model = ...)")
    nodes = []
    for dkey, d in drives.items():
        dwhere = f"{where}.drive.{dkey}"
        if not str(dkey).isdigit() or not 1 <= int(dkey) <= 127:
            raise PlcConfigError(f"{dwhere}: the node address must be 1..127")
        if not isinstance(d, dict):
            raise PlcConfigError(f"{dwhere} must be a table")
        nodes.append((int(dkey), d, dwhere))
    taken: list[tuple[int, str]] = []
    next_free = cfg.v
    for node, d, dwhere in sorted(nodes, key=lambda n: n[0]):
        cfg.drives[node] = dc = _drive(node, d, dwhere, next_free)
        for other, owhere in taken:
            if abs(other - dc.image) < IMAGE_BYTES:
                raise PlcConfigError(
                    f"{dwhere}.image: VB{dc.image}..VB{dc.image + IMAGE_BYTES - 1} overlaps "
                    f"the image of {owhere} at VB{other} ({IMAGE_BYTES} bytes each)")
        taken.append((dc.image, dwhere))
        next_free = max(next_free, dc.image + IMAGE_BYTES)


def _drive(node: int, d: dict, where: str, default_image: int) -> DriveConfig:
    unknown = set(d) - _DRIVE_KEYS
    if unknown:
        raise PlcConfigError(f"{where}: unknown key(s) {_keys(unknown)} "
                             f"(known: {', '.join(sorted(_DRIVE_KEYS))})")
    model = d.get("model")
    if not isinstance(model, str):
        raise PlcConfigError(f"{where}.model must name a drive model "
                             f"(plcrt cia402 models lists them)")
    image = _int(d.get("image", default_image), f"{where}.image")
    if image < 0:
        raise PlcConfigError(f"{where}.image must be a V byte address, got {image}")
    plant: dict[str, Any] = {}
    for k in ("neg_limit", "pos_limit", "index_period", "index_phase", "neg_stop", "pos_stop"):
        if k in d:
            plant[k] = _int(d[k], f"{where}.{k}")
    for k in ("home_switch", "probe", "probe2"):      # closed ranges (cia402.plant)
        if k not in d:
            continue
        r = d[k]
        if not (isinstance(r, list) and len(r) == 2):
            raise PlcConfigError(f"{where}.{k} must be [low, high]")
        plant[k] = (_int(r[0], f"{where}.{k}"), _int(r[1], f"{where}.{k}"))
    params = []
    raw = d.get("params", {})
    if not isinstance(raw, dict):
        raise PlcConfigError(f"{where}.params must be a table {{ \"6099:01\" = 20000 }}")
    for name, value in raw.items():
        m = _PARAM_RE.fullmatch(name.strip())
        if m is None:
            raise PlcConfigError(f"{where}.params: {shown_value(name)} is no object address "
                                 f"(write INDEX:SUB in hex, e.g. \"6099:01\")")
        params.append((int(m.group(1), 16), int(m.group(2) or "0", 16),
                       _int(value, f"{where}.params.{name}"), f"{where}.params.{name}"))
    layout = d.get("layout", "fixed")
    if layout not in LAYOUTS:
        raise PlcConfigError(f"{where}.layout must be one of {', '.join(map(repr, LAYOUTS))}, "
                             f"got {shown_value(layout)}")
    return DriveConfig(node, model, image, plant, params, where, layout)
