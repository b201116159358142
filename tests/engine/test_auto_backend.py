"""``backend="auto"``, the default of plcrt.load, every command, the
pytest plugin and the panel: native where llvmlite imports and works,
Python otherwise, with one line saying so once per process (on the
``plcrt`` logger: a command's stderr; in a pytest run only when asked).

Where llvmlite is missing is made real here: a directory on PYTHONPATH
whose ``llvmlite`` package fails to import, in a fresh interpreter.
"""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest

import plcrt
from plcrt.compiler.cache import programs
from plcrt.compiler.native import jit

pytest_plugins = ["pytester"]

PROGRAM = ("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNetwork 1\nLD I0.0\n= Q0.0\n"
           "END_ORGANIZATION_BLOCK\n")
LINE = ("plcrt: the native backend is not available (llvmlite is not installed); "
        "running on the Python backend")


@pytest.fixture(autouse=True)
def _empty_disk_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """No machine code, and no mark of it, left on disk by another test
    (a load of a marked program is native from the first scan)."""
    monkeypatch.setenv("PLCRT_CACHE_DIR", str(tmp_path / "cache"))


@pytest.fixture
def no_llvmlite(tmp_path: Path) -> dict[str, str]:
    """An environment whose ``import llvmlite`` fails."""
    fake = tmp_path / "hide" / "llvmlite"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('no llvmlite here')\n")
    env = dict(os.environ)
    env.pop("PLCRT_BACKEND", None)
    env["PYTHONPATH"] = os.pathsep.join([str(fake.parent), env.get("PYTHONPATH", "")])
    return env


def test_auto_is_the_default_and_native_where_llvmlite_works(
        monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture) -> None:
    monkeypatch.delenv("PLCRT_BACKEND", raising=False)
    assert jit.usable() is None
    with caplog.at_level(logging.INFO, logger="plcrt"):
        programs.clear()
        plc = plcrt.load(PROGRAM)             # Python first (engine/tiering.py)
        assert plc.backend == {"name": "python", "tiered": True, "python_scans": 0}
        plc._tier_up()
        assert plc.backend["name"] == "native" and plc.backend["pieces"] == 1
        # the machine code is on disk now: a later load (another process:
        # the program cache emptied) binds it at once
        programs.clear()
        again = plcrt.load(PROGRAM, backend="auto")
        assert again.backend["name"] == "native" and again.backend["cached"]
        assert again.backend["tiered"] and again.backend["python_scans"] == 0
    assert caplog.records == []          # nothing to say when native runs
    assert plcrt.load(PROGRAM, backend="python").backend == {"name": "python"}
    monkeypatch.setenv("PLCRT_BACKEND", "python")
    assert plcrt.load(PROGRAM).backend == {"name": "python"}


def test_a_stale_mark_costs_one_native_compile_and_no_cache_follows_no_mark(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A mark whose machine code is gone (trimmed, another llvmlite): the
    load compiles the native build before its first scan and keeps it on
    disk; with PLCRT_NATIVE_CACHE_MB=0 a mark is not followed."""
    programs.clear()
    plc = plcrt.load(PROGRAM, backend="auto")
    plc._tier_up()
    folder = tmp_path / "cache" / "native"
    marks = [f for f in folder.iterdir() if b"plcrt tier mark" in f.read_bytes()]
    assert len(marks) == 1
    for f in folder.iterdir():
        if f not in marks:
            f.unlink()                   # the machine code gone, the mark kept
    programs.clear()
    again = plcrt.load(PROGRAM, backend="auto")
    assert again.backend["name"] == "native" and not again.backend["cached"]
    assert again.backend["python_scans"] == 0
    assert len(list(folder.iterdir())) == 2       # the machine code kept again
    programs.clear()
    monkeypatch.setenv("PLCRT_NATIVE_CACHE_MB", "0")
    assert plcrt.load(PROGRAM, backend="auto").backend == {
        "name": "python", "tiered": True, "python_scans": 0}


def test_a_bad_backend_names_the_choices() -> None:
    with pytest.raises(plcrt.PlcConfigError, match="'auto', 'python', 'native'"):
        plcrt.load(PROGRAM, backend="fast")


def test_without_llvmlite_auto_runs_python_and_says_so_once(
        no_llvmlite: dict[str, str]) -> None:
    code = ("import plcrt\n"
            f"text = {PROGRAM!r}\n"
            "names = [plcrt.load(text, scan_ms=s).backend['name'] for s in (10, 20, 30)]\n"
            "print(names)\n"
            "try:\n"
            "    plcrt.load(text, backend='native')\n"
            "except plcrt.PlcConfigError as e:\n"
            "    print('refused')\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=no_llvmlite, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["['python', 'python', 'python']", "refused"]
    assert done.stderr.splitlines() == [LINE]


def test_a_command_without_llvmlite_says_it_in_one_line(
        tmp_path: Path, no_llvmlite: dict[str, str]) -> None:
    prog = tmp_path / "p.awl"
    prog.write_text(PROGRAM)
    done = subprocess.run([sys.executable, "-m", "plcrt", "run", str(prog), "--scans", "2",
                           "--json", "--set", "I0.0=1", "--watch", "Q0.0"],
                          capture_output=True, text=True, env=no_llvmlite, timeout=120)
    assert done.returncode == 0, done.stderr
    assert '"backend": "python"' in done.stdout and '"Q0.0": 1' in done.stdout
    assert done.stderr.splitlines() == [LINE]


def test_pytest_output_has_the_line_only_when_asked(
        pytester: pytest.Pytester, no_llvmlite: dict[str, str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    for key, value in no_llvmlite.items():
        monkeypatch.setenv(key, value)
    pytester.makefile(".awl", prog=PROGRAM)
    pytester.makepyfile(test_p="""\
import pytest


@pytest.mark.plc("prog.awl")
def test_q(plc):
    assert plc.backend["name"] == "python"
    plc["I0.0"] = 1
    plc.scan()
    assert plc["Q0.0"] == 1
""")
    quiet = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-p", "no:hypothesispytest")
    quiet.assert_outcomes(passed=1)
    assert "native backend is not available" not in quiet.stdout.str() + quiet.stderr.str()
    asked = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-p", "no:hypothesispytest",
                                          "--log-cli-level=WARNING")
    asked.assert_outcomes(passed=1)
    assert asked.stdout.str().count("native backend is not available") == 1
