"""Differential test: the native backend against the Python backend.

Hypothesis builds programs with the structure the native backend must get
right beside Python code: OB1 with or without a jump and a FOR loop (a block
with flow stays Python), a subroutine called from OB1, and an interrupt
routine on timed interrupt 0 that runs at its exact times inside the scan
interval.  The networks come from the reference test's generator (bit logic,
compares, moves, math, timers, counters, edges, strings, tables), so some
pieces are machine code and some fall back to Python in the same block.
After every scan every memory area of the two PLCs must be equal, and the
hidden timer state as well (its effect shows one scan later).
"""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import plcrt
from plcrt.errors import PlcRuntimeError

from test_differential import (COUNTERS, INITIAL_MEMORY, M_BYTES, SEGMENTS, V_BYTES,
                               draw_network)

pytest.importorskip("llvmlite")

AREAS = ("I", "Q", "PQ", "M", "V", "SM", "S", "TV", "TB", "CV", "CB", "AC")


def _block(head: str, tail: str, networks: list[list[str]]) -> list[str]:
    out = [head, "BEGIN"]
    for i, lines in enumerate(networks, 1):
        out.append(f"Network {i}")
        out.extend(lines)
    return out + [tail]


@st.composite
def structured_programs(draw: st.DrawFn) -> str:
    counters = list(COUNTERS)
    nets = st.integers(1, 3)
    ob1: list[list[str]] = []
    with_int = draw(st.booleans())
    if with_int:
        period = draw(st.sampled_from((1, 3, 7, 25)))
        ob1.append(["LD SM0.1", f"MOVB {period}, SMB34", "ATCH INT_0, 10", "ENI"])
    ob1 += [draw_network(draw, counters) for _ in range(draw(nets))]
    flow = draw(st.booleans())
    if flow:
        # a jump over some networks when I1.1 is on, and a counted loop
        ob1.append(["LD I1.1", "JMP 1"])
        ob1 += [draw_network(draw, counters) for _ in range(draw(nets))]
        ob1.append(["LBL 1"])
        ob1.append(["LD SM0.0", f"FOR VW100, +1, +{draw(st.integers(0, 3))}"])
        ob1.append(draw_network(draw, counters))
        ob1.append(["NEXT"])
    ob1.append(["LD SM0.0", "CALL SBR_0"])
    ob1 += [draw_network(draw, counters) for _ in range(draw(nets))]
    lines = _block("ORGANIZATION_BLOCK MAIN:OB1", "END_ORGANIZATION_BLOCK", ob1)
    sbr = [draw_network(draw, counters) for _ in range(draw(nets))]
    lines += _block("SUBROUTINE_BLOCK SBR_0:SBR0", "END_SUBROUTINE_BLOCK", sbr)
    if with_int:
        isr = [draw_network(draw, counters) for _ in range(draw(nets))]
        lines += _block("INTERRUPT_BLOCK INT_0:INT0", "END_INTERRUPT_BLOCK", isr)
    return "\n".join(lines) + "\n"


def scan_each(plcs, ib0: int, ib1: int) -> list:
    """One scan of every PLC with input bytes IB0/IB1: the fault each
    stopped on (its message), or None.  A drawn loop may run past the
    watchdog; the differential runs want the same fault at the same scan."""
    faults = []
    for plc in plcs:
        plc.mem.areas["PI"][0] = ib0
        plc.mem.areas["PI"][1] = ib1
        try:
            plc.scan()
            faults.append(None)
        except PlcRuntimeError as err:
            faults.append(str(err))
    return faults


def run_both(program: str, inputs, scan_ms: int, initial: bytes) -> None:
    plcs = [plcrt.load(program, scan_ms=scan_ms, backend=b) for b in ("python", "native")]
    for plc in plcs:
        plc.mem.areas["V"][:V_BYTES] = initial[:V_BYTES]
        plc.mem.areas["M"][:M_BYTES] = initial[V_BYTES:]
    py, nat = plcs
    scan = 0
    for ib0, ib1, repeat in inputs:
        for _ in range(repeat):
            faults = scan_each(plcs, ib0, ib1)
            scan += 1
            assert faults[1] == faults[0], f"scan {scan}: faults differ\n{program}"
            for area in AREAS:
                assert bytes(nat.mem.areas[area]) == bytes(py.mem.areas[area]), (
                    f"scan {scan}: {area} differs\n{program}")
            assert (bytes(nat.timers.running), list(nat.timers.preset)) == \
                (bytes(py.timers.running), list(py.timers.preset)), f"scan {scan}: timers"
            assert nat.mode == py.mode
            if faults[0] is not None:
                return      # both stopped on the same fault at the same scan


@settings(max_examples=120, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(program=structured_programs(), inputs=SEGMENTS, initial=INITIAL_MEMORY,
       scan_ms=st.sampled_from((1, 10, 50, 130)))
@example(program="ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD SM0.1\nMOVB 3, SMB34\n"
                 "ATCH INT_0, 10\nENI\nNetwork 2\nLD SM0.0\nCALL SBR_0\n"
                 "END_ORGANIZATION_BLOCK\nSUBROUTINE_BLOCK SBR_0:SBR0\nBEGIN\nNetwork 1\n"
                 "LD I0.0\nTON T37, +3\nLD T37\n= Q0.0\nEND_SUBROUTINE_BLOCK\n"
                 "INTERRUPT_BLOCK INT_0:INT0\nBEGIN\nNetwork 1\nLD SM0.0\nINCW VW2\n"
                 "+I VW2, VW4\nEND_INTERRUPT_BLOCK\n",
         inputs=((1, 0, 30), (0, 0, 3)), initial=bytes(V_BYTES + M_BYTES), scan_ms=50)
def test_native_matches_python_with_calls_jumps_loops_interrupts(program, inputs, initial,
                                                                  scan_ms) -> None:
    run_both(program, inputs, scan_ms, initial)
