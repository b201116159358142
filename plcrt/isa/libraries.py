"""Interface descriptions of instruction libraries (``library/*.toml``).

A library file lists its instructions and, for each, the parameters in
call order with direction (IN/OUT), type, and whether the argument must be
an address or is written back by the block.  This module reads and
validates those files; it does not execute anything.  It lies in the
instruction set, below the compiler (which checks calls and names of
library instructions against it) and below the block registry
(:mod:`plcrt.blocks`, which runs them; :mod:`plcrt.blocks.interface`
re-exports it).
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from ..errors import PlcConfigError

TYPES = ("BOOL", "BYTE", "WORD", "INT", "DINT", "DWORD", "REAL")


@dataclass(frozen=True, slots=True)
class Param:
    name: str
    dir: str          #: "IN" or "OUT"
    type: str         #: one of TYPES
    address: bool     #: argument must be a memory address
    written: bool     #: an IN the block writes back
    pointer: bool     #: a DWORD that may be given as &address
    also: tuple[str, ...] = ()  #: other types an IN argument may have (read as that type)


@dataclass(frozen=True, slots=True)
class BlockInterface:
    name: str
    library: str
    summary: str
    params: tuple[Param, ...]

    @property
    def results(self) -> tuple[Param, ...]:
        """Parameters the block returns values for, in call order."""
        return tuple(p for p in self.params if p.dir == "OUT" or p.written)


def library_dirs() -> list[Path]:
    """Where library files are looked for: ``$PLCRT_LIBRARY_PATH`` entries,
    then the project's ``library/`` folder."""
    dirs = [Path(p) for p in os.environ.get("PLCRT_LIBRARY_PATH", "").split(os.pathsep) if p]
    dirs.append(Path(__file__).resolve().parents[2] / "library")
    return dirs


@lru_cache(maxsize=None)
def interfaces() -> dict[str, BlockInterface]:
    """All block interfaces by upper-case name.

    Raises:
        PlcConfigError: a library file is malformed.
    """
    out: dict[str, BlockInterface] = {}
    for d in library_dirs():
        if not d.is_dir():
            continue
        for f in sorted(d.glob("*.toml")):
            for itf in _read(f):
                out.setdefault(itf.name.upper(), itf)
    return out


def _read(path: Path) -> list[BlockInterface]:
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise PlcConfigError(f"{path}: cannot read library description: {e}") from None
    lib = str(data.get("library", {}).get("name", path.stem))
    result = []
    for entry in data.get("instruction", []):
        try:
            params = tuple(
                Param(str(p["name"]), str(p["dir"]).upper(), str(p["type"]).upper(),
                      bool(p.get("address", False)), bool(p.get("written", False)),
                      bool(p.get("pointer", False)),
                      tuple(str(t).upper() for t in p.get("also", ())))
                for p in entry["params"])
            name = str(entry["name"])
        except (KeyError, TypeError) as e:
            raise PlcConfigError(f"{path}: instruction entry is missing {e}") from None
        for p in params:
            if p.dir not in ("IN", "OUT") or p.type not in TYPES \
                    or any(t not in TYPES for t in p.also) or (p.also and p.dir != "IN"):
                raise PlcConfigError(f"{path}: {name}.{p.name}: bad dir/type {p.dir}/{p.type}")
        result.append(BlockInterface(name, lib, str(entry.get("summary", "")), params))
    return result


__all__ = ["TYPES", "BlockInterface", "Param", "interfaces", "library_dirs"]
