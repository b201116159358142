"""``make setup`` installs plcrt without setuptools deprecation warnings.

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
