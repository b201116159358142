"""Shared test set-up: makes the helper modules in ``tests/`` importable
(``stl_helpers``, ``reference_interp``) from the mirrored sub-folders."""

from __future__ import annotations

import sys
from pathlib import Path

_TESTS = str(Path(__file__).resolve().parent)
if _TESTS not in sys.path:
    sys.path.insert(0, _TESTS)
