"""Helpers of the machine tests: the example programs and a bare program
whose outputs the test sets (VB0 is copied to QB0 every scan)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import plcrt

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples" / "machines"

#: the program copies VB0 to the outputs QB0: a test drives the machine's
#: outputs by writing VB0
MANUAL = """ORGANIZATION_BLOCK MAIN:OB1
BEGIN
Network 1
LD     SM0.0
MOVB   VB0, QB0
END_ORGANIZATION_BLOCK
"""


def manual(kind: str, scan_ms: float = 10.0, name: str | None = None,
           **params: Any) -> tuple[plcrt.Plc, Any]:
    """A PLC whose outputs the test sets through VB0, with one machine."""
    plant = {"machine": {name or kind: {"kind": kind, **params}}}
    plc = plcrt.load(MANUAL, plant=plant, scan_ms=scan_ms)
    return plc, plc.machine(name or kind)


def example(kind: str, **params: Any) -> tuple[plcrt.Plc, Any]:
    """The example program of *kind* with its machine (default wiring)."""
    plant = {"machine": {kind: params}}
    plc = plcrt.load(EXAMPLES / f"{kind}.awl", plant=plant)
    return plc, plc.machine(kind)


def outputs(plc: plcrt.Plc, m: Any, **levels: int) -> None:
    """Set the machine's outputs (by signal name) through VB0."""
    wiring = m.wiring()
    value = 0
    for sig, on in levels.items():
        addr = wiring[sig]
        assert addr.startswith("Q0."), addr
        value |= int(bool(on)) << int(addr[3])
    plc["VB0"] = value
