"""Command start-up stays cheap: ``plcrt --help`` and a usage error import
neither the parser generator (lark), the compiler, the engine nor numpy.

Timing is not tested (a shared machine makes it flaky); what makes start-up
slow is importing those modules, and that is what these tests pin: each
runs the command line in a fresh interpreter and lists the modules loaded.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

#: modules (and packages, with their submodules) that --help must not load
HEAVY = ("lark", "numpy", "aiohttp", "canopen", "rich", "plcrt.compiler", "plcrt.lang",
         "plcrt.engine.runtime", "plcrt.memory", "plcrt.view.ladder", "plcrt.trace.recorder",
         "plcrt.debug.session", "plcrt.web.server")

_PROBE = """
import json, sys
import plcrt.cli
status = plcrt.cli.main({argv!r})
print(json.dumps({{"status": status, "modules": sorted(sys.modules)}}))
"""


def _loaded(argv: list[str]) -> tuple[int, list[str]]:
    out = subprocess.run([sys.executable, "-c", _PROBE.format(argv=argv)],
                         capture_output=True, text=True, check=True).stdout
    result = json.loads(out.strip().splitlines()[-1])
    return result["status"], result["modules"]


def _heavy(modules: list[str]) -> list[str]:
    return [m for m in modules if any(m == h or m.startswith(h + ".") for h in HEAVY)]


@pytest.mark.parametrize("argv", [["--help"], ["run", "--help"], ["show", "--help"],
                                  ["debug", "--help"], ["trace", "--help"],
                                  ["run", "x.awl", "--bogus"]])
def test_help_and_usage_errors_load_no_heavy_module(argv: list[str]) -> None:
    status, modules = _loaded(argv)
    assert status in (0, 1)
    assert _heavy(modules) == []


def test_import_plcrt_loads_no_engine() -> None:
    """``import plcrt`` (the pytest plugin, scripts) loads the engine on first
    use of plcrt.load / plcrt.Plc (PEP 562), not at import."""
    code = ("import json, sys, plcrt; before = sorted(sys.modules); plcrt.load; "
            "print(json.dumps([before, sorted(sys.modules)]))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    before, after = json.loads(out)
    assert _heavy(before) == []
    assert "plcrt.engine.runtime" in after and "lark" in after
