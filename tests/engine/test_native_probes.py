"""Differential test: instrumented builds, native against Python.

An instrumented program (``instrument=True``: ``--plc-coverage``, ``plcrt
debug``, the panel with a breakpoint) runs its probes as machine code on
the native backend.  Hypothesis draws programs from the generators of
test_differential.py (flat OB1s) and test_backends.py (a subroutine, jumps,
a FOR loop, a timed interrupt), loads each on both backends with probes
and breakpoints on some of its networks, and after every scan the memory
and the coverage counts (networks, rung outcomes, contacts) must be equal;
the breakpoints must stop before the same networks in the same scans, with
the same memory at each stop.
"""

from __future__ import annotations

import hashlib

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import plcrt

from test_backends import AREAS, scan_each, structured_programs
from test_differential import INITIAL_MEMORY, M_BYTES, SEGMENTS, V_BYTES, programs

pytest.importorskip("llvmlite")

MAX_SCANS = 40


def _stop(plc, stops: list, net) -> None:
    """What a stop is: the network, the scan in progress and the memory
    the network is about to read."""
    image = hashlib.sha256(b"".join(bytes(plc.mem.areas[a]) for a in AREAS)).hexdigest()
    stops.append((net.name, plc.scans, image))


def run_probed(program: str, inputs, scan_ms: int, initial: bytes, breaks: list[int]) -> list:
    py, nat = (plcrt.load(program, scan_ms=scan_ms, backend=b, instrument=True)
               for b in ("python", "native"))
    assert nat.coverage.networks == py.coverage.networks
    nets = len(py.coverage.networks)
    stops: dict[str, list] = {"python": [], "native": []}
    for name, plc in (("python", py), ("native", nat)):
        plc.mem.areas["V"][:V_BYTES] = initial[:V_BYTES]
        plc.mem.areas["M"][:M_BYTES] = initial[V_BYTES:]
        for k in breaks:
            plc.coverage.breakpoints[k % nets] = 1
        plc.coverage.on_break = (lambda net, plc=plc, s=stops[name]: _stop(plc, s, net))
    scan = 0
    for ib0, ib1, repeat in inputs:
        for _ in range(repeat):
            if scan >= MAX_SCANS:
                break
            faults = scan_each((py, nat), ib0, ib1)
            scan += 1
            assert faults[1] == faults[0], f"scan {scan}: faults differ\n{program}"
            for area in AREAS:
                assert bytes(nat.mem.areas[area]) == bytes(py.mem.areas[area]), (
                    f"scan {scan}: {area} differs\n{program}")
            assert nat.coverage.data() == py.coverage.data(), f"scan {scan}\n{program}"
            assert stops["native"] == stops["python"], f"scan {scan}\n{program}"
            assert nat.mode == py.mode
            if faults[0] is not None:
                return stops["native"]   # both stopped on the same fault at the same scan
    return stops["native"]


BREAKS = st.lists(st.integers(0, 40), max_size=3)


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(program=programs(), inputs=SEGMENTS, initial=INITIAL_MEMORY,
       scan_ms=st.sampled_from((10, 100, 1000)), breaks=BREAKS)
def test_probed_native_matches_probed_python(program, inputs, initial, scan_ms,
                                             breaks) -> None:
    run_probed(program, inputs, scan_ms, initial, breaks)


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(program=structured_programs(), inputs=SEGMENTS, initial=INITIAL_MEMORY,
       scan_ms=st.sampled_from((1, 10, 50, 130)), breaks=BREAKS)
def test_probed_native_matches_with_calls_jumps_loops_interrupts(program, inputs, initial,
                                                                 scan_ms, breaks) -> None:
    run_probed(program, inputs, scan_ms, initial, breaks)


def test_the_differential_run_sees_breaks_and_counts() -> None:
    """The comparison above is not empty: a break in every scan."""
    text = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\n"
            "Network 2\nLD I0.1\nINCW VW0\nEND_ORGANIZATION_BLOCK\n")
    stops = run_probed(text, ((1, 0, 2), (2, 0, 3)), 10, bytes(V_BYTES + M_BYTES), [1])
    assert [s[:2] for s in stops] == [("OB1/2", k) for k in range(5)]


def test_probed_pieces_run_as_machine_code() -> None:
    """The probes do not keep a piece in Python: a program the native
    backend lowers whole stays whole with probes."""
    text = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\nA I0.1\nEU\n= Q0.0\n"
            "Network 2\nLDW>= VW0, 5\nON I0.2\nMOVW VW0, VW2\nTON T37, +4\n"
            "END_ORGANIZATION_BLOCK\n")
    plain = plcrt.load(text, backend="native").backend
    probed = plcrt.load(text, backend="native", instrument=True).backend
    assert plain["python"] == probed["python"] == []
    assert plain["pieces"] == probed["pieces"] == 2
