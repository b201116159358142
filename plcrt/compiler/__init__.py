"""Compiler: checked IR -> generated Python module (see :mod:`.codegen`).

``compile_program`` runs resolution, checks and code generation, collects
every diagnostic, and raises one :class:`~plcrt.errors.PlcCompileError`
listing all errors.  :func:`plcrt.compiler.program.compile_to_program`
makes of it the compiled program every PLC of it shares; it does not bind
memory: :class:`plcrt.engine.Plc` does.
"""

from __future__ import annotations

from typing import Any

from ..errors import DiagnosticSink, PlcCompileError, PlcError
from ..lang import ir
from ..lang.limits import MAX_INSTRUCTIONS, MAX_NETWORKS
from ..memory.cpu import CpuModel
from .codegen import generate
from .network import plcrt_bug
from .pieces import build_unit
from .unit import Compiled, Unit


def compile_program(program: ir.Program, model: CpuModel, *, symbols: Any = None,
                    system_symbols: dict[str, str] | None = None,
                    hooks: Any = None, plant: Any = None, probes: Any = None,
                    library: bool = False, native: bool = False
                    ) -> tuple[Unit, str, dict]:
    """Check and generate code; returns the unit, module source and line map.

    Args:
        hooks: compile-time hooks of the layers above, by name
            (``library_call``, ``protected_call``: :mod:`plcrt.parts`).
        plant: the parsed plant the program is compiled for (what the
            library blocks' load-time checks read), or None.
        probes: a :class:`plcrt.engine.coverage.CoverageMap` to instrument
            the code for (network and output coverage, breakpoints).
        library: accept a program without OB1 (a subroutine library, for
            checking only); otherwise that is an error.
        native: also plan the native backend's segments
            (:mod:`plcrt.compiler.native`; ``unit.native`` holds the plan),
            probes included.

    Raises:
        PlcCompileError: with every error found (warnings ride along).
    """
    _check_size(program)
    diag = DiagnosticSink()
    unit = build_unit(program, model, symbols, system_symbols or {}, diag, library=library)
    unit.probes = probes
    if native:
        from .native import NativePlan
        unit.native = NativePlan()
    unit.plant = plant
    unit.hooks.update(hooks or {})
    try:
        source, line_locs = generate(unit)
    except PlcError:
        raise
    except Exception as e:  # noqa: BLE001 - a plcrt bug outside one instruction
        # (an instruction's own is reported at it by emit_piece): at the
        # network being compiled, with everything found before it
        piece = unit.current_piece
        loc = None if piece is None else \
            piece.network.loc.within(piece.pou.ident, piece.network.number)
        diag.error(plcrt_bug("this network", e), loc, "plcrt-bug")
        diag.raise_if_errors(PlcCompileError)
        raise   # unreachable: the error above is raised
    diag.raise_if_errors(PlcCompileError)
    return unit, source, line_locs


def _check_size(program: ir.Program) -> None:
    """Refuse a program too big to compile in bounded memory (compiling
    costs several kilobytes per instruction and network), at its first
    network or instruction past :data:`~plcrt.lang.limits.MAX_NETWORKS` or
    :data:`~plcrt.lang.limits.MAX_INSTRUCTIONS`."""
    networks = program.network_count()
    if networks > MAX_NETWORKS:
        net = [n for p in program.pous for n in p.networks][MAX_NETWORKS]
        raise PlcCompileError(f"the program has {networks} networks, more than plcrt "
                              f"compiles ({MAX_NETWORKS})", net.loc)
    if program.instruction_count() <= MAX_INSTRUCTIONS:
        return
    count = 0
    for pou in program.pous:
        for net in pou.networks:
            count += len(net.insns)
            if count > MAX_INSTRUCTIONS:
                loc = net.insns[len(net.insns) - (count - MAX_INSTRUCTIONS)].loc
                raise PlcCompileError(
                    f"the program has {program.instruction_count()} instructions, more "
                    f"than plcrt compiles ({MAX_INSTRUCTIONS}); the largest S7-200 holds "
                    f"a few thousand", loc)
    raise AssertionError("unreachable")


__all__ = ["compile_program", "Compiled", "Unit"]
