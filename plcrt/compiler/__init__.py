"""Compiler: checked IR -> generated Python module (see :mod:`.codegen`).

``compile_program`` runs resolution, checks and code generation, collects
every diagnostic, and raises one :class:`~plcrt.errors.PlcCompileError`
listing all errors.  It does not bind memory: :class:`plcrt.engine.Plc` does.
"""

from __future__ import annotations

from typing import Any

from ..errors import DiagnosticSink, PlcCompileError
from ..lang import ir
from ..memory.cpu import CpuModel
from .codegen import Compiled, Unit, build_unit, generate


def compile_program(program: ir.Program, model: CpuModel, *, symbols: Any = None,
                    system_symbols: dict[str, str] | None = None,
                    bindings: dict[str, Any] | None = None,
                    setup: Any = None, probes: Any = None) -> tuple[Unit, str, dict]:
    """Check and generate code; returns the unit, module source and line map.

    Args:
        setup: optional callable ``setup(unit)`` run before generation, used by
            the engine to provide run-time objects (timer bank, ...) that
            emitters bind.
        probes: a :class:`plcrt.engine.coverage.CoverageMap` to instrument
            the code for (network and output coverage, breakpoints).

    Raises:
        PlcCompileError: with every error found (warnings ride along).
    """
    diag = DiagnosticSink()
    unit = build_unit(program, model, symbols, system_symbols or {}, diag)
    unit.probes = probes
    if setup is not None:
        setup(unit)
    source, line_locs = generate(unit)
    diag.raise_if_errors(PlcCompileError)
    return unit, source, line_locs


__all__ = ["compile_program", "Compiled", "Unit"]
