"""The engine stays below the devices and the library blocks, and in modules
of a readable size.

Every import is counted, also those inside functions and under
TYPE_CHECKING: the engine reaches what the layers above supply only
through plcrt.parts (docs/architecture.md, "The load path").
"""

from __future__ import annotations

import subprocess
import sys

from import_graph import PLCRT, graph, long_modules

ENGINE = PLCRT / "engine"

#: packages and modules above the engine (or the composition root over all)
ABOVE = ("plcrt.devices", "plcrt.blocks", "plcrt.loader", "plcrt.testing", "plcrt.web",
         "plcrt.debug", "plcrt.cli", "plcrt.view", "plcrt.trace", "plcrt.cia402",
         "plcrt.net", "plcrt.term", "plcrt.dump", "plcrt.cli_commands")


def test_the_engine_imports_nothing_above_it() -> None:
    climbing = {mod: sorted(t for t in targets
                            if any(t == a or t.startswith(a + ".") for a in ABOVE))
                for mod, targets in graph().items() if mod.startswith("plcrt.engine")}
    assert {m: t for m, t in climbing.items() if t} == {}


def test_every_engine_module_is_at_most_500_lines() -> None:
    assert long_modules(ENGINE) == {}


def test_a_plc_built_by_the_engine_alone_is_fitted_with_devices_and_library_blocks() -> None:
    """Plc() straight from plcrt.engine.runtime, in a fresh interpreter that
    never touched plcrt.load: the parts come from the loader plcrt/__init__
    hands plcrt.parts (an EM253 module from the plant, a library block's CALL)."""
    root = ENGINE.parents[1]
    code = f"""
import plcrt.engine.runtime as rt
from plcrt.devices.plant import load_plant
prog = rt.parse_sources({str(root / "programs/em253/pos_goto_r.awl")!r})
plc = rt.Plc(prog, plant=load_plant({str(root / "programs/em253/plant.toml")!r}))
plc.scan(3)
print(type(plc.module(0)).__name__, len(plc.axes()), plc.diagnostics == [])
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["EM253Module", "2", "True"]
