"""The narrow interfaces the drive hands its parts (drive_view.py).

The mode engines (modes.py) and the mechanical ends (stops.py) use of
their drive exactly what ModeDrive / StopsDrive name, and a Drive has all
of it; so they depend on drive_view.py, never on drive.py.
"""

from __future__ import annotations

import ast
from pathlib import Path

from plcrt.devices.cia402.drive import Drive
from plcrt.devices.cia402.drive_view import ModeDrive, StopsDrive
from plcrt.devices.cia402.plant import DrivePlant

CIA402 = Path(__file__).resolve().parents[3] / "plcrt" / "devices" / "cia402"


def _members(proto: type) -> set[str]:
    names: set[str] = set()
    for cls in proto.__mro__:
        if cls.__module__ == proto.__module__:
            names |= set(getattr(cls, "__annotations__", {}))
            names |= {n for n, v in vars(cls).items() if callable(v) and not n.startswith("__")}
    return names


def _used(module: str) -> set[str]:
    """Attributes read of the drive in *module*: ``self.d.x``, ``d.x``, ``drive.x``."""
    tree = ast.parse((CIA402 / module).read_text(encoding="utf-8"))
    out = set()
    for n in ast.walk(tree):
        if not isinstance(n, ast.Attribute):
            continue
        v = n.value
        if (isinstance(v, ast.Name) and v.id in ("d", "drive")) or (
                isinstance(v, ast.Attribute) and v.attr == "d"
                and isinstance(v.value, ast.Name) and v.value.id == "self"):
            out.add(n.attr)
    return out


def test_the_modes_use_what_mode_drive_names() -> None:
    assert _used("modes.py") == _members(ModeDrive)


def test_the_stops_use_only_what_stops_drive_names() -> None:
    assert _used("stops.py") <= _members(StopsDrive)
    assert _members(ModeDrive) < _members(StopsDrive)


def test_a_drive_has_everything_its_parts_see() -> None:
    d = Drive("hcfa-am0520b", plant=DrivePlant(neg_stop=-10_000, pos_stop=10_000))
    assert d.stops is not None
    missing = sorted(n for n in _members(StopsDrive) if not hasattr(d, n))
    assert missing == []
