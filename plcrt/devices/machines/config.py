"""The plant file's ``[machine.NAME]`` tables: which machine, its I/O map,
its parameters and the faults on at power-up.

::

    [machine.conveyor]              # the name: a kind, or any name with kind = ...
    kind = "conveyor"               # default: the table's name
    inputs = { eye_entry = "I1.0", start = false }   # signal -> address (false: not wired)
    outputs = { motor = "Q1.0" }
    speed = 250                     # the machine's own parameters (docs/machines.md)
    faults = ["jam", "stuck_on:eye_exit"]

A signal left out keeps its default address (each machine's ``INPUTS`` and
``OUTPUTS`` tables).  Inputs are bits ``I0.0`` .. ``I15.7`` or analog words
``AIW0`` .. ``AIW62``; outputs are bits ``Q0.0`` .. ``Q15.7``.

What it is not: the machines (they read the :class:`MachineConfig` this
module returns); it checks every key and value and raises a
:class:`~plcrt.errors.PlcConfigError` naming the file and the key.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

from ...errors import PlcConfigError
from ...safetext import printable, shown_value

__all__ = ["MachineConfig", "Param", "parse_machines", "parse_address"]

_NAME_RE = re.compile(r"[a-z][a-z0-9_]{0,31}")
_BIT_RE = re.compile(r"\s*([IQ])(\d{1,2})\.([0-7])\s*", re.I)
_WORD_RE = re.compile(r"\s*AIW(\d{1,2})\s*", re.I)
#: the process image's bytes a machine may use (the CPU's own and its
#: expansion modules' inputs and outputs)
IMAGE_BYTES = 16
#: at most this many machines in one plant (each is stepped every scan)
MAX_MACHINES = 16


@dataclass(frozen=True)
class Param:
    """One numeric parameter of a machine: its default and allowed range."""

    default: float
    lo: float
    hi: float
    integer: bool = True
    doc: str = ""
    #: a text parameter: the value must match this regular expression
    text: str = ""


@dataclass
class MachineConfig:
    """One machine of a plant, checked."""

    name: str
    kind: str
    #: signal -> ("I", bit number) | ("AIW", byte offset) | None (not wired)
    inputs: dict[str, tuple[str, int] | None]
    #: signal -> ("Q", bit number) | None
    outputs: dict[str, tuple[str, int] | None]
    params: dict[str, Any]
    faults: list[str] = field(default_factory=list)
    where: str = field(default="", compare=False)


def parse_address(text: Any, kinds: tuple[str, ...], where: str) -> tuple[str, int] | None:
    """``"I0.3"`` -> ("I", 3), ``"Q1.0"`` -> ("Q", 8), ``"AIW2"`` -> ("AIW", 2);
    ``False`` -> None (the signal is not wired)."""
    if text is False:
        return None
    want = " or ".join({"I": "an input bit I0.0..I15.7", "Q": "an output bit Q0.0..Q15.7",
                        "AIW": "an analog input word AIW0, AIW2 .. AIW62"}[k] for k in kinds)
    if isinstance(text, str) and len(text) <= 20:
        m = _BIT_RE.fullmatch(text)
        if m is not None and m.group(1).upper() in kinds and int(m.group(2)) < IMAGE_BYTES:
            return m.group(1).upper(), int(m.group(2)) * 8 + int(m.group(3))
        m = _WORD_RE.fullmatch(text)
        if m is not None and "AIW" in kinds and int(m.group(1)) % 2 == 0 \
                and int(m.group(1)) <= 62:
            return "AIW", int(m.group(1))
    raise PlcConfigError(f"{where} must be {want} (or false: not wired), got {shown_value(text)}")


def show_address(addr: tuple[str, int] | None) -> str:
    """The address as the program writes it (``"I0.3"``, ``"AIW2"``), ``""`` if not wired."""
    if addr is None:
        return ""
    kind, n = addr
    return f"AIW{n}" if kind == "AIW" else f"{kind}{n // 8}.{n % 8}"


def _number(v: Any, p: Param, where: str) -> Any:
    if p.text:
        if not isinstance(v, str) or len(v) > 256 or not re.fullmatch(p.text, v):
            raise PlcConfigError(f"{where} must be text matching {p.text}, got {shown_value(v)}")
        return v
    ok = not isinstance(v, bool) and isinstance(v, (int, float)) and math.isfinite(v) \
        and p.lo <= v <= p.hi and (not p.integer or v == int(v))
    if not ok:
        kind = "a whole number" if p.integer else "a number"
        raise PlcConfigError(f"{where} must be {kind} in {p.lo:g}..{p.hi:g}, "
                             f"got {shown_value(v)}")
    return int(v) if p.integer else float(v)


def _map(raw: Any, defaults: dict[str, str | None], kinds: tuple[str, ...],
         where: str) -> dict[str, tuple[str, int] | None]:
    if not isinstance(raw, dict):
        raise PlcConfigError(f"{where} must be a table {{ signal = \"address\" }}")
    unknown = [k for k in raw if k not in defaults]
    if unknown:
        names = ", ".join(sorted(printable(str(k))[:40] for k in unknown)[:8])
        raise PlcConfigError(f"{where}: unknown signal(s) {names} (known: "
                             f"{', '.join(defaults)})")
    out: dict[str, tuple[str, int] | None] = {}
    for sig, default in defaults.items():
        text = raw.get(sig, default if default is not None else False)
        out[sig] = parse_address(text, kinds, f"{where}.{sig}")
    return out


def parse_machines(raw: Any, file: str, kinds: dict[str, Any],
                   taken: dict[tuple[str, int], str] | None = None) -> list[MachineConfig]:
    """The ``[machine.NAME]`` tables of a plant; *kinds* maps a kind to its
    class (``INPUTS``, ``OUTPUTS``, ``PARAMS``, ``fault_names()``); *taken*:
    the inputs something else of the plant drives, ``("I", bit)`` or
    ``("AIW", byte // 2)`` -> its key."""
    if not isinstance(raw, dict):
        raise PlcConfigError(f"{file}: [machine] must be a table of machines ([machine.conveyor])")
    if len(raw) > MAX_MACHINES:
        raise PlcConfigError(f"{file}: at most {MAX_MACHINES} machines in one plant, "
                             f"got {len(raw)}")
    out: list[MachineConfig] = []
    driven: dict[tuple[str, int], str] = dict(taken or {})
    for name, table in raw.items():
        where = f"{file}: machine.{printable(str(name))[:40]}"
        if not isinstance(name, str) or not _NAME_RE.fullmatch(name):
            raise PlcConfigError(f"{where}: a machine's name is a lower-case word "
                                 f"(a-z, 0-9, _; at most 32 characters)")
        if not isinstance(table, dict):
            raise PlcConfigError(f"{where} must be a table")
        kind = table.get("kind", name)
        if not isinstance(kind, str) or kind not in kinds:
            raise PlcConfigError(f"{where}.kind: unknown machine {shown_value(kind)} "
                                 f"(known: {', '.join(kinds)}); name the table after one "
                                 f"or give kind = ...")
        cls = kinds[kind]
        keys = {"kind", "inputs", "outputs", "faults", *cls.PARAMS}
        unknown = [k for k in table if k not in keys]
        if unknown:
            names = ", ".join(sorted(printable(str(k))[:40] for k in unknown)[:8])
            raise PlcConfigError(f"{where}: unknown key(s) {names} "
                                 f"(known: {', '.join(sorted(keys))})")
        inputs = _map(table.get("inputs", {}), cls.INPUTS, ("I", "AIW"), f"{where}.inputs")
        outputs = _map(table.get("outputs", {}), cls.OUTPUTS, ("Q",), f"{where}.outputs")
        for sig, addr in inputs.items():
            if addr is None:
                continue
            if cls.ANALOG.get(sig, False) != (addr[0] == "AIW"):
                want = "an analog word AIWn" if cls.ANALOG.get(sig) else "an input bit In.m"
                raise PlcConfigError(f"{where}.inputs.{sig} must be {want}, got "
                                     f"{show_address(addr)}")
            key = (addr[0], addr[1] // 2 if addr[0] == "AIW" else addr[1])
            if key in driven:
                raise PlcConfigError(f"{where}.inputs.{sig}: {show_address(addr)} is already "
                                     f"driven by {driven[key]}; map one of them elsewhere")
            driven[key] = f"machine.{name}.inputs.{sig}"
        params = {p: _number(table.get(p, spec.default), spec, f"{where}.{p}")
                  for p, spec in cls.PARAMS.items()}
        cls.check_params(params, where)
        faults = table.get("faults", [])
        if not isinstance(faults, list) or len(faults) > 64:
            raise PlcConfigError(f"{where}.faults must be a list of fault names "
                                 f"(at most 64), got {shown_value(faults)}")
        known = cls.fault_names(inputs, outputs)
        for i, f in enumerate(faults):
            if not isinstance(f, str) or f not in known:
                raise PlcConfigError(f"{where}.faults[{i}]: unknown fault {shown_value(f)} "
                                     f"(the machine's faults: {', '.join(known)})")
        out.append(MachineConfig(name, kind, inputs, outputs, params, list(dict.fromkeys(faults)),
                                 where))
    return out
