"""Putting plcrt's layers together: the one module that knows them all.

What it is: the composition root.  It fits the engine with the parts of
the layers above it (:func:`plcrt.parts.supply`): which device each
module kind of a plant builds, the devices a plant puts at the
communication ports, what a parsed plant is, and the library blocks'
compiler hooks (:mod:`plcrt.blocks.call`).  And :func:`load`, the public
``plcrt.load``: read a program with its symbol table, data block and plant
file, and build a :class:`~plcrt.engine.runtime.Plc` of it (the CLI and
``Harness.load`` use it too).  ``plcrt/__init__.py`` hands the engine the
import of this module as its parts loader, so a ``Plc`` built any way
(``plcrt.Plc(...)``, a fork, the harness) is fitted the same.

What it is not: the engine, the file readers (:mod:`plcrt.lang.sources`,
:mod:`plcrt.devices.plant`) or the devices.  Nothing in plcrt below the
presentation layer imports it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

from .blocks.call import library_call, protected_call
from .compiler.cache import gc_paused
from .engine.device import Device
from .parts import Parts, supply
from .engine.runtime import Plc, parse_sources
from .engine.values import check_load_options, source_items
from .lang.limits import file_limit
from .lang.sources import read_program
from .project import frontend as _project  # noqa: F401  registers the .mwp/.smart reader
from .memory import cpu_model

__all__ = ["Plc", "build_devices", "attach_port_devices", "is_plant", "load", "parse_sources"]


def is_plant(x: Any) -> bool:
    """Whether *x* is a parsed plant (:class:`plcrt.devices.plant.Plant`)."""
    # perf: the plant reader (and the drives it knows) is imported when a
    # plant is given, not for every program
    from .devices.plant import Plant
    return isinstance(x, Plant)


def build_devices(plc: Any, plant: Any) -> list[Device]:
    """The devices a plant describes: its modules by slot (a table of
    module kinds), then its processes, then its machines."""
    # perf: the modules' simulations are imported when a plant is built
    from .devices.cia402.coupler import FieldbusModule
    from .devices.em253.module import EM253Module
    from .devices.process import FirstOrderProcess
    kinds = {"EM253": EM253Module, "FIELDBUS": FieldbusModule}
    devices = [kinds[m.kind](plc, m) for _, m in sorted(plant.modules.items())]
    devices += [FirstOrderProcess(plc, p) for p in plant.processes]
    if plant.machines:
        from .devices.machines import build
        devices += [build(plc, m) for m in plant.machines]
    return devices


def attach_port_devices(ports: list[Any], plant: Any) -> None:
    """Put the plant's devices at the ports: a scripted device, a Modbus
    slave or master, a USS bus (each ``[port.N]`` holds at most one)."""
    # perf: a port device's module is imported when a plant puts one there
    for k, cfg in (getattr(plant, "ports", None) or {}).items():
        if cfg.device is not None:
            from .devices.portdev import ScriptedDevice
            ScriptedDevice(cfg.device).attach(ports[k])
        elif cfg.modbus is not None:
            from .devices.modbus.slave import ModbusSlave
            ModbusSlave(cfg.modbus).attach(ports[k])
        elif getattr(cfg, "uss", None) is not None:
            from .devices.uss.drive import UssBus
            UssBus(cfg.uss).attach(ports[k])
        elif getattr(cfg, "modbus_master", None) is not None:
            from .devices.modbus.plantmaster import PlantMaster
            PlantMaster(cfg.modbus_master).attach(ports[k])


supply(Parts(is_plant=is_plant, build_devices=build_devices,
             attach_port_devices=attach_port_devices,
             compile_hooks={"library_call": library_call, "protected_call": protected_call}))


def load(source: str | Path | Sequence[str | Path], *, symbols: Any = None,
         data: Any = None, scan_ms: float = 10.0, cpu: str | None = None,
         encoding: str | None = None, **kw: Any) -> Plc:
    """Parse, compile and bind a program.

    Args:
        source: a path to a ``.awl`` file, program text (anything with a
            newline), or a list of them whose blocks are merged.
        symbols: path or text of a symbol table, or a parsed table.
        data: path or text of a data block, or a parsed one.
        scan_ms: simulated scan time in milliseconds, a whole number of
            microseconds from 0.001 to 60000 (``0.0015`` is refused, not
            rounded).
        cpu: CPU model name (default CPU 226).
        encoding: text encoding of the files (``"cp1252"``, ``"gbk"``,
            ``"utf-8"`` ...); by default it is detected, one for all files
            where one fits (:mod:`plcrt.lang.encoding`).
        library: accept a program without OB1 (a subroutine library: it
            compiles, a scan runs nothing); without it such a program, or an
            empty one, is a :class:`PlcCompileError`.
        max_file_mb: the largest program, symbol or data file read, in MB
            (default: :data:`plcrt.lang.limits.MAX_FILE_MB`).
        clock: the real-time clock's reading at power-up (TODR): a
            ``datetime``, a text ``"2026-12-02T08:00:00"`` or ``"now"`` (the
            host's clock); default the plant file's ``[cpu] clock``, else
            2024-01-01 00:00:00 (:mod:`plcrt.engine.clock`).

    Raises:
        PlcSyntaxError, PlcCompileError, PlcConfigError: with locations.
    """
    check_load_options(symbols=symbols, data=data, plant=kw.get("plant"), options=kw)
    plant = kw.pop("plant", None)
    max_file_mb = kw.pop("max_file_mb", None)
    limit = file_limit(max_file_mb)
    if isinstance(plant, (str, Path, dict)):
        plant = read_plant(plant)
    # the CPU's V size, so that data block entries past its end are
    # reported in the same run as the syntax errors
    # perf: parsing and compiling allocate millions of objects that all
    # stay alive; automatic collections would only walk them (gc_paused)
    with gc_paused():
        program, symbols, data = read_program(source_items(source), symbols, data,
                                              encoding=encoding, max_bytes=limit,
                                              v_bytes=cpu_model(cpu).v_bytes)
        plant = _project_plant(plant, program)
        return Plc(program, symbols=symbols, data=data, scan_ms=scan_ms, cpu=cpu, plant=plant,
                   **kw)


def _project_plant(plant: Any, program: Any) -> Any:
    """The plant with the ``[pto.N]`` / ``[pwm.N]`` tables of a project
    file's wizards (``program.project_plant``) for each output the plant
    does not configure itself: a plant file's table replaces the project's
    (docs/project-files.md, "Wizards")."""
    text = getattr(program, "project_plant", "")
    if not text:
        return plant
    # perf: see is_plant
    from dataclasses import replace

    from .devices.plant import load_plant
    from .devices.ptowizard.config import PROJECT_WIZARDS
    wizards = load_plant(text, f"{program.file} {PROJECT_WIZARDS}")
    if plant is None:
        return wizards
    own = set(plant.pto) | set(plant.pwm)
    pto = {n: c for n, c in wizards.pto.items() if n not in own}
    pwm = {n: c for n, c in wizards.pwm.items() if n not in own}
    return replace(plant, pto={**pto, **plant.pto}, pwm={**pwm, **plant.pwm})


def read_plant(plant: str | Path | dict[str, Any]) -> Any:
    """A plant file's path, its TOML text or a dict, parsed
    (:func:`plcrt.devices.plant.load_plant`)."""
    # perf: see is_plant
    from .devices.plant import load_plant
    return load_plant(plant)
