"""Helpers for tests that build small STL programs (not collected: the name
does not start with ``test_``)."""

from __future__ import annotations

from pathlib import Path

import pytest

import plcrt

#: the real-file corpus beside the repository (read where it is, never copied)
CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "corpus"


def corpus_awl_params() -> list:
    """The corpus's ``.awl`` files as pytest parameters (named by file), or
    one skipped parameter saying where the corpus was looked for."""
    files = sorted(CORPUS.glob("*.awl")) if CORPUS.is_dir() else []
    if not files:
        return [pytest.param(None, marks=pytest.mark.skip(reason=f"corpus not found at {CORPUS}"))]
    return [pytest.param(f, id=f.name) for f in files]


def ob1_text(*networks: str) -> str:
    """An OB1 made of ``networks`` (each a block of STL lines, one network each)."""
    lines = ["ORGANIZATION_BLOCK OB1", "BEGIN"]
    for i, net in enumerate(networks, 1):
        lines.append(f"Network {i}")
        lines.extend(ln.strip() for ln in net.strip().splitlines())
    lines.append("END_ORGANIZATION_BLOCK")
    return "\n".join(lines) + "\n"


def load_ob1(*networks: str, scan_ms: float = 10.0) -> plcrt.Plc:
    """Load :func:`ob1_text` of ``networks``."""
    return plcrt.load(ob1_text(*networks), scan_ms=scan_ms)
