"""How to install an optional extra of plcrt (``plot``, ``native``), said
the way that works for this installation.

An install hint that says ``pip install 'plcrt[plot]'`` is wrong for the
README's own set-up, an editable install of a clone into ``.venv``: pip
would fetch a second plcrt from the index, if there is one.  So the hint
names the interpreter running plcrt and, for a source checkout, the
checkout itself.  This module only builds the text; it installs nothing.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

#: where the README explains the set-up and the extras
DOCS = "README.md, 'Quick start'"


def _shown(path: str) -> str:
    """``path`` relative to the working directory when it is under it."""
    try:
        rel = os.path.relpath(path)
    except ValueError:     # another drive (Windows)
        return path
    return path if rel.startswith("..") else rel


def install_command(extra: str) -> str:
    """The command that installs the ``extra`` into the running interpreter:
    ``.venv/bin/python -m pip install -e '.[plot]'`` for a source checkout
    (an editable install, as the README sets it up), ``... pip install
    'plcrt[plot]'`` for an installed package."""
    python = _shown(sys.executable) if sys.executable else "python"
    if sys.executable and os.sep not in python:
        python = os.path.join(".", python)   # not a name the shell looks up on PATH
    root = Path(__file__).resolve().parent.parent
    if (root / "pyproject.toml").is_file() and (root / "plcrt" / "cli.py").is_file():
        target = _shown(str(root))
        return f"{python} -m pip install -e '{'.' if target == '.' else target}[{extra}]'"
    return f"{python} -m pip install 'plcrt[{extra}]'"


def install_hint(what: str, extra: str) -> str:
    """``<what>; install the extra: <command> (README.md, 'Quick start')``."""
    return f"{what}; install the '{extra}' extra: {install_command(extra)} ({DOCS})"


__all__ = ["DOCS", "install_command", "install_hint"]
