"""A program holding constants (string constants, lookup tables) forks,
snapshots and is recompiled on both backends: the compiler binds its
constants as shared, read-only objects that a fork never copies, and the
twin computes what the original computes.
"""

from __future__ import annotations

import pytest

import plcrt
from plcrt.testing import Harness
from stl_helpers import ob1_text

BACKENDS = ["python", "native"]

#: one program per kind of constant the instruction families bind, and a
#: word it writes from it: (instructions, address read, value after a scan)
CONSTANTS = {
    "string constant (SCPY)": ('SCPY "Pump 1", VB100', "VB100", 6),
    "string compare (LDS=)": ('MOVB 2, VB200\nMOVW 16#4142, VW201\nLDS= "AB", VB200\n= Q0.0',
                              "Q0.0", 1),
    "7-segment table (SEG)": ("MOVB 5, VB0\nSEG VB0, VB1", "VB1", 0x6D),
    "BCD table (BCDI)": ("MOVW 16#1234, VW10\nBCDI VW10", "VW10", 1234),
    "BCD table (IBCD)": ("MOVW 1234, VW12\nIBCD VW12", "VW12", 0x1234),
    "lowest-bit table (ENCO)": ("MOVW 16#0100, VW14\nENCO VW14, VB16", "VB16", 8),
}


def _program(body: str) -> str:
    return ob1_text("LD SM0.0\n" + body)


@pytest.fixture(autouse=True)
def _native_cache(tmp_path, monkeypatch: pytest.MonkeyPatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path))


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("case", sorted(CONSTANTS))
def test_a_program_with_a_constant_forks(case: str, backend: str) -> None:
    """fork(), snapshot()/restore() and Harness.fork() of a program with the
    constant: the twin runs and computes the same value."""
    body, addr, value = CONSTANTS[case]
    plc = plcrt.load(_program(body), backend=backend)
    twin = plc.fork()
    twin.scan()
    assert twin[addr] == value
    snap = plc.snapshot()
    plc.scan()
    assert plc[addr] == value
    plc.restore(snap)
    assert plc.scans == 0
    h = Harness(plcrt.load(_program(body), backend=backend))
    h.scan()
    other = h.fork()
    other.scan()
    assert other[addr] == value


@pytest.mark.parametrize("case", sorted(CONSTANTS))
def test_a_program_with_a_constant_moves_between_backends(case: str) -> None:
    """recompiled() to the other backend keeps the state and the constant."""
    body, addr, value = CONSTANTS[case]
    plc = plcrt.load(_program(body), backend="python")
    plc.scan()
    native = plc.recompiled(backend="native")
    native.scan()
    assert native[addr] == value and native.scans == 2


def test_constants_are_shared_and_state_is_not() -> None:
    """The twins of a fork share the compiler's constants (the same
    objects: nothing to copy) and have their own memory."""
    text = _program("\n".join(body for body, _, _ in CONSTANTS.values()))
    plc = plcrt.load(text)
    twin = plc.fork()
    assert plc.unit.constants, "the program binds constants"
    for name in plc.unit.constants:
        assert twin._bindings[name] is plc._bindings[name]
    twin.scan()
    assert twin["VB100"] == 6 and plc["VB100"] == 0


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_string_constant_program_is_served(backend: str) -> None:
    """What ``plcrt serve`` does with its program: a power-up snapshot, a
    build with probes (breakpoints, coverage) in the same state and back."""
    plc = plcrt.load(_program('SCPY "Pump 1", VB100'), backend=backend)
    power_up = plc.snapshot()
    plc.scan()
    probed = plc.recompiled(instrument=True)
    probed.scan()
    fast = probed.recompiled(instrument=False, backend=backend)
    for twin in (probed, fast):
        assert bytes(twin.read(f"VB{100 + i}") for i in range(7)) == b"\x06Pump 1"
    plc.restore(power_up)
    assert plc["VB100"] == 0


def test_an_immutable_binding_is_a_constant_whoever_binds_it() -> None:
    """The compiler takes bytes and tuples of numbers for constants even
    when an emitter binds them as objects (so a fork never meets them as
    state), and never a tuple holding a buffer."""
    from plcrt.compiler.codegen import Unit
    from plcrt.errors import DiagnosticSink
    from plcrt.lang import ir
    from plcrt.memory.cpu import cpu_model

    unit = Unit(ir.Program((), "<test>"), cpu_model(None), None, {}, DiagnosticSink())
    table, text, state = (1, 2, (3, b"x")), b"\x06Pump 1", (bytearray(2), 0)
    names = [unit.bind(table), unit.bind(text), unit.bind(state), unit.bind(bytearray(1))]
    assert unit.constants == set(names[:2])
