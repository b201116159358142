"""What ``make`` installs: plcrt without setuptools deprecation warnings;
``make demo`` only what running needs, ``make test`` the test extra too
(after a ``make demo``, only the test extra).

setuptools 77 deprecated ``project.license`` as a TOML table
(``{ text = "MIT" }``) in favour of an SPDX expression string, and warns
about the table three times per install (builds fail from 2027-02-18).
The fix is in ``pyproject.toml``: an SPDX string, and a build requirement
on the setuptools that understands it.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from packaging.licenses import canonicalize_license_expression
from packaging.requirements import Requirement
from packaging.version import Version

ROOT = Path(__file__).resolve().parents[2]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_license_is_an_spdx_expression() -> None:
    license = PYPROJECT["project"]["license"]
    assert isinstance(license, str), "a TOML table here is deprecated by setuptools 77"
    assert canonicalize_license_expression(license) == license


def test_build_requires_a_setuptools_that_takes_spdx_licenses() -> None:
    reqs = [Requirement(r) for r in PYPROJECT["build-system"]["requires"]]
    setuptools = next(r for r in reqs if r.name == "setuptools")
    # the oldest setuptools the requirement admits must know SPDX strings
    floor = min(Version(s.version) for s in setuptools.specifier if s.operator == ">=")
    assert floor >= Version("77")


def test_make_setup_keeps_pip_quiet() -> None:
    """pip runs with -qq: only errors are printed, so the demo starts at once
    (the editable install's information notice is not an error)."""
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    installs = re.findall(r"^\t.*pip install.*$", makefile, flags=re.M)
    assert installs and all(" -qq " in line for line in installs)


# ---------------------------------------------------------------------------
# What each make target installs (make -n: the commands, none of them run)
# ---------------------------------------------------------------------------

def _make_n(target: str, venv: Path) -> list[str]:
    import subprocess
    out = subprocess.run(["make", "-n", "-C", str(ROOT), f"VENV={venv}", target],
                         capture_output=True, text=True, check=True).stdout
    return [line for line in out.splitlines() if "pip install" in line]


def _stamp(venv: Path, name: str) -> None:
    import os
    path = venv / "bin" / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.touch()
    later = (ROOT / "pyproject.toml").stat().st_mtime + 10
    os.utime(path, (later, later))


def test_make_demo_installs_what_running_needs(tmp_path: Path) -> None:
    """The demo installs plcrt and its dependencies (llvmlite among them),
    not the test extra (pytest, hypothesis, matplotlib, playwright: hundreds
    of MB)."""
    installs = _make_n("demo", tmp_path / "venv")
    assert any(line.endswith("pip install -qq -e .") for line in installs)
    assert not any("[test]" in line or "[native]" in line for line in installs)


def test_make_demo_runs_only_what_it_installed() -> None:
    """The demo runs on the default backend (native where llvmlite works,
    else Python): no line names a backend."""
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    demo = makefile.split("\ndemo:", 1)[1].split("\n\n", 1)[0]
    assert "plcrt run" in demo and "--backend" not in demo


def test_make_test_from_a_fresh_clone_installs_the_test_extra(tmp_path: Path) -> None:
    installs = _make_n("test", tmp_path / "venv")
    assert any(line.endswith("pip install -qq -e .") for line in installs)
    assert any(line.endswith("pip install -qq -e '.[test]'") for line in installs)


def test_make_test_after_make_demo_adds_only_the_test_extra(tmp_path: Path) -> None:
    venv = tmp_path / "venv"
    _stamp(venv, ".installed")          # what make demo left
    installs = _make_n("test", venv)
    assert installs and all(line.endswith("pip install -qq -e '.[test]'")
                            for line in installs)
    _stamp(venv, ".installed-test")     # and after make test: nothing to install
    assert _make_n("test", venv) == [] and _make_n("demo", venv) == []
