"""Install hints give the command that works for how plcrt is installed:
from a source checkout (the README's editable install into .venv) the
checkout itself, ``python -m pip install -e '.[plot]'``, never
``pip install 'plcrt[plot]'``, which would fetch another plcrt; from an
installed package the package name.  Always with the running interpreter."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

import plcrt.extras
from plcrt.extras import install_command, install_hint

ROOT = Path(__file__).resolve().parents[2]


def test_from_the_checkout_root_the_hint_is_the_editable_install(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr(sys, "executable", str(ROOT / ".venv" / "bin" / "python"))
    assert install_command("plot") == \
        f"{os.path.join('.venv', 'bin', 'python')} -m pip install -e '.[plot]'"


def test_elsewhere_the_checkout_is_named_by_its_path(monkeypatch: pytest.MonkeyPatch,
                                                     tmp_path: Path) -> None:
    monkeypatch.chdir(tmp_path)
    cmd = install_command("native")
    assert cmd == f"{sys.executable} -m pip install -e '{ROOT}[native]'"


def test_an_installed_package_names_the_extra(monkeypatch: pytest.MonkeyPatch,
                                              tmp_path: Path) -> None:
    site = tmp_path / "site-packages" / "plcrt"
    site.mkdir(parents=True)
    monkeypatch.setattr(plcrt.extras, "__file__", str(site / "extras.py"))
    monkeypatch.chdir(tmp_path)
    assert install_command("plot") == f"{sys.executable} -m pip install 'plcrt[plot]'"


def test_the_plot_hint(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    hint = install_hint("plotting needs matplotlib, which is not installed", "plot")
    assert hint.startswith("plotting needs matplotlib, which is not installed; install the "
                           "'plot' extra: ")
    assert hint.endswith(" -m pip install -e '.[plot]' (README.md, 'Quick start')")
    assert "pip install 'plcrt[plot]'" not in hint
