"""Helpers for tests that build small STL programs (not collected: the name
does not start with ``test_``)."""

from __future__ import annotations

import plcrt


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
