"""At the switch to the native build (plcrt/engine/tiering.py) a large
program's Python build is freed at once, not at the collector's next run,
and the PLC runs on as before.
"""

from __future__ import annotations

import gc
import weakref

import pytest

import plcrt
from plcrt.compiler.cache import programs
from plcrt.engine import tiering

pytest.importorskip("llvmlite")

PROGRAM = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\n" + "".join(
    f"Network {i}\nLD     I0.{i % 4}\nINCW   VW{2 * (i % 30)}\n=      Q0.{i % 8}\n"
    for i in range(1, 40)) + "END_ORGANIZATION_BLOCK\n"


@pytest.mark.parametrize("least, freed", [(0, True), (10**9, False)])
def test_the_python_build_goes_at_the_switch_from_a_size_on(monkeypatch, least, freed):
    """With the collector off, the Python build is gone right after the
    switch when the program has at least RELEASE_STATEMENTS statements
    (else it waits for the collector: its namespace is a cycle); the
    images equal the Python backend's either way."""
    monkeypatch.setattr(tiering, "RELEASE_STATEMENTS", least)
    py = plcrt.load(PROGRAM, backend="python")
    programs.clear()           # the PLC on auto has a Python build of its own
    plc = plcrt.load(PROGRAM, backend="auto")
    plc.scan(5)
    py.scan(5)
    # the Python build's main function: it and its namespace hold each other
    build = weakref.ref(plc._ob1)
    was = gc.isenabled()
    gc.disable()
    try:
        plc._tier_up()
        assert plc.backend["name"] == "native"
        assert (build() is None) is freed
    finally:
        if was:
            gc.enable()
    for k in range(20):
        for p in (plc, py):
            p.mem.areas["PI"][0] = k % 16
            p.scan()
        assert bytes(plc.mem.areas["V"]) == bytes(py.mem.areas["V"])
        assert bytes(plc.mem.areas["Q"]) == bytes(py.mem.areas["Q"])
    programs.clear()
